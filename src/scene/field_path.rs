//! Dotted paths naming a field of the scene document (`mesh.h`, `fixed[0].where`), shared by the
//! deserializer, the `--set` overrides and validation so that every error names its field the
//! same way.

use std::fmt;

/// One step of a field path: a table key or an array index.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Segment {
    Key(String),
    Index(usize),
}

/// Path from the document root to a field.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct FieldPath(pub Vec<Segment>);

impl FieldPath {
    pub fn key(name: &str) -> Self {
        FieldPath(vec![Segment::Key(name.to_string())])
    }

    /// `self` extended by a key, for building paths during validation.
    pub fn join(&self, name: &str) -> Self {
        let mut out = self.clone();
        out.0.push(Segment::Key(name.to_string()));
        out
    }

    /// `self` extended by an array index.
    pub fn at(&self, index: usize) -> Self {
        let mut out = self.clone();
        out.0.push(Segment::Index(index));
        out
    }

    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }

    /// True when one path is an ancestor of (or equal to) the other.
    pub fn overlaps(&self, other: &FieldPath) -> bool {
        self.0.iter().zip(other.0.iter()).all(|(a, b)| a == b)
    }
}

impl fmt::Display for FieldPath {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, seg) in self.0.iter().enumerate() {
            match seg {
                Segment::Key(k) if i == 0 => write!(f, "{k}")?,
                Segment::Key(k) => write!(f, ".{k}")?,
                Segment::Index(n) => write!(f, "[{n}]")?,
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn display_mixes_keys_and_indices() {
        let p = FieldPath::key("body").join("rectangles").at(1).join("size");
        assert_eq!(p.to_string(), "body.rectangles[1].size");
    }

    #[test]
    fn overlap_is_prefix_either_way() {
        let a = FieldPath::key("mesh");
        let b = FieldPath::key("mesh").join("h");
        assert!(a.overlaps(&b) && b.overlaps(&a));
        assert!(!b.overlaps(&FieldPath::key("mesh").join("alpha")));
    }
}
