//! Where every value of a scenario file is written, so that any problem found later (by the
//! loader, by the semantic checks, or by the world builder, which only knows field paths) can be
//! shown at its line and column.

use std::collections::HashMap;
use std::path::Path;

use super::diagnostic::{Diagnostic, Finding};
use super::path::FieldPath;
use super::tree::{Node, Span};

/// Line and column, both counted from 1; the column counts characters, not bytes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub struct Location {
    pub line: usize,
    pub column: usize,
}

/// Which end of a `key = value` pair a problem belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Anchor {
    /// The key (unknown or missing fields: the name is what is wrong).
    Key,
    /// The value (wrong type, out of range).
    Value,
}

#[derive(Debug, Clone, PartialEq)]
struct Spans {
    key: Option<Span>,
    value: Span,
}

/// Spans of every value of one scenario text, by field path.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SourceMap {
    text: String,
    line_starts: Vec<usize>,
    spans: HashMap<FieldPath, Spans>,
}

impl SourceMap {
    /// A map of `text` that only knows lines (no tree: the text did not parse).
    pub(crate) fn lines_only(text: &str) -> Self {
        let mut line_starts = vec![0];
        line_starts.extend(
            text.char_indices()
                .filter(|&(_, c)| c == '\n')
                .map(|(i, _)| i + 1),
        );
        Self {
            text: text.to_owned(),
            line_starts,
            spans: HashMap::new(),
        }
    }

    /// The full map of `text`, parsed as `tree`.
    pub(crate) fn new(text: &str, tree: &Node) -> Self {
        let mut map = Self::lines_only(text);
        tree.walk(&FieldPath::root(), &mut |path, node| {
            map.spans.insert(
                path.clone(),
                Spans {
                    key: None,
                    value: node.span.clone(),
                },
            );
        });
        // Key spans come from the tables' entries.
        tree.walk(&FieldPath::root(), &mut |path, node| {
            if let super::tree::Value::Table(entries) = &node.value {
                for entry in entries {
                    if let Some(spans) = map.spans.get_mut(&path.key(&entry.key)) {
                        spans.key = Some(entry.key_span.clone());
                    }
                }
            }
        });
        map
    }

    /// The scenario text.
    pub fn text(&self) -> &str {
        &self.text
    }

    /// Line and column of a byte offset (clamped into the text, and back to a character
    /// boundary).
    pub fn location_of_offset(&self, offset: usize) -> Location {
        let mut offset = offset.min(self.text.len());
        while !self.text.is_char_boundary(offset) {
            offset -= 1;
        }
        let line_index = self.line_starts.partition_point(|&start| start <= offset) - 1;
        let line_start = self.line_starts[line_index];
        Location {
            line: line_index + 1,
            column: self.text[line_start..offset].chars().count() + 1,
        }
    }

    /// Where `path` is written; a path the file does not spell out (a field left at its
    /// default, a missing field) is shown at the nearest enclosing value that is written.
    pub fn locate(&self, path: &FieldPath, anchor: Anchor) -> Location {
        let mut at = Some(path.clone());
        while let Some(current) = at {
            if let Some(spans) = self.spans.get(&current) {
                let offset = match (anchor, &spans.key) {
                    (Anchor::Key, Some(key)) if current == *path => key.start,
                    // A missing or defaulted field: show its table (its header, or its key
                    // when it is written inline).
                    (_, Some(key)) if current != *path => key.start.min(spans.value.start),
                    _ => spans.value.start,
                };
                return self.location_of_offset(offset);
            }
            at = current.parent();
        }
        Location { line: 1, column: 1 }
    }

    /// A diagnostic for a problem of the file `file` (the one this maps) found after loading,
    /// by whoever only knows its field path (`uav[0].behaviour.overlap.y`), shown at the value.
    pub fn diagnostic(
        &self,
        file: &Path,
        field_path: &str,
        message: impl Into<String>,
    ) -> Diagnostic {
        Finding::new(FieldPath::parse(field_path), Anchor::Value, message).locate(file, self)
    }

    /// Whether the file writes a value at `path`.
    pub fn contains(&self, path: &FieldPath) -> bool {
        self.spans.contains_key(path)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::tree::parse_document;

    const TEXT: &str = "\
name = \"t\"
[world.bounds]
min = [0, 0, 0]
max = [1, 1, 1]

[[uav]]
name = \"é\"
  [[uav.sensor]]
  range_max = 5.0
";

    fn map() -> SourceMap {
        SourceMap::new(TEXT, &parse_document(TEXT).unwrap())
    }

    #[test]
    fn offsets_become_lines_and_character_columns() {
        let map = map();
        assert_eq!(map.location_of_offset(0), Location { line: 1, column: 1 });
        let e_acute = TEXT.find('é').unwrap();
        // The quote after é is one column further, although é takes two bytes.
        assert_eq!(
            map.location_of_offset(e_acute + 2),
            Location {
                line: 7,
                column: 10
            }
        );
        assert_eq!(
            map.location_of_offset(TEXT.len() + 10),
            Location {
                line: 10,
                column: 1
            }
        );
    }

    #[test]
    fn values_keys_and_defaults_are_located() {
        let map = map();
        let range = FieldPath::parse("uav[0].sensor[0].range_max");
        assert_eq!(
            map.locate(&range, Anchor::Value),
            Location {
                line: 9,
                column: 15
            }
        );
        assert_eq!(
            map.locate(&range, Anchor::Key),
            Location { line: 9, column: 3 }
        );
        assert_eq!(
            map.locate(&FieldPath::parse("world.bounds.max[2]"), Anchor::Value),
            Location {
                line: 4,
                column: 14
            }
        );
        // Not written: shown at the enclosing sensor table.
        let rate = FieldPath::parse("uav[0].sensor[0].rate_hz");
        assert!(!map.contains(&rate));
        assert_eq!(map.locate(&rate, Anchor::Value).line, 8);
        assert_eq!(
            map.locate(&FieldPath::parse("uav[0].behaviour"), Anchor::Key)
                .line,
            6
        );
        assert_eq!(
            map.locate(&FieldPath::parse("nothing.here"), Anchor::Key),
            Location { line: 1, column: 1 }
        );
    }
}
