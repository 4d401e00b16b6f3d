//! Measurement logs as CSV: one row per sample, columns `time_s`, `speed`, `power_w`, `phase`
//! (any order, header names case-insensitive; `time`, `speed_mps` and `power` are accepted too).
//! The phases are those of [`Phase`]; for `turn` rows the speed is the yaw rate (rad/s), for
//! `climb` and `descend` rows the vertical speed.

use super::CoverageIoError;
use std::path::Path;
use uavex_systems::coverage::{FitDegrees, FittedModel, Measurement, Phase, fit_model};

const COLUMNS: [(&str, &[&str]); 4] = [
    ("time_s", &["time_s", "time"]),
    ("speed", &["speed", "speed_mps"]),
    ("power_w", &["power_w", "power"]),
    ("phase", &["phase"]),
];

/// Reads every row; a bad cell is reported with its line and column.
pub fn read_measurements(path: &Path) -> Result<Vec<Measurement>, CoverageIoError> {
    let content = |message: String| CoverageIoError::Content {
        path: path.to_owned(),
        message,
    };
    let mut reader = csv::ReaderBuilder::new()
        .trim(csv::Trim::All)
        .from_path(path)
        .map_err(|e| content(e.to_string()))?;
    let headers = reader
        .headers()
        .map_err(|e| content(e.to_string()))?
        .clone();
    let mut index = [0usize; 4];
    for (slot, (name, aliases)) in index.iter_mut().zip(COLUMNS) {
        *slot = headers
            .iter()
            .position(|h| aliases.iter().any(|a| a.eq_ignore_ascii_case(h)))
            .ok_or_else(|| {
                content(format!(
                    "no `{name}` column (the header must name time_s, speed, power_w and phase)"
                ))
            })?;
    }
    let mut rows = Vec::new();
    for record in reader.records() {
        let record = record.map_err(|e| content(e.to_string()))?;
        let line = record.position().map_or(0, |p| p.line());
        let cell = |k: usize| record.get(index[k]).unwrap_or("");
        let number = |k: usize| -> Result<f64, CoverageIoError> {
            let text = cell(k);
            text.parse::<f64>()
                .ok()
                .filter(|x| x.is_finite())
                .ok_or_else(|| {
                    content(format!(
                        "line {line}, column `{}`: `{text}` is not a finite number",
                        COLUMNS[k].0
                    ))
                })
        };
        let phase: Phase = cell(3)
            .parse()
            .map_err(|e| content(format!("line {line}, column `phase`: {e}")))?;
        rows.push(Measurement {
            time_s: number(0)?,
            speed: number(1)?,
            power_w: number(2)?,
            phase,
        });
    }
    Ok(rows)
}

/// Fits a speed-based model named `name` from the measurements in `csv` with the chosen
/// polynomial degrees (coverage.md, "Deriving a model from measurements").
pub fn fit_measurements(
    csv: &Path,
    name: &str,
    degrees: FitDegrees,
) -> Result<FittedModel, CoverageIoError> {
    let rows = read_measurements(csv)?;
    fit_usable_model(name, &rows, degrees, csv)
}

/// Fits a model from `rows` (which came from `data`, named in errors) and refuses it right away
/// if the model loader would: `SpeedEnergyModel::validate`, the check
/// [`load_energy_model`](super::load_energy_model) applies to every model file. A least-squares
/// curve may dip to non-positive power within the measured speeds; such a model would otherwise
/// be written, and only refused when a mission used it.
pub(crate) fn fit_usable_model(
    name: &str,
    rows: &[Measurement],
    degrees: FitDegrees,
    data: &Path,
) -> Result<FittedModel, CoverageIoError> {
    let fitted = fit_model(name, rows, degrees).map_err(|source| CoverageIoError::Fit {
        path: data.to_owned(),
        source,
    })?;
    fitted
        .model
        .validate()
        .map_err(|source| CoverageIoError::UnusableFit {
            path: data.to_owned(),
            source,
        })?;
    Ok(fitted)
}

/// Writes rows in the format [`read_measurements`] reads.
pub fn write_measurements(path: &Path, rows: &[Measurement]) -> Result<(), CoverageIoError> {
    let io = |e: csv::Error| CoverageIoError::Content {
        path: path.to_owned(),
        message: e.to_string(),
    };
    let mut writer = csv::Writer::from_path(path).map_err(io)?;
    writer
        .write_record(COLUMNS.iter().map(|c| c.0))
        .map_err(io)?;
    for m in rows {
        writer
            .write_record([
                m.time_s.to_string(),
                m.speed.to_string(),
                m.power_w.to_string(),
                m.phase.to_string(),
            ])
            .map_err(io)?;
    }
    writer.flush().map_err(|source| CoverageIoError::Io {
        path: path.to_owned(),
        source,
    })
}

/// Rows of the IRIS model's experiments, 0.1 s apart, with `cruise_drop` W per m/s taken off the
/// level flight's power (test data of the coverage module's fits).
#[cfg(test)]
pub(crate) fn iris_rows(cruise_drop: f64) -> Vec<Measurement> {
    let iris = uavex_systems::coverage::SpeedEnergyModel::iris();
    let mut rows = Vec::new();
    let mut log = |speed: f64, power_w: f64, phase| {
        let time_s = rows.len() as f64 * 0.1;
        rows.push(Measurement {
            time_s,
            speed,
            power_w,
            phase,
        });
    };
    for i in 0..=150 {
        let v = i as f64 / 10.0;
        log(v, iris.accelerating.power(v), Phase::Accelerate);
    }
    for i in 0..=150 {
        let v = 15.0 - i as f64 / 10.0;
        log(v, iris.decelerating.power(v), Phase::Decelerate);
    }
    for i in 0..=15 {
        let v = i as f64;
        log(v, iris.level.power(v) - cruise_drop * v, Phase::Cruise);
    }
    log(2.0, 249.0, Phase::Climb);
    log(1.3, 212.0, Phase::Descend);
    log(2.1, 225.0, Phase::Turn);
    rows
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_and_aliases() {
        let dir = tempfile::tempdir().unwrap();
        let rows = vec![
            Measurement {
                time_s: 0.0,
                speed: 0.5,
                power_w: 230.25,
                phase: Phase::Accelerate,
            },
            Measurement {
                time_s: 0.05,
                speed: 2.1,
                power_w: 225.0,
                phase: Phase::Turn,
            },
        ];
        let path = dir.path().join("m.csv");
        write_measurements(&path, &rows).unwrap();
        assert_eq!(read_measurements(&path).unwrap(), rows);
        let path = dir.path().join("n.csv");
        std::fs::write(
            &path,
            "Phase, Power, Time, Speed_mps\nhover, 221.3, 1.5, 0\n",
        )
        .unwrap();
        assert_eq!(
            read_measurements(&path).unwrap(),
            vec![Measurement {
                time_s: 1.5,
                speed: 0.0,
                power_w: 221.3,
                phase: Phase::Hover
            }]
        );
    }

    /// A fit the model loader would refuse is refused when it is made, with the data file
    /// named, not later when the model is used.
    #[test]
    fn a_fit_the_loader_would_refuse_is_refused_naming_the_data() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("log.csv");
        write_measurements(&path, &iris_rows(0.0)).unwrap();
        let fitted = fit_measurements(&path, "iris again", FitDegrees::default()).unwrap();
        assert!(fitted.model.validate().is_ok());
        // Level flight that costs 30 W less per m/s: negative power at 15 m/s, the top speed.
        write_measurements(&path, &iris_rows(30.0)).unwrap();
        let err = fit_measurements(&path, "sinking", FitDegrees::default())
            .unwrap_err()
            .to_string();
        assert!(
            err.starts_with(&format!(
                "{}: the model fitted from these measurements is unusable: energy model \
                 `sinking`: level.coefficients give -",
                path.display()
            )),
            "{err}"
        );
        assert!(err.contains("must be positive at every speed"), "{err}");
    }

    #[test]
    fn bad_cells_name_line_and_column() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("m.csv");
        std::fs::write(
            &path,
            "time_s,speed,power_w,phase\n0,1,200,cruise\n0.1,fast,200,cruise\n",
        )
        .unwrap();
        let err = read_measurements(&path).unwrap_err().to_string();
        assert!(
            err.contains("line 3, column `speed`: `fast` is not a finite number"),
            "{err}"
        );
        std::fs::write(&path, "time_s,speed,power_w,phase\n0,1,200,glide\n").unwrap();
        let err = read_measurements(&path).unwrap_err().to_string();
        assert!(
            err.contains("line 2, column `phase`: unknown phase `glide`"),
            "{err}"
        );
        std::fs::write(&path, "time_s,speed,phase\n0,1,cruise\n").unwrap();
        let err = read_measurements(&path).unwrap_err().to_string();
        assert!(err.contains("no `power_w` column"), "{err}");
    }
}
