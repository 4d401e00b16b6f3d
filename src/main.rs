//! The `uavex` command line: a thin layer over `uavex_engine`.

mod console;
mod out_dir;
mod results;
mod validate;

use clap::{Parser, Subcommand};
use console::{errln, out, outln};
use out_dir::{check_out_dir, remove_created};
use results::{merge_command, sweep_command, write_plots};
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Duration;
use uavex_components::sim::Outcome;
use uavex_engine::run::{RunOptions, RunReport};
use uavex_engine::sweep::FileKind;

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
        /// Write a 3D recording of the run for the rerun viewer (`rerun FILE.rrd`): occupied
        /// voxels, frontier clusters, candidate trajectories, flown paths, over simulated time.
        /// Needs the `record` feature.
        #[arg(long, value_name = "FILE.rrd")]
        record: Option<PathBuf>,
        /// End the run as failed if it takes longer than this in wall-clock time (s).
        #[arg(long, value_name = "SECONDS", value_parser = wall_limit)]
        wall_limit: Option<Duration>,
    },
    /// Check scenario files and sweep plans (each scenario variant a plan makes) and report
    /// every problem with file, line, column and field; nothing is run.
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
        /// Runs at once, 1 to 1024 (default: one per core); never more than the runs to start.
        #[arg(long, value_parser = jobs)]
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
        /// End each run as failed if it takes longer than this in wall-clock time (s); the
        /// sweep goes on with the others.
        #[arg(long, value_name = "SECONDS", value_parser = wall_limit)]
        run_wall_limit: Option<Duration>,
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
    /// Optimal speed v*(d), energy E(d, v*) and time t(d) of a straight leg from rest to rest
    /// under a speed-based energy model (coverage.md).
    Energy {
        /// A preset name (`iris`) or a fitted-model file (JSON or TOML).
        model: String,
        /// Leg length (m).
        #[arg(long)]
        distance: f64,
    },
    /// Plan the energy-aware coverage of a scenario's `kind = "coverage"` UAV: prints the plan
    /// and writes the path (CSV, GeoJSON) and a picture (PNG, SVG).
    Cover {
        scenario: PathBuf,
        /// Folder for the outputs (default: the current folder).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Also fly the plan on the simulated quadrotor of the scenario's airframe and compare
        /// the predicted energy and time with the flown ones.
        #[arg(long)]
        fly: bool,
    },
    /// Fly the energy-model experiments (accelerate, brake, constant-speed legs, hover, climb,
    /// descend, turn in place) on a simulated airframe and fit a speed-based energy model.
    Calibrate {
        /// Airframe preset name (kingfisher, iris).
        airframe: String,
        /// The fitted model file, .json or .toml (default: AIRFRAME_energy.json); the fit
        /// report and the measurement log are written beside it.
        #[arg(long)]
        out: Option<PathBuf>,
        /// Override an airframe field, as a scenario's `airframe_overrides` (repeatable),
        /// e.g. `--set drag_body=0.3`.
        #[arg(long = "set", value_name = "NAME=VALUE", value_parser = parse_override)]
        overrides: Vec<(String, f64)>,
    },
}

/// `NAME=VALUE` of `uavex calibrate --set`.
fn parse_override(text: &str) -> Result<(String, f64), String> {
    let (name, value) = text
        .split_once('=')
        .ok_or_else(|| format!("expected NAME=VALUE, got `{text}`"))?;
    let value = value
        .trim()
        .parse()
        .map_err(|e| format!("`{value}` is not a number: {e}"))?;
    Ok((name.trim().to_owned(), value))
}

/// Exit code for a scenario that cannot be run as written.
pub(crate) const INVALID_INPUT: u8 = 2;

/// A wall-clock limit in seconds: positive, finite and within a `Duration` (about 5.8e11
/// years; `Duration::from_secs_f64` panics beyond).
fn wall_limit(text: &str) -> Result<Duration, String> {
    let seconds: f64 = text
        .parse()
        .map_err(|_| format!("expected a number of seconds, got {text:?}"))?;
    let limit = Duration::try_from_secs_f64(seconds).ok();
    limit.filter(|l| !l.is_zero()).ok_or_else(|| {
        format!(
            "expected a positive number of seconds up to {:e}, got {text}",
            Duration::MAX.as_secs_f64()
        )
    })
}

/// `uavex sweep --jobs`: 1 to [`MAX_JOBS`](uavex_engine::sweep::execute::MAX_JOBS). Zero is
/// refused rather than read as "all cores": that is what leaving `--jobs` out means, and a
/// zero from a script (an unset CPU count) is more likely a mistake than a wish.
fn jobs(text: &str) -> Result<usize, String> {
    use uavex_engine::sweep::execute::MAX_JOBS;
    match text.parse::<usize>() {
        Ok(jobs) if (1..=MAX_JOBS).contains(&jobs) => Ok(jobs),
        _ => Err(format!(
            "expected a number of runs at once from 1 to {MAX_JOBS}, got {text:?} \
             (leave --jobs out for one per core)"
        )),
    }
}

fn main() -> ExitCode {
    console::exit_code(command(Cli::parse().command))
}

/// Carries out one command; its exit code.
fn command(command: Command) -> ExitCode {
    match command {
        Command::Sweep {
            plan,
            out,
            jobs,
            shard,
            max_runs,
            retry_failed,
            run_wall_limit,
        } => {
            let mut options = uavex_engine::sweep::SweepOptions::new(out);
            if let Some(jobs) = jobs {
                options.jobs = jobs;
            }
            options.shard = shard;
            options.max_runs = max_runs;
            options.retry_failed = retry_failed;
            options.run_wall_limit = run_wall_limit;
            options.progress = true;
            sweep_command(&plan, options)
        }
        Command::Merge { out, shards } => merge_command(&out, &shards),
        Command::Energy { model, distance } => energy_command(&model, distance),
        Command::Cover { scenario, out, fly } => cover_command(&scenario, out.as_deref(), fly),
        Command::Calibrate {
            airframe,
            out,
            overrides,
        } => calibrate_command(&airframe, out, &overrides.into_iter().collect()),
        Command::Plot { dir } => write_plots(&dir),
        Command::Validate { scenarios } => validate::validate_command(&scenarios),
        Command::Run {
            scenario,
            out,
            seed,
            record,
            wall_limit,
        } => {
            if record.is_some() && !uavex_engine::record::AVAILABLE {
                errln!("--record: {}", uavex_engine::record::FEATURE_MISSING);
                return ExitCode::from(INVALID_INPUT);
            }
            let loaded = match uavex_engine::scenario::load(&scenario) {
                Ok(loaded) => loaded,
                Err(errors) => {
                    // A plan read as a scenario fails on every key; say what it is instead.
                    if FileKind::of_file(&scenario) == FileKind::Plan {
                        errln!(
                            "{}: a sweep plan (it lists [[scenario]] tables), not a scenario: \
                             run it with `uavex sweep {} --out DIR`",
                            scenario.display(),
                            scenario.display()
                        );
                    } else {
                        errln!("{errors}");
                    }
                    return ExitCode::from(INVALID_INPUT);
                }
            };
            let created = match out.as_deref().map(check_out_dir).transpose() {
                Ok(created) => created.unwrap_or_default(),
                Err(e) => {
                    errln!("{e}");
                    return ExitCode::from(INVALID_INPUT);
                }
            };
            let options = RunOptions {
                out_dir: out,
                seed,
                record,
                wall_limit,
            };
            match uavex_engine::run::run(&loaded, &options) {
                // The world was refused: the run did not start and wrote nothing.
                Err(errors) => {
                    errln!("{errors}");
                    remove_created(&created);
                    ExitCode::from(INVALID_INPUT)
                }
                Ok(RunReport {
                    summary,
                    write_error,
                }) => {
                    outln!(
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
                    // Checked before the run, but a disk can fill up during one.
                    if let Some(e) = &write_error {
                        errln!("no results written to {}", e.dir.display());
                        return ExitCode::FAILURE;
                    }
                    if let Some(out) = &options.out_dir {
                        outln!("results in {}", out.display());
                    }
                    if let Some(file) = options.record.as_ref().filter(|f| f.exists()) {
                        outln!("recording in {} (view it with `rerun {0}`)", file.display());
                    }
                    // A crash or an empty battery is a result of the study; `failed` (a panic,
                    // the wall-clock limit, a flight that diverged) means there is none, which
                    // a script running uavex must be able to tell.
                    if summary.outcome == Outcome::Failed {
                        ExitCode::FAILURE
                    } else {
                        ExitCode::SUCCESS
                    }
                }
            }
        }
    }
}

/// `uavex energy`: the straight-leg figures of a preset or fitted speed-based model.
fn energy_command(model: &str, distance: f64) -> ExitCode {
    use uavex_engine::coverage::{energy_report, load_energy_model};
    let report = load_energy_model(model, std::path::Path::new("."))
        .map_err(|e| e.to_string())
        .and_then(|m| energy_report(&m, distance).map_err(|e| e.to_string()));
    match report {
        Ok(text) => {
            out!("{text}");
            ExitCode::SUCCESS
        }
        Err(e) => {
            errln!("{e}");
            ExitCode::from(INVALID_INPUT)
        }
    }
}

/// `uavex cover`: plans the scenario's coverage UAV, prints the plan, writes the files.
fn cover_command(scenario: &std::path::Path, out: Option<&std::path::Path>, fly: bool) -> ExitCode {
    use uavex_engine::coverage::read_coverage_scenario;
    let setup = read_coverage_scenario(scenario).and_then(|s| {
        let setup = s.resolve()?;
        Ok((s, setup))
    });
    let (coverage, setup) = match setup {
        Ok(found) => found,
        Err(e) => {
            errln!("{e}");
            return ExitCode::from(INVALID_INPUT);
        }
    };
    let outcome = match coverage.plan(&setup) {
        Ok(outcome) => outcome,
        Err(e) => {
            errln!("{e}");
            return ExitCode::from(INVALID_INPUT);
        }
    };
    out!("{}", setup.report(&outcome));
    let dir = out.unwrap_or(std::path::Path::new("."));
    match setup.write(&outcome, dir, &coverage.name) {
        Ok(files) => {
            for file in [
                &files.waypoints_csv,
                &files.legs_csv,
                &files.geojson,
                &files.png,
                &files.svg,
            ] {
                outln!("wrote {}", file.display());
            }
        }
        Err(e) => {
            errln!("{e}");
            return ExitCode::FAILURE;
        }
    }
    if !fly {
        return ExitCode::SUCCESS;
    }
    let flown = uavex_components::airframe::Airframe::preset(&coverage.airframe)
        .and_then(|mut a| a.apply_overrides(&coverage.airframe_overrides).map(|()| a))
        .map_err(|e| format!("airframe `{}`: {e}", coverage.airframe))
        .and_then(|airframe| {
            uavex_engine::coverage::fly_plan(&airframe, &outcome.plan, &setup.model)
                .map_err(|e| e.to_string())
        });
    match flown {
        Ok(c) => {
            outln!(
                "flown on the simulated {} with model `{}`:",
                coverage.airframe,
                setup.model.name
            );
            outln!(
                "  energy  predicted {:>10.1} J   flown {:>10.1} J   ({:+.2} %)",
                c.predicted_energy_j,
                c.flown_energy_j,
                100.0 * c.energy_error
            );
            outln!(
                "  time    predicted {:>10.1} s   flown {:>10.1} s   ({:+.2} %)",
                c.predicted_time_s,
                c.flown_time_s,
                100.0 * c.time_error
            );
            let path = dir.join(format!("{}_flown.json", coverage.name));
            match serde_json::to_string_pretty(&c)
                .map_err(|e| e.to_string())
                .and_then(|text| std::fs::write(&path, text).map_err(|e| e.to_string()))
            {
                Ok(()) => {
                    outln!("wrote {}", path.display());
                    ExitCode::SUCCESS
                }
                Err(e) => {
                    errln!("{}: {e}", path.display());
                    ExitCode::FAILURE
                }
            }
        }
        Err(e) => {
            errln!("{e}");
            ExitCode::FAILURE
        }
    }
}

/// `uavex calibrate`: flies the experiments, fits, writes the model, its report and the log,
/// and checks the model on fresh legs.
fn calibrate_command(
    airframe_name: &str,
    out: Option<PathBuf>,
    overrides: &std::collections::BTreeMap<String, f64>,
) -> ExitCode {
    use uavex_engine::coverage::{
        CalibrationPlan, calibrate, check_legs, fit_report, save_fitted_model, write_measurements,
    };
    let airframe = match uavex_components::airframe::Airframe::preset(airframe_name)
        .and_then(|mut a| a.apply_overrides(overrides).map(|()| a))
    {
        Ok(airframe) => airframe,
        Err(e) => {
            errln!("{e}");
            return ExitCode::from(INVALID_INPUT);
        }
    };
    let out = out.unwrap_or_else(|| PathBuf::from(format!("{airframe_name}_energy.json")));
    let plan = CalibrationPlan::for_airframe(&airframe);
    let calibration = match calibrate(airframe_name, &airframe, &plan) {
        Ok(calibration) => calibration,
        Err(e) => {
            errln!("{e}");
            return ExitCode::FAILURE;
        }
    };
    let report = fit_report(&calibration.fitted);
    outln!("{}", report.trim_end());
    if let Some(dir) = out.parent().filter(|d| !d.as_os_str().is_empty())
        && let Err(e) = std::fs::create_dir_all(dir)
    {
        errln!("cannot create {}: {e}", dir.display());
        return ExitCode::FAILURE;
    }
    let stem = out.with_extension("");
    let report_path = PathBuf::from(format!("{}_fit.txt", stem.display()));
    let log_path = PathBuf::from(format!("{}_measurements.csv", stem.display()));
    let written = save_fitted_model(&calibration.fitted, &out)
        .map_err(|e| e.to_string())
        .and_then(|()| std::fs::write(&report_path, &report).map_err(|e| e.to_string()))
        .and_then(|()| write_measurements(&log_path, &calibration.log).map_err(|e| e.to_string()));
    if let Err(e) = written {
        errln!("{e}");
        return ExitCode::FAILURE;
    }
    for path in [&out, &report_path, &log_path] {
        outln!("wrote {}", path.display());
    }
    // Fresh legs: lengths and speeds the calibration did not fly.
    let top = airframe.max_velocity;
    let legs = [(17.0, 0.33 * top), (43.0, 0.57 * top), (95.0, 0.83 * top)];
    match check_legs(&airframe, &calibration.fitted.model, &legs) {
        Ok(checks) => {
            outln!("fresh legs, E(d, v) predicted by the fit against flown:");
            for c in checks {
                outln!(
                    "  {:>6.1} m at {:>5.2} m/s: predicted {:>8.1} J, flown {:>8.1} J ({:+.2} %)",
                    c.distance_m,
                    c.speed,
                    c.predicted_j,
                    c.flown_j,
                    100.0 * c.error
                );
            }
            ExitCode::SUCCESS
        }
        Err(e) => {
            errln!("{e}");
            ExitCode::FAILURE
        }
    }
}
