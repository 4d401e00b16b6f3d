//! One run from start to files: build, step to the end, summarise, write outputs. A run that
//! fails (a panic anywhere in a system) is recorded as `failed` with its reason, and whatever
//! was computed until then is still written.

use crate::exploration::{ExplorationSummary, decision_timings_csv, decisions_csv};
use crate::formats::{octomap, ply};
use crate::metrics::{EXPLORED_THRESHOLDS, RunRecord};
use crate::output::{
    ExplorationKeys, RunSummary, UavSummary, map_series_csv, stage_timings_csv, uav_series_csv,
    write_atomically,
};
use crate::reachable::ReachableVolume;
use crate::record;
use crate::scenario::{self, LoadedScenario, ScenarioErrors};
use crate::sim::Sim;
use bevy_ecs::prelude::World;
use bevy_ecs::system::SystemState;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::{Path, PathBuf};
use std::time::Instant;
use uavex_components::exploration::{DecisionLog, DecisionTimings, Explorer};
use uavex_components::map::{MapConfig, MapTotals};
use uavex_components::sim::{Outcome, SimClock};
use uavex_components::uav::{PredictedMission, Uav, UavEnded};
use uavex_components::world::WorldGeometry;
use uavex_systems::flight::{EnergySummary, FlightEnergy};
use uavex_systems::mapping::{MapReader, OccupancyMap, WorldVoxels, map_accuracy};
use uavex_systems::stage_clock::StageClock;

/// How to run a scenario.
#[derive(Debug, Clone, Default)]
pub struct RunOptions {
    /// Where to write the run's files; nothing is written when `None`.
    pub out_dir: Option<PathBuf>,
    /// Overrides the scenario's seed.
    pub seed: Option<u64>,
    /// Writes a 3D recording of the run (rerun `.rrd`) to this file (`crate::record`).
    pub record: Option<PathBuf>,
    /// Ends the run as `failed` once it has taken this long in wall-clock time
    /// ([`Sim::run_within`]); `None`: only the scenario's simulated time limit.
    pub wall_limit: Option<std::time::Duration>,
}

/// Loads a scenario file and refuses it, with every problem located, if it cannot run as
/// written (including the problems only the built world reveals).
pub fn load_and_check(path: &Path) -> Result<LoadedScenario, ScenarioErrors> {
    let loaded = scenario::load(path)?;
    Sim::build(&loaded, loaded.scenario.seed)?;
    Ok(loaded)
}

/// What a run gives back: its summary, and whether its results folder was written.
#[derive(Debug)]
pub struct RunReport {
    pub summary: RunSummary,
    /// Set when the run's files could not all be written into [`RunOptions::out_dir`] (`None`
    /// also when no folder was asked for). The summary says it too, as its reason with the
    /// outcome `failed`, for the tables of a sweep; a caller tells a write that failed by this
    /// field, not by reading the reason.
    pub write_error: Option<WriteError>,
}

/// A run's results folder that could not be written (a full disk, a folder where a file goes).
/// Its text is the reason the run's summary gets.
#[derive(Debug, thiserror::Error)]
#[error("could not write results to {}: {source}", dir.display())]
pub struct WriteError {
    pub dir: PathBuf,
    pub source: std::io::Error,
}

/// Loads, checks and runs a scenario file.
pub fn run_file(path: &Path, options: &RunOptions) -> Result<RunReport, ScenarioErrors> {
    let loaded = scenario::load(path)?;
    run(&loaded, options)
}

/// Runs a loaded scenario. `Err` only for a scenario the world builder refuses; once the run
/// has started, every ending (including a panic, and results that could not be written) is a
/// report.
pub fn run(loaded: &LoadedScenario, options: &RunOptions) -> Result<RunReport, ScenarioErrors> {
    let seed = options.seed.unwrap_or(loaded.scenario.seed);
    let started = Instant::now();
    let mut sim = Sim::build(loaded, seed)?;
    let recording = options
        .record
        .as_deref()
        .map(|file| record::start(&mut sim, file, &loaded.scenario.name));
    let (outcome, reason) = match &recording {
        // Asked for a recording that cannot be made: fail before flying, not after.
        Some(Err(reason)) => (Outcome::Failed, reason.clone()),
        _ => catch_unwind(AssertUnwindSafe(|| sim.run_within(options.wall_limit))).unwrap_or_else(
            |panic| {
                (
                    Outcome::Failed,
                    format!("the run panicked: {}", panic_message(&panic)),
                )
            },
        ),
    };
    // The world may be mid-tick after a panic; what it recorded until then is still valid.
    let mut summary = summarise(&mut sim, &loaded.scenario.name, seed, outcome, reason);
    if let Some(Ok(())) = recording
        && let Err(e) =
            catch_unwind(AssertUnwindSafe(|| record::finish(&mut sim))).unwrap_or_else(|panic| {
                Err(format!("the recorder panicked: {}", panic_message(&panic)))
            })
    {
        // The run's own ending stays in the reason: a crash must not hide behind a full disk.
        summary.reason = format!(
            "could not write the recording {e} (the run: {})",
            summary.reason
        );
        summary.outcome = Outcome::Failed;
    }
    summary.wall_time_s = started.elapsed().as_secs_f64();
    let write_error = options.out_dir.as_ref().and_then(|dir| {
        write_outputs(&mut sim, &summary, dir, loaded.scenario.outputs.export_map)
            .err()
            .map(|source| WriteError {
                dir: dir.clone(),
                source,
            })
    });
    if let Some(e) = &write_error {
        summary.outcome = Outcome::Failed;
        summary.reason = e.to_string();
    }
    Ok(RunReport {
        summary,
        write_error,
    })
}

/// The text a panic was raised with.
fn panic_message(panic: &(dyn std::any::Any + Send)) -> &str {
    panic
        .downcast_ref::<String>()
        .map(String::as_str)
        .or_else(|| panic.downcast_ref::<&str>().copied())
        .unwrap_or("unknown panic")
}

/// What the summary needs of one UAV: index, name, ending, energy account, prediction.
type UavEnding = (
    usize,
    String,
    Option<UavEnded>,
    Option<EnergySummary>,
    Option<PredictedMission>,
);

/// The summary of a finished (or failed) run, from what the world holds.
fn summarise(sim: &mut Sim, name: &str, seed: u64, outcome: Outcome, reason: String) -> RunSummary {
    let world = &mut sim.world;
    let time_s = world.resource::<SimClock>().time_s();
    let ticks = world.resource::<SimClock>().tick;
    let metrics = world
        .resource::<MapTotals>()
        .metrics(world.resource::<MapConfig>());
    let accuracy = with_map(world, |reader, world| {
        let geometry = world.resource::<WorldGeometry>();
        let resolution = reader.config().resolution() as f32;
        map_accuracy(
            reader,
            WorldVoxels {
                geometry,
                resolution,
            },
        )
    })
    .flatten();
    let mut uavs: Vec<UavEnding> = world
        .query::<(
            &Uav,
            Option<&UavEnded>,
            Option<&FlightEnergy>,
            Option<&PredictedMission>,
        )>()
        .iter(world)
        .map(|(uav, ended, energy, predicted)| {
            let energy = energy.map(FlightEnergy::summary);
            (
                uav.index,
                uav.name.clone(),
                ended.cloned(),
                energy,
                predicted.copied(),
            )
        })
        .collect();
    uavs.sort_by_key(|(index, ..)| *index);
    let energies: Vec<&EnergySummary> = uavs.iter().filter_map(|u| u.3.as_ref()).collect();
    let energy_j = (!energies.is_empty()).then(|| energies.iter().map(|e| e.energy_j).sum());
    let battery_soc_end = energies.iter().map(|e| e.battery_soc_end).reduce(f64::min);
    let exploration = exploration_summary(world, outcome, time_s);
    let mut record = world.resource_mut::<RunRecord>();
    record.close(time_s, metrics);
    let record = world.resource::<RunRecord>();
    let [t50, t90, t95, t99] = record.threshold_times_s;
    debug_assert_eq!(EXPLORED_THRESHOLDS.len(), 4);
    RunSummary {
        scenario: name.to_owned(),
        seed,
        outcome,
        reason,
        mission_time_s: time_s,
        ticks,
        explored_fraction: metrics.explored_fraction,
        known_voxels: metrics.known_voxels,
        occupied_voxels: metrics.occupied_voxels,
        box_voxels: metrics.box_voxels,
        entropy_known_bits: metrics.mean_entropy_known,
        entropy_box_bits: metrics.mean_entropy_box,
        uncertainty_total: metrics.uncertainty_total,
        uncertainty_mean: metrics.uncertainty_mean,
        uncertainty_free_mean: metrics.mean_uncertainty_free,
        uncertainty_occupied_mean: metrics.mean_uncertainty_occupied,
        map_accuracy: accuracy,
        time_to_explored_50_s: t50,
        time_to_explored_90_s: t90,
        time_to_explored_95_s: t95,
        time_to_explored_99_s: t99,
        path_length_m: record.path_length_m.iter().sum(),
        energy_j,
        avg_power_w: record.fleet_power.as_ref().map(|f| f.average_power_w()),
        peak_power_w: record.fleet_power.as_ref().map(|f| f.peak_power_w),
        power_std_w: record.fleet_power.as_ref().map(|f| f.power_std_w()),
        battery_soc_end,
        exploration,
        uavs: uavs
            .into_iter()
            .map(|(index, name, ended, energy, predicted)| {
                let (status, at) = match ended {
                    None => ("flying", None),
                    Some(UavEnded::Finished) => ("finished", None),
                    Some(UavEnded::ReturnedHome { .. }) => ("returned_home", None),
                    Some(UavEnded::Crashed { time_s, position }) => {
                        ("crashed", Some((time_s, position.to_array())))
                    }
                    Some(UavEnded::BatteryEmpty { time_s, position }) => {
                        ("battery_empty", Some((time_s, position.to_array())))
                    }
                };
                UavSummary::new(
                    name,
                    record.path_length_m[index],
                    status.to_owned(),
                    at,
                    energy.as_ref(),
                    predicted,
                )
            })
            .collect(),
        wall_time_s: 0.0,
    }
}

/// The exploration keys of the summary, when some UAV explores: decisions, completion time,
/// prediction error, decision times, and the share of the reachable volume explored (the
/// free space connected to the first explorer's start, `crate::reachable`).
fn exploration_summary(
    world: &mut World,
    outcome: Outcome,
    time_s: f64,
) -> Option<ExplorationKeys> {
    let log = world.get_resource::<DecisionLog>()?;
    let timings = world.get_resource::<DecisionTimings>()?;
    let summary = ExplorationSummary::of(log, timings);
    let home = world
        .query::<(&Uav, &Explorer)>()
        .iter(world)
        .min_by_key(|(uav, _)| uav.index)
        .map(|(_, explorer)| explorer.home)?;
    let reachable = ReachableVolume::flood(
        world.resource::<MapConfig>(),
        world.resource::<WorldGeometry>(),
        home,
    )
    .ok();
    let explored_reachable_pct =
        reachable.and_then(|r| with_map(world, |reader, _| r.explored_pct(reader)));
    Some(ExplorationKeys {
        decisions: summary.decisions,
        completion_time_s: (outcome == Outcome::Complete).then_some(time_s),
        mean_prediction_error: summary.mean_prediction_error,
        decision_ms_p50: summary.decision_ms_p50,
        decision_ms_p95: summary.decision_ms_p95,
        explored_reachable_pct,
    })
}

/// Writes summary, series and (optionally) the map exports into `dir`.
fn write_outputs(
    sim: &mut Sim,
    summary: &RunSummary,
    dir: &Path,
    export_map: bool,
) -> std::io::Result<()> {
    std::fs::create_dir_all(dir)?;
    let world = &mut sim.world;
    {
        let record = world.resource::<RunRecord>();
        write_atomically(
            &dir.join("series.csv"),
            map_series_csv(&record.map_rows).as_bytes(),
        )?;
        write_atomically(
            &dir.join("uavs.csv"),
            uav_series_csv(&record.uav_rows).as_bytes(),
        )?;
    }
    if export_map {
        let (bt, cloud) = with_map(world, |reader, _| -> std::io::Result<_> {
            let config = reader.config();
            let mut bt = Vec::new();
            octomap::write_bt(&mut bt, config.resolution(), reader.known_voxels())?;
            let occupied = reader
                .known_voxels()
                .filter(|&(_, l)| l >= 0.0)
                .map(|(key, _)| config.center_of(key));
            let mut cloud = Vec::new();
            ply::write_points(&mut cloud, occupied)?;
            Ok((bt, cloud))
        })
        .ok_or_else(|| std::io::Error::other("the map is not readable"))??;
        write_atomically(&dir.join("map.bt"), &bt)?;
        write_atomically(&dir.join("map_occupied.ply"), &cloud)?;
    }
    if let Some(log) = world.get_resource::<DecisionLog>() {
        write_atomically(&dir.join("decisions.csv"), decisions_csv(log).as_bytes())?;
    }
    if let Some(timings) = world.get_resource::<DecisionTimings>() {
        write_atomically(
            &dir.join("decision_timings.csv"),
            decision_timings_csv(timings).as_bytes(),
        )?;
    }
    if let Some(clock) = world.get_resource::<StageClock>() {
        write_atomically(
            &dir.join("stage_timings.csv"),
            stage_timings_csv(clock).as_bytes(),
        )?;
    }
    // The summary goes last: its presence marks a run whose files are all written.
    let json = serde_json::to_vec_pretty(summary).map_err(std::io::Error::other)?;
    write_atomically(&dir.join("summary.json"), &json)
}

/// Calls `f` with a read-only view of the map; `None` if the world holds no map.
fn with_map<R>(world: &mut World, f: impl FnOnce(&MapReader, &World) -> R) -> Option<R> {
    let mut state = SystemState::<MapReader>::new(world);
    let reader = state.get(world).ok()?;
    Some(f(&reader, world))
}
