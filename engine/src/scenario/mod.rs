//! Scenario files: the schema (TOML, serde), loading with located diagnostics, validation.
//!
//! Loading refuses a file that cannot be read or makes no sense before anything runs, and says
//! everything that is wrong with it at once, each problem with its file, line, column, field
//! path and what was expected (DESIGN.md, "Bad input"):
//! 1. syntax: every TOML syntax error the parser recovers from;
//! 2. structure: every unknown field (with the closest valid name), every type error, every
//!    non-finite number, decoding each `[[uav]]`, `[[uav.sensor]]` and `[[world.obstacle]]`
//!    on its own so one bad entry does not hide the others (see `decode`);
//! 3. meaning: the semantic checks (see `check`) on every piece that decoded.
//!
//! Geometry checks (a start inside an obstacle, a missing mesh file) need the built world; the
//! world builder reports them as field paths and [`LoadedScenario::diagnostic`] locates them.

mod check;
mod de;
mod decode;
mod diagnostic;
mod document;
mod path;
pub mod schema;
mod source_map;
mod suggest;
mod tree;

use std::path::{Path, PathBuf};

pub use check::{
    KNOWN_AIRFRAMES, MAX_PILLARS, MAX_RAYS_PER_SCAN, MAX_STEPS, MAX_VOXELS, MIN_VOXELS_PER_SIDE,
    check,
};
pub use diagnostic::{Diagnostic, ScenarioErrors};
pub use path::{FieldPath, Segment};
pub use schema::*;
pub use source_map::{Anchor, Location, SourceMap};

pub(crate) use document::Document;

use diagnostic::Finding;

/// A scenario that loaded and passed every check, with what is needed to point back into its
/// file.
#[derive(Debug, Clone)]
pub struct LoadedScenario {
    pub scenario: Scenario,
    /// The file as it was named to the loader (used in messages).
    pub path: PathBuf,
    /// The folder relative file paths in the scenario (meshes, clouds) are resolved against:
    /// the scenario file's folder, `.` for a bare file name.
    pub base_dir: PathBuf,
    /// Where every value is written in the file.
    pub source: SourceMap,
}

impl LoadedScenario {
    /// Line and column of a field path (`world.obstacle[3].file`); a path the file does not
    /// spell out is placed at the nearest enclosing value that it does.
    pub fn locate(&self, field_path: &str) -> Location {
        self.source
            .locate(&FieldPath::parse(field_path), Anchor::Value)
    }

    /// A located diagnostic for a problem found after loading, e.g. by the world builder
    /// (`"world.obstacle[3].file"`, `"mesh file not found: ..."`) or a geometry check
    /// (`"uav[0].start.position"`, `"starts inside obstacle 'pillar 1'"`).
    pub fn diagnostic(&self, field_path: &str, message: impl Into<String>) -> Diagnostic {
        self.source.diagnostic(&self.path, field_path, message)
    }

    /// The located errors for a list of `(field path, message)` problems, for merging the
    /// world builder's errors into the loader's form.
    pub fn errors<P, M>(&self, problems: impl IntoIterator<Item = (P, M)>) -> ScenarioErrors
    where
        P: AsRef<str>,
        M: Into<String>,
    {
        ScenarioErrors {
            diagnostics: problems
                .into_iter()
                .map(|(path, message)| self.diagnostic(path.as_ref(), message))
                .collect(),
        }
    }

    /// A file named in the scenario, relative to the scenario's folder (absolute paths stay).
    pub fn resolve(&self, file: &Path) -> PathBuf {
        self.base_dir.join(file)
    }
}

/// Reads, decodes and checks the scenario file at `path`.
pub fn load(path: impl AsRef<Path>) -> Result<LoadedScenario, ScenarioErrors> {
    let path = path.as_ref();
    parse_str(&read_text(path)?, path)
}

/// The text of the scenario file at `path`, refused (with the place, for text that is not
/// UTF-8) when it cannot be read.
fn read_text(path: &Path) -> Result<String, ScenarioErrors> {
    let whole_file = |message: String, line: usize, column: usize| ScenarioErrors {
        diagnostics: vec![Diagnostic {
            file: path.to_owned(),
            line,
            column,
            path: String::new(),
            message,
            expected: Some("a readable UTF-8 TOML file".to_owned()),
            found: None,
        }],
    };
    let bytes = std::fs::read(path)
        .map_err(|error| whole_file(format!("cannot read the scenario file: {error}"), 0, 0))?;
    String::from_utf8(bytes).map_err(|error| {
        let valid = error.utf8_error().valid_up_to();
        let prefix = String::from_utf8_lossy(&error.as_bytes()[..valid]).into_owned();
        let at = SourceMap::lines_only(&prefix).location_of_offset(valid);
        whole_file(
            "the file is not valid UTF-8 text".to_owned(),
            at.line,
            at.column,
        )
    })
}

/// Decodes and checks scenario `text`; `path` names it in messages and gives the base folder.
pub fn parse_str(text: &str, path: impl AsRef<Path>) -> Result<LoadedScenario, ScenarioErrors> {
    let path = path.as_ref().to_owned();
    let base_dir = match path.parent() {
        Some(parent) if !parent.as_os_str().is_empty() => parent.to_owned(),
        _ => PathBuf::from("."),
    };
    let tree = parse_tree(text, &path)?;
    let source = SourceMap::new(text, &tree);

    let mut structure = Vec::new();
    let decoded = decode::decode(&tree, &mut structure);
    structure.extend(decode::non_finite(&tree, &FieldPath::root()));
    let semantic = check::check_parts(&check::Parts::of_decoded(&decoded));

    let mut diagnostics = in_file_order(structure, &path, &source);
    diagnostics.extend(in_file_order(semantic, &path, &source));
    if !diagnostics.is_empty() {
        return Err(ScenarioErrors { diagnostics });
    }
    match decoded.into_scenario() {
        Some(scenario) => Ok(LoadedScenario {
            scenario,
            path,
            base_dir,
            source,
        }),
        // Unreachable in practice: a piece only fails to decode with a finding. Kept total.
        None => Err(ScenarioErrors {
            diagnostics: vec![Diagnostic {
                file: path,
                line: 1,
                column: 1,
                path: String::new(),
                message: "the scenario could not be decoded".to_owned(),
                expected: None,
                found: None,
            }],
        }),
    }
}

/// The tree of scenario `text` (named `path` in messages), or every TOML syntax error in it.
fn parse_tree(text: &str, path: &Path) -> Result<tree::Node, ScenarioErrors> {
    tree::parse_document(text).map_err(|errors| {
        let source = SourceMap::lines_only(text);
        let diagnostics = errors
            .into_iter()
            .map(|error| {
                let at = source.location_of_offset(error.span.start);
                Diagnostic {
                    file: path.to_owned(),
                    line: at.line,
                    column: at.column,
                    path: String::new(),
                    message: format!("TOML syntax: {}", error.message),
                    expected: Some("valid TOML".to_owned()),
                    found: None,
                }
            })
            .collect();
        ScenarioErrors { diagnostics }
    })
}

/// Locates findings and sorts them by place (stable, so same-place findings keep their order),
/// dropping repeats.
fn in_file_order(findings: Vec<Finding>, file: &Path, source: &SourceMap) -> Vec<Diagnostic> {
    let mut diagnostics: Vec<Diagnostic> = findings
        .into_iter()
        .map(|finding| finding.locate(file, source))
        .collect();
    diagnostics.sort_by_key(|d| (d.line, d.column));
    diagnostics.dedup();
    diagnostics
}
