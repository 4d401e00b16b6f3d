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

/// `items` grouped by `key`: groups in order of first appearance, members in their order. A
/// map finds a key's group, not a search of the groups seen so far, which would be quadratic
/// in a sweep of many groups (a million single-seed combinations: 10^12 comparisons).
pub fn group_by<T, K: Ord + Clone>(
    items: impl IntoIterator<Item = T>,
    key: impl Fn(&T) -> K,
) -> Vec<(K, Vec<T>)> {
    let mut number = std::collections::BTreeMap::new();
    let mut groups: Vec<(K, Vec<T>)> = Vec::new();
    for item in items {
        let k = key(&item);
        let g = *number.entry(k.clone()).or_insert(groups.len());
        if g == groups.len() {
            groups.push((k, Vec::new()));
        }
        groups[g].1.push(item);
    }
    groups
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn groups_come_in_order_of_first_appearance() {
        let groups = group_by(["b1", "a1", "b2", "c1", "a2"], |s| s[..1].to_owned());
        let got: Vec<(String, Vec<&str>)> = groups;
        assert_eq!(
            got,
            [
                ("b".to_owned(), vec!["b1", "b2"]),
                ("a".to_owned(), vec!["a1", "a2"]),
                ("c".to_owned(), vec!["c1"]),
            ]
        );
    }
}
