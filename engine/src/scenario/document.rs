//! A scenario file read for one part of it, not decoded or checked as a whole: for tools that
//! need a single piece of a scenario (`uavex cover` plans its coverage UAV, so the world, the
//! map and the sensors need not be valid or even present) yet must report problems the way the
//! loader does, at file, line, column and field path. Reading, syntax errors, decoding and
//! locating are the loader's own.

use std::path::{Path, PathBuf};

use serde::de::DeserializeOwned;

use super::decode::{decode_unit, non_finite};
use super::diagnostic::{Diagnostic, ScenarioErrors};
use super::path::FieldPath;
use super::source_map::SourceMap;
use super::tree::{Node, Value};
use super::{in_file_order, parse_tree, read_text};

/// A parsed scenario file and where each of its values is written.
#[derive(Debug, Clone)]
pub(crate) struct Document {
    path: PathBuf,
    tree: Node,
    source: SourceMap,
}

impl Document {
    /// Reads the file at `path`, refused as the loader refuses it (unreadable, not UTF-8, TOML
    /// syntax errors).
    pub fn read(path: &Path) -> Result<Self, ScenarioErrors> {
        Self::parse(&read_text(path)?, path)
    }

    /// Parses scenario `text`; `path` names it in messages.
    pub fn parse(text: &str, path: &Path) -> Result<Self, ScenarioErrors> {
        let tree = parse_tree(text, path)?;
        let source = SourceMap::new(text, &tree);
        Ok(Self {
            path: path.to_owned(),
            tree,
            source,
        })
    }

    /// The value at `field_path` (`uav[1].behaviour`) decoded as a `T`, `None` when the file
    /// does not write one. Every problem is reported as the loader reports it: each unknown
    /// field, wrong type and unusable number, located.
    pub fn decode<T: DeserializeOwned>(
        &self,
        field_path: &str,
    ) -> Result<Option<T>, ScenarioErrors> {
        let at = FieldPath::parse(field_path);
        let Some(node) = self.tree.get(at.segments()) else {
            return Ok(None);
        };
        let mut findings = non_finite(node, &at);
        let decoded = decode_unit::<T>(node.clone(), &at, &mut findings);
        match decoded {
            Some(value) if findings.is_empty() => Ok(Some(value)),
            _ => Err(ScenarioErrors {
                diagnostics: in_file_order(findings, &self.path, &self.source),
            }),
        }
    }

    /// The string at `field_path`, if the file writes one there.
    pub fn text(&self, field_path: &str) -> Option<&str> {
        match &self
            .tree
            .get(FieldPath::parse(field_path).segments())?
            .value
        {
            Value::String(text) => Some(text),
            _ => None,
        }
    }

    /// The indices of the array at `field_path` (`uav`), none when it is not an array.
    pub fn indices(&self, field_path: &str) -> Vec<usize> {
        match self
            .tree
            .get(FieldPath::parse(field_path).segments())
            .map(|node| &node.value)
        {
            Some(Value::Array(elements)) => elements.iter().map(|e| e.index).collect(),
            _ => Vec::new(),
        }
    }

    /// The problem `message` at `field_path`, located.
    pub fn diagnostic(&self, field_path: &str, message: impl Into<String>) -> Diagnostic {
        self.source.diagnostic(&self.path, field_path, message)
    }

    /// Where every value of the file is written.
    pub fn source(&self) -> &SourceMap {
        &self.source
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::schema::BehaviourSpec;

    const TEXT: &str = "\
name = \"t\"
[[uav]]
name = \"a\"
[uav.behaviour]
kind = \"scripted\"
speed = nan
waypoints = [[1.0, 2.0]]
spead = 3.0
";

    #[test]
    fn a_part_decodes_with_every_problem_located_as_the_loader_does() {
        let document = Document::parse(TEXT, Path::new("s.toml")).unwrap();
        assert_eq!(document.text("name"), Some("t"));
        assert_eq!(document.text("uav[0].behaviour.kind"), Some("scripted"));
        assert_eq!(document.indices("uav"), [0]);
        assert!(document.indices("name").is_empty());
        assert!(
            document
                .decode::<BehaviourSpec>("uav[3].behaviour")
                .unwrap()
                .is_none()
        );
        let errors = document
            .decode::<BehaviourSpec>("uav[0].behaviour")
            .unwrap_err()
            .to_string();
        let lines: Vec<&str> = errors.lines().collect();
        assert_eq!(lines.len(), 3, "{errors}");
        assert!(
            lines[0].starts_with("s.toml:6:9: uav[0].behaviour.speed: must be a finite number"),
            "{errors}"
        );
        assert!(
            lines[1].starts_with("s.toml:7:14: uav[0].behaviour.waypoints[0]"),
            "{errors}"
        );
        assert!(
            lines[2].starts_with("s.toml:8:1: uav[0].behaviour.spead: unknown field"),
            "{errors}"
        );
    }

    #[test]
    fn syntax_errors_are_the_loaders() {
        let errors = Document::parse("a = [1,\n", Path::new("s.toml")).unwrap_err();
        assert!(
            errors.diagnostics[0].message.starts_with("TOML syntax: "),
            "{errors}"
        );
        let missing = Document::read(Path::new("/no/such/scenario.toml")).unwrap_err();
        assert!(
            missing
                .to_string()
                .contains("cannot read the scenario file"),
            "{missing}"
        );
    }
}
