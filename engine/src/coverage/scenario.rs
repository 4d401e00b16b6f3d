//! The coverage part of a scenario file, for `uavex cover`: the first UAV whose behaviour is
//! `kind = "coverage"`, with its airframe. Read straight from the TOML tree, so planning needs
//! nothing else of the scenario (world, map, sensors) to be valid or even present.

use super::CoverageIoError;
use super::outputs::plain_file_stem;
use super::spec::CoverageSpec;
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// A coverage UAV as its scenario file describes it.
#[derive(Debug, Clone, PartialEq)]
pub struct CoverageScenario {
    /// The scenario's `name` (else the file stem).
    pub name: String,
    /// The scenario file.
    pub path: PathBuf,
    /// The UAV's name.
    pub uav: String,
    /// Airframe preset name (default `kingfisher`, as in scenarios).
    pub airframe: String,
    pub airframe_overrides: BTreeMap<String, f64>,
    pub spec: CoverageSpec,
}

impl CoverageScenario {
    /// The folder relative paths in the spec start from.
    pub fn base_dir(&self) -> &Path {
        self.path.parent().unwrap_or(Path::new("."))
    }
}

#[derive(Deserialize)]
struct Behaviour {
    kind: String,
}

/// Reads `path` and returns its first coverage UAV.
pub fn read_coverage_scenario(path: &Path) -> Result<CoverageScenario, CoverageIoError> {
    let content = |message: String| CoverageIoError::Content {
        path: path.to_owned(),
        message,
    };
    let text = std::fs::read_to_string(path).map_err(|source| CoverageIoError::Io {
        path: path.to_owned(),
        source,
    })?;
    let table: toml::Table = text
        .parse()
        .map_err(|e| content(format!("not valid TOML: {e}")))?;
    let name = match table.get("name") {
        Some(toml::Value::String(name)) => name.clone(),
        _ => path
            .file_stem()
            .map_or("scenario".to_owned(), |s| s.to_string_lossy().into_owned()),
    };
    // `uavex cover` names its output files after the scenario: a name with a path in it would
    // write outside the output folder.
    plain_file_stem(&name).map_err(|message| content(format!("name: {message}")))?;
    let uavs = match table.get("uav") {
        Some(toml::Value::Array(uavs)) => uavs.as_slice(),
        _ => &[],
    };
    for (index, uav) in uavs.iter().enumerate() {
        let Some(behaviour) = uav.get("behaviour") else {
            continue;
        };
        let kind = behaviour
            .clone()
            .try_into::<Behaviour>()
            .map(|b| b.kind)
            .unwrap_or_default();
        if kind != "coverage" {
            continue;
        }
        let mut settings = behaviour.as_table().cloned().unwrap_or_default();
        settings.remove("kind");
        let spec: CoverageSpec = toml::Value::Table(settings)
            .try_into()
            .map_err(|e| content(format!("uav[{index}].behaviour: {e}")))?;
        let text_of = |key: &str| uav.get(key).and_then(toml::Value::as_str);
        let overrides = match uav.get("airframe_overrides") {
            Some(value) => value
                .clone()
                .try_into()
                .map_err(|e| content(format!("uav[{index}].airframe_overrides: {e}")))?,
            None => BTreeMap::new(),
        };
        return Ok(CoverageScenario {
            name,
            path: path.to_owned(),
            uav: text_of("name").unwrap_or("uav").to_owned(),
            airframe: text_of("airframe").unwrap_or("kingfisher").to_owned(),
            airframe_overrides: overrides,
            spec,
        });
    }
    Err(content(
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
            error.contains("uav[0].behaviour") && error.contains("areaa"),
            "{error}"
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
                error.contains("name: ") && error.contains("plain file name"),
                "{name}: {error}"
            );
        }
        std::fs::write(&path, format!("name = \"field 2.v1\"\n{coverage}")).unwrap();
        assert_eq!(read_coverage_scenario(&path).unwrap().name, "field 2.v1");
    }
}
