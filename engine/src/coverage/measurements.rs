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
    fit_model(name, &rows, degrees).map_err(|source| CoverageIoError::Fit {
        path: csv.to_owned(),
        source,
    })
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
