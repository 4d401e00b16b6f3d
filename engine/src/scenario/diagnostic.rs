//! Problems of a scenario file, each with its place (file, line, column, field path), what is
//! wrong and what was expected (DESIGN.md, "Bad input").

use std::fmt;
use std::path::{Path, PathBuf};

use super::path::FieldPath;
use super::source_map::{Anchor, SourceMap};

/// One problem, located. Line and column count from 1; line 0 means the problem concerns the
/// file as a whole (it could not be read).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Diagnostic {
    pub file: PathBuf,
    pub line: usize,
    pub column: usize,
    /// Field path (`uav[0].sensor[1].range_max`); empty for problems of the text itself.
    pub path: String,
    /// What is wrong, as a reader should see it (`must be below range_max (5.0)`).
    pub message: String,
    /// What would have been accepted (`below range_max (5.0)`, `one of ...`).
    pub expected: Option<String>,
    /// What the file says, when it helps (`6.0`).
    pub found: Option<String>,
}

impl fmt::Display for Diagnostic {
    /// `scenarios/x.toml:12:5: uav[0].sensor[0].range_min: must be below range_max (5.0), got 6.0`
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.file.display())?;
        if self.line > 0 {
            write!(f, ":{}:{}", self.line, self.column)?;
        }
        f.write_str(": ")?;
        if !self.path.is_empty() {
            write!(f, "{}: ", self.path)?;
        }
        f.write_str(&self.message)?;
        if let Some(found) = &self.found {
            write!(f, ", got {found}")?;
        }
        Ok(())
    }
}

/// Every problem found in one scenario file; the loader refuses the file when there is any.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub struct ScenarioErrors {
    pub diagnostics: Vec<Diagnostic>,
}

impl fmt::Display for ScenarioErrors {
    /// One problem per line, in the order they were found.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, diagnostic) in self.diagnostics.iter().enumerate() {
            if i > 0 {
                f.write_str("\n")?;
            }
            write!(f, "{diagnostic}")?;
        }
        Ok(())
    }
}

/// A problem not yet located: the checks produce these from plain data, the loader places them.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Finding {
    pub path: FieldPath,
    pub anchor: Anchor,
    pub message: String,
    pub expected: Option<String>,
    pub found: Option<String>,
}

impl Finding {
    pub fn new(path: FieldPath, anchor: Anchor, message: impl Into<String>) -> Self {
        Self {
            path,
            anchor,
            message: message.into(),
            expected: None,
            found: None,
        }
    }

    /// `<path>: must be <expected>, got <found>`, the form of most range checks.
    pub fn must_be(path: FieldPath, expected: impl Into<String>, found: impl fmt::Display) -> Self {
        let expected = expected.into();
        Self {
            path,
            anchor: Anchor::Value,
            message: format!("must be {expected}"),
            expected: Some(expected),
            found: Some(found.to_string()),
        }
    }

    pub fn expected(mut self, expected: impl Into<String>) -> Self {
        self.expected = Some(expected.into());
        self
    }

    pub fn found(mut self, found: impl Into<String>) -> Self {
        self.found = Some(found.into());
        self
    }

    pub fn locate(self, file: &Path, source: &SourceMap) -> Diagnostic {
        let location = source.locate(&self.path, self.anchor);
        Diagnostic {
            file: file.to_owned(),
            line: location.line,
            column: location.column,
            path: self.path.to_string(),
            message: self.message,
            expected: self.expected,
            found: self.found,
        }
    }
}

/// Numbers as a reader wrote them: `5.0`, `0.1`, `1e-7` (Rust's `Debug` form of `f64`).
pub(crate) fn number(x: f64) -> String {
    format!("{x:?}")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn display_matches_the_documented_form() {
        let diagnostic = Diagnostic {
            file: PathBuf::from("scenarios/x.toml"),
            line: 12,
            column: 5,
            path: "uav[0].sensor[0].range_min".into(),
            message: "must be below range_max (5.0)".into(),
            expected: Some("below range_max (5.0)".into()),
            found: Some(number(6.0)),
        };
        assert_eq!(
            diagnostic.to_string(),
            "scenarios/x.toml:12:5: uav[0].sensor[0].range_min: must be below range_max (5.0), got 6.0"
        );
        let whole_file = Diagnostic {
            line: 0,
            path: String::new(),
            found: None,
            message: "cannot read the file".into(),
            ..diagnostic.clone()
        };
        assert_eq!(
            whole_file.to_string(),
            "scenarios/x.toml: cannot read the file"
        );
        let errors = ScenarioErrors {
            diagnostics: vec![diagnostic, whole_file],
        };
        assert_eq!(errors.to_string().lines().count(), 2);
    }
}
