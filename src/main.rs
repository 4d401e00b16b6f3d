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
}

/// Exit code for a scenario that cannot be run as written.
const INVALID_INPUT: u8 = 2;

fn main() -> ExitCode {
    match Cli::parse().command {
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
