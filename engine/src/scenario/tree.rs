//! The scenario file as an owned tree of TOML values, each with its byte span in the text.
//!
//! The loader decodes this tree into the typed schema piece by piece and may cut bad values out
//! of it to go on looking for further problems; spans let every problem be shown at its line and
//! column. Tables keep their keys in file order (sorted by span), so problems are found, and
//! reported, in the order a reader meets them.

use std::ops::Range;

use toml::Spanned;
use toml::de::{DeTable, DeValue};

use super::path::{FieldPath, Segment};

/// Byte range in the scenario text.
pub(crate) type Span = Range<usize>;

/// A value and where it is written.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Node {
    pub span: Span,
    pub value: Value,
}

#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Value {
    String(String),
    Integer(i64),
    Float(f64),
    Boolean(bool),
    /// TOML datetimes: no scenario field takes one; kept so the type error can say what it saw.
    Datetime(String),
    /// An integer that does not fit in 64 bits (its text).
    OutOfRange(String),
    Array(Vec<Element>),
    Table(Vec<Entry>),
}

/// An array element that remembers its index in the file, so paths stay true after elements
/// before it were cut out.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Element {
    pub index: usize,
    pub node: Node,
}

/// A table entry: its key, where the key is written, and its value.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Entry {
    pub key: String,
    pub key_span: Span,
    pub node: Node,
}

/// A TOML syntax error: where and what.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct SyntaxError {
    pub span: Span,
    pub message: String,
}

/// Parses a document, collecting every syntax error the TOML parser recovers from.
pub(crate) fn parse_document(text: &str) -> Result<Node, Vec<SyntaxError>> {
    let (table, errors) = DeTable::parse_recoverable(text);
    if errors.is_empty() {
        return Ok(Node {
            span: 0..text.len(),
            value: table_value(table.get_ref()),
        });
    }
    Err(errors
        .iter()
        .map(|error| SyntaxError {
            span: error.span().unwrap_or(0..0),
            message: error.message().trim().to_owned(),
        })
        .collect())
}

fn node(value: &Spanned<DeValue<'_>>) -> Node {
    let value_ref = value.get_ref();
    let converted = match value_ref {
        DeValue::String(text) => Value::String(text.to_string()),
        DeValue::Integer(integer) => match i64::from_str_radix(integer.as_str(), integer.radix()) {
            Ok(v) => Value::Integer(v),
            Err(_) => Value::OutOfRange(integer.to_string()),
        },
        // Overflowing literals (1e400) parse to infinity and are refused as non-finite later.
        DeValue::Float(float) => match float.as_str().parse::<f64>() {
            Ok(v) => Value::Float(v),
            Err(_) => Value::OutOfRange(float.to_string()),
        },
        DeValue::Boolean(b) => Value::Boolean(*b),
        DeValue::Datetime(datetime) => Value::Datetime(datetime.to_string()),
        DeValue::Array(items) => Value::Array(
            items
                .iter()
                .enumerate()
                .map(|(index, item)| Element {
                    index,
                    node: node(item),
                })
                .collect(),
        ),
        DeValue::Table(table) => table_value(table),
    };
    Node {
        span: value.span(),
        value: converted,
    }
}

fn table_value(table: &DeTable<'_>) -> Value {
    let mut entries: Vec<Entry> = table
        .iter()
        .map(|(key, value)| Entry {
            key: key.get_ref().to_string(),
            key_span: key.span(),
            node: node(value),
        })
        .collect();
    entries.sort_by_key(|entry| entry.key_span.start);
    Value::Table(entries)
}

impl Node {
    /// The value at `segments` below this node.
    pub fn get(&self, segments: &[Segment]) -> Option<&Node> {
        let Some((first, rest)) = segments.split_first() else {
            return Some(self);
        };
        self.child(first)?.get(rest)
    }

    fn child(&self, segment: &Segment) -> Option<&Node> {
        match (&self.value, segment) {
            (Value::Table(entries), Segment::Key(key)) => entries
                .iter()
                .find(|entry| &entry.key == key)
                .map(|entry| &entry.node),
            (Value::Array(elements), Segment::Index(index)) => elements
                .iter()
                .find(|element| element.index == *index)
                .map(|element| &element.node),
            _ => None,
        }
    }

    /// Cuts out the value at `segments` (not empty); whether there was one.
    pub fn remove(&mut self, segments: &[Segment]) -> bool {
        self.take(segments).is_some()
    }

    /// Cuts out and returns the value at `segments` (not empty).
    pub fn take(&mut self, segments: &[Segment]) -> Option<Node> {
        let (last, parents) = segments.split_last()?;
        let parent = parents
            .iter()
            .try_fold(self, |node, segment| node.child_mut(segment))?;
        match (&mut parent.value, last) {
            (Value::Table(entries), Segment::Key(key)) => {
                let at = entries.iter().position(|entry| &entry.key == key)?;
                Some(entries.remove(at).node)
            }
            (Value::Array(elements), Segment::Index(index)) => {
                let at = elements
                    .iter()
                    .position(|element| element.index == *index)?;
                Some(elements.remove(at).node)
            }
            _ => None,
        }
    }

    /// The value at `segments` below this node, for editing.
    pub fn get_mut(&mut self, segments: &[Segment]) -> Option<&mut Node> {
        segments
            .iter()
            .try_fold(self, |node, segment| node.child_mut(segment))
    }

    /// Keeps the first `count` values of a table or an array (in file order) and drops the
    /// rest; a table's `kind` tag is kept when it is a string (see `decode::blame`), and
    /// `count` does not include it.
    pub fn keep_first(&mut self, count: usize) {
        match &mut self.value {
            Value::Table(entries) => {
                let mut kept = 0;
                entries.retain(|entry| {
                    if entry.key == "kind" && matches!(entry.node.value, Value::String(_)) {
                        return true;
                    }
                    kept += 1;
                    kept <= count
                });
            }
            Value::Array(elements) => elements.truncate(count),
            _ => {}
        }
    }

    fn child_mut(&mut self, segment: &Segment) -> Option<&mut Node> {
        match (&mut self.value, segment) {
            (Value::Table(entries), Segment::Key(key)) => entries
                .iter_mut()
                .find(|entry| &entry.key == key)
                .map(|entry| &mut entry.node),
            (Value::Array(elements), Segment::Index(index)) => elements
                .iter_mut()
                .find(|element| element.index == *index)
                .map(|element| &mut element.node),
            _ => None,
        }
    }

    /// The direct children with their paths (`at` names this node), in file order; a
    /// table's `kind` tag is left out when it is a string (it selects the type of the table
    /// rather than being one of its values; see `keep_first`).
    pub fn children(&self, at: &FieldPath) -> Vec<(FieldPath, &Node)> {
        match &self.value {
            Value::Table(entries) => entries
                .iter()
                .filter(|entry| {
                    !(entry.key == "kind" && matches!(entry.node.value, Value::String(_)))
                })
                .map(|entry| (at.key(&entry.key), &entry.node))
                .collect(),
            Value::Array(elements) => elements
                .iter()
                .map(|element| (at.index(element.index), &element.node))
                .collect(),
            _ => Vec::new(),
        }
    }

    /// Every value in the tree with its path, parents before children (`at` names this node).
    pub fn walk<'a>(&'a self, at: &FieldPath, visit: &mut impl FnMut(&FieldPath, &'a Node)) {
        visit(at, self);
        match &self.value {
            Value::Table(entries) => {
                for entry in entries {
                    entry.node.walk(&at.key(&entry.key), visit);
                }
            }
            Value::Array(elements) => {
                for element in elements {
                    element.node.walk(&at.index(element.index), visit);
                }
            }
            _ => {}
        }
    }

    /// The keys of a table (empty for other values).
    pub fn keys(&self) -> Vec<&str> {
        match &self.value {
            Value::Table(entries) => entries.iter().map(|entry| entry.key.as_str()).collect(),
            _ => Vec::new(),
        }
    }

    pub fn is_container(&self) -> bool {
        matches!(self.value, Value::Table(_) | Value::Array(_))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const TEXT: &str = "name = \"a\"\n\n[[uav]]\nname = \"u\"\nstart.position = [0, 0, 1.5]\n";

    #[test]
    fn spans_point_at_keys_and_values() {
        let tree = parse_document(TEXT).unwrap();
        let uav = tree.get(FieldPath::parse("uav[0]").segments()).unwrap();
        assert!(matches!(uav.value, Value::Table(_)));
        let z = tree
            .get(FieldPath::parse("uav[0].start.position[2]").segments())
            .unwrap();
        assert_eq!(z.value, Value::Float(1.5));
        assert_eq!(&TEXT[z.span.clone()], "1.5");
        let Value::Table(entries) = &tree.value else {
            panic!("the document is a table")
        };
        assert_eq!(&TEXT[entries[0].key_span.clone()], "name");
        assert_eq!(entries[0].key, "name");
        assert_eq!(entries[1].key, "uav");
    }

    #[test]
    fn remove_keeps_original_indices() {
        let mut tree = parse_document("a = [1, 2, 3]\n").unwrap();
        assert!(tree.remove(FieldPath::parse("a[1]").segments()));
        assert!(!tree.remove(FieldPath::parse("a[1]").segments()));
        let last = tree.get(FieldPath::parse("a[2]").segments()).unwrap();
        assert_eq!(last.value, Value::Integer(3));
        assert!(!tree.remove(&[]));
    }

    #[test]
    fn children_come_in_file_order_with_their_paths() {
        let tree = parse_document("t = { b = [1], a = 2 }\n").unwrap();
        let t = tree.get(FieldPath::parse("t").segments()).unwrap();
        let paths: Vec<String> = t
            .children(&FieldPath::parse("t"))
            .iter()
            .map(|(path, _)| path.to_string())
            .collect();
        assert_eq!(paths, ["t.b", "t.a"]);
    }

    #[test]
    fn syntax_errors_are_all_collected_with_spans() {
        let errors = parse_document("a = \nb = [1,\nc = 3\n").unwrap_err();
        assert!(!errors.is_empty());
        assert!(errors.iter().all(|e| !e.message.is_empty()));
    }

    #[test]
    fn odd_numbers_are_kept_as_written() {
        let tree = parse_document("a = nan\nb = 0x10\nc = 1e400\n").unwrap();
        let get = |p: &str| &tree.get(FieldPath::parse(p).segments()).unwrap().value;
        assert!(matches!(get("a"), Value::Float(x) if x.is_nan()));
        assert_eq!(get("b"), &Value::Integer(16));
        assert_eq!(get("c"), &Value::Float(f64::INFINITY));
    }
}
