//! Commit step: a strategy's pick becomes the UAV's goal (eaae.md step 9), every candidate is
//! written to the decision log, and the candidates are despawned. Without a pick:
//! - nothing affordable within the energy budget: fly home;
//! - no reachable frontier cluster left: the UAV has explored all it can (eaae.md step 10);
//! - clusters left but none with a feasible trajectory: wait and retry a few times (the UAV
//!   may sit where the inflated map blocks its start), then finish.

use super::propose::PendingDecision;
use crate::flight::ecs::{FlightEnergy, ReferenceTrajectory};
use bevy_ecs::prelude::*;
use std::sync::Arc;
use uavex_components::exploration::{
    CandidateRecord, CandidateTrajectory, Candidates, Chosen, DecisionLog, DecisionRecord,
    DecisionTimings, ExplorationGoal, Explorer, GoalKind, NeedsDecision, PredictedDuration,
    PredictedEnergy, Toward, Unaffordable,
};
use uavex_components::frontier::{ClusterMembers, FrontierCluster};
use uavex_components::sim::SimClock;
use uavex_components::trajectory::{Trajectory, TrajectoryPoint};
use uavex_components::uav::{QuadState, Uav, UavEnded};

/// Decisions without a feasible candidate tried before the UAV gives up on the clusters left.
pub const MAX_EMPTY_DECISIONS: u32 = 3;
/// Wait between such attempts (s): time for the map (and the UAV's hover) to settle.
pub const RETRY_AFTER_S: f64 = 1.0;

/// A UAV waiting to retry a decision that found no feasible candidate.
#[derive(Component, Debug, Clone, Copy, PartialEq)]
pub struct DecisionBackoff {
    pub retry_at_s: f64,
    pub attempts: u32,
}

/// The energy a UAV has drawn so far (0 for a kinematic UAV without an account).
pub fn energy_drawn(energy: Option<&FlightEnergy>) -> f64 {
    energy.map_or(0.0, |e| e.meter.energy_j)
}

/// Commit step (see module doc).
#[allow(clippy::type_complexity)]
pub fn commit_decisions(
    mut commands: Commands,
    clock: Res<SimClock>,
    mut log: ResMut<DecisionLog>,
    mut timings: ResMut<DecisionTimings>,
    mut uavs: Query<
        (
            Entity,
            &Uav,
            &Explorer,
            &QuadState,
            &PendingDecision,
            Option<&Chosen>,
            Option<&Candidates>,
            Option<&FlightEnergy>,
            Option<&mut ReferenceTrajectory>,
            Option<&DecisionBackoff>,
        ),
        With<NeedsDecision>,
    >,
    candidates: Query<(
        &CandidateTrajectory,
        &Toward,
        &PredictedEnergy,
        &PredictedDuration,
        Option<&Unaffordable>,
    )>,
    clusters: Query<(&FrontierCluster, &ClusterMembers)>,
) {
    let time_s = clock.time_s();
    let mut rows: Vec<_> = uavs.iter_mut().collect();
    // One record per UAV in scenario order, whatever the storage order.
    rows.sort_by_key(|row| row.1.index);
    for (uav, id, explorer, state, pending, chosen, list, energy, reference, backoff) in rows {
        let settings = &explorer.settings;
        let entities = list.map_or(&[][..], Candidates::entities);
        let mut records = Vec::with_capacity(entities.len());
        let mut chosen_index = None;
        for (i, &entity) in entities.iter().enumerate() {
            let Ok((candidate, toward, energy_j, duration, unaffordable)) = candidates.get(entity)
            else {
                continue;
            };
            if chosen.is_some_and(|c| c.0 == entity) {
                chosen_index = Some(i);
            }
            let centroid = clusters
                .get(toward.0)
                .map_or(candidate.goal, |(c, _)| c.centroid);
            records.push(CandidateRecord {
                centroid: centroid.to_array(),
                goal: candidate.goal.to_array(),
                information_gain: candidate.information_gain,
                centroid_distance_m: candidate.centroid_distance_m,
                path_length_m: candidate.path_length_m,
                predicted_energy_j: energy_j.0,
                predicted_duration_s: duration.0,
                unaffordable: unaffordable.is_some(),
            });
        }
        let mut timing = pending.timing;
        timing.clustering_ms = timings.pending_clustering_ms;
        timing.total_ms += timing.clustering_ms;

        for &entity in entities {
            commands.entity(entity).despawn();
        }

        // What to fly, if anything.
        let goal = match chosen_index {
            Some(i) => {
                let entity = entities[i];
                candidates.get(entity).ok().map(|(candidate, toward, ..)| {
                    let members = clusters
                        .get(toward.0)
                        .map(|(_, m)| m.0.clone())
                        .unwrap_or_default();
                    (
                        GoalKind::Frontier,
                        candidate.trajectory.clone() as Arc<dyn Trajectory>,
                        members,
                    )
                })
            }
            None => pending.go_home.as_ref().map(|home| {
                (
                    GoalKind::Home,
                    home.trajectory.clone() as Arc<dyn Trajectory>,
                    Vec::new(),
                )
            }),
        };
        let decision = log.decisions.len();
        log.decisions.push(DecisionRecord {
            uav: id.index,
            time_s,
            position: state.position.to_array(),
            clusters: pending.clusters,
            candidates: records,
            chosen: chosen_index,
            goal_kind: goal.as_ref().map(|g| g.0),
            flown: None,
        });
        timings.decisions.push(timing);

        let mut commands_for_uav = commands.entity(uav);
        commands_for_uav.remove::<(NeedsDecision, Chosen, PendingDecision, DecisionBackoff)>();
        let home_distance = f64::from(state.position.distance(explorer.home));
        match goal {
            Some((kind, trajectory, members)) => {
                let end: TrajectoryPoint = trajectory.sample(trajectory.duration());
                if let Some(mut reference) = reference {
                    *reference = ReferenceTrajectory {
                        trajectory,
                        start_s: time_s,
                    };
                }
                commands_for_uav.insert(ExplorationGoal {
                    kind,
                    decision,
                    position: end.position.as_vec3(),
                    yaw: end.yaw as f32,
                    members,
                    started_s: time_s,
                    energy_at_start_j: energy_drawn(energy),
                    best_distance_m: f64::from(state.position.distance(end.position.as_vec3())),
                    best_distance_s: time_s,
                    last_plan_s: if settings.unified {
                        time_s
                    } else {
                        f64::NEG_INFINITY
                    },
                    last_check_s: time_s,
                    flying_candidate: settings.unified,
                });
            }
            None if settings.budget.is_some() && !entities.is_empty() => {
                // Nothing affordable, and no way home planned: either the UAV is home already,
                // or no path leads there and it stays where it is.
                commands_for_uav.insert(if home_distance <= settings.goal_tolerance_m {
                    UavEnded::ReturnedHome { time_s }
                } else {
                    UavEnded::Finished
                });
            }
            None if pending.clusters == 0 => {
                commands_for_uav.insert(UavEnded::Finished);
            }
            None => {
                let attempts = backoff.map_or(1, |b| b.attempts + 1);
                if attempts > MAX_EMPTY_DECISIONS {
                    commands_for_uav.insert(UavEnded::Finished);
                } else {
                    commands_for_uav.insert(DecisionBackoff {
                        retry_at_s: time_s + RETRY_AFTER_S,
                        attempts,
                    });
                }
            }
        }
    }
}
