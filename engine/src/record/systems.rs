//! The thin systems of the recorder. Each tick, in the Account stage, the recorder notes which
//! chunks changed and where the UAVs are; at its rate, and whenever a decision was made, the
//! log systems send what changed. Candidates live only inside the Decide stage (the commit step
//! despawns them), so one system takes their sketch there, between choice and commit.
//!
//! Every system only reads the simulation: a run records the same results with or without a
//! recorder.

use super::candidates::{
    CandidateSketch, candidate_strips, candidate_values, candidates_entity, chosen_entity,
    chosen_strip,
};
use super::frontier::{
    CENTROIDS, CLUSTERS, ClusterSketch, cluster_boxes, cluster_centroids, cluster_values,
};
use super::map::{chunk_entity, occupied_boxes, occupied_mask};
use super::plots::{map_scalars, uav_scalars};
use super::recorder::{DecisionSketch, Recorder};
use super::uav::{body_entity, body_pose, path_entity, path_strip};
use super::writer::Together;
use bevy_ecs::prelude::*;
use bevy_ecs::schedule::ScheduleConfigs;
use bevy_ecs::system::ScheduleSystem;
use re_chunk::EntityPath;
use uavex_components::exploration::{
    CandidateTrajectory, Candidates, Chosen, NeedsDecision, PredictedDuration, PredictedEnergy,
    Unaffordable,
};
use uavex_components::frontier::{FrontierCluster, Reachable};
use uavex_components::map::{ChunkCoord, ChunkIndex, MapConfig, MapTotals, VoxelChunk};
use uavex_components::sim::SimClock;
use uavex_components::uav::{QuadState, Uav};
use uavex_systems::exploration::propose::PendingDecision;
use uavex_systems::exploration::{DecideStep, any_uav_needs_decision};
use uavex_systems::flight::FlightEnergy;
use uavex_systems::stages::Stage;

/// The recorder's systems, for a run's tick schedule.
pub fn recorder_systems() -> ScheduleConfigs<ScheduleSystem> {
    (
        capture_decisions
            .run_if(any_uav_needs_decision)
            .in_set(Stage::Decide)
            .after(DecideStep::Choose)
            .before(DecideStep::Commit),
        (
            (note_changed_chunks, note_flown_paths),
            log_systems().run_if(log_due),
        )
            .chain()
            .in_set(Stage::Account),
    )
        .into_configs()
}

/// The systems that log (also run once more, alone, when the run has ended).
pub fn log_systems() -> ScheduleConfigs<ScheduleSystem> {
    (log_map, log_frontier, log_decisions, log_uavs, end_log).chain()
}

/// Run condition: a regular log is due, or a decision was made this tick.
pub fn log_due(recorder: Res<Recorder>, clock: Res<SimClock>) -> bool {
    recorder.due(clock.time_s())
}

/// Every tick: the chunks the Map stage changed (a chunk is spawned changed).
pub fn note_changed_chunks(
    mut recorder: ResMut<Recorder>,
    chunks: Query<&ChunkCoord, Changed<VoxelChunk>>,
) {
    for &coord in &chunks {
        recorder.note_changed(coord);
    }
}

/// Every tick: the UAVs' positions, for their flown paths.
pub fn note_flown_paths(
    mut recorder: ResMut<Recorder>,
    clock: Res<SimClock>,
    uavs: Query<(&Uav, &QuadState)>,
) {
    let time_s = clock.time_s();
    for (uav, state) in &uavs {
        if let Some(path) = recorder.paths.get_mut(uav.index) {
            path.note(time_s, state.position);
        }
    }
}

/// Decide stage, after the strategies chose and before the commit step despawns the
/// candidates: a sketch of every decision the commit step will log (a UAV that needs a goal and
/// was proposed candidates, possibly none).
#[allow(clippy::type_complexity)]
pub fn capture_decisions(
    mut recorder: ResMut<Recorder>,
    uavs: Query<
        (&Uav, Option<&Candidates>, Option<&Chosen>),
        (With<NeedsDecision>, With<PendingDecision>),
    >,
    candidates: Query<(
        &CandidateTrajectory,
        &PredictedEnergy,
        &PredictedDuration,
        Has<Unaffordable>,
    )>,
) {
    let mut decisions: Vec<DecisionSketch> = uavs
        .iter()
        .map(|(uav, list, chosen)| {
            let entities = list.map_or(&[][..], Candidates::entities);
            let sketches = entities
                .iter()
                .filter_map(|&entity| {
                    let (candidate, energy, duration, unaffordable) =
                        candidates.get(entity).ok()?;
                    let is_chosen = chosen.is_some_and(|c| c.0 == entity);
                    Some(CandidateSketch::of(
                        candidate,
                        energy.0,
                        duration.0,
                        !unaffordable,
                        is_chosen,
                    ))
                })
                .collect();
            DecisionSketch {
                uav: uav.index,
                candidates: sketches,
            }
        })
        .collect();
    decisions.sort_by_key(|d| d.uav);
    recorder.decisions.extend(decisions);
}

/// The occupied voxels of every chunk whose occupied set changed, and the map's series.
pub fn log_map(
    mut recorder: ResMut<Recorder>,
    clock: Res<SimClock>,
    config: Res<MapConfig>,
    totals: Res<MapTotals>,
    index: Res<ChunkIndex>,
    chunks: Query<&VoxelChunk>,
) {
    let time_s = clock.time_s();
    for coord in recorder.take_changed() {
        let Some(chunk) = index.get(coord).and_then(|e| chunks.get(e).ok()) else {
            continue;
        };
        let mask = occupied_mask(chunk);
        if recorder.show(coord, mask.clone()) {
            let boxes = occupied_boxes(coord, &mask, &config);
            recorder.log(&chunk_entity(coord), time_s, &boxes);
        }
    }
    for (entity, scalars) in map_scalars(&totals.metrics(&config)) {
        recorder.log(&entity, time_s, &scalars);
    }
}

/// At a decision: the frontier clusters it was made on.
pub fn log_frontier(
    mut recorder: ResMut<Recorder>,
    clock: Res<SimClock>,
    config: Res<MapConfig>,
    clusters: Query<(&FrontierCluster, Has<Reachable>)>,
) {
    if recorder.decisions.is_empty() {
        return;
    }
    let time_s = clock.time_s();
    let sketches: Vec<ClusterSketch> = clusters
        .iter()
        .map(|(cluster, reachable)| ClusterSketch::of(cluster, reachable))
        .collect();
    let boxes = cluster_boxes(&sketches, config.resolution());
    recorder.log(&EntityPath::from(CLUSTERS), time_s, &boxes);
    let centroids = cluster_centroids(&sketches);
    let values = cluster_values(&sketches);
    recorder.log(
        &EntityPath::from(CENTROIDS),
        time_s,
        &Together(&[&centroids, &values]),
    );
}

/// This tick's decisions: every candidate coloured by predicted energy, and the choice.
pub fn log_decisions(mut recorder: ResMut<Recorder>, clock: Res<SimClock>) {
    let time_s = clock.time_s();
    for decision in std::mem::take(&mut recorder.decisions) {
        let Some(name) = recorder.names.get(decision.uav).cloned() else {
            continue;
        };
        let strips = candidate_strips(&decision.candidates);
        let values = candidate_values(&decision.candidates);
        recorder.log(
            &candidates_entity(&name),
            time_s,
            &Together(&[&strips, &values]),
        );
        let chosen = chosen_strip(&decision.candidates);
        recorder.log(&chosen_entity(&name), time_s, &chosen);
    }
}

/// Each UAV's pose, the stretches of its path still being flown, its speed and power.
pub fn log_uavs(
    mut recorder: ResMut<Recorder>,
    clock: Res<SimClock>,
    uavs: Query<(&Uav, &QuadState, Option<&FlightEnergy>)>,
) {
    let time_s = clock.time_s();
    let mut uavs: Vec<_> = uavs.iter().collect();
    uavs.sort_by_key(|(uav, ..)| uav.index);
    for (uav, state, energy) in uavs {
        recorder.log(&body_entity(&uav.name), time_s, &body_pose(state));
        let stretches = recorder
            .paths
            .get_mut(uav.index)
            .map(|path| path.take_for_log())
            .unwrap_or_default();
        for (segment, points) in stretches {
            let strip = path_strip(&points);
            recorder.log(&path_entity(&uav.name, segment), time_s, &strip);
        }
        let speed = state.velocity.length();
        for (entity, scalars) in uav_scalars(&uav.name, speed, energy.map(|e| e.power_w)) {
            recorder.log(&entity, time_s, &scalars);
        }
    }
}

/// Closes this log: the next regular one is scheduled (decisions do not move it).
pub fn end_log(mut recorder: ResMut<Recorder>, clock: Res<SimClock>) {
    recorder.cadence.take(clock.time_s());
}
