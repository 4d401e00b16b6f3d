//! The dynamic `waypoints` behaviour: a minimum-snap trajectory through the scenario's
//! waypoints (Richter, Bry & Roy 2013; `crate::trajectory`), planned once when the run is built
//! and flown on the true quadrotor by the geometric controller ([`crate::flight::ecs`]). The UAV
//! has finished when it has arrived at the last waypoint and slowed down (the [`Completion`]
//! rule the offline rollout uses too); it then hovers there.
//!
//! Headings: given per waypoint, or "follow": each waypoint faces the direction of travel
//! there ([`follow_headings`]), and the polynomial turns the heading smoothly in between.

use crate::flight::ecs::ReferenceTrajectory;
use crate::flight::{Completion, FlightState, Progress};
use crate::trajectory::{DynamicLimits, PlanError, Waypoint, plan_collision_free, plan_min_snap};
use bevy_ecs::prelude::*;
use glam::{DVec2, DVec3};
use uavex_components::airframe::Airframe;
use uavex_components::sim::SimClock;
use uavex_components::trajectory::{PiecewisePolynomial, TrajectoryPoint};
use uavex_components::uav::{QuadState, UavEnded};

/// Clearance (m) the plan keeps from obstacles beyond the airframe's bounding radius: room for
/// tracking error, which stays below 2 cm RMS at 3 m/s on the kingfisher (flight tests) and a
/// few centimetres at its 5 m/s limit.
pub const CLEARANCE_MARGIN_M: f64 = 0.1;

/// Distance (m) between the points at which a plan is checked against obstacles: half the
/// default voxel, far below the diameter of the inflated ball, so no obstacle fits between two.
pub const COLLISION_SAMPLE_SPACING_M: f64 = 0.05;

/// A UAV flying its waypoint tour: when it counts as arrived.
#[derive(Component, Debug, Clone, Copy, PartialEq)]
pub struct WaypointTour {
    pub completion: Completion,
}

/// Headings that face the direction of travel: at an inner waypoint, the bisector of the legs
/// arriving and leaving (where a smooth path through the corner points); at the last one, the
/// arriving leg. A vertical leg has no direction: the bisector uses the other leg, and with
/// neither (or a reversal, whose bisector vanishes) the heading of the arriving leg, or failing
/// that the heading before, is kept.
pub fn follow_headings(start: DVec3, start_yaw: f64, waypoints: &[DVec3]) -> Vec<f64> {
    let direction = |from: DVec3, to: DVec3| {
        let d = DVec2::new(to.x - from.x, to.y - from.y);
        (d.length() > 1e-6).then(|| d.normalize())
    };
    let mut points = Vec::with_capacity(waypoints.len() + 1);
    points.push(start);
    points.extend_from_slice(waypoints);
    let legs: Vec<Option<DVec2>> = points.windows(2).map(|w| direction(w[0], w[1])).collect();
    let mut previous = start_yaw;
    let mut headings = Vec::with_capacity(waypoints.len());
    for i in 0..waypoints.len() {
        let arriving = legs[i];
        let leaving = legs.get(i + 1).copied().flatten();
        let bisector = match (arriving, leaving) {
            (Some(a), Some(l)) => Some(a + l).filter(|s| s.length() > 1e-6),
            (a, l) => a.or(l),
        };
        let heading = bisector.or(arriving).map_or(previous, |d| d.y.atan2(d.x));
        headings.push(heading);
        previous = heading;
    }
    headings
}

/// Waypoints at `positions`, each with its heading from `headings`.
pub fn headed(positions: &[DVec3], headings: impl IntoIterator<Item = f64>) -> Vec<Waypoint> {
    positions
        .iter()
        .zip(headings)
        .map(|(&position, yaw)| Waypoint {
            position,
            yaw: Some(yaw),
        })
        .collect()
}

/// The minimum-snap tour from rest at `start` (heading `start_yaw`) through `positions`, within
/// the airframe's speed and acceleration limits. Headings are `yaws` (one per waypoint) or
/// [`follow_headings`]. With `blocked` (a predicate that already inflates obstacles by the
/// UAV's radius and margin), a plan that comes into a blocked point is refused or bent around
/// it (`plan_collision_free`); without, the path is flown as the polynomial makes it.
pub fn plan_tour(
    airframe: &Airframe,
    start: DVec3,
    start_yaw: f64,
    positions: &[DVec3],
    yaws: Option<&[f64]>,
    blocked: Option<&dyn Fn(DVec3) -> bool>,
) -> Result<PiecewisePolynomial, PlanError> {
    let headings = match yaws {
        Some(yaws) if yaws.len() != positions.len() => {
            return Err(PlanError::Internal(format!(
                "{} headings for {} waypoints",
                yaws.len(),
                positions.len()
            )));
        }
        Some(yaws) => yaws.to_vec(),
        None => follow_headings(start, start_yaw, positions),
    };
    let waypoints = headed(positions, headings);
    let from = TrajectoryPoint::at_rest(start, start_yaw);
    let limits = DynamicLimits::of(airframe);
    match blocked {
        Some(blocked) => plan_collision_free(
            &from,
            &waypoints,
            &limits,
            blocked,
            COLLISION_SAMPLE_SPACING_M,
        ),
        None => plan_min_snap(&from, &waypoints, &limits),
    }
}

/// Control stage: a UAV whose tour has arrived (or timed out settling) has finished.
pub fn finish_waypoint_tours(
    clock: Res<SimClock>,
    mut commands: Commands,
    uavs: Query<(Entity, &WaypointTour, &ReferenceTrajectory, &QuadState), Without<UavEnded>>,
) {
    let time_s = clock.time_s();
    for (entity, tour, reference, state) in &uavs {
        let progress = tour.completion.progress(
            reference.elapsed(time_s),
            reference.trajectory.as_ref(),
            &FlightState::from(state),
        );
        if progress != Progress::Flying {
            commands.entity(entity).insert(UavEnded::Finished);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI};
    use std::sync::Arc;
    use uavex_components::trajectory::Trajectory;

    fn p(x: f64, y: f64, z: f64) -> DVec3 {
        DVec3::new(x, y, z)
    }

    #[test]
    fn headings_bisect_corners_and_keep_the_last_leg() {
        // East, then north, then west: corners at 45 deg and 135 deg, the end faces west.
        let headings = follow_headings(
            p(0.0, 0.0, 1.0),
            0.0,
            &[p(2.0, 0.0, 1.0), p(2.0, 2.0, 1.0), p(0.0, 2.0, 1.0)],
        );
        let expected = [FRAC_PI_4, 3.0 * FRAC_PI_4, PI];
        for (h, e) in headings.iter().zip(expected) {
            assert!((h - e).abs() < 1e-12, "{headings:?}");
        }
    }

    #[test]
    fn vertical_legs_and_reversals_keep_a_heading() {
        // Up (no direction), then north; then back south (a reversal).
        let headings = follow_headings(
            p(0.0, 0.0, 1.0),
            0.3,
            &[p(0.0, 0.0, 2.0), p(0.0, 3.0, 2.0), p(0.0, 1.0, 2.0)],
        );
        // At the top of the climb the only direction is the leaving one (north); at the turn
        // back the bisector vanishes and the arriving heading (north) is kept; the end faces
        // south.
        let expected = [FRAC_PI_2, FRAC_PI_2, -FRAC_PI_2];
        for (h, e) in headings.iter().zip(expected) {
            assert!((h - e).abs() < 1e-12, "{headings:?}");
        }
        // A climb alone keeps the start heading.
        assert_eq!(
            follow_headings(p(0.0, 0.0, 1.0), 0.3, &[p(0.0, 0.0, 2.0)]),
            vec![0.3]
        );
    }

    #[test]
    fn a_planned_tour_passes_its_waypoints_with_their_headings() {
        let airframe = Airframe::kingfisher();
        let positions = [p(3.0, 0.0, 1.0), p(3.0, 3.0, 1.5)];
        let tour = plan_tour(&airframe, p(0.0, 0.0, 1.0), 0.0, &positions, None, None).unwrap();
        let end = tour.sample(tour.duration());
        assert!((end.position - positions[1]).length() < 1e-9);
        assert!((end.yaw - FRAC_PI_2).abs() < 1e-9, "{}", end.yaw);
        assert_eq!(end.velocity, DVec3::ZERO);
        // Given headings are used as they are; a wrong count is refused.
        let tour = plan_tour(
            &airframe,
            p(0.0, 0.0, 1.0),
            0.0,
            &positions,
            Some(&[0.5, 1.0]),
            None,
        )
        .unwrap();
        assert!((tour.sample(tour.duration()).yaw - 1.0).abs() < 1e-9);
        assert!(
            plan_tour(
                &airframe,
                p(0.0, 0.0, 1.0),
                0.0,
                &positions,
                Some(&[0.5]),
                None
            )
            .is_err()
        );
    }

    #[test]
    fn a_blocked_waypoint_is_refused_with_its_index() {
        let airframe = Airframe::kingfisher();
        // A wall filling x in [4, 5].
        let wall = |q: DVec3| (4.0..=5.0).contains(&q.x);
        let result = plan_tour(
            &airframe,
            p(0.0, 0.0, 1.0),
            0.0,
            &[p(2.0, 0.0, 1.0), p(4.5, 0.0, 1.0)],
            None,
            Some(&wall),
        );
        assert!(
            matches!(result, Err(PlanError::WaypointBlocked { index: 1, .. })),
            "{result:?}"
        );
    }

    #[test]
    fn the_tour_finishes_once_arrived() {
        let airframe = Airframe::kingfisher();
        let tour = plan_tour(
            &airframe,
            p(0.0, 0.0, 1.0),
            0.0,
            &[p(1.0, 0.0, 1.0)],
            None,
            None,
        )
        .unwrap();
        let duration = tour.duration();
        let mut world = World::new();
        let dt = 1.0 / 300.0;
        let mut clock = SimClock::new(300.0);
        world.insert_resource(clock);
        let uav = world
            .spawn((
                WaypointTour {
                    completion: Completion::default(),
                },
                ReferenceTrajectory {
                    trajectory: Arc::new(tour),
                    start_s: 0.0,
                },
                QuadState::at_rest(glam::Vec3::new(1.0, 0.0, 1.0), 0.0),
            ))
            .id();
        let mut schedule = Schedule::default();
        schedule.add_systems(finish_waypoint_tours);
        // Already at the end point, but the trajectory is not over: still flying.
        schedule.run(&mut world);
        assert!(world.get::<UavEnded>(uav).is_none());
        clock.tick = (duration / dt).ceil() as u64;
        world.insert_resource(clock);
        schedule.run(&mut world);
        assert_eq!(world.get::<UavEnded>(uav), Some(&UavEnded::Finished));
    }
}
