//! Candidates (eaae.md steps 5-7): a trajectory to every reachable frontier cluster, each rolled
//! out through the quadrotor model for its energy and duration.
//!
//! The published system planned each of its three candidates with its own kinodynamic search
//! (1.9-3.3 s per decision). Here one multi-goal search from the UAV reaches every cluster's
//! centroid and viewpoints at once; each cluster then gets its minimum-snap trajectory (centroid
//! first, then viewpoints in turn, eaae.md step 6) and its rollout, clusters in parallel
//! (rayon), results in cluster order so that the decision is the same on any thread count.

use super::budget::{ReturnHome, return_energies};
use crate::flight::ecs::{FlightEnergy, ReferenceTrajectory};
use crate::flight::{Completion, FlightState, RolloutConfig, RolloutResult, rollout};
use crate::mapping::MapReader;
use crate::planning::{GlobalPlan, Traversability, TraversableGrid, find_paths, plan_along};
use crate::trajectory::DynamicLimits;
use bevy_ecs::prelude::*;
use glam::{DVec3, Vec3};
use rayon::prelude::*;
use std::sync::Arc;
use std::time::Instant;
use uavex_components::airframe::Airframe;
use uavex_components::exploration::{
    CandidateTrajectory, DecisionTiming, Explorer, For, NeedsDecision, PredictedDuration,
    PredictedEnergy, Toward, Unaffordable,
};
use uavex_components::frontier::{FrontierCluster, Reachable, Viewpoint, Viewpoints};
use uavex_components::sim::SimClock;
use uavex_components::trajectory::{Trajectory, TrajectoryPoint};
use uavex_components::uav::QuadState;

/// Longest search (voxel expansions) of one decision: a few times the voxels of the largest
/// maps the exploration scenes use, so that a search always ends.
pub const MAX_EXPANSIONS: usize = 8_000_000;

/// A frontier cluster as the planner sees it.
#[derive(Debug, Clone, PartialEq)]
pub struct ClusterTarget {
    pub entity: Entity,
    pub centroid: Vec3,
    pub size: u32,
    pub viewpoints: Vec<Viewpoint>,
}

/// A cluster with a feasible trajectory toward it.
#[derive(Debug, Clone)]
pub struct PlannedCandidate {
    /// Index into the targets.
    pub target: usize,
    pub plan: GlobalPlan,
    pub goal: DVec3,
    pub goal_yaw: f64,
    /// `None`: the centroid; `Some(i)`: viewpoint `i`.
    pub viewpoint: Option<usize>,
}

/// Eaae.md step 6 for every target: the trajectory to its centroid, or failing that to each of
/// its viewpoints in turn; targets without a feasible trajectory are left out. One search
/// reaches every goal ([`find_paths`]); the trajectories are planned in parallel.
/// Goals within `min_travel_m` of the start are skipped: flying there gains nothing.
pub fn plan_candidates(
    grid: &TraversableGrid,
    start: &TrajectoryPoint,
    targets: &[ClusterTarget],
    limits: &DynamicLimits,
    min_travel_m: f64,
) -> Vec<PlannedCandidate> {
    // Goals: for each target its centroid, then its viewpoints.
    let mut goals = Vec::new();
    let mut first_goal = Vec::with_capacity(targets.len());
    for target in targets {
        first_goal.push(goals.len());
        goals.push(target.centroid.as_dvec3());
        goals.extend(target.viewpoints.iter().map(|v| v.position.as_dvec3()));
    }
    let paths = find_paths(grid, start.position, &goals, MAX_EXPANSIONS);
    targets
        .par_iter()
        .enumerate()
        .filter_map(|(index, target)| {
            let first = first_goal[index];
            let options = std::iter::once((None, None)).chain(
                target
                    .viewpoints
                    .iter()
                    .enumerate()
                    .map(|(i, v)| (Some(i), Some(f64::from(v.yaw)))),
            );
            options.enumerate().find_map(|(k, (viewpoint, yaw))| {
                let path = paths[first + k].as_ref()?;
                if goals[first + k].distance(start.position) <= min_travel_m {
                    return None;
                }
                let plan = plan_along(grid, start, path, yaw, limits).ok()?;
                let end = plan.trajectory.sample(plan.trajectory.duration());
                Some(PlannedCandidate {
                    target: index,
                    goal: end.position,
                    goal_yaw: end.yaw,
                    plan,
                    viewpoint,
                })
            })
        })
        .collect()
}

/// Eaae.md step 7: the predicted energy and duration of every planned candidate, from the
/// UAV's true state, in parallel; a rollout that fails (an unflyable trajectory) drops it.
pub fn roll_out_candidates(
    airframe: &Airframe,
    start: &FlightState,
    planned: &[PlannedCandidate],
    config: &RolloutConfig,
) -> Vec<Option<RolloutResult>> {
    planned
        .par_iter()
        .map(|candidate| rollout(airframe, start, &candidate.plan.trajectory, config).ok())
        .collect()
}

/// Where a new trajectory starts: the reference the controller tracks now (so the commanded
/// path stays continuous), or the UAV's pose at rest if it has none.
pub fn planning_start(
    reference: Option<&ReferenceTrajectory>,
    state: &QuadState,
    time_s: f64,
) -> TrajectoryPoint {
    reference.map_or_else(
        || TrajectoryPoint::at_rest(state.position.as_dvec3(), FlightState::from(state).yaw()),
        |r| r.at(time_s),
    )
}

/// Eaae.md steps 3 (the too-close rule) and 6 for one UAV at `position`: the targets at least
/// `min_distance` away (in the order given: the caller sorts them deterministically) and their
/// planned candidates; when none of those is feasible, the too-close targets instead (rather
/// than ending with frontier in reach). Returns the targets planned and the candidates, whose
/// `target` indexes them.
pub fn plan_decision(
    grid: &TraversableGrid,
    start: &TrajectoryPoint,
    clusters: &[ClusterTarget],
    position: Vec3,
    min_distance: f32,
    limits: &DynamicLimits,
    min_travel_m: f64,
) -> (Vec<ClusterTarget>, Vec<PlannedCandidate>) {
    let (far, near): (Vec<ClusterTarget>, Vec<ClusterTarget>) = clusters
        .iter()
        .cloned()
        .partition(|c| c.centroid.distance(position) >= min_distance);
    let planned = plan_candidates(grid, start, &far, limits, min_travel_m);
    if !planned.is_empty() || near.is_empty() {
        return (far, planned);
    }
    let planned = plan_candidates(grid, start, &near, limits, min_travel_m);
    (near, planned)
}

/// The reachable clusters as planning targets, ordered by centroid then size: entity order is
/// an accident of storage, and the decision must not depend on it.
pub fn cluster_targets(
    clusters: &Query<(Entity, &FrontierCluster, &Viewpoints), With<Reachable>>,
) -> Vec<ClusterTarget> {
    let mut all: Vec<ClusterTarget> = clusters
        .iter()
        .map(|(entity, cluster, viewpoints)| ClusterTarget {
            entity,
            centroid: cluster.centroid,
            size: cluster.size,
            viewpoints: viewpoints.0.clone(),
        })
        .collect();
    all.sort_by(|a, b| {
        a.centroid
            .to_array()
            .map(f32::to_bits)
            .cmp(&b.centroid.to_array().map(f32::to_bits))
            .then(a.size.cmp(&b.size))
    });
    all
}

/// Candidates of this decision, for the commit (how many clusters it saw, its timings, the
/// way home when nothing was affordable).
#[derive(Component, Debug, Clone)]
pub struct PendingDecision {
    pub clusters: usize,
    pub timing: DecisionTiming,
    pub go_home: Option<ReturnHome>,
}

/// Propose step: candidate entities for every UAV that needs a decision.
#[allow(clippy::type_complexity)]
pub fn propose_candidates(
    mut commands: Commands,
    clock: Res<SimClock>,
    map: MapReader,
    mut grid: ResMut<Traversability>,
    uavs: Query<
        (
            Entity,
            &Explorer,
            &Airframe,
            &QuadState,
            Option<&ReferenceTrajectory>,
            Option<&FlightEnergy>,
        ),
        With<NeedsDecision>,
    >,
    clusters: Query<(Entity, &FrontierCluster, &Viewpoints), With<Reachable>>,
) {
    if uavs.is_empty() {
        return;
    }
    grid.0.refresh(&map);
    let all = cluster_targets(&clusters);
    let time_s = clock.time_s();
    for (uav, explorer, airframe, state, reference, energy) in &uavs {
        let settings = &explorer.settings;
        let limits = DynamicLimits::of(airframe);
        let start = planning_start(reference, state, time_s);
        let flight_start = FlightState::from(state);
        // The rollout ends a flight by the same rule the goal is judged by when flown.
        let config = RolloutConfig {
            completion: Completion {
                position_tolerance: settings.goal_tolerance_m,
                speed_tolerance: settings.goal_speed_tolerance,
                ..Completion::default()
            },
            ..RolloutConfig::default()
        };
        let min_travel = settings.goal_tolerance_m;

        let planning = Instant::now();
        let (targets, planned) = plan_decision(
            &grid.0,
            &start,
            &all,
            state.position,
            settings.min_goal_distance_m,
            &limits,
            min_travel,
        );
        let trajectory_ms = planning.elapsed().as_secs_f64() * 1e3;

        let estimating = Instant::now();
        let rollouts = roll_out_candidates(airframe, &flight_start, &planned, &config);
        let mut returns = None;
        if let (Some(budget), Some(energy)) = (settings.budget, energy) {
            let left = energy.battery.usable_j - energy.battery.used_j - budget.reserve_j;
            returns = Some((
                left,
                return_energies(
                    &grid.0,
                    airframe,
                    explorer.home.as_dvec3(),
                    f64::from(explorer.home_yaw),
                    &planned,
                    &limits,
                    &config,
                ),
            ));
        }
        let energy_ms = estimating.elapsed().as_secs_f64() * 1e3;

        let mut any_affordable = false;
        for (k, (candidate, result)) in planned.iter().zip(&rollouts).enumerate() {
            let Some(result) = result else { continue };
            let target = &targets[candidate.target];
            let mut entity = commands.spawn((
                CandidateTrajectory {
                    trajectory: Arc::new(candidate.plan.trajectory.clone()),
                    goal: candidate.goal.as_vec3(),
                    goal_yaw: candidate.goal_yaw as f32,
                    information_gain: target.size,
                    centroid_distance_m: target.centroid.distance(state.position),
                    path_length_m: candidate.plan.path_length_m as f32,
                    viewpoint: candidate.viewpoint,
                },
                For(uav),
                Toward(target.entity),
                PredictedEnergy(result.energy_j),
                PredictedDuration(result.duration_s),
            ));
            match &returns {
                Some((left, home)) => match home[k] {
                    Some(back) if result.energy_j + back <= *left => any_affordable = true,
                    back => {
                        entity.insert(Unaffordable {
                            return_energy_j: back.unwrap_or(f64::INFINITY),
                        });
                    }
                },
                None => any_affordable = true,
            }
        }
        // Home when there were goals but none affordable; with nothing left to explore the
        // mission is complete where it is.
        let go_home = match (&returns, any_affordable) {
            (Some(_), false) if !planned.is_empty() => super::budget::plan_home(
                &grid.0,
                &start,
                explorer.home.as_dvec3(),
                f64::from(explorer.home_yaw),
                &limits,
            ),
            _ => None,
        };
        commands.entity(uav).insert(PendingDecision {
            clusters: targets.len(),
            timing: DecisionTiming {
                // Measured around the clustering step; the commit fills it in.
                clustering_ms: 0.0,
                trajectory_ms,
                energy_ms,
                total_ms: trajectory_ms + energy_ms,
            },
            go_home,
        });
    }
}
