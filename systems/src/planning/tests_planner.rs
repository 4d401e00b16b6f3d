//! Tests of the global and local trajectory planners.

use super::tests::{FREE, OCCUPIED, TestMap, wall_room};
use super::*;
use crate::trajectory::DynamicLimits;
use crate::trajectory::limits::segment_peaks;
use glam::{DVec3, IVec3};
use proptest::prelude::*;
use std::sync::atomic::{AtomicUsize, Ordering};
use uavex_components::airframe::Airframe;
use uavex_components::trajectory::{PiecewisePolynomial, Trajectory, TrajectoryPoint};

pub(super) fn kingfisher() -> DynamicLimits {
    DynamicLimits::of(&Airframe::kingfisher())
}

/// Every 0.05 m of the trajectory is traversable (no escape allowance) and the peaks hold the
/// limits; returns the end point.
pub(super) fn assert_safe(
    grid: &TraversableGrid,
    trajectory: &PiecewisePolynomial,
    limits: &DynamicLimits,
) {
    let step = 0.05 / limits.max_velocity;
    let n = (trajectory.duration() / step).ceil() as usize;
    for i in 0..=n {
        let t = (i as f64 * step).min(trajectory.duration());
        let p = trajectory.sample(t).position;
        assert!(
            grid.is_traversable_point(p),
            "t = {t}: {p} is not traversable"
        );
    }
    for (v, a) in segment_peaks(trajectory) {
        assert!(v <= limits.max_velocity * (1.0 + 1e-6), "speed {v}");
        assert!(
            a <= limits.max_acceleration * (1.0 + 1e-6),
            "acceleration {a}"
        );
    }
}

pub(super) fn end_of(trajectory: &PiecewisePolynomial) -> TrajectoryPoint {
    trajectory.sample(trajectory.duration())
}

#[test]
fn the_global_plan_goes_around_the_wall_within_the_limits() {
    let mut map = wall_room();
    let grid = map.grid(0.27);
    let limits = kingfisher();
    let start = TrajectoryPoint::at_rest(DVec3::new(1.1, 1.1, 0.7), 0.0);
    let goal = DVec3::new(5.1, 1.1, 0.7);
    let plan = plan_global(&grid, &start, goal, Some(1.0), &limits).unwrap();
    assert_safe(&grid, &plan.trajectory, &limits);
    let end = end_of(&plan.trajectory);
    assert!(end.position.distance(goal) < 1e-9 && end.velocity.length() < 1e-9);
    assert!((end.yaw - 1.0).abs() < 1e-9);
    assert_eq!(
        (plan.path[0], *plan.path.last().unwrap()),
        (start.position, goal)
    );
    assert!((plan.path_length_m - path_length(&plan.path)).abs() < 1e-12);
    // Around the wall's inflated end (y >= 4.0 + 0.27): longer than the straight 4 m.
    assert!(plan.path_length_m > 2.0 * (1.9f64.powi(2) + 3.17f64.powi(2)).sqrt());
    // From a moving start (1 m/s along +y) as well.
    let moving = TrajectoryPoint {
        velocity: DVec3::new(0.0, 1.0, 0.0),
        ..start
    };
    let plan = plan_global(&grid, &moving, goal, None, &limits).unwrap();
    assert_safe(&grid, &plan.trajectory, &limits);
    assert!(remains_traversable(
        &grid,
        &plan.trajectory,
        0.0,
        limits.max_velocity
    ));
}

#[test]
fn unreachable_goals_and_bad_input_are_errors() {
    let mut map = wall_room();
    map.fill(IVec3::new(40, 0, 0), IVec3::new(41, 63, 15), OCCUPIED);
    let grid = map.grid(0.27);
    let limits = kingfisher();
    let start = TrajectoryPoint::at_rest(DVec3::new(1.1, 1.1, 0.7), 0.0);
    let goal = DVec3::new(5.1, 1.1, 0.7);
    assert_eq!(
        plan_global(&grid, &start, goal, None, &limits),
        Err(crate::trajectory::PlanError::NoPath { goal })
    );
    assert!(plan_along(&grid, &start, &[start.position], None, &limits).is_err());
    assert!(plan_along(&grid, &start, &[DVec3::NAN], None, &limits).is_err());
    assert!(plan_local(&grid, &start, goal, None, f64::NAN, &limits).is_err());
}

/// An open room 10.4 x 6.4 x 2.4 m, all free.
pub(super) fn open_room() -> TestMap {
    let mut map = TestMap::new(DVec3::ZERO, DVec3::new(10.4, 6.4, 2.4));
    map.fill_all(FREE);
    map
}

#[test]
fn the_local_plan_stops_at_the_horizon_and_reaches_a_near_goal() {
    let mut map = open_room();
    let grid = map.grid(0.27);
    let limits = kingfisher();
    let start = TrajectoryPoint::at_rest(DVec3::new(1.1, 3.1, 1.1), 0.0);
    // 8 m straight ahead, horizon 3 m: the plan ends at rest 3 m along the line.
    let far = plan_local(
        &grid,
        &start,
        DVec3::new(9.1, 3.1, 1.1),
        Some(2.0),
        3.0,
        &limits,
    )
    .unwrap();
    assert!(!far.reaches_goal);
    let end = end_of(&far.trajectory);
    assert!(
        end.position.distance(DVec3::new(4.1, 3.1, 1.1)) < 1e-9,
        "{}",
        end.position
    );
    assert!(end.velocity.length() < 1e-9);
    assert!(
        end.yaw.abs() < 1e-9,
        "faces the direction of travel, not the goal yaw"
    );
    assert_safe(&grid, &far.trajectory, &limits);
    // 2 m ahead: reached, with the goal's heading.
    let goal = DVec3::new(3.1, 3.1, 1.1);
    let near = plan_local(&grid, &start, goal, Some(2.0), 3.0, &limits).unwrap();
    assert!(near.reaches_goal);
    let end = end_of(&near.trajectory);
    assert!(end.position.distance(goal) < 1e-9 && (end.yaw - 2.0).abs() < 1e-9);
    assert_safe(&grid, &near.trajectory, &limits);
}

#[test]
fn a_new_obstacle_on_the_trajectory_triggers_a_replan() {
    let mut map = open_room();
    let mut grid = map.grid(0.27);
    let limits = kingfisher();
    let start = TrajectoryPoint::at_rest(DVec3::new(1.1, 3.1, 1.1), 0.0);
    let goal = DVec3::new(9.1, 3.1, 1.1);
    let plan = plan_local(&grid, &start, goal, None, 7.5, &limits).unwrap();
    assert!(remains_traversable(&grid, &plan.trajectory, 0.0, 5.0));
    // A pillar appears at x = 6 m, on the line; the trajectory from t = 1 s collides.
    map.fill(IVec3::new(58, 28, 0), IVec3::new(62, 34, 23), OCCUPIED);
    map.update(&mut grid);
    assert!(!remains_traversable(&grid, &plan.trajectory, 1.0, 5.0));
    assert!(!remains_traversable(&grid, &plan.trajectory, 0.0, f64::NAN));
    // The replan from the reference at t = 1 s goes around it.
    let state = plan.trajectory.sample(1.0);
    let replan = plan_local(&grid, &state, goal, None, 7.5, &limits).unwrap();
    assert_safe(&grid, &replan.trajectory, &limits);
}

#[test]
fn a_start_inside_the_inflation_escapes() {
    let mut map = wall_room();
    let grid = map.grid(0.27);
    let limits = kingfisher();
    let start = TrajectoryPoint::at_rest(DVec3::new(2.85, 1.0, 0.8), 0.0);
    assert!(!grid.is_traversable_point(start.position));
    let plan = plan_global(&grid, &start, DVec3::new(1.0, 2.0, 0.8), None, &limits).unwrap();
    // Out of the inflation within 0.5 m, traversable from there on.
    assert!(first_untraversable(&grid, &plan.trajectory, 0.0, 5.0).is_none());
    let mut left = false;
    let step = 0.05 / 5.0;
    for i in 0..=(plan.trajectory.duration() / step).ceil() as usize {
        let p = plan.trajectory.sample(i as f64 * step).position;
        left |= grid.is_traversable_point(p);
        assert!(left || p.distance(start.position) <= SNAP_RADIUS_M);
        assert!(!left || grid.is_traversable_point(p));
    }
}

/// Random box obstacles (pillars and floating blocks) in a 6.4 x 6.4 x 2.4 m room.
/// The check samples positions only ([`Trajectory::position`]); through a trait object it
/// answers as on the concrete trajectory, and as a check on full samples would.
#[test]
fn the_check_answers_alike_through_a_trait_object_and_on_full_samples() {
    // Around the wall (several segments) and out of the inflation (the escape rule).
    let mut map = wall_room();
    let mut grid = map.grid(0.27);
    let limits = kingfisher();
    let start = TrajectoryPoint::at_rest(DVec3::new(2.85, 1.0, 0.8), 0.0);
    let plan = plan_global(&grid, &start, DVec3::new(1.0, 2.0, 0.8), None, &limits).unwrap();
    let trajectory = &plan.trajectory;
    let dynamic: &dyn Trajectory = trajectory;
    let full = FullSamples(trajectory);
    let end = trajectory.duration();
    for t0 in [0.0, 0.3 * end, end] {
        let answer = first_untraversable(&grid, trajectory, t0, 5.0);
        assert_eq!(first_untraversable(&grid, dynamic, t0, 5.0), answer);
        assert_eq!(first_untraversable(&grid, &full, t0, 5.0), answer);
    }
    // A block on the way: all report the same first sample.
    map.fill(IVec3::new(5, 8, 0), IVec3::new(25, 30, 23), OCCUPIED);
    map.update(&mut grid);
    let blocked = first_untraversable(&grid, trajectory, 0.0, 5.0);
    assert!(blocked.is_some());
    assert_eq!(first_untraversable(&grid, dynamic, 0.0, 5.0), blocked);
    assert_eq!(first_untraversable(&grid, &full, 0.0, 5.0), blocked);
    assert_eq!(
        first_untraversable(&grid, trajectory, 0.0, f64::NAN),
        first_untraversable(&grid, &full, 0.0, f64::NAN)
    );
}

/// A trajectory that keeps [`Trajectory::position`]'s default: positions of full samples.
#[derive(Debug)]
struct FullSamples<'a>(&'a PiecewisePolynomial);

impl Trajectory for FullSamples<'_> {
    fn duration(&self) -> f64 {
        self.0.duration()
    }

    fn sample(&self, t: f64) -> TrajectoryPoint {
        self.0.sample(t)
    }
}

fn random_map(boxes: &[(i32, i32, i32, i32, i32, i32)]) -> TestMap {
    let mut map = TestMap::new(DVec3::ZERO, DVec3::new(6.4, 6.4, 2.4));
    map.fill_all(FREE);
    for &(x, y, z, sx, sy, sz) in boxes {
        let lo = IVec3::new(x, y, z);
        map.fill(lo, lo + IVec3::new(sx, sy, sz), OCCUPIED);
    }
    map
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    /// The planner never returns a trajectory through known-occupied (inflated) voxels: every
    /// sample 0.05 m apart is traversable, and the speed and acceleration hold their limits.
    #[test]
    fn planned_trajectories_stay_traversable_and_feasible(
        boxes in prop::collection::vec((0..60i32, 0..60i32, 0..20i32, 1..15i32, 1..15i32, 2..24i32), 1..14),
        from in (0.3..6.1f64, 0.3..6.1f64, 0.3..2.1f64),
        to in (0.3..6.1f64, 0.3..6.1f64, 0.3..2.1f64),
        speed in (-2.5..2.5f64, -2.5..2.5f64),
        acceleration in (-2.8..2.8f64, -2.8..2.8f64),
    ) {
        let mut map = random_map(&boxes);
        let grid = map.grid(0.27);
        let limits = kingfisher();
        let (from, to) = (DVec3::new(from.0, from.1, from.2), DVec3::new(to.0, to.1, to.2));
        prop_assume!(grid.is_traversable_point(from));
        let start = TrajectoryPoint {
            velocity: DVec3::new(speed.0, speed.1, 0.0),
            acceleration: DVec3::new(acceleration.0, acceleration.1, 0.0),
            ..TrajectoryPoint::at_rest(from, 0.3)
        };
        if let Ok(plan) = plan_global(&grid, &start, to, None, &limits) {
            assert_safe(&grid, &plan.trajectory, &limits);
        }
        if let Ok(plan) = plan_local(&grid, &start, to, None, 3.0, &limits) {
            assert_safe(&grid, &plan.trajectory, &limits);
        }
    }
}

#[test]
fn planning_succeeds_on_random_maps_whenever_a_path_exists() {
    use rand::{Rng, SeedableRng};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
    let limits = kingfisher();
    let (mut paths, mut global, mut local) = (0, 0, 0);
    for _ in 0..40 {
        let boxes: Vec<_> = (0..rng.random_range(1..14))
            .map(|_| {
                (
                    rng.random_range(0..60),
                    rng.random_range(0..60),
                    rng.random_range(0..20),
                    rng.random_range(1..15),
                    rng.random_range(1..15),
                    rng.random_range(2..24),
                )
            })
            .collect();
        let mut map = random_map(&boxes);
        let grid = map.grid(0.27);
        let mut point = || loop {
            let p = DVec3::new(
                rng.random_range(0.3..6.1),
                rng.random_range(0.3..6.1),
                rng.random_range(0.3..2.1),
            );
            if grid.is_traversable_point(p) {
                break p;
            }
        };
        let (from, to) = (point(), point());
        if find_path(&grid, from, to, usize::MAX).is_none() {
            continue;
        }
        paths += 1;
        let start = TrajectoryPoint::at_rest(from, 0.0);
        global += usize::from(plan_global(&grid, &start, to, None, &limits).is_ok());
        local += usize::from(plan_local(&grid, &start, to, None, 3.0, &limits).is_ok());
    }
    // Measured: 40 of 40 maps have a path, and both planners succeed on every one.
    assert!(paths >= 30, "{paths}");
    assert_eq!((global, local), (paths, paths));
}

/// A check refreshed only along the trajectory ([`refresh_along`]) answers as one on a fully
/// refreshed grid, and leaves chunks away from the trajectory dirty.
#[test]
fn a_check_refreshed_along_the_trajectory_equals_one_on_the_full_grid() {
    let mut map = wall_room();
    let mut grid = map.grid(0.27);
    let limits = kingfisher();
    let start = TrajectoryPoint::at_rest(DVec3::new(1.1, 1.1, 0.7), 0.0);
    let plan = plan_global(&grid, &start, DVec3::new(5.1, 1.1, 0.7), None, &limits).unwrap();
    let t0 = 0.5;
    // Two changes: an obstacle on the trajectory's way, one far from it (y = 6 m).
    let on_path = plan
        .trajectory
        .sample(plan.trajectory.duration() * 0.6)
        .position;
    let key = (on_path / 0.1).floor().as_ivec3();
    map.fill(key - IVec3::ONE, key + IVec3::ONE, OCCUPIED);
    map.fill(IVec3::new(10, 60, 5), IVec3::new(11, 61, 6), OCCUPIED);
    for coord in map.store.take_written() {
        grid.mark_changed(coord);
    }
    let mut partial = grid.clone();
    refresh_along(
        &mut partial,
        &map.store,
        &plan.trajectory,
        t0,
        limits.max_velocity,
    );
    grid.refresh(&map.store);
    let check =
        |g: &TraversableGrid| first_untraversable(g, &plan.trajectory, t0, limits.max_velocity);
    assert!(check(&grid).is_some(), "the obstacle blocks the trajectory");
    assert_eq!(check(&partial), check(&grid));
    assert!(partial.dirty_chunks() > 0, "the far chunks are left dirty");
    // A full refresh afterwards catches up with the rest.
    partial.refresh(&map.store);
    assert_eq!(partial.dirty_chunks(), 0);
    for z in 0..16 {
        for y in 0..64 {
            for x in 0..64 {
                let k = IVec3::new(x, y, z);
                assert_eq!(partial.is_traversable(k), grid.is_traversable(k), "{k}");
            }
        }
    }
}

/// Inner path points within a moving start's stopping distance are dropped; at rest, or
/// beyond it, they stay, and the start and end always stay.
#[test]
fn a_moving_start_drops_the_points_within_its_stopping_distance() {
    let limits = kingfisher();
    // 2 m/s at 4 m/s^2: 0.5 m to stop.
    let moving = TrajectoryPoint {
        velocity: DVec3::new(2.0, 0.0, 0.0),
        ..TrajectoryPoint::at_rest(DVec3::ZERO, 0.0)
    };
    let original: Vec<DVec3> = [0.0, -0.01, -0.3, -0.6, -0.9, -0.2]
        .iter()
        .map(|&x| DVec3::new(x, 0.0, 0.0))
        .collect();
    let all = [0, 1, 2, 3, 4, 5];
    assert_eq!(
        global::beyond_stopping(&all, &original, &moving, &limits),
        vec![0, 3, 4, 5]
    );
    let at_rest = TrajectoryPoint::at_rest(DVec3::ZERO, 0.0);
    assert_eq!(
        global::beyond_stopping(&all, &original, &at_rest, &limits),
        all
    );
    assert_eq!(
        global::beyond_stopping(&[0, 1], &original, &moving, &limits),
        vec![0, 1]
    );
}

/// [`first_untraversable`] from `t0` with every sample taken, none skipped: the oracle of the
/// skipping through open space (`super::check`).
fn first_untraversable_every_sample(
    grid: &TraversableGrid,
    trajectory: &PiecewisePolynomial,
    t0: f64,
    max_speed: f64,
) -> Option<(f64, DVec3)> {
    let end = trajectory.duration();
    let step = crate::behaviour::waypoints::COLLISION_SAMPLE_SPACING_M / max_speed;
    let t0 = t0.clamp(0.0, end);
    let origin = trajectory.position(t0);
    let mut escaping = !grid.is_traversable_point(origin);
    for i in 0..=((end - t0) / step).ceil() as u64 {
        let t = (t0 + i as f64 * step).min(end);
        let p = trajectory.position(t);
        if grid.is_traversable_point(p) {
            escaping = false;
        } else if !escaping || p.distance(origin) > SNAP_RADIUS_M {
            return Some((t, p));
        }
    }
    None
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    /// The check skips samples in open space and finds the same first untraversable sample
    /// as a check of every sample, on trajectories through random obstacles (unchecked
    /// minimum-snap tours within the kingfisher's limits, from starts in and out of the
    /// inflation).
    #[test]
    fn skipping_open_space_finds_what_every_sample_finds(
        boxes in prop::collection::vec((0..60i32, 0..60i32, 0..20i32, 1..15i32, 1..15i32, 2..24i32), 0..10),
        points in prop::collection::vec((0.3..6.1f64, 0.3..6.1f64, 0.3..2.1f64), 2..5),
        t0 in 0.0..1.0f64,
    ) {
        let mut map = random_map(&boxes);
        let grid = map.grid(0.27);
        let limits = kingfisher();
        let points: Vec<DVec3> = points.iter().map(|&(x, y, z)| DVec3::new(x, y, z)).collect();
        let start = TrajectoryPoint::at_rest(points[0], 0.0);
        let waypoints: Vec<_> = points[1..].iter().map(|&p| crate::trajectory::Waypoint::new(p)).collect();
        let Ok(trajectory) = crate::trajectory::plan_min_snap(&start, &waypoints, &limits) else {
            return Ok(());
        };
        let t0 = t0 * trajectory.duration();
        prop_assert_eq!(
            first_untraversable(&grid, &trajectory, t0, limits.max_velocity),
            first_untraversable_every_sample(&grid, &trajectory, t0, limits.max_velocity)
        );
    }
}

/// Counts the positions asked of a trajectory.
#[derive(Debug)]
struct Counted<'a>(&'a PiecewisePolynomial, AtomicUsize);

impl Trajectory for Counted<'_> {
    fn duration(&self) -> f64 {
        self.0.duration()
    }

    fn sample(&self, t: f64) -> TrajectoryPoint {
        self.1.fetch_add(1, Ordering::Relaxed);
        self.0.sample(t)
    }
}

#[test]
fn the_check_skips_most_samples_in_open_space() {
    // An empty room: every sample in the middle of it is at least 0.2 m inside a cube of open
    // cells, four samples of 5 cm at full speed.
    let mut map = random_map(&[]);
    let grid = map.grid(0.27);
    let limits = kingfisher();
    let start = TrajectoryPoint::at_rest(DVec3::new(1.0, 1.0, 1.2), 0.0);
    let end = crate::trajectory::Waypoint::new(DVec3::new(5.0, 5.0, 1.2));
    let trajectory = crate::trajectory::plan_min_snap(&start, &[end], &limits).unwrap();
    let counted = Counted(&trajectory, AtomicUsize::new(0));
    assert_eq!(
        first_untraversable(&grid, &counted, 0.0, limits.max_velocity),
        None
    );
    let samples = (trajectory.duration() / (0.05 / limits.max_velocity)).ceil() as usize + 1;
    // One position for the origin, then one for each sample taken.
    let taken = counted.1.load(Ordering::Relaxed);
    assert!(taken < samples / 3, "{taken} of {samples}");
}

#[test]
fn skipping_open_space_stops_short_of_a_wall_met_at_full_speed() {
    // Straight at the wall of `wall_room` (x = 3.0 m, inflated to 2.73 m) at 4-5 m/s, from
    // starts shifted by a fraction of a voxel: the first untraversable sample is the one every
    // sample finds, however the skips fall.
    let mut map = wall_room();
    let grid = map.grid(0.27);
    let limits = kingfisher();
    for i in 0..40 {
        let x = 0.3 + 0.01 * f64::from(i);
        let start = TrajectoryPoint::at_rest(DVec3::new(x - 2.0, 1.0, 0.8), 0.0);
        let end = crate::trajectory::Waypoint::new(DVec3::new(x + 5.5, 1.0, 0.8));
        let trajectory = crate::trajectory::plan_min_snap(&start, &[end], &limits).unwrap();
        let found = first_untraversable(&grid, &trajectory, 0.0, limits.max_velocity);
        assert!(found.is_some());
        assert_eq!(
            found,
            first_untraversable_every_sample(&grid, &trajectory, 0.0, limits.max_velocity)
        );
    }
}
