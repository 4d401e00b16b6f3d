//! Decoding errors in the words of a scenario file's reader.

use serde::de::DeserializeOwned;

use super::try_decode;
use crate::scenario::de::{DeError, DeErrorKind};
use crate::scenario::diagnostic::Finding;
use crate::scenario::path::{FieldPath, Segment};
use crate::scenario::schema::{BehaviourSpec, ObstacleSpec, SensorSpec};
use crate::scenario::source_map::Anchor;
use crate::scenario::suggest::{closest, list, plain_list};
use crate::scenario::tree::{Entry, Node, Value};

/// The internally tagged tables of the schema, by where they sit.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Tagged {
    Behaviour,
    Sensor,
    Obstacle,
}

impl Tagged {
    /// Which tagged table `path` names, if any.
    fn at(path: &FieldPath) -> Option<Self> {
        match path.segments() {
            [.., Segment::Key(k)] if k == "behaviour" => Some(Self::Behaviour),
            [.., Segment::Key(k), Segment::Index(_)] if k == "sensor" => Some(Self::Sensor),
            [Segment::Key(w), Segment::Key(o), Segment::Index(_)]
                if w == "world" && o == "obstacle" =>
            {
                Some(Self::Obstacle)
            }
            _ => None,
        }
    }

    fn kinds(self) -> &'static [&'static str] {
        match self {
            Self::Behaviour => kinds_of::<BehaviourSpec>(),
            Self::Sensor => kinds_of::<SensorSpec>(),
            Self::Obstacle => kinds_of::<ObstacleSpec>(),
        }
    }
}

/// The `kind`s an internally tagged enum knows, read from serde itself (by asking it to decode
/// a kind no enum has), so that adding a variant needs no edit here.
pub(crate) fn kinds_of<T: DeserializeOwned>() -> &'static [&'static str] {
    let probe = Node {
        span: 0..0,
        value: Value::Table(vec![Entry {
            key: "kind".to_owned(),
            key_span: 0..0,
            node: Node {
                span: 0..0,
                value: Value::String("\u{0}".to_owned()),
            },
        }]),
    };
    match try_decode::<T>(&probe, &FieldPath::root()) {
        Err(DeError {
            kind: DeErrorKind::UnknownVariant { expected, .. },
            ..
        }) => expected,
        _ => &[],
    }
}

pub(super) fn missing_field(table: &FieldPath, field: &str) -> Finding {
    let path = table.key(field);
    let mut finding = Finding::new(path, Anchor::Key, "required field is missing");
    let tagged = (field == "kind").then(|| Tagged::at(table)).flatten();
    finding = match tagged {
        Some(tagged) => {
            let kinds = plain_list(tagged.kinds());
            finding.message = format!("required field is missing; this build knows: {kinds}");
            finding.expected(format!("one of: {kinds}"))
        }
        None => finding.expected(format!("a value for `{field}`")),
    };
    finding
}

/// The finding for an error located at `culprit`.
pub(super) fn finding(
    kind: &DeErrorKind,
    culprit: &FieldPath,
    node: &Node,
    root: &FieldPath,
) -> Finding {
    match kind {
        DeErrorKind::UnknownField { field, expected } => {
            let valid = if expected.is_empty() {
                "no fields here".to_owned()
            } else {
                format!("one of {}", list(expected))
            };
            let message = match closest(field, expected) {
                Some(near) => format!("unknown field `{field}`, did you mean `{near}`?"),
                None => format!("unknown field `{field}`, expected {valid}"),
            };
            Finding::new(culprit.clone(), Anchor::Key, message).expected(valid)
        }
        DeErrorKind::UnknownVariant { variant, expected } => {
            unknown_kind(culprit, variant, expected)
        }
        DeErrorKind::MissingField { field } => missing_field(culprit, field),
        DeErrorKind::DuplicateField { field } => Finding::new(
            culprit.clone(),
            Anchor::Key,
            format!("`{field}` is given twice"),
        )
        .expected(format!("one `{field}`")),
        DeErrorKind::InvalidType { found, expected }
        | DeErrorKind::InvalidValue { found, expected } => {
            let expected = plain_expected(expected);
            Finding::new(
                culprit.clone(),
                Anchor::Value,
                format!("expected {expected}"),
            )
            .expected(expected)
            .found(plain_found(found))
        }
        DeErrorKind::InvalidLength { len, expected } => {
            let expected = plain_expected(expected);
            Finding::new(
                culprit.clone(),
                Anchor::Value,
                format!("expected {expected}"),
            )
            .expected(expected)
            .found(format!("{len} elements"))
        }
        DeErrorKind::Custom(message) => match untagged_expected(message) {
            Some(expected) => {
                let found = culprit
                    .strip_prefix(root)
                    .and_then(|rel| node.get(rel))
                    .map(describe)
                    .unwrap_or_else(|| "something else".to_owned());
                Finding::new(
                    culprit.clone(),
                    Anchor::Value,
                    format!("expected {expected}"),
                )
                .expected(expected)
                .found(found)
            }
            None => Finding::new(culprit.clone(), Anchor::Value, message.clone()),
        },
    }
}

/// What the schema's untagged enums take, for serde's "data did not match any variant of
/// untagged enum X", which names a Rust type the reader of a file does not know.
fn untagged_expected(message: &str) -> Option<&'static str> {
    let name = message.strip_prefix("data did not match any variant of untagged enum ")?;
    match name.trim() {
        "RayGridSpec" => Some("\"auto\" or [columns, rows]"),
        "CandidateCount" => Some("a whole number of clusters, or \"all\""),
        _ => None,
    }
}

fn unknown_kind(culprit: &FieldPath, variant: &str, expected: &'static [&'static str]) -> Finding {
    let kinds = plain_list(expected);
    let table = culprit.parent().unwrap_or_default();
    let mut message = match Tagged::at(&table).filter(|_| culprit.last_key() == Some("kind")) {
        Some(Tagged::Behaviour) => {
            let owner = table.parent().unwrap_or_default();
            format!("unknown behaviour '{variant}' for {owner}: this build knows: {kinds}")
        }
        Some(Tagged::Sensor) => {
            format!("unknown sensor kind '{variant}': this build knows: {kinds}")
        }
        Some(Tagged::Obstacle) => {
            format!("unknown obstacle kind '{variant}': this build knows: {kinds}")
        }
        None => format!("unknown value '{variant}', expected one of: {kinds}"),
    };
    if let Some(near) = closest(variant, expected) {
        message.push_str(&format!(" (did you mean '{near}'?)"));
    }
    Finding::new(culprit.clone(), Anchor::Value, message).expected(format!("one of: {kinds}"))
}

/// serde's names of what it wanted, in the words of a TOML file.
fn plain_expected(expected: &str) -> String {
    match expected {
        "f64" | "f32" => "a number".to_owned(),
        "u32" => "a whole number from 0 to 4294967295".to_owned(),
        "u64" => "a whole number from 0 up".to_owned(),
        "a sequence" => "an array".to_owned(),
        "a map" => "a table".to_owned(),
        "path string" => "a file path (a string)".to_owned(),
        "variant identifier" => "a kind name (a string)".to_owned(),
        // Values buffered for a `kind` table: only a datetime is refused there.
        "any value" => "a number, string, boolean, array or table".to_owned(),
        other if other.starts_with("struct ") => "a table".to_owned(),
        other if other.starts_with("internally tagged enum ") => "a table with a `kind`".to_owned(),
        other => other.to_owned(),
    }
}

/// serde's names of what it saw, in the words of a TOML file.
fn plain_found(found: &str) -> String {
    match found {
        "map" => "a table".to_owned(),
        "sequence" => "an array".to_owned(),
        other => other.to_owned(),
    }
}

fn describe(node: &Node) -> String {
    match &node.value {
        Value::String(text) => format!("string {text:?}"),
        Value::Integer(v) => format!("integer `{v}`"),
        Value::Float(v) => format!("floating point `{v:?}`"),
        Value::Boolean(v) => format!("boolean `{v}`"),
        Value::Datetime(text) => format!("datetime `{text}`"),
        Value::OutOfRange(text) => format!("number `{text}`"),
        Value::Array(elements) => format!("an array of {} elements", elements.len()),
        Value::Table(_) => "a table".to_owned(),
    }
}
