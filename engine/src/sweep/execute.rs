//! Running a plan: runs in parallel on a rayon pool, each into its own folder, resumable and
//! robust to failing runs (DESIGN.md, "Runs, sweeps and scale").
//!
//! Layout of a results folder:
//! ```text
//! DIR/plan.toml              the plan as written (the record of what was asked)
//! DIR/runs/<run id>/run.json the run's coordinates, written before it starts
//! DIR/runs/<run id>/...      the run's files (series.csv, uavs.csv, maps)
//! DIR/runs/<run id>/summary.json   written last: its presence marks a finished run
//! ```
//! A run is finished when its `summary.json` exists, whatever its outcome: running the plan
//! again into the same folder skips it. A folder without `summary.json` is what an
//! interrupted run left; it is cleared and the run starts over.

use super::apply::apply_overrides;
use super::expand::{RunSpec, Shard, expand};
use super::plan::Plan;
use super::schedule::RunQueue;
use super::validate::read_scenario;
use crate::output::write_atomically;
use crate::run::{RunOptions, RunReport, run as run_scenario};
use crate::scenario::{LoadedScenario, parse_str};
use indicatif::{ProgressBar, ProgressStyle};
use serde::Serialize;
use std::collections::BTreeMap;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::{Path, PathBuf};
use std::sync::{Mutex, MutexGuard};
use std::time::{Duration, Instant};
use thiserror::Error;
use uavex_components::sim::Outcome;

/// File whose presence marks a finished run.
pub const SUMMARY_FILE: &str = "summary.json";
/// A run's coordinates in its folder.
pub const RUN_FILE: &str = "run.json";
/// Sub-folder of a results folder that holds one folder per run.
pub const RUNS_DIR: &str = "runs";
/// The plan's copy in a results folder.
pub const PLAN_FILE: &str = "plan.toml";
/// Most runs at once `uavex sweep --jobs` accepts. A worker is a thread of the pool, and
/// thousands of them only cost time to start (10000 took over a minute for 2 runs).
pub const MAX_JOBS: usize = 1024;
/// Lines of a failed run's reason that the console shows (a refused scenario's diagnostics);
/// the whole reason is in the run's `summary.json`.
pub const REASON_LINES: usize = 6;

/// How to run a plan.
#[derive(Debug, Clone)]
pub struct SweepOptions {
    pub out_dir: PathBuf,
    /// Runs at once (threads of the pool); at least 1, and never more than the runs to start.
    pub jobs: usize,
    /// Run only this part of the plan.
    pub shard: Option<Shard>,
    /// Start at most this many runs now (in plan order), leaving the rest for a later resume.
    pub max_runs: Option<usize>,
    /// Draw a progress bar on stderr (only when stderr is a terminal).
    pub progress: bool,
    /// Run again the runs that failed before (a failure is otherwise a finished result).
    pub retry_failed: bool,
    /// Each run's wall-clock limit ([`RunOptions::wall_limit`]).
    pub run_wall_limit: Option<Duration>,
}

impl SweepOptions {
    pub fn new(out_dir: impl Into<PathBuf>) -> Self {
        Self {
            out_dir: out_dir.into(),
            jobs: std::thread::available_parallelism().map_or(1, |n| n.get()),
            shard: None,
            max_runs: None,
            progress: false,
            retry_failed: false,
            run_wall_limit: None,
        }
    }
}

/// What a sweep did.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SweepReport {
    /// Runs of the plan (of this shard).
    pub planned: usize,
    /// Runs skipped because they had finished before.
    pub already_done: usize,
    /// Runs run now.
    pub ran: usize,
    /// Runs run now that failed (id, reason), in plan order.
    pub failed: Vec<(String, String)>,
    /// Runs left for later by `max_runs`.
    pub not_started: usize,
    /// Runs that ran at once: the jobs asked for, but no more than the runs to start.
    pub jobs: usize,
}

/// A sweep that cannot start or whose results cannot be written at all.
#[derive(Debug, Error)]
pub enum SweepError {
    #[error("{path}: {source}")]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("cannot start the worker threads: {0}")]
    Pool(String),
    #[error("{0} and {1} hold results of different plans (their plan.toml differ)")]
    PlansDiffer(PathBuf, PathBuf),
    #[error(transparent)]
    Plan(#[from] super::plan::PlanError),
    #[error(transparent)]
    NotResults(#[from] NotResultsFolder),
}

/// A folder given as a results folder (to merge or plot) that no sweep wrote.
#[derive(Debug, Error)]
#[error("{path} is not a results folder of `uavex sweep`: {why}")]
pub struct NotResultsFolder {
    pub path: PathBuf,
    pub why: &'static str,
}

/// Accepts a folder a sweep (or a merge) wrote: it holds `runs/` or `plan.toml`. Reading a
/// misspelt folder as one with no runs would give empty tables and a success.
pub fn check_results_folder(dir: &Path) -> Result<(), NotResultsFolder> {
    let why = if !dir.exists() {
        "there is no such folder"
    } else if !dir.is_dir() {
        "it is not a folder"
    } else if !dir.join(RUNS_DIR).is_dir() && !dir.join(PLAN_FILE).is_file() {
        "it holds neither a runs/ folder nor a plan.toml"
    } else {
        return Ok(());
    };
    Err(NotResultsFolder {
        path: dir.to_owned(),
        why,
    })
}

/// The first [`REASON_LINES`] lines of a failed run's reason, the later ones indented by
/// `indent`, and how many more there are.
pub fn reason_excerpt(reason: &str, indent: &str) -> String {
    let lines: Vec<&str> = reason.trim_end().lines().collect();
    let mut text = lines
        .iter()
        .take(REASON_LINES)
        .copied()
        .collect::<Vec<_>>()
        .join(&format!("\n{indent}"));
    if lines.len() > REASON_LINES {
        let more = lines.len() - REASON_LINES;
        text.push_str(&format!(
            "\n{indent}({more} more line{} in its {SUMMARY_FILE})",
            if more == 1 { "" } else { "s" }
        ));
    }
    text
}

pub(super) fn io_error(path: &Path) -> impl FnOnce(std::io::Error) -> SweepError + '_ {
    move |source| SweepError::Io {
        path: path.to_owned(),
        source,
    }
}

/// The summary of a run that never started (its scenario was refused) or whose results could
/// not be written: only what is known, so tables show its metrics as missing, not as zeros.
#[derive(Debug, Serialize)]
struct FailedSummary<'a> {
    scenario: &'a str,
    seed: u64,
    outcome: Outcome,
    reason: &'a str,
}

/// Runs `plan` (or its shard) into `options.out_dir`, skipping runs finished before.
pub fn run_sweep(plan: &Plan, options: &SweepOptions) -> Result<SweepReport, SweepError> {
    let runs_dir = options.out_dir.join(RUNS_DIR);
    std::fs::create_dir_all(&runs_dir).map_err(io_error(&runs_dir))?;
    let plan_copy = options.out_dir.join(PLAN_FILE);
    write_atomically(&plan_copy, plan.text.as_bytes()).map_err(io_error(&plan_copy))?;

    let mine: Vec<RunSpec> = expand(plan)
        .into_iter()
        .filter(|run| options.shard.is_none_or(|shard| shard.contains(run.index)))
        .collect();
    let mut report = SweepReport {
        planned: mine.len(),
        ..SweepReport::default()
    };
    let mut todo: Vec<&RunSpec> = mine
        .iter()
        .filter(|run| {
            let dir = runs_dir.join(&run.id);
            !is_finished(&dir) || (options.retry_failed && has_failed(&dir))
        })
        .collect();
    report.already_done = mine.len() - todo.len();
    if let Some(max) = options.max_runs
        && todo.len() > max
    {
        report.not_started = todo.len() - max;
        todo.truncate(max);
    }
    if todo.is_empty() {
        return Ok(report);
    }
    // No more runs at once than runs to start. The pool may keep more threads, up to the
    // cores, for the runs' own parallel parts; threads beyond both would only idle, and
    // thousands of them take long to start.
    report.jobs = options.jobs.clamp(1, todo.len());
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let threads = report.jobs.max(options.jobs.min(cores));

    // Each scenario file is read once; a file that cannot be read fails its runs.
    let texts: BTreeMap<&Path, Result<String, String>> = todo
        .iter()
        .map(|run| {
            let file = run.scenario_file.as_path();
            (file, read_scenario(file))
        })
        .collect();

    let bar = progress_bar(todo.len(), options.progress);
    let failed = Mutex::new(Vec::new());
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| SweepError::Pool(e.to_string()))?;
    // Runs that differ only in their seed form a group (see `schedule`): plan order lists a
    // group's seeds one after another, so its number is the plan index over the seed count.
    let groups: Vec<usize> = todo
        .iter()
        .map(|run| run.index / plan.seeds.len().max(1))
        .collect();
    let queue = Mutex::new(RunQueue::new(&groups));
    let take = || lock(&queue).take();
    // One worker per thread of the pool, each taking the next run until none is left; the
    // runs' own parallel parts (a decision's plans and rollouts) share the pool.
    pool.broadcast(|_| {
        while let Some(next) = take() {
            let run = &todo[next];
            let text = &texts[run.scenario_file.as_path()];
            let dir = runs_dir.join(&run.id);
            let started = Instant::now();
            let ending = execute_run(run, text, &dir, options.run_wall_limit);
            lock(&queue).finished(next, started.elapsed());
            if let Err(reason) = &ending {
                bar.println(format!(
                    "run {} failed: {}",
                    run.id,
                    reason_excerpt(reason, "    ")
                ));
                let mut failed = lock(&failed);
                failed.push((run.index, run.id.clone(), reason.clone()));
                bar.set_message(format!("{} failed", failed.len()));
            }
            bar.inc(1);
        }
    });
    // The report printed after the sweep says what the bar said.
    bar.finish_and_clear();

    let mut failed = failed.into_inner().unwrap_or_else(|e| e.into_inner());
    failed.sort();
    report.ran = todo.len();
    report.failed = failed.into_iter().map(|(_, id, why)| (id, why)).collect();
    Ok(report)
}

/// The data behind `mutex`, also after a panic elsewhere (a run's panic is caught and
/// recorded; the sweep goes on).
fn lock<T>(mutex: &Mutex<T>) -> MutexGuard<'_, T> {
    mutex.lock().unwrap_or_else(|e| e.into_inner())
}

/// True when the run in `dir` has finished (its summary exists).
pub fn is_finished(dir: &Path) -> bool {
    dir.join(SUMMARY_FILE).is_file()
}

/// True when the finished run in `dir` failed.
pub fn has_failed(dir: &Path) -> bool {
    std::fs::read_to_string(dir.join(SUMMARY_FILE))
        .ok()
        .and_then(|text| serde_json::from_str::<serde_json::Value>(&text).ok())
        .is_some_and(|summary| summary["outcome"] == "failed")
}

/// Runs one run into `dir`; `Err(reason)` when it failed (and its failed summary is written).
fn execute_run(
    run: &RunSpec,
    text: &Result<String, String>,
    dir: &Path,
    wall_limit: Option<Duration>,
) -> Result<(), String> {
    let attempt = catch_unwind(AssertUnwindSafe(|| attempt_run(run, text, dir, wall_limit)));
    let outcome = attempt.unwrap_or_else(|panic| {
        let message = panic
            .downcast_ref::<String>()
            .map(String::as_str)
            .or_else(|| panic.downcast_ref::<&str>().copied())
            .unwrap_or("unknown panic");
        Err(format!("the run panicked: {message}"))
    });
    match outcome {
        Ok(Some(reason)) => Err(reason),
        Ok(None) => Ok(()),
        Err(reason) => {
            let summary = FailedSummary {
                scenario: &run.scene,
                seed: run.seed,
                outcome: Outcome::Failed,
                reason: &reason,
            };
            let written = serde_json::to_vec_pretty(&summary)
                .map_err(std::io::Error::other)
                .and_then(|json| {
                    std::fs::create_dir_all(dir)?;
                    write_atomically(&dir.join(SUMMARY_FILE), &json)
                });
            match written {
                Ok(()) => Err(reason),
                Err(e) => Err(format!(
                    "{reason} (and its summary could not be written: {e})"
                )),
            }
        }
    }
}

/// `Ok(None)`: finished well; `Ok(Some(reason))`: ran and failed, summary written by the run;
/// `Err(reason)`: did not run or its summary was not written.
fn attempt_run(
    run: &RunSpec,
    text: &Result<String, String>,
    dir: &Path,
    wall_limit: Option<Duration>,
) -> Result<Option<String>, String> {
    // Clear what an interrupted attempt left.
    if dir.exists() {
        std::fs::remove_dir_all(dir)
            .map_err(|e| format!("cannot clear {} for a new attempt: {e}", dir.display()))?;
    }
    std::fs::create_dir_all(dir).map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
    let json = serde_json::to_vec_pretty(&run.record()).map_err(|e| e.to_string())?;
    write_atomically(&dir.join(RUN_FILE), &json)
        .map_err(|e| format!("cannot write {}: {e}", dir.join(RUN_FILE).display()))?;

    let loaded = load_run(run, text)?;
    let options = RunOptions {
        out_dir: Some(dir.to_owned()),
        seed: Some(run.seed),
        record: None,
        wall_limit,
    };
    let RunReport {
        summary,
        write_error,
    } = run_scenario(&loaded, &options)
        .map_err(|errors| format!("the world was refused:\n{errors}"))?;
    // Its files were not written: the reason says why, and `execute_run` writes it as the
    // run's summary.
    if write_error.is_some() {
        return Err(summary.reason);
    }
    Ok((summary.outcome == Outcome::Failed).then_some(summary.reason))
}

/// `run`'s scenario (`text`, as read from its file) with the run's overrides applied, loaded
/// and checked; or why the run cannot start.
pub(super) fn load_run(
    run: &RunSpec,
    text: &Result<String, String>,
) -> Result<LoadedScenario, String> {
    let text = text.as_ref().map_err(Clone::clone)?;
    let edited = apply_overrides(text, &run.overrides).map_err(|e| e.to_string())?;
    parse_str(&edited, &run.scenario_file)
        .map_err(|errors| format!("the scenario was refused:\n{errors}"))
}

fn progress_bar(len: usize, show: bool) -> ProgressBar {
    if !show {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::new(len as u64);
    let style = ProgressStyle::with_template(
        "{elapsed_precise} [{bar:32}] {pos}/{len} runs, {msg} (ETA {eta})",
    )
    .map(|s| s.progress_chars("=> "))
    .unwrap_or_else(|_| ProgressStyle::default_bar());
    bar.set_style(style);
    bar.set_message("0 failed");
    bar.enable_steady_tick(Duration::from_millis(500));
    bar
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_reason_is_shown_up_to_its_sixth_line() {
        assert_eq!(reason_excerpt("one line\n", "  "), "one line");
        let long: String = (1..=9).map(|i| format!("line {i}\n")).collect();
        assert_eq!(
            reason_excerpt(&long, "  "),
            "line 1\n  line 2\n  line 3\n  line 4\n  line 5\n  line 6\n  \
             (3 more lines in its summary.json)"
        );
    }
}
