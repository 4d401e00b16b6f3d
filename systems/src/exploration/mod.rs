//! Exploration (EAAE, eaae.md "Exploration cycle"): a UAV explores an unknown space, choosing
//! every next frontier cluster by a strategy, and flies there with a local reactive planner.
//!
//! One decision is a chain of small systems in the Decide stage ([`DecideStep`]):
//! 1. `Cluster`: frontier clusters as entities (`crate::frontier::refresh_clusters`);
//! 2. `Propose`: [`propose::propose_candidates`] plans a trajectory to the reachable clusters
//!    the strategy needs ([`evaluate`]: one multi-goal search, then minimum-snap per cluster, in
//!    parallel) and rolls each out through the quadrotor model (energy, duration), as
//!    candidate entities;
//! 3. `Choose`: exactly one strategy system per UAV marks its pick with `Chosen`
//!    ([`strategy`]: `eaae`, `classic`, `nearest`, `tour`; a new strategy is a new system here);
//! 4. `Commit`: [`commit::commit_decisions`] makes the pick the UAV's goal, logs the decision
//!    and despawns the candidates; with nothing left to explore the UAV has finished.
//!
//! Between decisions, [`execute::fly_to_goals`] (Plan stage) replans locally toward the goal
//! and decides when the goal is reached, invalid, or hopeless.

pub mod budget;
pub mod commit;
pub mod evaluate;
pub mod execute;
pub mod interior;
pub mod open_tour;
pub mod propose;
pub mod strategy;

use crate::frontier::{refresh_clusters, update_frontiers};
use crate::planning::track_traversability;
use crate::stages::Stage;
use bevy_ecs::prelude::*;
use std::time::Instant;
use uavex_components::exploration::{DecisionTimings, NeedsDecision};

/// The steps of one decision inside [`Stage::Decide`], in order.
#[derive(SystemSet, Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum DecideStep {
    Cluster,
    Propose,
    Choose,
    Commit,
}

/// Run condition: some UAV needs a goal this tick.
pub fn any_uav_needs_decision(uavs: Query<(), With<NeedsDecision>>) -> bool {
    !uavs.is_empty()
}

/// Adds the shared exploration systems (frontier upkeep, clustering, candidates, commit,
/// execution) to `schedule`; strategies are added on their own ([`strategy`]).
pub fn add_exploration_systems(schedule: &mut Schedule) {
    schedule.configure_sets(
        (
            DecideStep::Cluster,
            DecideStep::Propose,
            DecideStep::Choose,
            DecideStep::Commit,
        )
            .chain()
            .in_set(Stage::Decide),
    );
    schedule.add_systems((
        (update_frontiers, track_traversability).in_set(Stage::Frontier),
        (
            start_clustering_clock,
            refresh_clusters,
            stop_clustering_clock,
        )
            .chain()
            .run_if(any_uav_needs_decision)
            .in_set(DecideStep::Cluster),
        propose::propose_candidates.in_set(DecideStep::Propose),
        commit::commit_decisions.in_set(DecideStep::Commit),
        execute::fly_to_goals.in_set(Stage::Plan),
    ));
}

/// When the clustering of the current decision started (wall clock, for timings only: no
/// decision ever reads it).
#[derive(Resource, Debug, Default)]
pub struct ClusteringClock(Option<Instant>);

fn start_clustering_clock(mut clock: ResMut<ClusteringClock>) {
    clock.0 = Some(Instant::now());
}

/// Clustering time of the decision (EAAE Table 6.2 "clustering").
fn stop_clustering_clock(clock: Res<ClusteringClock>, mut timings: ResMut<DecisionTimings>) {
    timings.pending_clustering_ms = clock.0.map_or(0.0, |t| t.elapsed().as_secs_f64() * 1e3);
}

/// Inserts the exploration resources (the frontier and planning resources are inserted by
/// their own stages).
pub fn insert_exploration_resources(world: &mut World) {
    world.init_resource::<ClusteringClock>();
    world.init_resource::<DecisionTimings>();
    world.init_resource::<uavex_components::exploration::DecisionLog>();
    world.init_resource::<execute::VisitedFrontier>();
}
