//! The coverage part of a scenario file, for `uavex cover`: the first UAV whose behaviour is
//! `kind = "coverage"`, with its airframe. Read straight from the file's tree, so planning needs
//! nothing else of the scenario (world, map, sensors) to be valid or even present; its problems
//! are reported as the loader reports a scenario's, at file, line and field
//! (`s.toml:12:9: uav[0].behaviour.overlap.y: ...`).

use super::CoverageIoError;
use super::outputs::plain_file_stem;
use super::spec::{CoverageSetup, CoverageSpec};
use crate::scenario::{BehaviourSpec, Document, ScenarioErrors, SourceMap};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use uavex_systems::coverage::AltitudeOutcome;

/// A coverage UAV as its scenario file describes it.
#[derive(Debug, Clone, PartialEq)]
pub struct CoverageScenario {
    /// The scenario's `name` (else the file stem).
    pub name: String,
    /// The scenario file.
    pub path: PathBuf,
    /// The UAV's index in the file (`uav[index]`).
    pub index: usize,
    /// The UAV's name.
    pub uav: String,
    /// Airframe preset name (default `kingfisher`, as in scenarios).
    pub airframe: String,
    pub airframe_overrides: BTreeMap<String, f64>,
    pub spec: CoverageSpec,
    /// Where every value of the file is written, to show problems at their line.
    pub source: SourceMap,
}

impl CoverageScenario {
    /// The folder relative paths in the spec start from.
    pub fn base_dir(&self) -> &Path {
        self.path.parent().unwrap_or(Path::new("."))
    }

    /// [`CoverageSpec::resolve`], each problem at its line and field in the scenario file.
    pub fn resolve(&self) -> Result<CoverageSetup, CoverageIoError> {
        self.spec
            .resolve(self.base_dir(), &self.path)
            .map_err(|e| self.locate(e))
    }

    /// [`CoverageSetup::plan`] for the `setup` this scenario resolved to, each problem at its
    /// line and field in the scenario file.
    pub fn plan(&self, setup: &CoverageSetup) -> Result<AltitudeOutcome, CoverageIoError> {
        setup.plan().map_err(|e| self.locate(e))
    }

    /// A coverage problem of this UAV at the line of the scenario field it concerns; problems
    /// of no one field are shown at the behaviour.
    pub fn locate(&self, error: CoverageIoError) -> CoverageIoError {
        let (field, message) = scenario_field(self.index, error);
        CoverageIoError::Scenario(ScenarioErrors {
            diagnostics: vec![self.source.diagnostic(&self.path, &field, message)],
        })
    }
}

/// The scenario field a coverage problem of `uav[index]` is about
/// (`uav[0].behaviour.overlap.y`), with its message; problems of no one field stay at the
/// behaviour. `uavex cover` and the world builder of `uavex run` both place them so.
pub(crate) fn scenario_field(index: usize, error: CoverageIoError) -> (String, String) {
    let behaviour = format!("uav[{index}].behaviour");
    match error {
        CoverageIoError::Spec { field, message, .. } => (format!("{behaviour}.{field}"), message),
        CoverageIoError::Plan { field, source } => {
            (format!("{behaviour}.{field}"), source.to_string())
        }
        other => (behaviour, other.to_string()),
    }
}

/// Reads `path` and returns its first coverage UAV.
pub fn read_coverage_scenario(path: &Path) -> Result<CoverageScenario, CoverageIoError> {
    let document = Document::read(path)?;
    let refuse = |field: &str, message: String| {
        CoverageIoError::Scenario(ScenarioErrors {
            diagnostics: vec![document.diagnostic(field, message)],
        })
    };
    let name = match document.decode::<String>("name")? {
        Some(name) => {
            // `uavex cover` names its output files after the scenario: a name with a path in
            // it would write outside the output folder.
            plain_file_stem(&name).map_err(|message| refuse("name", message))?;
            name
        }
        None => path
            .file_stem()
            .map_or("scenario".to_owned(), |s| s.to_string_lossy().into_owned()),
    };
    for index in document.indices("uav") {
        let uav = format!("uav[{index}]");
        let behaviour = format!("{uav}.behaviour");
        if document.text(&format!("{behaviour}.kind")) != Some("coverage") {
            continue;
        }
        let Some(BehaviourSpec::Coverage(spec)) = document.decode(&behaviour)? else {
            continue;
        };
        let overrides = document
            .decode(&format!("{uav}.airframe_overrides"))?
            .unwrap_or_default();
        let text_of = |key: &str| document.text(&format!("{uav}.{key}"));
        return Ok(CoverageScenario {
            name,
            path: path.to_owned(),
            index,
            uav: text_of("name").unwrap_or("uav").to_owned(),
            airframe: text_of("airframe").unwrap_or("kingfisher").to_owned(),
            airframe_overrides: overrides,
            spec,
            source: document.source().clone(),
        });
    }
    Err(refuse(
        "uav",
        "no UAV with `[uav.behaviour] kind = \"coverage\"` in this scenario".to_owned(),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_the_coverage_uav_and_its_airframe() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("field.toml");
        std::fs::write(
            &path,
            r#"
name = "field"
[[uav]]
name = "mapper"
start = { position = [0.0, 0.0, 1.0] }
behaviour = { kind = "scripted", speed = 1.0, waypoints = [[1.0, 0.0, 1.0]] }

[[uav]]
name = "surveyor"
airframe = "iris"
airframe_overrides = { drag_body = 0.2 }
start = { position = [0.0, 0.0, 0.0] }
[uav.behaviour]
kind = "coverage"
area = { vertices = [[0, 0], [100, 0], [100, 50], [0, 50]] }
camera = { angle_of_view = 1.2, width_px = 4000, height_px = 3000, shot_period_s = 1.0 }
overlap = { x = 0.2, y = 0.3 }
resolution_px_per_m = 50.0
available_energy_j = 90000.0
"#,
        )
        .unwrap();
        let scenario = read_coverage_scenario(&path).unwrap();
        assert_eq!(scenario.name, "field");
        assert_eq!(scenario.uav, "surveyor");
        assert_eq!(scenario.index, 1);
        assert_eq!(scenario.airframe, "iris");
        assert_eq!(scenario.airframe_overrides["drag_body"], 0.2);
        assert_eq!(scenario.spec.resolution_px_per_m, 50.0);
        assert_eq!(scenario.base_dir(), dir.path());
    }

    #[test]
    fn a_scenario_without_coverage_or_with_a_typo_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("s.toml");
        std::fs::write(&path, "name = \"x\"\n").unwrap();
        let error = read_coverage_scenario(&path).unwrap_err().to_string();
        assert!(error.contains("no UAV with"), "{error}");
        std::fs::write(
            &path,
            "[[uav]]\nname = \"a\"\n[uav.behaviour]\nkind = \"coverage\"\nareaa = 1\n",
        )
        .unwrap();
        let error = read_coverage_scenario(&path).unwrap_err().to_string();
        assert!(
            error.contains(":5:1: uav[0].behaviour.areaa: unknown field"),
            "{error}"
        );
    }

    /// `uavex cover` shows every problem of its scenario the way `uavex validate` does: file,
    /// line, column and field path, whether the settings do not decode, make no sense or cannot
    /// be planned.
    #[test]
    fn problems_are_shown_at_their_line_and_field() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("s.toml");
        let file = |behaviour: &str| {
            format!(
                "name = \"s\"\n\
                 [[uav]]\n\
                 name = \"mapper\"\n\
                 behaviour = {{ kind = \"scripted\", speed = 1.0, waypoints = [] }}\n\
                 [[uav]]\n\
                 name = \"surveyor\"\n\
                 [uav.behaviour]\n\
                 kind = \"coverage\"\n\
                 area = {{ vertices = [[0, 0], [300, 0], [300, 150], [0, 150]] }}\n\
                 camera = {{ angle_of_view = 1.5707963267948966, width_px = 4000, \
                 height_px = 3000, shot_period_s = 1.0 }}\n\
                 {behaviour}\n\
                 resolution_px_per_m = 100.0\n"
            )
        };
        let error = |behaviour: &str| {
            std::fs::write(&path, file(behaviour)).unwrap();
            let scenario = match read_coverage_scenario(&path) {
                Ok(scenario) => scenario,
                Err(e) => return e.to_string(),
            };
            let setup = match scenario.resolve() {
                Ok(setup) => setup,
                Err(e) => return e.to_string(),
            };
            scenario.plan(&setup).unwrap_err().to_string()
        };
        let at = |line_column: &str| format!("{}:{line_column}: uav[1].behaviour.", path.display());
        // Decoding: a value of the wrong type.
        let e = error("overlap = { x = 0.2, y = \"0.3\" }\navailable_energy_j = 2e5");
        assert!(e.starts_with(&format!("{}overlap.y: ", at("11:26"))), "{e}");
        assert_eq!(e.lines().count(), 1, "{e}");
        // Resolving: an overlap out of range.
        let e = error("overlap = { x = 1.5, y = 0.3 }\navailable_energy_j = 2e5");
        assert_eq!(
            e,
            format!(
                "{}overlap.x: overlap along x must lie in [0, 1), got 1.5",
                at("11:17")
            )
        );
        let e = error("overlap = { x = 0.2, y = 0.3 }\navailable_energy_j = -5.0");
        assert_eq!(
            e,
            format!(
                "{}available_energy_j: must be positive, got -5",
                at("12:22")
            )
        );
        // Planning: the altitude search's step, written on line 13.
        let e = error(
            "overlap = { x = 0.2, y = 0.3 }\navailable_energy_j = 2e5\n\
             altitude = { step_m = 1e-30, min_altitude_m = 10.0, max_altitude_m = 10.0 }",
        );
        assert!(
            e.starts_with(&format!("{}altitude.step_m: altitude search", at("13:23"))),
            "{e}"
        );
    }

    #[test]
    fn a_name_that_would_write_outside_the_output_folder_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("s.toml");
        let coverage = "[[uav]]\nname = \"a\"\n[uav.behaviour]\nkind = \"coverage\"\n\
                        area = { vertices = [[0, 0], [10, 0], [0, 10]] }\n\
                        camera = { angle_of_view = 1.2, width_px = 400, height_px = 300, \
                        shot_period_s = 1.0 }\noverlap = { x = 0.2, y = 0.3 }\n\
                        resolution_px_per_m = 10.0\navailable_energy_j = 1e5\n";
        for name in ["../../escape_cov", "/tmp/abs", "a/b", "..", ".", ""] {
            std::fs::write(&path, format!("name = {name:?}\n{coverage}")).unwrap();
            let error = read_coverage_scenario(&path).unwrap_err().to_string();
            assert!(
                error.contains(":1:8: name: ") && error.contains("plain file name"),
                "{name}: {error}"
            );
        }
        std::fs::write(&path, format!("name = \"field 2.v1\"\n{coverage}")).unwrap();
        assert_eq!(read_coverage_scenario(&path).unwrap().name, "field 2.v1");
    }
}
