//! Joining the results folders of a plan's shards (or of several machines) into one.
//!
//! Every finished run of every shard is copied into the merged folder (into a temporary name,
//! then renamed, so a merge that is interrupted leaves no half-copied run). A run present in
//! two folders is kept once; if its deterministic results differ between them, that is
//! reported as a conflict. Runs of the plan present in no folder are reported as missing.

use super::execute::{
    PLAN_FILE, RUNS_DIR, SUMMARY_FILE, SweepError, check_results_folder, io_error, is_finished,
};
use super::expand::expand;
use super::plan::Plan;
use crate::output::{HOST_FIELDS, write_atomically};
use std::path::{Path, PathBuf};

/// What a merge did.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct MergeReport {
    /// Runs copied into the merged folder.
    pub copied: usize,
    /// Runs already in the merged folder (or in an earlier shard) with the same results.
    pub already_present: usize,
    /// Runs found twice with different results (their ids).
    pub conflicts: Vec<String>,
    /// Runs of the plan that no folder holds (their ids), when the plan is known.
    pub missing: Vec<String>,
}

/// Merges the finished runs of `shards` into `out` (which may be one of them). Every shard
/// must be a results folder: a misspelt one would otherwise merge as a shard with no runs.
pub fn merge(out: &Path, shards: &[PathBuf]) -> Result<MergeReport, SweepError> {
    for shard in shards {
        check_results_folder(shard)?;
    }
    let plan_text = common_plan(out, shards)?;
    let runs_out = out.join(RUNS_DIR);
    std::fs::create_dir_all(&runs_out).map_err(io_error(&runs_out))?;
    if let Some(text) = &plan_text {
        let copy = out.join(PLAN_FILE);
        write_atomically(&copy, text.as_bytes()).map_err(io_error(&copy))?;
    }

    let mut report = MergeReport::default();
    for shard in shards {
        let runs_in = shard.join(RUNS_DIR);
        for id in finished_runs(&runs_in)? {
            let from = runs_in.join(&id);
            let to = runs_out.join(&id);
            if is_finished(&to) {
                if same_results(&from.join(SUMMARY_FILE), &to.join(SUMMARY_FILE))? {
                    report.already_present += 1;
                } else {
                    report.conflicts.push(id);
                }
                continue;
            }
            let partial = runs_out.join(format!(".{id}.partial"));
            for stale in [&partial, &to] {
                if stale.exists() {
                    std::fs::remove_dir_all(stale).map_err(io_error(stale))?;
                }
            }
            copy_dir(&from, &partial)?;
            std::fs::rename(&partial, &to).map_err(io_error(&to))?;
            report.copied += 1;
        }
    }

    if let Some(text) = plan_text {
        let plan = Plan::parse(&text, &out.join(PLAN_FILE))?;
        report.missing = expand(&plan)
            .into_iter()
            .filter(|run| !is_finished(&runs_out.join(&run.id)))
            .map(|run| run.id)
            .collect();
    }
    Ok(report)
}

/// The plan all folders share (`None` when none has one); refuses folders of different plans.
fn common_plan(out: &Path, shards: &[PathBuf]) -> Result<Option<String>, SweepError> {
    let mut found: Option<(PathBuf, String)> = None;
    for dir in shards.iter().map(PathBuf::as_path).chain([out]) {
        let path = dir.join(PLAN_FILE);
        if !path.is_file() {
            continue;
        }
        let text = std::fs::read_to_string(&path).map_err(io_error(&path))?;
        match &found {
            Some((first, known)) if *known != text => {
                return Err(SweepError::PlansDiffer(first.clone(), path));
            }
            Some(_) => {}
            None => found = Some((path, text)),
        }
    }
    Ok(found.map(|(_, text)| text))
}

/// Ids of the finished runs under `runs_dir`, sorted (none if the folder does not exist).
pub fn finished_runs(runs_dir: &Path) -> Result<Vec<String>, SweepError> {
    if !runs_dir.is_dir() {
        return Ok(Vec::new());
    }
    let mut ids = Vec::new();
    for entry in std::fs::read_dir(runs_dir).map_err(io_error(runs_dir))? {
        let entry = entry.map_err(io_error(runs_dir))?;
        let name = entry.file_name().to_string_lossy().into_owned();
        if !name.starts_with('.') && is_finished(&entry.path()) {
            ids.push(name);
        }
    }
    ids.sort();
    Ok(ids)
}

/// Two summaries agree on everything but the host's measurements ([`HOST_FIELDS`]).
fn same_results(a: &Path, b: &Path) -> Result<bool, SweepError> {
    let read = |path: &Path| -> Result<serde_json::Value, SweepError> {
        let text = std::fs::read_to_string(path).map_err(io_error(path))?;
        let mut value: serde_json::Value =
            serde_json::from_str(&text).unwrap_or(serde_json::Value::String(text));
        if let Some(object) = value.as_object_mut() {
            for field in HOST_FIELDS {
                object.remove(field);
            }
        }
        Ok(value)
    };
    Ok(read(a)? == read(b)?)
}

fn copy_dir(from: &Path, to: &Path) -> Result<(), SweepError> {
    std::fs::create_dir_all(to).map_err(io_error(to))?;
    for entry in std::fs::read_dir(from).map_err(io_error(from))? {
        let entry = entry.map_err(io_error(from))?;
        let target = to.join(entry.file_name());
        if entry.path().is_dir() {
            copy_dir(&entry.path(), &target)?;
        } else {
            std::fs::copy(entry.path(), &target).map_err(io_error(&target))?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn summary(dir: &Path, name: &str, energy: f64, wall: f64, decision_ms: f64) -> PathBuf {
        let path = dir.join(name);
        let text = format!(
            r#"{{"outcome": "complete", "energy_j": {energy}, "wall_time_s": {wall}, "decision_ms_p50": {decision_ms}, "decision_ms_p95": {decision_ms}}}"#
        );
        std::fs::write(&path, text).unwrap();
        path
    }

    #[test]
    fn runs_agree_whatever_the_host_measured_but_not_when_a_result_differs() {
        let dir = tempfile::tempdir().unwrap();
        let a = summary(dir.path(), "a.json", 100.0, 1.0, 20.0);
        let slower_host = summary(dir.path(), "b.json", 100.0, 3.0, 45.0);
        let other_result = summary(dir.path(), "c.json", 101.0, 1.0, 20.0);
        assert!(same_results(&a, &slower_host).unwrap());
        assert!(!same_results(&a, &other_result).unwrap());
    }
}
