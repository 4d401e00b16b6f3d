//! Speed-based energy models by name: a preset (`iris`) or a model file, JSON or TOML, holding
//! either a bare model or a fitted model with its fit report (as [`save_fitted_model`] writes
//! it: `uavex calibrate`, or a fit of measured flights by [`super::fit_measurements`]).

use super::CoverageIoError;
use std::path::Path;
use uavex_systems::coverage::{FittedModel, SpeedEnergyModel};

/// A preset by name, else the file `name_or_file` (relative to `base_dir`), validated.
pub fn load_energy_model(
    name_or_file: &str,
    base_dir: &Path,
) -> Result<SpeedEnergyModel, CoverageIoError> {
    if let Some(model) = SpeedEnergyModel::preset(name_or_file) {
        return Ok(model);
    }
    let path = base_dir.join(name_or_file);
    if !path.exists() {
        return Err(CoverageIoError::Content {
            path,
            message: format!(
                "no such file, and `{name_or_file}` is not a preset energy model (presets: {})",
                SpeedEnergyModel::PRESETS.join(", ")
            ),
        });
    }
    let text = std::fs::read_to_string(&path).map_err(|source| CoverageIoError::Io {
        path: path.clone(),
        source,
    })?;
    let content = |message: String| CoverageIoError::Content {
        path: path.clone(),
        message,
    };
    let model = match extension(&path).as_deref() {
        Some("json") => {
            let value: serde_json::Value =
                serde_json::from_str(&text).map_err(|e| content(format!("not valid JSON: {e}")))?;
            if value.get("model").is_some() {
                serde_json::from_value::<FittedModel>(value).map(|f| f.model)
            } else {
                serde_json::from_value::<SpeedEnergyModel>(value)
            }
            .map_err(|e| content(format!("not an energy model: {e}")))?
        }
        Some("toml") => {
            let table: toml::Table = text
                .parse()
                .map_err(|e| content(format!("not valid TOML: {e}")))?;
            if table.contains_key("model") {
                toml::from_str::<FittedModel>(&text).map(|f| f.model)
            } else {
                toml::from_str::<SpeedEnergyModel>(&text)
            }
            .map_err(|e| content(format!("not an energy model: {e}")))?
        }
        _ => {
            return Err(content(
                "an energy model file must end in .json or .toml".to_owned(),
            ));
        }
    };
    model.validate().map_err(|e| content(e.to_string()))?;
    Ok(model)
}

/// Writes a fitted model (and its report) as JSON or TOML, by the file's extension.
pub fn save_fitted_model(fitted: &FittedModel, path: &Path) -> Result<(), CoverageIoError> {
    let content = |message: String| CoverageIoError::Content {
        path: path.to_owned(),
        message,
    };
    let text = match extension(path).as_deref() {
        Some("json") => serde_json::to_string_pretty(fitted).map_err(|e| content(e.to_string()))?,
        Some("toml") => toml::to_string_pretty(fitted).map_err(|e| content(e.to_string()))?,
        _ => {
            return Err(content(
                "an energy model file must end in .json or .toml".to_owned(),
            ));
        }
    };
    std::fs::write(path, text).map_err(|source| CoverageIoError::Io {
        path: path.to_owned(),
        source,
    })
}

fn extension(path: &Path) -> Option<String> {
    path.extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
}

#[cfg(test)]
mod tests {
    use super::*;
    use uavex_systems::coverage::{FitDegrees, fit_model};

    fn fitted() -> FittedModel {
        let rows = super::super::measurements::iris_rows(0.0);
        fit_model("refit", &rows, FitDegrees::default()).unwrap()
    }

    #[test]
    fn presets_and_files_load() {
        let dir = tempfile::tempdir().unwrap();
        assert_eq!(
            load_energy_model("iris", dir.path()).unwrap(),
            SpeedEnergyModel::iris()
        );
        let fitted = fitted();
        for name in ["model.json", "model.toml"] {
            save_fitted_model(&fitted, &dir.path().join(name)).unwrap();
            let loaded = load_energy_model(name, dir.path()).unwrap();
            assert_eq!(loaded.name, "refit");
            assert_eq!(loaded.climb, fitted.model.climb);
            for v in [0.0, 5.0, 12.5] {
                assert!((loaded.level.power(v) - fitted.model.level.power(v)).abs() < 1e-9);
            }
        }
        // A bare model file.
        let bare = dir.path().join("bare.json");
        std::fs::write(
            &bare,
            serde_json::to_string(&SpeedEnergyModel::iris()).unwrap(),
        )
        .unwrap();
        assert_eq!(
            load_energy_model("bare.json", dir.path()).unwrap(),
            SpeedEnergyModel::iris()
        );
    }

    #[test]
    fn bad_models_are_refused_with_the_reason() {
        let dir = tempfile::tempdir().unwrap();
        let err = load_energy_model("kestrel", dir.path())
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("not a preset energy model (presets: iris)"),
            "{err}"
        );
        let mut broken = SpeedEnergyModel::iris();
        broken.turn.rate = -1.0;
        std::fs::write(
            dir.path().join("b.json"),
            serde_json::to_string(&broken).unwrap(),
        )
        .unwrap();
        let err = load_energy_model("b.json", dir.path())
            .unwrap_err()
            .to_string();
        assert!(err.contains("turn rate must be positive"), "{err}");
        std::fs::write(dir.path().join("c.toml"), "name = \"x\"\nlevel = 3\n").unwrap();
        let err = load_energy_model("c.toml", dir.path())
            .unwrap_err()
            .to_string();
        assert!(err.contains("not an energy model"), "{err}");
        std::fs::write(dir.path().join("d.json"), "{\"name\": \"x\", \"typo\": 1}").unwrap();
        let err = load_energy_model("d.json", dir.path())
            .unwrap_err()
            .to_string();
        assert!(err.contains("unknown field `typo`"), "{err}");
    }
}
