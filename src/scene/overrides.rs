//! `--set a.b.c=value` overrides, applied to the TOML value tree before deserialization so that
//! an override goes through exactly the same type checks and validation as the scene file.
//!
//! Paths are dotted keys with optional array indices: `mesh.h=0.25`,
//! `point_load[0].force=[0.0, -5.0e4]`, `material.model=tresca`. The value is read as a TOML
//! value; a bare word that is not valid TOML (`tresca`) is taken as a string.

use toml::Value;

use super::field_path::{FieldPath, Segment};

/// A parsed `--set` argument.
#[derive(Debug, Clone)]
pub struct SetArg {
    /// The argument as given, for error messages.
    pub raw: String,
    pub path: FieldPath,
    pub value: Value,
}

fn parse_path(text: &str) -> Result<FieldPath, String> {
    let mut segs = Vec::new();
    for part in text.split('.') {
        let part = part.trim();
        let (key, mut rest) = match part.find('[') {
            Some(pos) => (&part[..pos], &part[pos..]),
            None => (part, ""),
        };
        if key.is_empty() {
            return Err(format!("empty key in path \"{text}\""));
        }
        segs.push(Segment::Key(key.to_string()));
        while !rest.is_empty() {
            let close = rest
                .find(']')
                .filter(|_| rest.starts_with('['))
                .ok_or_else(|| format!("malformed index in path \"{text}\""))?;
            let index: usize = rest[1..close].trim().parse().map_err(|_| {
                format!(
                    "index \"{}\" in path \"{text}\" is not a whole number",
                    &rest[1..close]
                )
            })?;
            segs.push(Segment::Index(index));
            rest = &rest[close + 1..];
        }
    }
    Ok(FieldPath(segs))
}

fn parse_value(text: &str) -> Result<Value, String> {
    let text = text.trim();
    // The value is parsed as the line `v = VALUE`: a line break would let it go on with more
    // `key = value` lines, which were silently dropped.
    if text.contains(['\n', '\r']) {
        return Err(format!(
            "the value {text:?} contains a line break; give one value, on one line, per --set"
        ));
    }
    match format!("v = {text}").parse::<toml::Table>() {
        Ok(mut t) => t
            .remove("v")
            .ok_or_else(|| format!("cannot read value \"{text}\"")),
        Err(e) => {
            // Something that starts like a number, array, table or quoted string was meant as
            // one; only a bare word falls back to a string.
            let looks_typed = text
                .chars()
                .next()
                .is_none_or(|c| c.is_ascii_digit() || "+-.[{\"'".contains(c));
            if looks_typed {
                Err(format!("cannot read value \"{text}\": {}", e.message()))
            } else {
                Ok(Value::String(text.to_string()))
            }
        }
    }
}

impl SetArg {
    /// Parses `path=value`.
    pub fn parse(raw: &str) -> Result<SetArg, String> {
        let (path, value) = raw
            .split_once('=')
            .ok_or_else(|| "expected KEY=VALUE, e.g. mesh.h=0.25".to_string())?;
        Ok(SetArg {
            raw: raw.to_string(),
            path: parse_path(path)?,
            value: parse_value(value)?,
        })
    }

    /// Stores the value in the tree, creating missing tables along the way (a key the schema
    /// does not have is then reported by deserialization, naming the path). Fails with the path
    /// prefix at fault when the tree's shape does not allow the path.
    pub fn apply(&self, root: &mut toml::Table) -> Result<(), (FieldPath, String)> {
        let segs = &self.path.0;
        let mut node: &mut Value = match segs.first() {
            Some(Segment::Key(k)) => root
                .entry(k.clone())
                .or_insert_with(|| Value::Table(toml::Table::new())),
            _ => return Err((FieldPath::default(), "empty path".to_string())),
        };
        for (depth, seg) in segs.iter().enumerate().skip(1) {
            let here = FieldPath(segs[..depth].to_vec());
            node = match (seg, node) {
                (Segment::Key(k), Value::Table(t)) => t
                    .entry(k.clone())
                    .or_insert_with(|| Value::Table(toml::Table::new())),
                (Segment::Index(i), Value::Array(items)) => {
                    let len = items.len();
                    items.get_mut(*i).ok_or_else(|| {
                        (
                            here.at(*i),
                            format!("index {i} is out of range: {here} has {len} entries"),
                        )
                    })?
                }
                (Segment::Key(_), _) => {
                    return Err((here.clone(), format!("{here} is not a table")));
                }
                (Segment::Index(_), _) => {
                    return Err((here.clone(), format!("{here} is not an array")));
                }
            };
        }
        *node = self.value.clone();
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_paths_with_indices() {
        let s = SetArg::parse("point_load[0].force=[0.0, -5.0e4]").unwrap();
        assert_eq!(s.path.to_string(), "point_load[0].force");
        assert_eq!(s.value.as_array().unwrap().len(), 2);
    }

    #[test]
    fn values_are_typed_and_bare_words_are_strings() {
        assert_eq!(
            SetArg::parse("mesh.h=0.25").unwrap().value,
            Value::Float(0.25)
        );
        assert_eq!(
            SetArg::parse("steps.count=20").unwrap().value,
            Value::Integer(20)
        );
        assert_eq!(
            SetArg::parse("mesh.refine=false").unwrap().value,
            Value::Boolean(false)
        );
        assert_eq!(
            SetArg::parse("material.model=tresca").unwrap().value,
            Value::String("tresca".to_string())
        );
        assert!(SetArg::parse("mesh.h=0.2.5").is_err());
        assert!(SetArg::parse("mesh.h").is_err());
        assert!(SetArg::parse("mesh..h=1").is_err());
    }

    #[test]
    fn apply_creates_tables_and_indexes_arrays() {
        let mut t: toml::Table = "[[fixed]]\nwhere = \"x <= 0\"\ndofs = [\"x\"]"
            .parse()
            .unwrap();
        SetArg::parse("gravity.g=[0.0, -9.81]")
            .unwrap()
            .apply(&mut t)
            .unwrap();
        SetArg::parse("fixed[0].dofs=[\"y\"]")
            .unwrap()
            .apply(&mut t)
            .unwrap();
        assert_eq!(t["gravity"]["g"][1].as_float(), Some(-9.81));
        assert_eq!(t["fixed"][0]["dofs"][0].as_str(), Some("y"));
        let (path, msg) = SetArg::parse("fixed[3].dofs=[\"y\"]")
            .unwrap()
            .apply(&mut t)
            .unwrap_err();
        assert_eq!(path.to_string(), "fixed[3]");
        assert!(msg.contains("out of range"), "{msg}");
    }
}
