//! The tidy per-run table: one row per run, one column per variable (plan coordinates, seed,
//! then every summary field), as CSV; the same table is written as Parquet by `parquet`.

use super::cells::Cell;
use super::results::RunRow;

/// A table: named columns, rows of cells (a row has one cell per column).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Table {
    pub columns: Vec<String>,
    pub rows: Vec<Vec<Cell>>,
}

impl Table {
    /// The column's cells, top to bottom.
    pub fn column(&self, name: &str) -> Option<Vec<&Cell>> {
        let at = self.columns.iter().position(|c| c == name)?;
        Some(self.rows.iter().map(|row| &row[at]).collect())
    }
}

/// Columns every per-run table starts with, before the grid paths.
pub const LEADING_COLUMNS: [&str; 2] = ["run_id", "scene"];

/// One row per run: `run_id`, `scene`, one column per grid path (named by the path), `seed`,
/// then every field of the summaries in their order (a field only some runs have, such as a
/// failed run's missing metrics, is empty in the others).
pub fn runs_table(rows: &[RunRow]) -> Table {
    let mut coordinate_columns: Vec<String> = Vec::new();
    let mut summary_columns: Vec<String> = Vec::new();
    for row in rows {
        for c in &row.run.coordinates {
            if !coordinate_columns.contains(&c.path) {
                coordinate_columns.push(c.path.clone());
            }
        }
        for (name, _) in &row.summary.0 {
            if name != "seed" && !summary_columns.contains(name) {
                summary_columns.push(name.clone());
            }
        }
    }
    let leading: Vec<String> = LEADING_COLUMNS.iter().map(|c| (*c).to_owned()).collect();
    // A summary field named like a grid path keeps both, the summary's with a prefix.
    let summary_names: Vec<String> = summary_columns
        .iter()
        .map(|name| {
            if coordinate_columns.contains(name) || leading.contains(name) {
                format!("summary.{name}")
            } else {
                name.clone()
            }
        })
        .collect();
    let mut columns = leading;
    columns.extend(coordinate_columns.iter().cloned());
    columns.push("seed".to_owned());
    columns.extend(summary_names);

    let table_rows = rows
        .iter()
        .map(|row| {
            let mut cells = vec![
                Cell::Text(row.run.id.clone()),
                Cell::Text(row.run.scene.clone()),
            ];
            cells.extend(coordinate_columns.iter().map(|path| {
                row.run
                    .coordinates
                    .iter()
                    .find(|c| &c.path == path)
                    .map_or(Cell::Null, |c| Cell::from_json(&c.value))
            }));
            cells.push(Cell::Int(i64::try_from(row.run.seed).unwrap_or(i64::MAX)));
            cells.extend(
                summary_columns
                    .iter()
                    .map(|name| row.summary.get(name).cloned().unwrap_or(Cell::Null)),
            );
            cells
        })
        .collect();
    Table {
        columns,
        rows: table_rows,
    }
}

/// The table as CSV (RFC 4180 quoting: reasons hold commas and line breaks).
pub fn to_csv(table: &Table) -> Result<Vec<u8>, csv::Error> {
    let mut writer = csv::Writer::from_writer(Vec::new());
    writer.write_record(&table.columns)?;
    for row in &table.rows {
        writer.write_record(row.iter().map(Cell::to_csv))?;
    }
    writer
        .into_inner()
        .map_err(|e| csv::Error::from(std::io::Error::other(e.to_string())))
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::sweep::expand::{Coordinate, RunCoordinates};
    use crate::tables::cells::FlatRecord;

    pub(crate) fn row(index: usize, scene: &str, speed: f64, seed: u64, summary: &str) -> RunRow {
        RunRow {
            run: RunCoordinates {
                index,
                id: format!("{scene}-{speed}-{seed}"),
                scene: scene.to_owned(),
                scenario: format!("{scene}.toml"),
                coordinates: vec![Coordinate {
                    path: "uav.0.behaviour.speed".to_owned(),
                    value: serde_json::json!(speed),
                }],
                seed,
            },
            summary: FlatRecord::from_json_text(summary).unwrap(),
            dir: std::path::PathBuf::from("unused"),
        }
    }

    #[test]
    fn columns_are_ids_coordinates_seed_then_summary_fields() {
        let rows = [
            row(
                0,
                "room",
                1.0,
                0,
                r#"{"scenario": "r", "seed": 0, "outcome": "complete", "reason": "done, all seen", "mission_time_s": 2.5, "ticks": 250, "map_accuracy": null}"#,
            ),
            row(
                1,
                "room",
                2.0,
                0,
                r#"{"scenario": "room", "seed": 0, "outcome": "failed", "reason": "refused:\nline 3"}"#,
            ),
        ];
        let table = runs_table(&rows);
        assert_eq!(
            table.columns,
            [
                "run_id",
                "scene",
                "uav.0.behaviour.speed",
                "seed",
                "scenario",
                "outcome",
                "reason",
                "mission_time_s",
                "ticks",
                "map_accuracy"
            ]
        );
        assert_eq!(table.rows[0][2], Cell::Float(1.0));
        assert_eq!(table.rows[0][8], Cell::Int(250));
        // The failed run has no metrics: empty, not zero.
        assert_eq!(table.rows[1][7], Cell::Null);
        let csv = String::from_utf8(to_csv(&table).unwrap()).unwrap();
        let lines: Vec<&str> = csv.lines().collect();
        assert_eq!(
            lines[0],
            "run_id,scene,uav.0.behaviour.speed,seed,scenario,outcome,reason,mission_time_s,ticks,map_accuracy"
        );
        assert_eq!(
            lines[1],
            "room-1-0,room,1,0,r,complete,\"done, all seen\",2.5,250,"
        );
        assert_eq!(lines[2], "room-2-0,room,2,0,room,failed,\"refused:");
        assert_eq!(lines[3], "line 3\",,,");
    }
}
