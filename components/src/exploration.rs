//! Exploration (EAAE, eaae.md "Exploration cycle"): the data of a UAV that explores, of the
//! candidate trajectories it weighs at each decision, and of the decision log.
//!
//! A decision is a small pipeline of systems (DESIGN.md "Decide"): a UAV that needs a goal
//! carries [`NeedsDecision`]; candidate trajectories are entities tied to it by [`For`] and to
//! their frontier cluster by [`Toward`], each with its [`PredictedEnergy`] and
//! [`PredictedDuration`]; a strategy system marks its pick with [`Chosen`]; the commit system
//! turns the pick into the UAV's [`ExplorationGoal`] and a [`DecisionRecord`].

use bevy_ecs::prelude::*;
use glam::{IVec3, Vec3};
use serde::Serialize;
use std::sync::Arc;

use crate::trajectory::PiecewisePolynomial;

/// How a UAV explores: the parameters of the cycle shared by every strategy.
#[derive(Debug, Clone, PartialEq)]
pub struct ExplorerSettings {
    /// Clusters whose centroid lies closer than this to the UAV are not candidates (eaae.md
    /// step 3, "as the authors' code does": about 2 m), unless no other cluster is feasible.
    pub min_goal_distance_m: f32,
    /// Path length the local planner plans ahead (eaae.md step 9: about 1.5 x sensor range).
    pub horizon_m: f64,
    /// Period of the local planner's regular replanning (s).
    pub replan_period_s: f64,
    /// A goal on which the UAV got no closer by `progress_distance_m` for this long is given up
    /// and a new decision made (s).
    pub no_progress_timeout_s: f64,
    pub progress_distance_m: f64,
    /// Distance (m) and speed (m/s) under which a goal counts as reached.
    pub goal_tolerance_m: f64,
    pub goal_speed_tolerance: f64,
    /// The goal is invalid once fewer than this fraction of its cluster's voxels are still
    /// frontier ("its frontier vanished", eaae.md step 10).
    pub vanished_fraction: f32,
    /// Fly the evaluated candidate trajectory itself while it stays collision-free (the
    /// thesis' future work), so that predicted and flown energy coincide by design.
    pub unified: bool,
    /// Energy budget (beyond the thesis): `None` flies until the battery is empty.
    pub budget: Option<EnergyBudget>,
    /// When a goal is reached, the frontier voxels within this distance of the UAV (the space
    /// its camera has just seen: the sensor's range) are searched for the insides of obstacles
    /// behind them (`uavex_systems::exploration::interior`).
    pub interior_search_m: f32,
    /// Beyond the thesis: fly to a viewpoint this far from a cluster's centroid, level with
    /// it and facing it, before trying the centroid (`None`: the thesis' centroid first, then
    /// its viewpoints 0.5 m off; eaae.md step 6). See
    /// `uavex_systems::frontier::standoff_viewpoints`.
    pub standoff_m: Option<f32>,
    /// Beyond the thesis: after a cluster's viewpoints, try its frontier voxel nearest to its
    /// centroid (`false`: the thesis' goals alone; eaae.md steps 4 and 6). See
    /// `uavex_systems::frontier::frontier_viewpoint`.
    pub frontier_viewpoint: bool,
}

impl ExplorerSettings {
    /// The EAAE defaults for a camera of range `range_max_m`.
    pub fn for_range(range_max_m: f64) -> Self {
        Self {
            min_goal_distance_m: 2.0,
            horizon_m: 1.5 * range_max_m,
            replan_period_s: 0.5,
            no_progress_timeout_s: 6.0,
            progress_distance_m: 0.5,
            goal_tolerance_m: 0.3,
            goal_speed_tolerance: 0.5,
            vanished_fraction: 0.2,
            unified: false,
            budget: None,
            interior_search_m: range_max_m as f32,
            standoff_m: None,
            frontier_viewpoint: false,
        }
    }
}

/// Never choose a goal from which the predicted energy to fly home exceeds what is left minus
/// the reserve (the energy budget).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EnergyBudget {
    /// Energy kept in reserve on top of the predicted return (J).
    pub reserve_j: f64,
}

/// A UAV that explores (EAAE), and where it started (its home for the energy budget).
#[derive(Component, Debug, Clone, PartialEq)]
pub struct Explorer {
    pub settings: ExplorerSettings,
    pub home: Vec3,
    pub home_yaw: f32,
    /// The capsule (segment and radius, m) at the start checked clear of obstacles, which the
    /// planner takes as known free.
    pub start_clear: [Vec3; 2],
    pub start_clear_radius: f64,
}

/// Which clusters a decision plans and rolls out (eaae.md steps 6-7), a component of the UAV
/// set with its strategy; absent means [`CandidateScope::All`].
///
/// Planning a trajectory and rolling it out is most of a decision's cost, and a strategy that
/// looks only at the first clusters of some order (EAAE: the N of largest IG; Classic: the
/// largest; Nearest: the closest) needs only those that are choosable (feasible, and
/// affordable under an energy budget): `Ranked` evaluates clusters in that order until it has
/// `needed` of them, and the pick is the one evaluating every cluster would give (ties are
/// kept in the clusters' order either way). `All` evaluates every cluster, so that the decision
/// log prices every option (and any strategy may choose among them).
#[derive(Component, Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum CandidateScope {
    #[default]
    All,
    Ranked {
        by: Ranking,
        needed: usize,
    },
}

/// An order of clusters for [`CandidateScope::Ranked`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Ranking {
    /// Largest information gain first.
    InformationGain,
    /// Nearest centroid first (straight-line distance from the UAV).
    Distance,
}

/// Marker: the UAV needs a new goal; the Decide stage makes one this tick.
#[derive(Component, Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct NeedsDecision;

/// A candidate trajectory toward one frontier cluster (eaae.md steps 6-7).
#[derive(Component, Debug, Clone)]
pub struct CandidateTrajectory {
    pub trajectory: Arc<PiecewisePolynomial>,
    /// Where it ends (the cluster's centroid, or the viewpoint the planner had to fall back
    /// to; with `ExplorerSettings::standoff_m` a standoff viewpoint, or the centroid as the
    /// fallback) and the heading there.
    pub goal: Vec3,
    pub goal_yaw: f32,
    /// Information gain IG(c) = the cluster's frontier voxels (eaae.md step 5).
    pub information_gain: u32,
    /// Straight-line distance from the UAV to the cluster's centroid (the Nearest baseline).
    pub centroid_distance_m: f32,
    /// Length of the searched, shortened path (m).
    pub path_length_m: f32,
    /// Which goal was planned to: `None` the centroid, `Some(i)` viewpoint `i` (of the
    /// cluster's `Viewpoints`, or with the standoff option of its standoff viewpoints).
    pub viewpoint: Option<usize>,
}

/// Ties a candidate to the UAV whose decision it belongs to.
#[derive(Component, Debug, Clone, Copy, PartialEq, Eq)]
#[relationship(relationship_target = Candidates)]
pub struct For(pub Entity);

/// A UAV's candidates (maintained by bevy from [`For`]); they are despawned with the UAV.
#[derive(Component, Debug, Default)]
#[relationship_target(relationship = For, linked_spawn)]
pub struct Candidates(Vec<Entity>);

impl Candidates {
    pub fn entities(&self) -> &[Entity] {
        &self.0
    }
}

/// The frontier cluster a candidate flies toward.
#[derive(Component, Debug, Clone, Copy, PartialEq, Eq)]
pub struct Toward(pub Entity);

/// Energy the offline rollout predicts for a candidate (J; common.md §4).
#[derive(Component, Debug, Clone, Copy, PartialEq)]
pub struct PredictedEnergy(pub f64);

/// Duration the offline rollout predicts for a candidate (s).
#[derive(Component, Debug, Clone, Copy, PartialEq)]
pub struct PredictedDuration(pub f64);

/// Marker: with the energy budget, the return home from this candidate's goal would not be
/// affordable; strategies must not choose it.
#[derive(Component, Debug, Clone, Copy, PartialEq)]
pub struct Unaffordable {
    /// Predicted energy of the return flight from the goal (J).
    pub return_energy_j: f64,
}

/// A strategy's pick for its UAV this decision (set on the UAV by the strategy system).
#[derive(Component, Debug, Clone, Copy, PartialEq, Eq)]
pub struct Chosen(pub Entity);

/// Why the UAV is flying where it flies.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum GoalKind {
    /// A frontier cluster chosen by the strategy.
    Frontier,
    /// Home, because no goal was affordable within the energy budget.
    Home,
}

/// The goal a UAV is flying to, and what is needed to judge the decision afterwards.
#[derive(Component, Debug, Clone, PartialEq)]
pub struct ExplorationGoal {
    pub kind: GoalKind,
    /// Index of the decision in the [`DecisionLog`].
    pub decision: usize,
    pub position: Vec3,
    pub yaw: f32,
    /// The chosen cluster's frontier voxels when chosen (empty for `Home`).
    pub members: Vec<IVec3>,
    /// Simulation time and flown energy when the goal was set.
    pub started_s: f64,
    pub energy_at_start_j: f64,
    /// Closest distance to the goal so far and when it was reached (no-progress rule).
    pub best_distance_m: f64,
    pub best_distance_s: f64,
    /// Last replanning time of the local planner, and last check of the flown trajectory
    /// against the map (s).
    pub last_plan_s: f64,
    pub last_check_s: f64,
    /// Flying the evaluated candidate itself (unified mode) rather than the local planner's.
    pub flying_candidate: bool,
}

/// One candidate as the decision log keeps it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CandidateRecord {
    pub centroid: [f32; 3],
    pub goal: [f32; 3],
    pub information_gain: u32,
    pub centroid_distance_m: f32,
    pub path_length_m: f32,
    pub predicted_energy_j: f64,
    pub predicted_duration_s: f64,
    /// The return home would break the energy budget.
    pub unaffordable: bool,
}

/// How a decision's goal ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum GoalOutcome {
    Reached,
    /// Its frontier vanished before the UAV got there.
    Invalidated,
    /// No progress for the set time.
    NoProgress,
    /// The run ended first.
    Unfinished,
}

/// What the flight to a decision's goal cost, recorded when the goal ends.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct FlownLeg {
    pub outcome: GoalOutcome,
    pub energy_j: f64,
    pub time_s: f64,
    /// (flown - predicted) / predicted energy; meaningful when `outcome` is `Reached`.
    pub prediction_error: f64,
    /// Whether the evaluated candidate itself was flown to the end (unified mode, never
    /// replaced by the local planner).
    pub flew_candidate: bool,
}

/// One decision: every candidate, the choice, and afterwards the flown leg. Deterministic: a
/// pure function of scenario and seed (the wall-clock timings live in [`DecisionTimings`]).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DecisionRecord {
    pub uav: usize,
    pub time_s: f64,
    pub position: [f32; 3],
    /// Frontier clusters that passed the filters, and how many of them were too close.
    pub clusters: usize,
    pub candidates: Vec<CandidateRecord>,
    /// Index into `candidates`.
    pub chosen: Option<usize>,
    pub goal_kind: Option<GoalKind>,
    pub flown: Option<FlownLeg>,
}

/// Wall-clock cost of one decision (ms), split as EAAE Table 6.2 reports it.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct DecisionTiming {
    pub clustering_ms: f64,
    pub trajectory_ms: f64,
    pub energy_ms: f64,
    pub total_ms: f64,
}

/// Every decision of the run, in order.
#[derive(Resource, Debug, Clone, Default, PartialEq)]
pub struct DecisionLog {
    pub decisions: Vec<DecisionRecord>,
}

/// Timings of the decisions, index-aligned with [`DecisionLog::decisions`].
#[derive(Resource, Debug, Clone, Default, PartialEq)]
pub struct DecisionTimings {
    pub decisions: Vec<DecisionTiming>,
    /// Clustering time of the current decision (ms), set by the clustering stage.
    pub pending_clustering_ms: f64,
}
