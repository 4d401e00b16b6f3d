//! Candidates (eaae.md steps 5-7): a trajectory to the reachable frontier clusters the UAV's
//! strategy needs (its `CandidateScope`, see [`super::evaluate`]), each rolled out through the
//! quadrotor model for its energy and duration, as candidate entities.
//!
//! The published system planned each of its three candidates with its own kinodynamic search
//! (1.9-3.3 s per decision). Here one multi-goal search from the UAV reaches every cluster's
//! centroid and viewpoints at once; each cluster then gets its minimum-snap trajectory (centroid
//! first, then viewpoints in turn, eaae.md step 6; viewpoints first with the standoff option,
//! [`with_standoff`]) and its rollout, clusters in parallel
//! (rayon), results in a fixed order so that the decision is the same on any thread count.

use super::budget::ReturnHome;
use super::evaluate::{
    BudgetCheck, DecisionInputs, Evaluation, TargetPaths, evaluate, plan_targets,
};
use crate::flight::ecs::{FlightEnergy, ReferenceTrajectory};
use crate::flight::{Completion, FlightState, RolloutConfig};
use crate::frontier::{frontier_viewpoint, standoff_viewpoints};
use crate::mapping::{MapReader, OccupancyMap};
use crate::planning::{GlobalPlan, Traversability, TraversableGrid};
use crate::trajectory::DynamicLimits;
use bevy_ecs::prelude::*;
use glam::{DVec3, IVec3, Vec3};
use std::sync::Arc;
use uavex_components::airframe::Airframe;
use uavex_components::exploration::{
    CandidateScope, CandidateTrajectory, DecisionTiming, Explorer, ExplorerSettings, For,
    NeedsDecision, PredictedDuration, PredictedEnergy, Toward, Unaffordable,
};
use uavex_components::frontier::{
    ClusterMembers, ClusterSettings, FrontierCluster, Reachable, Viewpoint, Viewpoints,
};
use uavex_components::map::MapConfig;
use uavex_components::sim::SimClock;
use uavex_components::trajectory::TrajectoryPoint;
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
    /// Whether a decision plans toward the centroid before the viewpoints (eaae.md step 6)
    /// or after them (the standoff option: `ExplorerSettings::standoff_m`).
    pub centroid_first: bool,
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

/// Eaae.md step 6 for every target (see [`plan_targets`]): one search reaches every goal,
/// the trajectories are planned in parallel.
pub fn plan_candidates(
    grid: &TraversableGrid,
    start: &TrajectoryPoint,
    targets: &[ClusterTarget],
    limits: &DynamicLimits,
    min_travel_m: f64,
) -> Vec<PlannedCandidate> {
    let mut paths = TargetPaths::new(grid, start.position, targets);
    let all: Vec<usize> = (0..targets.len()).collect();
    plan_targets(grid, start, targets, &mut paths, &all, limits, min_travel_m)
}

/// The rollout of a candidate: it ends a flight by the same rule the goal is judged by when
/// flown (the explorer's goal tolerances).
pub fn goal_rollout(settings: &ExplorerSettings) -> RolloutConfig {
    RolloutConfig {
        completion: Completion {
            position_tolerance: settings.goal_tolerance_m,
            speed_tolerance: settings.goal_speed_tolerance,
            ..Completion::default()
        },
        ..RolloutConfig::default()
    }
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

/// Eaae.md step 3's too-close rule: the targets at least `min_distance` from `position`, and
/// the others (in the order given: the caller sorts them deterministically). Decisions plan
/// the near ones only when none of the far ones has a feasible trajectory (rather than ending
/// with frontier in reach).
pub fn split_too_close(
    clusters: &[ClusterTarget],
    position: Vec3,
    min_distance: f32,
) -> (Vec<ClusterTarget>, Vec<ClusterTarget>) {
    clusters
        .iter()
        .cloned()
        .partition(|c| c.centroid.distance(position) >= min_distance)
}

/// Eaae.md steps 3 and 6 for one UAV at `position`, every cluster planned (the propose step
/// with [`CandidateScope::All`], trajectories only): the far targets of [`split_too_close`]
/// and their candidates, or the near ones if no far one is feasible. Returns the targets
/// planned and the candidates, whose `target` indexes them.
pub fn plan_decision(
    grid: &TraversableGrid,
    start: &TrajectoryPoint,
    clusters: &[ClusterTarget],
    position: Vec3,
    min_distance: f32,
    limits: &DynamicLimits,
    min_travel_m: f64,
) -> (Vec<ClusterTarget>, Vec<PlannedCandidate>) {
    let (far, near) = split_too_close(clusters, position, min_distance);
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
            centroid_first: true,
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

/// `targets` as a UAV with the standoff option plans them: each cluster's viewpoints
/// `distance` from its centroid ([`standoff_viewpoints`], nearest to `from` first) in place
/// of the thesis' and tried before the centroid.
pub fn with_standoff(
    targets: &[ClusterTarget],
    map: &impl OccupancyMap,
    distance: f32,
    clearance: f32,
    from: Vec3,
) -> Vec<ClusterTarget> {
    targets
        .iter()
        .map(|target| ClusterTarget {
            entity: target.entity,
            centroid: target.centroid,
            size: target.size,
            viewpoints: standoff_viewpoints(map, target.centroid, distance, clearance, from),
            centroid_first: false,
        })
        .collect()
}

/// `targets` with each cluster's frontier voxel nearest to its centroid ([`frontier_viewpoint`]
/// of its `members`) added after its viewpoints (the option beyond the thesis:
/// `ExplorerSettings::frontier_viewpoint`). With the standoff option the centroid is still
/// tried last.
pub fn with_frontier_viewpoints<'m>(
    targets: &[ClusterTarget],
    config: &MapConfig,
    members: impl Fn(Entity) -> Option<&'m [IVec3]>,
) -> Vec<ClusterTarget> {
    targets
        .iter()
        .map(|target| {
            let mut target = target.clone();
            let nearest = members(target.entity)
                .and_then(|keys| frontier_viewpoint(config, target.centroid, keys));
            target.viewpoints.extend(nearest);
            target
        })
        .collect()
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
#[allow(clippy::type_complexity, clippy::too_many_arguments)]
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
            Option<&CandidateScope>,
        ),
        With<NeedsDecision>,
    >,
    clusters: Query<(Entity, &FrontierCluster, &Viewpoints), With<Reachable>>,
    members: Query<&ClusterMembers>,
    cluster_settings: Res<ClusterSettings>,
) {
    if uavs.is_empty() {
        return;
    }
    grid.0.refresh(&map);
    let all = cluster_targets(&clusters);
    let time_s = clock.time_s();
    for (uav, explorer, airframe, state, reference, energy, scope) in &uavs {
        let settings = &explorer.settings;
        let limits = DynamicLimits::of(airframe);
        let start = planning_start(reference, state, time_s);
        let inputs = DecisionInputs {
            grid: &grid.0,
            start,
            flight: FlightState::from(state),
            airframe,
            limits,
            rollout: goal_rollout(settings),
            min_travel_m: settings.goal_tolerance_m,
            budget: settings
                .budget
                .zip(energy)
                .map(|(budget, energy)| BudgetCheck {
                    left_j: energy.battery.usable_j - energy.battery.used_j - budget.reserve_j,
                    home: explorer.home.as_dvec3(),
                    home_yaw: f64::from(explorer.home_yaw),
                }),
        };
        let scope = scope.copied().unwrap_or_default();

        let standoff;
        let clusters = match settings.standoff_m {
            None => &all,
            Some(distance) => {
                let clearance = cluster_settings.viewpoint_clearance_m;
                standoff = with_standoff(&all, &map, distance, clearance, state.position);
                &standoff
            }
        };
        let with_frontier;
        let clusters = if settings.frontier_viewpoint {
            with_frontier = with_frontier_viewpoints(clusters, &map.config, |entity| {
                members.get(entity).ok().map(|m| m.0.as_slice())
            });
            &with_frontier
        } else {
            clusters
        };
        let (far, near) = split_too_close(clusters, state.position, settings.min_goal_distance_m);
        let mut evaluation = evaluate(&inputs, &far, state.position, scope);
        let mut targets = far;
        if evaluation.planned == 0 && !near.is_empty() {
            let near_evaluation = evaluate(&inputs, &near, state.position, scope);
            evaluation = Evaluation {
                trajectory_ms: evaluation.trajectory_ms + near_evaluation.trajectory_ms,
                energy_ms: evaluation.energy_ms + near_evaluation.energy_ms,
                ..near_evaluation
            };
            targets = near;
        }

        let mut any_affordable = false;
        for evaluated in &evaluation.candidates {
            let (candidate, result) = (&evaluated.candidate, &evaluated.result);
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
            if evaluated.affordable(inputs.budget.as_ref()) {
                any_affordable = true;
            } else {
                entity.insert(Unaffordable {
                    return_energy_j: evaluated.return_j.flatten().unwrap_or(f64::INFINITY),
                });
            }
        }
        // Home when there were goals but none affordable; with nothing left to explore the
        // mission is complete where it is.
        let go_home = match (&inputs.budget, any_affordable) {
            (Some(budget), false) if evaluation.planned > 0 => super::budget::plan_home(
                &grid.0,
                &inputs.start,
                budget.home,
                budget.home_yaw,
                &inputs.limits,
            ),
            _ => None,
        };
        let (trajectory_ms, energy_ms) = (evaluation.trajectory_ms, evaluation.energy_ms);
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
