//! The commands over results folders: `uavex sweep`, `uavex merge`, `uavex plot`.

use crate::INVALID_INPUT;
use crate::console::{errln, outln};
use std::path::PathBuf;
use std::process::ExitCode;
use uavex_engine::sweep::FileKind;

/// `uavex sweep`: runs the plan, then writes tables and plots of everything in the folder.
pub(crate) fn sweep_command(
    plan_path: &std::path::Path,
    options: uavex_engine::sweep::SweepOptions,
) -> ExitCode {
    use uavex_engine::sweep::execute::reason_excerpt;
    use uavex_engine::sweep::{Plan, run_sweep};
    let plan = match Plan::load(plan_path) {
        Ok(plan) => plan,
        Err(e) => {
            // A scenario read as a plan fails on its first table; say what it is instead.
            if FileKind::of_file(plan_path) == FileKind::Scenario {
                errln!(
                    "{}: a scenario (it lists [[uav]] tables), not a sweep plan: run it with \
                     `uavex run {}`, or name it in a plan's [[scenario]] table (docs/sweeps.md)",
                    plan_path.display(),
                    plan_path.display()
                );
            } else {
                errln!("{e}");
            }
            return ExitCode::from(INVALID_INPUT);
        }
    };
    let started = std::time::Instant::now();
    let report = match run_sweep(&plan, &options) {
        Ok(report) => report,
        Err(e) => {
            errln!("sweep {}: {e}", plan.name);
            return ExitCode::FAILURE;
        }
    };
    let part = options
        .shard
        .map_or(String::new(), |s| format!(" (shard {s})"));
    outln!(
        "sweep {}{part}: {} runs, {} finished before, {} ran in {:.1} s on {} jobs, {} failed{}",
        plan.name,
        report.planned,
        report.already_done,
        report.ran,
        started.elapsed().as_secs_f64(),
        report.jobs,
        report.failed.len(),
        if report.not_started > 0 {
            format!(", {} left for later", report.not_started)
        } else {
            String::new()
        },
    );
    for (id, reason) in &report.failed {
        outln!("  failed {id}: {}", reason_excerpt(reason, "    "));
    }
    write_results(&options.out_dir)
}

/// `uavex merge`: joins shard folders, then writes tables and plots of the merged folder.
pub(crate) fn merge_command(out: &std::path::Path, shards: &[PathBuf]) -> ExitCode {
    let report = match uavex_engine::sweep::merge(out, shards) {
        Ok(report) => report,
        Err(e) => {
            errln!("merge: {e}");
            return match e {
                uavex_engine::sweep::SweepError::NotResults(_) => ExitCode::from(INVALID_INPUT),
                _ => ExitCode::FAILURE,
            };
        }
    };
    outln!(
        "merged {} folders into {}: {} runs copied, {} already there, {} conflicting, {} missing",
        shards.len(),
        out.display(),
        report.copied,
        report.already_present,
        report.conflicts.len(),
        report.missing.len(),
    );
    for id in &report.conflicts {
        outln!("  conflict (different results in two folders): {id}");
    }
    for id in &report.missing {
        outln!("  missing: {id}");
    }
    let written = write_results(out);
    if !report.missing.is_empty() {
        // The tables hold what the folders had; a script (a Slurm merge job) must still see
        // that the result is not the plan's.
        errln!(
            "merge: {} of the plan's runs are in no folder; run their shards again (a sweep \
             resumes) and merge again",
            report.missing.len()
        );
    }
    if report.conflicts.is_empty() && report.missing.is_empty() {
        written
    } else {
        ExitCode::FAILURE
    }
}

/// Tables and plots of a results folder.
fn write_results(dir: &std::path::Path) -> ExitCode {
    match uavex_engine::tables::write_tables(dir) {
        Ok(runs) => outln!(
            "tables of {runs} runs: {0}/runs.csv, runs.parquet, summary.csv, summary.md",
            dir.display()
        ),
        Err(e) => {
            errln!("cannot write the tables of {}: {e}", dir.display());
            return ExitCode::FAILURE;
        }
    }
    write_plots(dir)
}

/// The plots of a results folder (`uavex plot`, and the end of a sweep or merge).
pub(crate) fn write_plots(dir: &std::path::Path) -> ExitCode {
    match uavex_engine::plot::plot_dir(dir) {
        Ok(files) => {
            outln!(
                "{} plot files in {}",
                files.len(),
                dir.join("plots").display()
            );
            ExitCode::SUCCESS
        }
        Err(e) => {
            errln!("cannot plot {}: {e}", dir.display());
            match e {
                uavex_engine::plot::PlotError::NotResults(_) => ExitCode::from(INVALID_INPUT),
                _ => ExitCode::FAILURE,
            }
        }
    }
}
