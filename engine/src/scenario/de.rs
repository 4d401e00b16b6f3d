//! A serde deserializer over the spanned tree whose errors keep their structure and the field
//! path where they arose.
//!
//! The toml crate's own deserializer stops at the first error and folds it into a string; to
//! report every problem with its place, and to suggest the closest field name for a typo, the
//! loader needs the error's kind (unknown field with the valid names, missing field, wrong type)
//! and its path. Errors raised inside buffered content (serde's internally tagged enums, such as
//! `kind = "box"` tables) only know the table they came from; `decode` narrows them down.

use std::fmt;

use serde::de::value::{BorrowedStrDeserializer, MapAccessDeserializer};
use serde::de::{self, DeserializeSeed, Deserializer, Expected, Unexpected, Visitor};
use serde::forward_to_deserialize_any;

use super::path::FieldPath;
use super::tree::{Element, Entry, Node, Value};

/// What went wrong, as serde reported it.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum DeErrorKind {
    UnknownField {
        field: String,
        expected: &'static [&'static str],
    },
    UnknownVariant {
        variant: String,
        expected: &'static [&'static str],
    },
    MissingField {
        field: &'static str,
    },
    DuplicateField {
        field: &'static str,
    },
    InvalidType {
        found: String,
        expected: String,
    },
    InvalidValue {
        found: String,
        expected: String,
    },
    InvalidLength {
        len: usize,
        expected: String,
    },
    Custom(String),
}

/// A deserialization error and the path of the value it belongs to (`None` until a
/// deserializer that knows its place sees it go by).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct DeError {
    pub kind: DeErrorKind,
    pub path: Option<FieldPath>,
}

impl DeError {
    fn new(kind: DeErrorKind) -> Self {
        Self { kind, path: None }
    }

    /// Places the error at `path` unless a deeper deserializer already did.
    pub fn at(mut self, path: &FieldPath) -> Self {
        if self.path.is_none() {
            self.path = Some(path.clone());
        }
        self
    }
}

impl fmt::Display for DeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if let Some(path) = &self.path {
            write!(f, "{path}: ")?;
        }
        match &self.kind {
            DeErrorKind::UnknownField { field, .. } => write!(f, "unknown field `{field}`"),
            DeErrorKind::UnknownVariant { variant, .. } => {
                write!(f, "unknown variant `{variant}`")
            }
            DeErrorKind::MissingField { field } => write!(f, "missing field `{field}`"),
            DeErrorKind::DuplicateField { field } => write!(f, "duplicate field `{field}`"),
            DeErrorKind::InvalidType { found, expected }
            | DeErrorKind::InvalidValue { found, expected } => {
                write!(f, "expected {expected}, got {found}")
            }
            DeErrorKind::InvalidLength { len, expected } => {
                write!(f, "expected {expected}, got {len} elements")
            }
            DeErrorKind::Custom(message) => f.write_str(message),
        }
    }
}

impl std::error::Error for DeError {}

impl de::Error for DeError {
    fn custom<T: fmt::Display>(msg: T) -> Self {
        Self::new(DeErrorKind::Custom(msg.to_string()))
    }

    fn invalid_type(unexp: Unexpected<'_>, exp: &dyn Expected) -> Self {
        Self::new(DeErrorKind::InvalidType {
            found: unexp.to_string(),
            expected: exp.to_string(),
        })
    }

    fn invalid_value(unexp: Unexpected<'_>, exp: &dyn Expected) -> Self {
        Self::new(DeErrorKind::InvalidValue {
            found: unexp.to_string(),
            expected: exp.to_string(),
        })
    }

    fn invalid_length(len: usize, exp: &dyn Expected) -> Self {
        Self::new(DeErrorKind::InvalidLength {
            len,
            expected: exp.to_string(),
        })
    }

    fn unknown_variant(variant: &str, expected: &'static [&'static str]) -> Self {
        Self::new(DeErrorKind::UnknownVariant {
            variant: variant.to_owned(),
            expected,
        })
    }

    fn unknown_field(field: &str, expected: &'static [&'static str]) -> Self {
        Self::new(DeErrorKind::UnknownField {
            field: field.to_owned(),
            expected,
        })
    }

    fn missing_field(field: &'static str) -> Self {
        Self::new(DeErrorKind::MissingField { field })
    }

    fn duplicate_field(field: &'static str) -> Self {
        Self::new(DeErrorKind::DuplicateField { field })
    }
}

/// Deserializes one node of the tree; `path` names it.
pub(crate) struct NodeDeserializer<'a> {
    node: &'a Node,
    path: FieldPath,
}

impl<'a> NodeDeserializer<'a> {
    pub fn new(node: &'a Node, path: FieldPath) -> Self {
        Self { node, path }
    }
}

impl<'de> Deserializer<'de> for NodeDeserializer<'de> {
    type Error = DeError;

    fn deserialize_any<V: Visitor<'de>>(self, visitor: V) -> Result<V::Value, DeError> {
        let result = match &self.node.value {
            Value::String(text) => visitor.visit_borrowed_str(text),
            Value::Integer(v) => visitor.visit_i64(*v),
            Value::Float(v) => visitor.visit_f64(*v),
            Value::Boolean(v) => visitor.visit_bool(*v),
            Value::Datetime(_) => Err(de::Error::invalid_type(
                Unexpected::Other("a datetime"),
                &visitor,
            )),
            Value::OutOfRange(text) => Err(de::Error::custom(format!(
                "number {text} does not fit in 64 bits"
            ))),
            Value::Array(elements) => {
                let mut access = ArrayAccess::new(elements, &self.path);
                let value = visitor.visit_seq(&mut access);
                value.and_then(|value| access.end().map(|()| value))
            }
            Value::Table(entries) => visitor.visit_map(TableAccess::new(entries, &self.path)),
        };
        result.map_err(|error| error.at(&self.path))
    }

    /// TOML has no null: a present value is `Some`, an absent one never reaches here.
    fn deserialize_option<V: Visitor<'de>>(self, visitor: V) -> Result<V::Value, DeError> {
        let path = self.path.clone();
        visitor.visit_some(self).map_err(|error| error.at(&path))
    }

    fn deserialize_newtype_struct<V: Visitor<'de>>(
        self,
        _name: &'static str,
        visitor: V,
    ) -> Result<V::Value, DeError> {
        let path = self.path.clone();
        visitor
            .visit_newtype_struct(self)
            .map_err(|error| error.at(&path))
    }

    /// Structs come from tables only (serde would also accept an array of the fields in
    /// order, which no one writes on purpose in a scenario).
    fn deserialize_struct<V: Visitor<'de>>(
        self,
        _name: &'static str,
        _fields: &'static [&'static str],
        visitor: V,
    ) -> Result<V::Value, DeError> {
        if matches!(self.node.value, Value::Array(_)) {
            return Err(
                <DeError as de::Error>::invalid_type(Unexpected::Seq, &visitor).at(&self.path),
            );
        }
        self.deserialize_any(visitor)
    }

    /// Externally tagged enums: a string names a unit variant, a one-entry table a variant with
    /// data.
    fn deserialize_enum<V: Visitor<'de>>(
        self,
        _name: &'static str,
        _variants: &'static [&'static str],
        visitor: V,
    ) -> Result<V::Value, DeError> {
        let result = match &self.node.value {
            Value::String(text) => {
                visitor.visit_enum(BorrowedStrDeserializer::<DeError>::new(text.as_str()))
            }
            Value::Table(entries) if entries.len() == 1 => visitor.visit_enum(
                MapAccessDeserializer::new(TableAccess::new(entries, &self.path)),
            ),
            _ => return self.deserialize_any(visitor),
        };
        result.map_err(|error| error.at(&self.path))
    }

    fn deserialize_ignored_any<V: Visitor<'de>>(self, visitor: V) -> Result<V::Value, DeError> {
        visitor.visit_unit()
    }

    forward_to_deserialize_any! {
        bool i8 i16 i32 i64 i128 u8 u16 u32 u64 u128 f32 f64 char str string
        bytes byte_buf unit unit_struct seq tuple tuple_struct map identifier
    }
}

/// Walks a table's entries in file order.
struct TableAccess<'a> {
    entries: std::slice::Iter<'a, Entry>,
    pending: Option<&'a Entry>,
    path: FieldPath,
}

impl<'a> TableAccess<'a> {
    fn new(entries: &'a [Entry], path: &FieldPath) -> Self {
        Self {
            entries: entries.iter(),
            pending: None,
            path: path.clone(),
        }
    }
}

impl<'de> de::MapAccess<'de> for TableAccess<'de> {
    type Error = DeError;

    fn next_key_seed<K: DeserializeSeed<'de>>(
        &mut self,
        seed: K,
    ) -> Result<Option<K::Value>, DeError> {
        let Some(entry) = self.entries.next() else {
            return Ok(None);
        };
        self.pending = Some(entry);
        seed.deserialize(BorrowedStrDeserializer::<DeError>::new(entry.key.as_str()))
            .map(Some)
            .map_err(|error| error.at(&self.path.key(&entry.key)))
    }

    fn next_value_seed<S: DeserializeSeed<'de>>(&mut self, seed: S) -> Result<S::Value, DeError> {
        let Some(entry) = self.pending.take() else {
            return Err(de::Error::custom("a value was asked for before its key"));
        };
        let path = self.path.key(&entry.key);
        seed.deserialize(NodeDeserializer::new(&entry.node, path.clone()))
            .map_err(|error| error.at(&path))
    }

    fn size_hint(&self) -> Option<usize> {
        Some(self.entries.len())
    }
}

/// Walks an array's elements; refuses leftovers the visitor did not take (a fixed-size array
/// such as `[f64; 3]` stops reading after its length).
struct ArrayAccess<'a> {
    elements: std::slice::Iter<'a, Element>,
    taken: usize,
    path: FieldPath,
}

impl<'a> ArrayAccess<'a> {
    fn new(elements: &'a [Element], path: &FieldPath) -> Self {
        Self {
            elements: elements.iter(),
            taken: 0,
            path: path.clone(),
        }
    }

    fn end(&self) -> Result<(), DeError> {
        let left = self.elements.len();
        if left == 0 {
            return Ok(());
        }
        let expected = format!("an array of {} elements", self.taken);
        Err(de::Error::invalid_length(
            self.taken + left,
            &expected.as_str(),
        ))
    }
}

impl<'de> de::SeqAccess<'de> for &mut ArrayAccess<'de> {
    type Error = DeError;

    fn next_element_seed<S: DeserializeSeed<'de>>(
        &mut self,
        seed: S,
    ) -> Result<Option<S::Value>, DeError> {
        let Some(element) = self.elements.next() else {
            return Ok(None);
        };
        self.taken += 1;
        let path = self.path.index(element.index);
        seed.deserialize(NodeDeserializer::new(&element.node, path.clone()))
            .map(Some)
            .map_err(|error| error.at(&path))
    }

    fn size_hint(&self) -> Option<usize> {
        Some(self.elements.len())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::schema::{MountSpec, SensorSpec, StartSpec};
    use crate::scenario::tree::parse_document;
    use serde::Deserialize;

    fn decode<T: for<'de> Deserialize<'de>>(text: &str) -> Result<T, DeError> {
        let tree = parse_document(text).unwrap();
        T::deserialize(NodeDeserializer::new(&tree, FieldPath::root()))
    }

    #[test]
    fn plain_structs_decode() {
        let start: StartSpec = decode("position = [1, 2.5, 3]\nyaw = 0.5\n").unwrap();
        assert_eq!(start.position, [1.0, 2.5, 3.0]);
        assert_eq!(start.yaw, 0.5);
    }

    #[test]
    fn unknown_field_keeps_the_valid_names_and_its_path() {
        let error = decode::<MountSpec>("translation = [0, 0, 0]\nrpyy = [0, 0, 0]\n").unwrap_err();
        assert_eq!(error.path.unwrap().to_string(), "rpyy");
        assert_eq!(
            error.kind,
            DeErrorKind::UnknownField {
                field: "rpyy".into(),
                expected: &["translation", "rpy"],
            }
        );
    }

    #[test]
    fn type_errors_name_the_element() {
        let error = decode::<StartSpec>("position = [1, \"two\", 3]\n").unwrap_err();
        assert_eq!(error.path.unwrap().to_string(), "position[1]");
        assert_eq!(
            error.kind,
            DeErrorKind::InvalidType {
                found: "string \"two\"".into(),
                expected: "f64".into(),
            }
        );
    }

    #[test]
    fn arrays_that_are_too_long_are_refused() {
        let error = decode::<StartSpec>("position = [1, 2, 3, 4]\n").unwrap_err();
        assert_eq!(error.path.unwrap().to_string(), "position");
        assert_eq!(
            error.kind,
            DeErrorKind::InvalidLength {
                len: 4,
                expected: "an array of 3 elements".into(),
            }
        );
    }

    #[test]
    fn tagged_enums_decode_and_bad_tags_point_at_kind() {
        let sensor: SensorSpec = decode("kind = \"lidar\"\nbeams_h = 360\n").unwrap();
        assert!(matches!(sensor, SensorSpec::Lidar { beams_h: 360, .. }));
        let error = decode::<SensorSpec>("kind = \"sonar\"\n").unwrap_err();
        assert_eq!(error.path.unwrap().to_string(), "kind");
        assert!(matches!(
            error.kind,
            DeErrorKind::UnknownVariant { ref variant, .. } if variant == "sonar"
        ));
    }

    #[test]
    fn datetimes_and_structs_from_arrays_are_type_errors() {
        let error = decode::<StartSpec>("position = 1979-05-27\n").unwrap_err();
        assert_eq!(error.path.unwrap().to_string(), "position");
        assert!(
            matches!(error.kind, DeErrorKind::InvalidType { ref found, .. } if found == "a datetime")
        );
        let tree = parse_document("m = [[0, 0, 0], [0, 0, 0]]\n").unwrap();
        let m = tree.get(FieldPath::parse("m").segments()).unwrap();
        let error =
            MountSpec::deserialize(NodeDeserializer::new(m, FieldPath::parse("m"))).unwrap_err();
        assert_eq!(error.path.unwrap().to_string(), "m");
        assert!(
            matches!(error.kind, DeErrorKind::InvalidType { ref found, .. } if found == "sequence")
        );
    }
}
