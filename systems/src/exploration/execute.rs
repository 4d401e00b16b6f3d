//! Execution (eaae.md steps 9-10): the local reactive planner flies toward the goal, and the
//! goal ends when reached, when its frontier vanished, or after no progress for a set time;
//! each ending triggers the next decision.
//!
//! Local planner: every `replan_period_s`, and as soon as the map makes the rest of the
//! current trajectory non-traversable (checked every [`COLLISION_CHECK_PERIOD_S`]), a new
//! trajectory is planned from the current reference
//! state toward the goal over at most `horizon_m` of path (1.5 x the sensor range), on the
//! latest map ([`plan_local`]). In unified mode the evaluated candidate itself is flown while
//! it stays traversable; once it does not, the local planner takes over.
//!
//! Frontier that a reached goal could not clear (a sliver no viewpoint sees) would attract the
//! UAV forever: a voxel still frontier after a second reached goal covering it is ignored from
//! then on ([`VisitedFrontier`]); so is at once, when a goal is reached, a frontier voxel of
//! the goal or within the sensor's range that is one only because it borders the inside of an
//! obstacle ([`super::interior`]).

use super::commit::{DecisionBackoff, energy_drawn};
use super::interior::{around_interiors, frontier_near};
use crate::flight::ecs::{FlightEnergy, ReferenceTrajectory};
use crate::mapping::MapReader;
use crate::planning::{
    Traversability, TraversableGrid, plan_local, refresh_along, remains_traversable,
};
use crate::trajectory::DynamicLimits;
use bevy_ecs::prelude::*;
use glam::IVec3;
use std::collections::HashSet;
use std::sync::Arc;
use uavex_components::airframe::Airframe;
use uavex_components::exploration::{
    DecisionLog, ExplorationGoal, Explorer, ExplorerSettings, FlownLeg, GoalKind, GoalOutcome,
    NeedsDecision,
};
use uavex_components::frontier::FrontierSet;
use uavex_components::sim::SimClock;
use uavex_components::trajectory::Hold;
use uavex_components::uav::{QuadState, Uav, UavEnded};

/// How often the rest of the flown trajectory is checked against the latest map (s): a
/// trajectory the map makes collide is replanned at once, between the regular replans. (Every
/// map update would be 30 Hz; the inflation's refresh then costs as much as the mapping.)
pub const COLLISION_CHECK_PERIOD_S: f64 = 0.1;

/// Frontier voxels that were still frontier after a goal covering them was reached.
#[derive(Resource, Debug, Default, Clone, PartialEq)]
pub struct VisitedFrontier(pub HashSet<IVec3>);

/// Where a goal stands.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GoalStatus {
    Flying,
    Ended(GoalOutcome),
}

/// The goal rules of eaae.md step 10 (plain function): reached when the reference has run to
/// its end and the UAV is within the distance and speed tolerances there (the rule the
/// rollout's `Completion` applies, so flown and predicted legs end alike); invalid when fewer than `vanished_fraction` of its voxels are still
/// frontier; hopeless after `no_progress_timeout_s` without getting closer.
#[allow(clippy::too_many_arguments)]
pub fn goal_status(
    goal: &ExplorationGoal,
    settings: &ExplorerSettings,
    reference_ended: bool,
    distance_m: f64,
    speed: f64,
    still_frontier: usize,
    time_s: f64,
) -> GoalStatus {
    if reference_ended
        && distance_m <= settings.goal_tolerance_m
        && speed <= settings.goal_speed_tolerance
    {
        return GoalStatus::Ended(GoalOutcome::Reached);
    }
    if goal.kind == GoalKind::Frontier
        && (still_frontier as f32) < settings.vanished_fraction * goal.members.len() as f32
    {
        return GoalStatus::Ended(GoalOutcome::Invalidated);
    }
    if time_s - goal.best_distance_s > settings.no_progress_timeout_s {
        return GoalStatus::Ended(GoalOutcome::NoProgress);
    }
    GoalStatus::Flying
}

/// A new local plan from the reference at `time_s` toward the goal, or `None` if none is
/// feasible.
pub fn local_replan(
    grid: &TraversableGrid,
    reference: &ReferenceTrajectory,
    goal: &ExplorationGoal,
    settings: &ExplorerSettings,
    limits: &DynamicLimits,
    time_s: f64,
) -> Option<ReferenceTrajectory> {
    let start = reference.at(time_s);
    let plan = plan_local(
        grid,
        &start,
        goal.position.as_dvec3(),
        Some(f64::from(goal.yaw)),
        settings.horizon_m,
        limits,
    )
    .ok()?;
    Some(ReferenceTrajectory {
        trajectory: Arc::new(plan.trajectory),
        start_s: time_s,
    })
}

/// Plan stage: fly toward each UAV's goal and end goals (see module doc).
#[allow(clippy::type_complexity, clippy::too_many_arguments)]
pub fn fly_to_goals(
    mut commands: Commands,
    clock: Res<SimClock>,
    map: MapReader,
    mut grid: ResMut<Traversability>,
    mut frontier: ResMut<FrontierSet>,
    mut visited: ResMut<VisitedFrontier>,
    mut log: ResMut<DecisionLog>,
    mut uavs: Query<
        (
            Entity,
            &Uav,
            &Explorer,
            &Airframe,
            &QuadState,
            &mut ExplorationGoal,
            &mut ReferenceTrajectory,
            Option<&FlightEnergy>,
        ),
        (Without<NeedsDecision>, Without<UavEnded>),
    >,
    waiting: Query<(Entity, &DecisionBackoff), (Without<NeedsDecision>, Without<UavEnded>)>,
) {
    let time_s = clock.time_s();
    for (uav, backoff) in &waiting {
        if time_s >= backoff.retry_at_s {
            commands.entity(uav).insert(NeedsDecision);
        }
    }
    let mut rows: Vec<_> = uavs.iter_mut().collect();
    rows.sort_by_key(|row| row.1.index);
    for (uav, _, explorer, airframe, state, mut goal, mut reference, energy) in rows {
        let settings = &explorer.settings;
        let distance = f64::from(state.position.distance(goal.position));
        if distance < goal.best_distance_m - settings.progress_distance_m {
            goal.best_distance_m = distance;
            goal.best_distance_s = time_s;
        }
        let due = time_s - goal.last_plan_s >= settings.replan_period_s;
        // Whether the goal's frontier vanished is checked at the replanning rate: counting its
        // voxels every physics step would cost more than the rest of the step.
        let still_frontier = if due {
            goal.members
                .iter()
                .filter(|&&key| frontier.contains(key))
                .count()
        } else {
            goal.members.len()
        };
        let speed = f64::from(state.velocity.length());
        let reference_ended = reference.elapsed(time_s) >= reference.trajectory.duration() - 1e-9;
        if let GoalStatus::Ended(outcome) = goal_status(
            &goal,
            settings,
            reference_ended,
            distance,
            speed,
            still_frontier,
            time_s,
        ) {
            let flown_energy = energy_drawn(energy) - goal.energy_at_start_j;
            if let Some(record) = log.decisions.get_mut(goal.decision) {
                let predicted = record
                    .chosen
                    .and_then(|i| record.candidates.get(i))
                    .map(|c| c.predicted_energy_j);
                record.flown = Some(FlownLeg {
                    outcome,
                    energy_j: flown_energy,
                    time_s: time_s - goal.started_s,
                    prediction_error: predicted
                        .filter(|p| *p > 0.0)
                        .map_or(f64::NAN, |p| (flown_energy - p) / p),
                    flew_candidate: goal.flying_candidate,
                });
            }
            let mut entity = commands.entity(uav);
            entity.remove::<ExplorationGoal>();
            match (goal.kind, outcome) {
                (GoalKind::Home, GoalOutcome::Reached) => {
                    entity.insert(UavEnded::ReturnedHome { time_s });
                }
                (GoalKind::Frontier, GoalOutcome::Reached) => {
                    let left: Vec<IVec3> = goal
                        .members
                        .iter()
                        .copied()
                        .filter(|&k| frontier.contains(k))
                        .collect();
                    for &key in &left {
                        if !visited.0.insert(key) {
                            frontier.ignore(key);
                        }
                    }
                    // The goal's own frontier first, then the rest in sight, nearest first.
                    let mut search = left;
                    search.extend(frontier_near(
                        &frontier,
                        map.config.resolution() as f32,
                        state.position,
                        settings.interior_search_m,
                    ));
                    for key in around_interiors(&map, &search) {
                        frontier.ignore(key);
                    }
                    entity.insert(NeedsDecision);
                }
                _ => {
                    entity.insert(NeedsDecision);
                }
            }
            continue;
        }

        let check_due = time_s - goal.last_check_s >= COLLISION_CHECK_PERIOD_S;
        if !due && !check_due {
            continue;
        }
        let limits = DynamicLimits::of(airframe);
        let elapsed = reference.elapsed(time_s);
        if due {
            grid.0.refresh(&map);
        } else {
            // A check only: the grid need be current where the trajectory goes.
            refresh_along(
                &mut grid.0,
                &map,
                reference.trajectory.as_ref(),
                elapsed.max(0.0),
                limits.max_velocity,
            );
        }
        let blocked = !remains_traversable(
            &grid.0,
            reference.trajectory.as_ref(),
            elapsed.max(0.0),
            limits.max_velocity,
        );
        goal.last_check_s = time_s;
        if !due && !blocked {
            continue;
        }
        goal.last_plan_s = time_s;
        if goal.flying_candidate && !blocked {
            continue;
        }
        goal.flying_candidate = false;
        grid.0.refresh(&map);
        match local_replan(&grid.0, &reference, &goal, settings, &limits, time_s) {
            Some(plan) => *reference = plan,
            None if blocked => {
                // No way on and the current one collides: stop where the reference is and
                // wait for a replan (or the no-progress rule).
                let here = reference.at(time_s);
                *reference = ReferenceTrajectory {
                    trajectory: Arc::new(Hold {
                        position: here.position,
                        yaw: here.yaw,
                        duration: 0.0,
                    }),
                    start_s: time_s,
                };
            }
            None => {}
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    fn goal(members: usize) -> ExplorationGoal {
        ExplorationGoal {
            kind: GoalKind::Frontier,
            decision: 0,
            position: Vec3::new(5.0, 0.0, 1.0),
            yaw: 0.0,
            members: vec![IVec3::ZERO; members],
            started_s: 10.0,
            energy_at_start_j: 0.0,
            best_distance_m: 5.0,
            best_distance_s: 10.0,
            last_plan_s: 10.0,
            last_check_s: 10.0,
            flying_candidate: false,
        }
    }

    #[test]
    fn goal_rules_in_order() {
        let settings = ExplorerSettings::for_range(5.0);
        let g = goal(100);
        // Far, fast, all frontier left, recent progress: flying.
        assert_eq!(
            goal_status(&g, &settings, true, 3.0, 2.0, 100, 12.0),
            GoalStatus::Flying
        );
        // Within 0.3 m and slower than 0.5 m/s: reached (even if the frontier is gone).
        assert_eq!(
            goal_status(&g, &settings, true, 0.29, 0.4, 0, 12.0),
            GoalStatus::Ended(GoalOutcome::Reached)
        );
        // Close and slow, but the reference still runs: not yet.
        assert_eq!(
            goal_status(&g, &settings, false, 0.29, 0.4, 100, 12.0),
            GoalStatus::Flying
        );
        // Close but still fast: not reached.
        assert_eq!(
            goal_status(&g, &settings, true, 0.29, 0.6, 100, 12.0),
            GoalStatus::Flying
        );
        // 19 of 100 voxels left < 20 %: invalidated; 20 left is still valid.
        assert_eq!(
            goal_status(&g, &settings, true, 3.0, 2.0, 19, 12.0),
            GoalStatus::Ended(GoalOutcome::Invalidated)
        );
        assert_eq!(
            goal_status(&g, &settings, true, 3.0, 2.0, 20, 12.0),
            GoalStatus::Flying
        );
        // No progress since t = 10 s: hopeless after 6 s.
        assert_eq!(
            goal_status(&g, &settings, true, 3.0, 2.0, 100, 16.01),
            GoalStatus::Ended(GoalOutcome::NoProgress)
        );
        // A home goal has no frontier to vanish.
        let home = ExplorationGoal {
            kind: GoalKind::Home,
            ..goal(0)
        };
        assert_eq!(
            goal_status(&home, &settings, true, 3.0, 2.0, 0, 12.0),
            GoalStatus::Flying
        );
    }
}
