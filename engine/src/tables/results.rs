//! Reading a results folder: every finished run's coordinates (`run.json`) and summary
//! (`summary.json`), in plan order.

use super::TablesError;
use super::cells::{Cell, FlatRecord};
use crate::sweep::RunCoordinates;
use crate::sweep::execute::{RUN_FILE, RUNS_DIR, SUMMARY_FILE};
use crate::sweep::merge::finished_runs;
use std::path::{Path, PathBuf};

/// One finished run.
#[derive(Debug, Clone, PartialEq)]
pub struct RunRow {
    pub run: RunCoordinates,
    /// Every field of `summary.json`, in its order, flattened (`uavs.0.status`).
    pub summary: FlatRecord,
    /// The run's folder.
    pub dir: PathBuf,
}

impl RunRow {
    /// True for a run whose outcome is `failed` (refused, panicked, or unwritable).
    pub fn failed(&self) -> bool {
        self.summary.get("outcome") == Some(&Cell::Text("failed".to_owned()))
    }

    /// The group a run belongs to in the summary table: its scene and grid values.
    pub fn group_key(&self) -> (String, Vec<(String, String)>) {
        let coordinates = self
            .run
            .coordinates
            .iter()
            .map(|c| (c.path.clone(), value_text(&c.value)))
            .collect();
        (self.run.scene.clone(), coordinates)
    }
}

/// A grid value as a person reads it: strings without quotes, the rest as JSON.
pub fn value_text(value: &serde_json::Value) -> String {
    match value {
        serde_json::Value::String(s) => s.clone(),
        other => other.to_string(),
    }
}

/// The finished runs under `dir/runs`, in plan order (ties, as after a plan change, by id).
pub fn read_results(dir: &Path) -> Result<Vec<RunRow>, TablesError> {
    let runs_dir = dir.join(RUNS_DIR);
    let ids = finished_runs(&runs_dir).map_err(|e| TablesError::Read(e.to_string()))?;
    let mut rows = Vec::with_capacity(ids.len());
    for id in ids {
        let run_dir = runs_dir.join(&id);
        let read = |name: &str| {
            let path = run_dir.join(name);
            std::fs::read_to_string(&path).map_err(|e| TablesError::Io { path, source: e })
        };
        let bad = |name: &str, e: serde_json::Error| {
            TablesError::Read(format!("{}: {e}", run_dir.join(name).display()))
        };
        let run: RunCoordinates =
            serde_json::from_str(&read(RUN_FILE)?).map_err(|e| bad(RUN_FILE, e))?;
        let summary =
            FlatRecord::from_json_text(&read(SUMMARY_FILE)?).map_err(|e| bad(SUMMARY_FILE, e))?;
        rows.push(RunRow {
            run,
            summary,
            dir: run_dir,
        });
    }
    rows.sort_by(|a, b| (a.run.index, &a.run.id).cmp(&(b.run.index, &b.run.id)));
    Ok(rows)
}
