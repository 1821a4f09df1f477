//! A serde deserializer over a `toml::Value` tree that remembers the path of the field where
//! deserialization failed.
//!
//! The scene is deserialized from the value tree (not from text) because `--set` overrides are
//! applied to the tree first; the tree carries no source spans, and toml's own value
//! deserializer reports keys only as free text. Engineers need to be told exactly which key is
//! wrong, in the same `a.b[0].c` form that `--set` accepts.

use std::fmt;

use serde::de::{self, DeserializeSeed, Expected, Unexpected, Visitor};
use serde::forward_to_deserialize_any;
use toml::Value;

use super::field_path::{FieldPath, Segment};

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DeErrorKind {
    /// A key that the schema does not have (usually a typo).
    UnknownKey,
    /// A required key is absent.
    MissingKey,
    /// A key is present with a value of the wrong type or out of range for its type.
    Invalid,
}

/// Deserialization failure at `path`.
#[derive(Debug, Clone)]
pub struct DeError {
    pub path: FieldPath,
    pub kind: DeErrorKind,
    pub message: String,
}

impl DeError {
    fn prefixed(mut self, seg: Segment) -> Self {
        self.path.0.insert(0, seg);
        self
    }

    fn invalid(message: String) -> Self {
        DeError {
            path: FieldPath::default(),
            kind: DeErrorKind::Invalid,
            message,
        }
    }
}

impl fmt::Display for DeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.path.is_empty() {
            write!(f, "{}", self.message)
        } else {
            write!(f, "field {}: {}", self.path, self.message)
        }
    }
}

impl std::error::Error for DeError {}

/// serde's descriptions speak Rust (`f64`, `usize`, `struct Mesh`); the users speak TOML.
fn describe_expected(exp: &dyn Expected) -> String {
    let text = exp.to_string();
    match text.as_str() {
        "f32" | "f64" => "a number".to_string(),
        "u8" | "u16" | "u32" | "u64" | "usize" => "a whole number >= 0".to_string(),
        "i8" | "i16" | "i32" | "i64" | "isize" => "a whole number".to_string(),
        "a boolean" | "bool" => "true or false".to_string(),
        "a sequence" => "an array".to_string(),
        _ if text.starts_with("struct ") || text.starts_with("a map") => "a table".to_string(),
        _ if text.starts_with("an array of length ") => {
            format!(
                "an array of {} values",
                &text["an array of length ".len()..]
            )
        }
        _ => text,
    }
}

fn describe_unexpected(unexp: Unexpected<'_>) -> String {
    match unexp {
        Unexpected::Map => "a table".to_string(),
        Unexpected::Seq => "an array".to_string(),
        other => other.to_string(),
    }
}

fn quoted_list(names: &[&str]) -> String {
    names
        .iter()
        .map(|n| format!("\"{n}\""))
        .collect::<Vec<_>>()
        .join(", ")
}

impl de::Error for DeError {
    fn custom<T: fmt::Display>(msg: T) -> Self {
        DeError::invalid(msg.to_string())
    }

    fn invalid_type(unexp: Unexpected<'_>, exp: &dyn Expected) -> Self {
        DeError::invalid(format!(
            "expected {}, found {}",
            describe_expected(exp),
            describe_unexpected(unexp)
        ))
    }

    fn invalid_value(unexp: Unexpected<'_>, exp: &dyn Expected) -> Self {
        Self::invalid_type(unexp, exp)
    }

    fn invalid_length(len: usize, exp: &dyn Expected) -> Self {
        DeError::invalid(format!(
            "expected {}, found an array of {len} values",
            describe_expected(exp)
        ))
    }

    fn unknown_variant(variant: &str, expected: &'static [&'static str]) -> Self {
        DeError::invalid(format!(
            "unknown value \"{variant}\"; expected one of {}",
            quoted_list(expected)
        ))
    }

    fn unknown_field(field: &str, expected: &'static [&'static str]) -> Self {
        let message = if expected.is_empty() {
            "unknown key; this table takes no keys".to_string()
        } else {
            format!("unknown key; expected one of {}", expected.join(", "))
        };
        DeError {
            path: FieldPath::key(field),
            kind: DeErrorKind::UnknownKey,
            message,
        }
    }

    fn missing_field(field: &'static str) -> Self {
        DeError {
            path: FieldPath::key(field),
            kind: DeErrorKind::MissingKey,
            message: "required key is missing".to_string(),
        }
    }
}

/// Number of elements a visitor consumed, for the trailing-elements error.
struct ExpectedLen(usize);

impl Expected for ExpectedLen {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "an array of length {}", self.0)
    }
}

struct OneOf(&'static [&'static str]);

impl Expected for OneOf {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "one of {}", quoted_list(self.0))
    }
}

fn unexpected(value: &Value) -> Unexpected<'_> {
    match value {
        Value::String(s) => Unexpected::Str(s),
        Value::Integer(i) => Unexpected::Signed(*i),
        Value::Float(x) => Unexpected::Float(*x),
        Value::Boolean(b) => Unexpected::Bool(*b),
        Value::Datetime(_) => Unexpected::Other("a date-time"),
        Value::Array(_) => Unexpected::Seq,
        Value::Table(_) => Unexpected::Map,
    }
}

/// Deserializes any `Deserialize` type from a borrowed TOML value.
pub struct ValueDeserializer<'de> {
    value: &'de Value,
}

impl<'de> ValueDeserializer<'de> {
    pub fn new(value: &'de Value) -> Self {
        ValueDeserializer { value }
    }
}

impl<'de> de::Deserializer<'de> for ValueDeserializer<'de> {
    type Error = DeError;

    fn deserialize_any<V: Visitor<'de>>(self, visitor: V) -> Result<V::Value, DeError> {
        match self.value {
            Value::String(s) => visitor.visit_borrowed_str(s),
            Value::Integer(i) => visitor.visit_i64(*i),
            Value::Float(x) => visitor.visit_f64(*x),
            Value::Boolean(b) => visitor.visit_bool(*b),
            Value::Datetime(d) => visitor.visit_string(d.to_string()),
            Value::Array(items) => {
                let mut seq = SeqAccess {
                    items: items.iter().enumerate(),
                    consumed: 0,
                };
                let out = visitor.visit_seq(&mut seq)?;
                // Visitors of fixed-size arrays stop after N elements; extra ones are an error,
                // not something to drop silently.
                if seq.consumed < items.len() {
                    return Err(de::Error::invalid_length(
                        items.len(),
                        &ExpectedLen(seq.consumed),
                    ));
                }
                Ok(out)
            }
            Value::Table(table) => visitor.visit_map(MapAccess {
                entries: table.iter(),
                pending: None,
            }),
        }
    }

    fn deserialize_option<V: Visitor<'de>>(self, visitor: V) -> Result<V::Value, DeError> {
        visitor.visit_some(self)
    }

    fn deserialize_newtype_struct<V: Visitor<'de>>(
        self,
        _name: &'static str,
        visitor: V,
    ) -> Result<V::Value, DeError> {
        visitor.visit_newtype_struct(self)
    }

    fn deserialize_enum<V: Visitor<'de>>(
        self,
        _name: &'static str,
        variants: &'static [&'static str],
        visitor: V,
    ) -> Result<V::Value, DeError> {
        match self.value {
            Value::String(s) => {
                visitor.visit_enum(de::value::BorrowedStrDeserializer::<DeError>::new(s))
            }
            other => Err(de::Error::invalid_type(unexpected(other), &OneOf(variants))),
        }
    }

    forward_to_deserialize_any! {
        bool i8 i16 i32 i64 i128 u8 u16 u32 u64 u128 f32 f64 char str string
        bytes byte_buf unit unit_struct seq tuple tuple_struct map struct
        identifier ignored_any
    }
}

struct SeqAccess<'de> {
    items: std::iter::Enumerate<std::slice::Iter<'de, Value>>,
    consumed: usize,
}

impl<'de> de::SeqAccess<'de> for SeqAccess<'de> {
    type Error = DeError;

    fn next_element_seed<T: DeserializeSeed<'de>>(
        &mut self,
        seed: T,
    ) -> Result<Option<T::Value>, DeError> {
        match self.items.next() {
            Some((index, value)) => {
                self.consumed += 1;
                seed.deserialize(ValueDeserializer::new(value))
                    .map(Some)
                    .map_err(|e| e.prefixed(Segment::Index(index)))
            }
            None => Ok(None),
        }
    }

    fn size_hint(&self) -> Option<usize> {
        Some(self.items.len())
    }
}

struct MapAccess<'de> {
    entries: toml::map::Iter<'de>,
    pending: Option<(&'de String, &'de Value)>,
}

impl<'de> de::MapAccess<'de> for MapAccess<'de> {
    type Error = DeError;

    fn next_key_seed<K: DeserializeSeed<'de>>(
        &mut self,
        seed: K,
    ) -> Result<Option<K::Value>, DeError> {
        match self.entries.next() {
            Some((key, value)) => {
                self.pending = Some((key, value));
                // An unknown key reports itself (DeError::unknown_field), so no prefix here.
                seed.deserialize(de::value::BorrowedStrDeserializer::<DeError>::new(key))
                    .map(Some)
            }
            None => Ok(None),
        }
    }

    fn next_value_seed<V: DeserializeSeed<'de>>(&mut self, seed: V) -> Result<V::Value, DeError> {
        match self.pending.take() {
            Some((key, value)) => seed
                .deserialize(ValueDeserializer::new(value))
                .map_err(|e| e.prefixed(Segment::Key(key.clone()))),
            None => Err(de::Error::custom("value requested before its key")),
        }
    }
}
