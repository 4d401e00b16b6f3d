//! Tests of a start that turns back: the braking leg before a plan from a UAV moving away from
//! its goal, in the local planner and in the candidates' plans.

use super::tests::{FREE, OCCUPIED, TestMap};
use super::tests_planner::{assert_safe, end_of, kingfisher, open_room};
use super::*;
use crate::trajectory::DynamicLimits;
use glam::{DVec3, IVec3};
use uavex_components::trajectory::{Trajectory, TrajectoryPoint};

/// A UAV at 2.48 m/s still accelerating away at 3.6 m/s^2 (the start of a decision of an EAAE
/// Pillars mission, seed 2), 4.6 m from the room's end, whose goal lies behind it.
fn turning_back() -> (TestMap, TrajectoryPoint, DVec3) {
    let mut map = TestMap::new(DVec3::ZERO, DVec3::new(6.4, 6.4, 1.6));
    map.fill_all(FREE);
    let start = TrajectoryPoint {
        position: DVec3::new(1.5, 1.5, 0.8),
        velocity: DVec3::new(0.06, 2.48, 0.0),
        acceleration: DVec3::new(0.09, 3.6, 0.0),
        jerk: DVec3::new(-0.11, -4.15, 0.0),
        yaw: std::f64::consts::FRAC_PI_2,
        ..TrajectoryPoint::default()
    };
    (map, start, DVec3::new(1.5, 0.6, 0.8))
}

/// A decision's candidate along `path` ([`plan_along_seen`], with fresh memos).
fn candidate(
    grid: &TraversableGrid,
    start: &TrajectoryPoint,
    path: &[DVec3],
    limits: &DynamicLimits,
) -> Result<GlobalPlan, crate::trajectory::PlanError> {
    let (mut sight, braking) = (SightMemo::new(grid), BrakingMemo::new());
    plan_along_seen(&mut sight, &braking, start, path, None, limits)
}

#[test]
fn a_start_that_turns_back_stops_first_then_goes() {
    let (mut map, start, goal) = turning_back();
    let grid = map.grid(0.27);
    let limits = kingfisher();
    let plan = plan_global(&grid, &start, goal, None, &limits).unwrap();
    assert_safe(&grid, &plan.trajectory, &limits);
    let first = plan.trajectory.sample(0.0);
    assert!(first.velocity.distance(start.velocity) < 1e-9);
    assert!(first.acceleration.distance(start.acceleration) < 1e-9);
    assert!(end_of(&plan.trajectory).position.distance(goal) < 1e-9);
    // It stops ahead (the path's second point), then turns back.
    let braking = Braking::of(&grid, &start, &limits).expect("room to brake");
    let stop = braking.stop.position;
    assert_eq!(plan.path[1], stop);
    assert!(
        stop.y > start.position.y
            && stop.x == start.position.x + 0.06 / 2.48 * (stop.y - start.position.y)
    );
    let join = braking.trajectory.duration();
    let at_stop = plan.trajectory.sample(join);
    assert!(at_stop.position.distance(stop) < 1e-9 && at_stop.velocity.length() < 1e-9);
    // A decision's candidate stops first at once, on the shared braking leg: the same plan.
    let path = find_path(&grid, start.position, goal, usize::MAX).unwrap();
    assert_eq!(candidate(&grid, &start, &path, &limits).unwrap(), plan);
}

#[test]
fn the_local_planner_turns_back_smoothly_where_it_can_and_a_candidate_stops_first() {
    let mut map = open_room();
    let grid = map.grid(0.27);
    let limits = kingfisher();
    // 1.5 m/s along +y in the middle of the room, the goal 1.5 m behind.
    let start = TrajectoryPoint {
        velocity: DVec3::new(0.0, 1.5, 0.0),
        ..TrajectoryPoint::at_rest(DVec3::new(3.2, 2.5, 0.8), std::f64::consts::FRAC_PI_2)
    };
    let goal = DVec3::new(3.2, 1.0, 0.8);
    let path = find_path(&grid, start.position, goal, usize::MAX).unwrap();
    let stop = Braking::of(&grid, &start, &limits)
        .expect("room to brake")
        .stop
        .position;
    let smooth = plan_along(&grid, &start, &path, None, &limits).unwrap();
    assert_safe(&grid, &smooth.trajectory, &limits);
    assert!(!smooth.path.contains(&stop));
    let candidate = candidate(&grid, &start, &path, &limits).unwrap();
    assert_safe(&grid, &candidate.trajectory, &limits);
    assert_eq!(candidate.path[1], stop);
}

#[test]
fn a_braking_leg_stops_ahead_without_running_past_its_stop() {
    let (mut map, start, _) = turning_back();
    let grid = map.grid(0.27);
    let limits = kingfisher();
    let braking = Braking::of(&grid, &start, &limits).expect("room to brake");
    assert_safe(&grid, &braking.trajectory, &limits);
    let end = end_of(&braking.trajectory);
    assert!(end.position.distance(braking.stop.position) < 1e-9);
    assert!(end.velocity.length() < 1e-9 && end.acceleration.length() < 1e-9);
    // Still accelerating away, it needs more than the 0.77 m of v^2 / 2 amax (measured: four
    // times that, 3.1 m in 1.8 s), and never runs more than 10 % (+ 5 cm) past its stop.
    let stopping_m = start.velocity.length_squared() / (2.0 * limits.max_acceleration);
    let ahead = start.velocity.normalize();
    let distance = (braking.stop.position - start.position).dot(ahead);
    assert!(distance > 1.4 * stopping_m, "{distance} m");
    let duration = braking.trajectory.duration();
    let farthest = (0..=200)
        .map(|i| braking.trajectory.position(duration * f64::from(i) / 200.0))
        .map(|p| (p - start.position).dot(ahead))
        .fold(f64::NEG_INFINITY, f64::max);
    assert!(
        farthest <= 1.1 * distance + 0.05,
        "{farthest} m for a stop at {distance} m"
    );

    // A slow start needs no braking leg; one with a wall within its stopping distance has none.
    let slow = TrajectoryPoint {
        velocity: DVec3::new(0.0, 0.6, 0.0),
        acceleration: DVec3::ZERO,
        jerk: DVec3::ZERO,
        ..start
    };
    assert!(Braking::of(&grid, &slow, &limits).is_none());
    map.fill(IVec3::new(0, 20, 0), IVec3::new(63, 21, 15), OCCUPIED);
    let grid = map.grid(0.27);
    assert!(Braking::of(&grid, &start, &limits).is_none());
}

/// A UAV 0.8 m from a wall, moving toward it at `speed_scale` times 1.03 m/s and accelerating
/// toward it at `speed_scale` times 3.3 m/s^2 (scaled from the start of a decision of an EAAE
/// Pillars mission, seed 2, whose candidates lasted up to 40 times their rest-to-rest time), in
/// a room with a pillar.
fn carried_toward_the_wall(speed_scale: f64) -> (TestMap, TrajectoryPoint) {
    let mut map = open_room();
    map.fill(IVec3::new(40, 25, 0), IVec3::new(45, 40, 23), OCCUPIED);
    let start = TrajectoryPoint {
        position: DVec3::new(2.0, 0.8, 1.2),
        velocity: speed_scale * DVec3::new(0.56, -0.82, 0.27),
        acceleration: speed_scale * DVec3::new(1.76, -2.67, 0.92),
        jerk: DVec3::new(-2.49, 2.75, -0.45),
        ..TrajectoryPoint::default()
    };
    (map, start)
}

/// Checks a plan from `start` to `goal`: it continues the start, stays traversable within the
/// limits, ends at the goal, and stops first at the braking leg's stop. Returns its duration
/// over the rest-to-rest time of the straight line.
fn stopped_first(
    grid: &TraversableGrid,
    start: &TrajectoryPoint,
    goal: DVec3,
    plan: &GlobalPlan,
    limits: &DynamicLimits,
) -> f64 {
    assert_safe(grid, &plan.trajectory, limits);
    let first = plan.trajectory.sample(0.0);
    assert!(first.velocity.distance(start.velocity) < 1e-9);
    assert!(first.acceleration.distance(start.acceleration) < 1e-9);
    assert!(end_of(&plan.trajectory).position.distance(goal) < 1e-9);
    let braking = Braking::of(grid, start, limits).expect("room to brake");
    assert_eq!(plan.path[1], braking.stop.position);
    plan.trajectory.duration() / limits.rest_to_rest_time(start.position.distance(goal))
}

/// The fit pulls a trajectory carried into the wall back with waypoints from the path, ever
/// closer to the start; pinned there, the start's motion has to loop, and the time allocation
/// stretched the whole trajectory (to 12.9 times the rest-to-rest time, toward the first
/// goal), or no allocation held the limits at all (toward the second). A decision's candidate
/// stops first when that is faster, in both; the local planner keeps its smooth continuation
/// where there is one, and stops first where there is none.
#[test]
fn a_trajectory_pinned_near_a_moving_start_stops_first_when_that_is_faster() {
    let limits = kingfisher();
    for (speed_scale, goal, most, smooth) in [
        (0.8, DVec3::new(8.0, 3.0, 1.2), 1.7, true),
        (1.0, DVec3::new(6.0, 1.0, 1.2), 1.75, false),
    ] {
        let (mut map, start) = carried_toward_the_wall(speed_scale);
        let grid = map.grid(0.27);
        let path = find_path(&grid, start.position, goal, usize::MAX).unwrap();
        let candidate = candidate(&grid, &start, &path, &limits).unwrap();
        let stretch = stopped_first(&grid, &start, goal, &candidate, &limits);
        assert!(stretch < most, "{speed_scale}: {stretch}");
        let local = plan_along(&grid, &start, &path, None, &limits).unwrap();
        if smooth {
            assert_safe(&grid, &local.trajectory, &limits);
            assert_ne!(local.path[1], candidate.path[1]);
            assert!(local.trajectory.duration() > 5.0 * candidate.trajectory.duration());
        } else {
            assert_eq!(local, candidate);
        }
    }
}
