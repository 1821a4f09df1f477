//! The scene reference (`docs/guide/scene-reference.md`, `pfem-mpi schema`) generated from the
//! scene schema's own source: every table and key with its type, whether it is required, and
//! its doc comment, which states the unit, the default and the rule. Generated at build time so
//! that the reference cannot drift from the code: a key added with a doc comment appears, and
//! CI compares the committed file with this output.

use std::collections::HashMap;
use std::fmt::Write as _;
use syn::{Attribute, Fields, Item, Type};

/// The schema's sources, in the order their items are searched.
pub const SOURCES: &[&str] = &["src/scene/schema.rs", "src/scene/rigid.rs"];

struct Field {
    key: String,
    ty: Type,
    doc: String,
    defaulted: bool,
}

struct Struct {
    doc: String,
    fields: Vec<Field>,
}

struct Enum {
    values: Vec<(String, String)>,
}

fn doc_of(attrs: &[Attribute]) -> String {
    let lines: Vec<String> = attrs
        .iter()
        .filter(|a| a.path().is_ident("doc"))
        .filter_map(|a| match &a.meta {
            syn::Meta::NameValue(nv) => match &nv.value {
                syn::Expr::Lit(syn::ExprLit {
                    lit: syn::Lit::Str(s),
                    ..
                }) => Some(s.value().trim().to_string()),
                _ => None,
            },
            _ => None,
        })
        .collect();
    lines.join(" ").trim().to_string()
}

/// The `#[serde(...)]` settings this generator reads: rename, rename_all, default, skip.
#[derive(Default)]
struct Serde {
    rename: Option<String>,
    rename_all: Option<String>,
    default: bool,
    skip: bool,
    deserializes: bool,
}

fn serde_of(attrs: &[Attribute]) -> Serde {
    let mut s = Serde::default();
    for a in attrs {
        if a.path().is_ident("derive") {
            s.deserializes |= quote_text(&a.meta).contains("Deserialize");
        }
        if !a.path().is_ident("serde") {
            continue;
        }
        let _ = a.parse_nested_meta(|m| {
            let name = m
                .path
                .get_ident()
                .map(|i| i.to_string())
                .unwrap_or_default();
            let value = if m.input.peek(syn::Token![=]) {
                let lit: syn::LitStr = m.value()?.parse()?;
                Some(lit.value())
            } else {
                None
            };
            match name.as_str() {
                "rename" => s.rename = value,
                "rename_all" => s.rename_all = value,
                "default" => s.default = true,
                "skip" => s.skip = true,
                _ => {}
            }
            Ok(())
        });
    }
    s
}

fn quote_text<T: quote::ToTokens>(t: &T) -> String {
    t.to_token_stream().to_string()
}

fn renamed(ident: &str, rule: Option<&str>) -> String {
    let words: Vec<String> = {
        let mut w = Vec::new();
        let mut cur = String::new();
        for c in ident.chars() {
            if c.is_uppercase() && !cur.is_empty() {
                w.push(std::mem::take(&mut cur));
            }
            cur.push(c.to_ascii_lowercase());
        }
        w.push(cur);
        w
    };
    match rule {
        Some("kebab-case") => words.join("-"),
        Some("snake_case") => words.join("_"),
        Some("lowercase") => words.concat(),
        _ => ident.to_string(),
    }
}

type Items = (HashMap<String, Struct>, HashMap<String, Enum>);

/// Every deserialised struct and enum of the sources, by type name.
fn collect(sources: &[String]) -> Result<Items, String> {
    let (mut structs, mut enums) = (HashMap::new(), HashMap::new());
    for text in sources {
        let file = syn::parse_file(text).map_err(|e| e.to_string())?;
        for item in file.items {
            match item {
                Item::Struct(s) => {
                    let Fields::Named(named) = &s.fields else {
                        continue;
                    };
                    let attrs = serde_of(&s.attrs);
                    if !attrs.deserializes {
                        continue;
                    }
                    let fields = named
                        .named
                        .iter()
                        .filter_map(|f| {
                            let a = serde_of(&f.attrs);
                            let ident = f.ident.as_ref()?.to_string();
                            (!a.skip).then(|| Field {
                                key: a.rename.unwrap_or(ident),
                                ty: f.ty.clone(),
                                doc: doc_of(&f.attrs),
                                defaulted: a.default || attrs.default,
                            })
                        })
                        .collect();
                    let doc = doc_of(&s.attrs);
                    structs.insert(s.ident.to_string(), Struct { doc, fields });
                }
                Item::Enum(e) => {
                    let attrs = serde_of(&e.attrs);
                    if !attrs.deserializes {
                        continue;
                    }
                    let values = e
                        .variants
                        .iter()
                        .map(|v| {
                            let a = serde_of(&v.attrs);
                            let name = a.rename.unwrap_or_else(|| {
                                renamed(&v.ident.to_string(), attrs.rename_all.as_deref())
                            });
                            (name, doc_of(&v.attrs))
                        })
                        .collect();
                    enums.insert(e.ident.to_string(), Enum { values });
                }
                _ => {}
            }
        }
    }
    Ok((structs, enums))
}

/// `Option<T>` → (T, true); other types unchanged.
fn unwrap_generic<'a>(ty: &'a Type, outer: &str) -> Option<&'a Type> {
    let Type::Path(p) = ty else { return None };
    let seg = p.path.segments.last()?;
    if seg.ident != outer {
        return None;
    }
    let syn::PathArguments::AngleBracketed(args) = &seg.arguments else {
        return None;
    };
    match args.args.first()? {
        syn::GenericArgument::Type(t) => Some(t),
        _ => None,
    }
}

fn type_name(ty: &Type) -> Option<String> {
    match ty {
        Type::Path(p) => p.path.segments.last().map(|s| s.ident.to_string()),
        _ => None,
    }
}

/// A reader's name for a type.
fn describe(ty: &Type, enums: &HashMap<String, Enum>) -> String {
    if let Some(t) = unwrap_generic(ty, "Option") {
        return describe(t, enums);
    }
    if let Some(t) = unwrap_generic(ty, "Vec") {
        return match describe(t, enums).as_str() {
            "table" => "list of tables".to_string(),
            inner => format!("list of {inner}"),
        };
    }
    if let Type::Array(a) = ty {
        let inner = describe(&a.elem, enums);
        let n = quote_text(&a.len);
        return format!("[{}]", vec![inner; n.parse().unwrap_or(2)].join(", "));
    }
    let name = type_name(ty).unwrap_or_else(|| quote_text(ty));
    if let Some(e) = enums.get(&name) {
        let values: Vec<String> = e.values.iter().map(|(v, _)| format!("\"{v}\"")).collect();
        return values.join(" or ");
    }
    match name.as_str() {
        "f64" => "number".into(),
        "u32" | "u64" | "usize" => "integer".into(),
        "bool" => "boolean".into(),
        "String" => "string".into(),
        "Selector" => "string (\"x <= 1 and y >= 2\")".into(),
        "Materials" => "table or list of tables".into(),
        _ => "table".into(),
    }
}

/// The struct a field's value is a table (or list of tables) of, if any.
fn table_of(ty: &Type, structs: &HashMap<String, Struct>) -> Option<(String, bool)> {
    if let Some(t) = unwrap_generic(ty, "Option") {
        return table_of(t, structs);
    }
    if let Some(t) = unwrap_generic(ty, "Vec") {
        return table_of(t, structs).map(|(n, _)| (n, true));
    }
    let name = type_name(ty)?;
    if name == "Materials" {
        return Some(("Material".into(), true));
    }
    structs.contains_key(&name).then_some((name, false))
}

fn cell(text: &str) -> String {
    text.replace('|', "\\|")
}

/// The reference as Markdown, from the sources' texts (in [`SOURCES`] order).
pub fn generate(sources: &[String]) -> Result<String, String> {
    let (structs, enums) = collect(sources)?;
    let mut out = String::new();
    out.push_str(
        "# Scene reference\n\n\
         Every table and key of a scene file, generated from the doc comments of the scene \
         schema (`src/scene/schema.rs`, `src/scene/rigid.rs`) by `pfem-mpi schema`. Do not \
         edit it by hand: CI fails when it differs from what the code generates (regenerate \
         with `pfem-mpi schema > docs/guide/scene-reference.md`).\n\n\
         *Required* keys have no default; an optional key's default and unit are in its \
         description. Unknown keys are errors.\n",
    );
    let mut queue: Vec<(String, String, bool)> = vec![("Scene".into(), String::new(), false)];
    let mut seen = std::collections::HashSet::new();
    while !queue.is_empty() {
        let (name, path, many) = queue.remove(0);
        let Some(s) = structs.get(&name) else {
            continue;
        };
        if !seen.insert(path.clone()) {
            continue;
        }
        let title = match (path.is_empty(), many) {
            (true, _) => "The top level".to_string(),
            (false, true) => format!("`[[{path}]]`"),
            (false, false) => format!("`[{path}]`"),
        };
        let _ = writeln!(out, "\n## {title}\n");
        if !s.doc.is_empty() {
            let _ = writeln!(out, "{}\n", s.doc);
        }
        out.push_str("| key | type | | description |\n|---|---|---|---|\n");
        let mut nested = Vec::new();
        for f in &s.fields {
            let optional = f.defaulted || unwrap_generic(&f.ty, "Option").is_some();
            let required = if optional { "optional" } else { "required" };
            let mut doc = f.doc.clone();
            let ty = describe(&f.ty, &enums);
            if let Some((inner, list)) = table_of(&f.ty, &structs) {
                let child = if path.is_empty() {
                    f.key.clone()
                } else {
                    format!("{path}.{}", f.key)
                };
                let shown = if list {
                    format!("[[{child}]]")
                } else {
                    format!("[{child}]")
                };
                doc = format!("{doc} See `{shown}`.").trim().to_string();
                nested.push((inner, child, list));
            }
            if let Some(e) = type_name(unwrap_generic(&f.ty, "Option").unwrap_or(&f.ty))
                .and_then(|n| enums.get(&n))
            {
                let values: Vec<String> = e
                    .values
                    .iter()
                    .filter(|(_, d)| !d.is_empty())
                    .map(|(v, d)| format!("\"{v}\": {d}"))
                    .collect();
                if !values.is_empty() && !doc.contains(&values[0]) {
                    doc = format!("{doc} Values: {}", values.join("; "));
                }
            }
            let _ = writeln!(
                out,
                "| `{}` | {} | {required} | {} |",
                f.key,
                cell(&ty),
                cell(&doc)
            );
        }
        queue.extend(nested);
    }
    Ok(out)
}
