//! The `uavex` command line: a thin layer over `uavex_engine`.

use clap::{Parser, Subcommand};
use std::path::PathBuf;
use std::process::ExitCode;
use uavex_engine::run::{RunOptions, load_and_check, run_file};

#[derive(Parser)]
#[command(
    name = "uavex",
    version,
    about = "Simulation engine for energy-aware UAV missions"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Run one scenario headlessly and write its results.
    Run {
        /// The scenario file (TOML).
        scenario: PathBuf,
        /// Folder for summary.json, series.csv, uavs.csv and the map exports.
        #[arg(long)]
        out: Option<PathBuf>,
        /// Override the scenario's seed.
        #[arg(long)]
        seed: Option<u64>,
    },
    /// Check scenario files and report every problem with file, line, column and field.
    Validate {
        #[arg(required = true)]
        scenarios: Vec<PathBuf>,
    },
    /// Run a sweep plan (scenarios x overrides x seeds) in parallel into a results folder;
    /// running it again into the same folder skips finished runs. Writes the tables
    /// (runs.csv, runs.parquet, summary.csv, summary.md) and plots (plots/) at the end.
    Sweep {
        /// The plan file (TOML).
        plan: PathBuf,
        /// The results folder.
        #[arg(long)]
        out: PathBuf,
        /// Runs at once (default: one per core).
        #[arg(long)]
        jobs: Option<usize>,
        /// Run only part i of N of the plan (1 <= i <= N), e.g. 2/4.
        #[arg(long)]
        shard: Option<uavex_engine::sweep::Shard>,
        /// Start at most this many runs now; the rest is left for a later resume.
        #[arg(long)]
        max_runs: Option<usize>,
        /// Run again the runs that failed before (otherwise a failure is a finished result).
        #[arg(long)]
        retry_failed: bool,
    },
    /// Join the results folders of a plan's shards into one, and write its tables and plots.
    Merge {
        /// The merged results folder (may be one of the shard folders).
        #[arg(long)]
        out: PathBuf,
        /// The shard folders.
        #[arg(required = true)]
        shards: Vec<PathBuf>,
    },
    /// Redraw the plots of a results folder (into DIR/plots).
    Plot { dir: PathBuf },
}

/// Exit code for a scenario that cannot be run as written.
const INVALID_INPUT: u8 = 2;

fn main() -> ExitCode {
    match Cli::parse().command {
        Command::Sweep {
            plan,
            out,
            jobs,
            shard,
            max_runs,
            retry_failed,
        } => {
            let mut options = uavex_engine::sweep::SweepOptions::new(out);
            if let Some(jobs) = jobs {
                options.jobs = jobs.max(1);
            }
            options.shard = shard;
            options.max_runs = max_runs;
            options.retry_failed = retry_failed;
            options.progress = true;
            sweep_command(&plan, options)
        }
        Command::Merge { out, shards } => merge_command(&out, &shards),
        Command::Plot { dir } => match uavex_engine::plot::plot_dir(&dir) {
            Ok(files) => {
                println!(
                    "{} plot files in {}",
                    files.len(),
                    dir.join("plots").display()
                );
                ExitCode::SUCCESS
            }
            Err(e) => {
                eprintln!("cannot plot {}: {e}", dir.display());
                ExitCode::FAILURE
            }
        },
        Command::Validate { scenarios } => {
            let mut all_valid = true;
            for path in &scenarios {
                match load_and_check(path) {
                    Ok(_) => println!("{}: ok", path.display()),
                    Err(errors) => {
                        all_valid = false;
                        eprintln!("{errors}");
                    }
                }
            }
            if all_valid {
                ExitCode::SUCCESS
            } else {
                ExitCode::from(INVALID_INPUT)
            }
        }
        Command::Run {
            scenario,
            out,
            seed,
        } => {
            let options = RunOptions { out_dir: out, seed };
            match run_file(&scenario, &options) {
                Err(errors) => {
                    eprintln!("{errors}");
                    ExitCode::from(INVALID_INPUT)
                }
                Ok(summary) => {
                    println!(
                        "{}: {} after {:.1} s simulated ({:.2} s wall), explored {:.1} %, map accuracy {}",
                        summary.scenario,
                        summary.reason,
                        summary.mission_time_s,
                        summary.wall_time_s,
                        summary.explored_fraction * 100.0,
                        summary
                            .map_accuracy
                            .map_or("n/a".to_owned(), |a| format!("{:.2} %", a * 100.0)),
                    );
                    if let Some(out) = &options.out_dir {
                        println!("results in {}", out.display());
                    }
                    ExitCode::SUCCESS
                }
            }
        }
    }
}

/// `uavex sweep`: runs the plan, then writes tables and plots of everything in the folder.
fn sweep_command(
    plan_path: &std::path::Path,
    options: uavex_engine::sweep::SweepOptions,
) -> ExitCode {
    use uavex_engine::sweep::{Plan, run_sweep};
    let plan = match Plan::load(plan_path) {
        Ok(plan) => plan,
        Err(e) => {
            eprintln!("{e}");
            return ExitCode::from(INVALID_INPUT);
        }
    };
    let started = std::time::Instant::now();
    let report = match run_sweep(&plan, &options) {
        Ok(report) => report,
        Err(e) => {
            eprintln!("sweep {}: {e}", plan.name);
            return ExitCode::FAILURE;
        }
    };
    let part = options
        .shard
        .map_or(String::new(), |s| format!(" (shard {s})"));
    println!(
        "sweep {}{part}: {} runs, {} finished before, {} ran in {:.1} s on {} jobs, {} failed{}",
        plan.name,
        report.planned,
        report.already_done,
        report.ran,
        started.elapsed().as_secs_f64(),
        options.jobs,
        report.failed.len(),
        if report.not_started > 0 {
            format!(", {} left for later", report.not_started)
        } else {
            String::new()
        },
    );
    for (id, reason) in &report.failed {
        println!(
            "  failed {id}: {}",
            reason.lines().next().unwrap_or_default()
        );
    }
    write_results(&options.out_dir)
}

/// `uavex merge`: joins shard folders, then writes tables and plots of the merged folder.
fn merge_command(out: &std::path::Path, shards: &[PathBuf]) -> ExitCode {
    let report = match uavex_engine::sweep::merge(out, shards) {
        Ok(report) => report,
        Err(e) => {
            eprintln!("merge: {e}");
            return ExitCode::FAILURE;
        }
    };
    println!(
        "merged {} folders into {}: {} runs copied, {} already there, {} conflicting, {} missing",
        shards.len(),
        out.display(),
        report.copied,
        report.already_present,
        report.conflicts.len(),
        report.missing.len(),
    );
    for id in &report.conflicts {
        println!("  conflict (different results in two folders): {id}");
    }
    for id in &report.missing {
        println!("  missing: {id}");
    }
    let written = write_results(out);
    if report.conflicts.is_empty() {
        written
    } else {
        ExitCode::FAILURE
    }
}

/// Tables and plots of a results folder.
fn write_results(dir: &std::path::Path) -> ExitCode {
    match uavex_engine::tables::write_tables(dir) {
        Ok(runs) => println!(
            "tables of {runs} runs: {0}/runs.csv, runs.parquet, summary.csv, summary.md",
            dir.display()
        ),
        Err(e) => {
            eprintln!("cannot write the tables of {}: {e}", dir.display());
            return ExitCode::FAILURE;
        }
    }
    match uavex_engine::plot::plot_dir(dir) {
        Ok(files) => {
            println!(
                "{} plot files in {}",
                files.len(),
                dir.join("plots").display()
            );
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("cannot plot {}: {e}", dir.display());
            ExitCode::FAILURE
        }
    }
}
