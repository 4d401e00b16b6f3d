//! Minimum-snap trajectories through waypoints with a feasible time allocation, and their
//! collision-free variant (Richter, Bry & Roy 2013).
//!
//! Time allocation: each segment starts with the time a rest-to-rest trapezoidal profile at
//! (vmax, amax) would take over its straight length (and enough to turn the yaw at
//! `max_yaw_rate`), which sets the segments' proportions. The minimum-snap solution then gets
//! its exact peaks ([`super::limits`], [`super::yaw_rate`]), and every duration is scaled
//! until the worst excess ratio `max(v/vmax, sqrt(a/amax), yaw rate/max_yaw_rate)` is just
//! within 1 ([`super::retime`]). Uniform scaling
//! keeps the shape of the path: from rest, speed scales as 1/s and acceleration as 1/s^2
//! exactly, so one round lands on the binding limit; from a moving start (whose velocity does
//! not scale) a secant search takes a few. A solution slower than needed is tightened the
//! same way. (Stretching only the offending segments does not work: a long segment between
//! short ones bulges, and its peaks grow.)
//!
//! The start: the trajectory continues the start's position, velocity and acceleration, and
//! holds its jerk too when it can (C3: the body rates, which follow from the jerk by
//! differential flatness, stay continuous). From a moving start the held jerk can make the
//! limits unreachable: the start's jerk does not scale with the durations, and stretching
//! them lets the acceleration it drives grow (the scale search then gives up). The jerk is
//! then left free (C2, as the published system's B-spline planner joins its start, and as
//! eaae.md step 6 allows), and the allocation runs again. Over the decisions of five EAAE Pillars
//! missions (decision bench, seeds 1-5) 27 % of all plans had failed that way, up to 34 % in
//! one mission; with the fallback 3 % fail for the limits (docs/performance.md).
//!
//! Collisions: when a segment of the solution crosses a blocked point, the midpoint of that
//! segment's straight chord is added as a waypoint and the problem solved again (Richter et
//! al., §IV), as long as that midpoint is free.

use super::PlanError;
use super::collision::first_blocked;
use super::limits::worst_ratio;
use super::min_snap::{JointConstraints, build_segments, solve_outputs};
use super::retime::{MARGIN, ScaleSearch, Step};
use super::yaw_rate::yaw_rate_ratio;
use glam::DVec3;
use std::f64::consts::{PI, TAU};
use uavex_components::airframe::Airframe;
use uavex_components::trajectory::{PiecewisePolynomial, TrajectoryPoint};

/// A point to pass through, with an optional heading there (None: the planner chooses).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Waypoint {
    pub position: DVec3,
    pub yaw: Option<f64>,
}

impl Waypoint {
    pub fn new(position: DVec3) -> Self {
        Self {
            position,
            yaw: None,
        }
    }
}

/// Limits the trajectory must respect everywhere.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DynamicLimits {
    /// m/s.
    pub max_velocity: f64,
    /// m/s^2.
    pub max_acceleration: f64,
    /// rad/s: the heading's rate, a limit like the other two (see [`super::yaw_rate`] for
    /// what a reference turning faster than the yaw loop follows does).
    pub max_yaw_rate: f64,
}

impl DynamicLimits {
    /// The airframe's planning limits (EAAE Table 5.1 for the kingfisher) and a yaw rate of
    /// 2 rad/s, which the slow yaw loop (kp_att_z = 3) follows. Why 2: over three EAAE
    /// missions (Simple nearest seed 5, Pillars eaae seed 1, Simple classic seed 2) the
    /// position stayed within 5 cm of the reference at 1 and at 2 rad/s (yaw within 0.4 and
    /// 0.7 rad); at 3 rad/s it strayed 1 m in one mission. At 1 rad/s the nearest strategy's
    /// short hops, each with a turn of up to pi, took so long that one mission ran its battery
    /// empty (docs/performance.md, forty-eighth session).
    pub fn of(airframe: &Airframe) -> Self {
        Self {
            max_velocity: airframe.max_velocity,
            max_acceleration: airframe.max_acceleration,
            max_yaw_rate: 2.0,
        }
    }

    /// The largest `max(v / vmax, sqrt(a / amax), yaw rate / max_yaw_rate)` over
    /// `trajectory` when above `floor` ([`worst_ratio`], [`yaw_rate_ratio`]).
    fn worst_ratio(&self, trajectory: &PiecewisePolynomial, floor: f64) -> f64 {
        let motion = worst_ratio(trajectory, self.max_velocity, self.max_acceleration, floor);
        motion.max(yaw_rate_ratio(
            trajectory,
            self.max_yaw_rate,
            motion.max(floor),
        ))
    }

    /// The time of the fastest rest-to-rest move over `distance` (m) within the limits: the
    /// trapezoidal speed profile (a triangle when `vmax` is not reached). The time allocation
    /// starts from it; the allocations of a Pillars mission end at 1.1 times it in the median
    /// (docs/performance.md, fifty-first session).
    pub fn rest_to_rest_time(&self, distance: f64) -> f64 {
        let (v, a) = (self.max_velocity, self.max_acceleration);
        if distance <= v * v / a {
            2.0 * (distance / a).sqrt()
        } else {
            distance / v + v / a
        }
    }

    fn check(&self) -> Result<(), PlanError> {
        for (name, value) in [
            ("max_velocity", self.max_velocity),
            ("max_acceleration", self.max_acceleration),
            ("max_yaw_rate", self.max_yaw_rate),
        ] {
            if !(value.is_finite() && value > 0.0) {
                return Err(PlanError::InvalidLimits(format!("{name} = {value}")));
            }
        }
        Ok(())
    }
}

/// Rescaling rounds: one suffices from rest (exact scaling); a moving start needs a few.
const MAX_ROUNDS: usize = 30;

/// Minimum-snap trajectory from `start` through `waypoints`, ending at rest, whose speed and
/// acceleration stay within `limits` everywhere.
pub fn plan_min_snap(
    start: &TrajectoryPoint,
    waypoints: &[Waypoint],
    limits: &DynamicLimits,
) -> Result<PiecewisePolynomial, PlanError> {
    limits.check()?;
    check_inputs(start, waypoints)?;
    let speed0 = start.velocity.length();
    let acceleration0 = start.acceleration.length();
    let yaw_rate0 = start.yaw_rate.abs();
    if speed0 > limits.max_velocity * MARGIN
        || acceleration0 > limits.max_acceleration * MARGIN
        || yaw_rate0 > limits.max_yaw_rate * MARGIN
    {
        return Err(PlanError::StartExceedsLimits(format!(
            "speed {speed0:.3} m/s, acceleration {acceleration0:.3} m/s^2, yaw rate \
             {yaw_rate0:.3} rad/s"
        )));
    }
    let yaws = unwrapped_yaws(start.yaw, waypoints);
    for jerk in [StartJerk::Held, StartJerk::Free] {
        if let Some(trajectory) = allocate(start, waypoints, &yaws, limits, jerk)? {
            return Ok(trajectory);
        }
    }
    Err(PlanError::LimitsUnreachable)
}

/// Whether a trajectory holds its start's jerk (module doc).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum StartJerk {
    /// Prescribed: the start's (C3).
    Held,
    /// Chosen by the minimum-snap solution (C2).
    Free,
}

/// The time allocation of [`plan_min_snap`] with the start's jerk `jerk`: `None` when scaling
/// the durations cannot meet the limits.
fn allocate(
    start: &TrajectoryPoint,
    waypoints: &[Waypoint],
    yaws: &[Option<f64>],
    limits: &DynamicLimits,
    jerk: StartJerk,
) -> Result<Option<PiecewisePolynomial>, PlanError> {
    let mut durations = initial_durations(start, waypoints, yaws, limits)?;
    let mut search = ScaleSearch::new();
    for _ in 0..MAX_ROUNDS {
        let trajectory = solve(start, waypoints, yaws, &durations, jerk)?;
        let worst = limits.worst_ratio(&trajectory, 0.0);
        match search.step(worst) {
            Step::Accept => {
                let tightened = tighten(start, waypoints, yaws, &durations, worst, limits, jerk);
                return Ok(Some(tightened.unwrap_or(trajectory)));
            }
            Step::Scale(factor) => durations.iter_mut().for_each(|d| *d *= factor),
            Step::GiveUp => break,
        }
    }
    Ok(None)
}

/// Scales every duration by `worst` (< 1) so that the binding limit is met with equality,
/// if the result still holds every limit (it may not when the start is moving).
fn tighten(
    start: &TrajectoryPoint,
    waypoints: &[Waypoint],
    yaws: &[Option<f64>],
    durations: &[f64],
    worst: f64,
    limits: &DynamicLimits,
    jerk: StartJerk,
) -> Option<PiecewisePolynomial> {
    if worst >= 1.0 / MARGIN || worst <= 0.0 {
        return None;
    }
    let scaled: Vec<f64> = durations.iter().map(|d| d * worst * MARGIN).collect();
    let trajectory = solve(start, waypoints, yaws, &scaled, jerk).ok()?;
    (limits.worst_ratio(&trajectory, 1.0) <= 1.0).then_some(trajectory)
}

/// Minimum-snap trajectory with given segment durations (no limits enforced).
pub fn min_snap_with_durations(
    start: &TrajectoryPoint,
    waypoints: &[Waypoint],
    durations: &[f64],
) -> Result<PiecewisePolynomial, PlanError> {
    check_inputs(start, waypoints)?;
    if durations.len() != waypoints.len() || durations.iter().any(|d| !(d.is_finite() && *d > 0.0))
    {
        return Err(PlanError::Internal(format!(
            "{} durations (all finite and > 0) are needed for {} waypoints",
            durations.len(),
            waypoints.len()
        )));
    }
    let yaws = unwrapped_yaws(start.yaw, waypoints);
    solve(start, waypoints, &yaws, durations, StartJerk::Held)
}

/// Like [`plan_min_snap`], and free of `blocked` points (sampled every `spacing` metres along
/// the path; pass a predicate that already inflates obstacles by the UAV's radius).
pub fn plan_collision_free(
    start: &TrajectoryPoint,
    waypoints: &[Waypoint],
    limits: &DynamicLimits,
    blocked: &dyn Fn(DVec3) -> bool,
    spacing: f64,
) -> Result<PiecewisePolynomial, PlanError> {
    check_inputs(start, waypoints)?;
    if !(spacing.is_finite() && spacing > 0.0) {
        return Err(PlanError::InvalidLimits(format!(
            "sampling spacing {spacing}"
        )));
    }
    if blocked(start.position) {
        return Err(PlanError::StartBlocked);
    }
    if let Some(index) = waypoints.iter().position(|w| blocked(w.position)) {
        return Err(PlanError::WaypointBlocked {
            index,
            position: waypoints[index].position,
        });
    }
    let mut waypoints = waypoints.to_vec();
    // Each insertion halves a chord; a path that still collides after this many has a chord
    // through an obstacle, which midpoints cannot fix.
    let max_insertions = 8 * waypoints.len() + 16;
    let mut added = 0;
    loop {
        let trajectory = plan_min_snap(start, &waypoints, limits)?;
        let Some((time_s, position)) =
            first_blocked(&trajectory, blocked, spacing, limits.max_velocity)?
        else {
            return Ok(trajectory);
        };
        if added == max_insertions {
            return Err(PlanError::StillBlocked {
                added,
                time_s,
                position,
            });
        }
        let (segment, _) = trajectory.locate(time_s);
        let from = if segment == 0 {
            start.position
        } else {
            waypoints[segment - 1].position
        };
        let midpoint = 0.5 * (from + waypoints[segment].position);
        if blocked(midpoint) {
            return Err(PlanError::Collision { time_s, position });
        }
        waypoints.insert(segment, Waypoint::new(midpoint));
        added += 1;
    }
}

fn check_inputs(start: &TrajectoryPoint, waypoints: &[Waypoint]) -> Result<(), PlanError> {
    if waypoints.is_empty() {
        return Err(PlanError::NoWaypoints);
    }
    let start_values = [
        start.position,
        start.velocity,
        start.acceleration,
        start.jerk,
    ];
    if start_values.iter().any(|v| !v.is_finite())
        || !(start.yaw.is_finite()
            && start.yaw_rate.is_finite()
            && start.yaw_acceleration.is_finite())
    {
        return Err(PlanError::NonFinite("start state".into()));
    }
    for (i, w) in waypoints.iter().enumerate() {
        if !w.position.is_finite() || w.yaw.is_some_and(|y| !y.is_finite()) {
            return Err(PlanError::NonFinite(format!("waypoint {i}")));
        }
    }
    Ok(())
}

/// Waypoint yaws unwrapped so that each differs from the previous known one by at most pi:
/// the heading turns the short way.
fn unwrapped_yaws(start_yaw: f64, waypoints: &[Waypoint]) -> Vec<Option<f64>> {
    let mut previous = start_yaw;
    waypoints
        .iter()
        .map(|w| {
            w.yaw.map(|yaw| {
                let delta = (yaw - previous + PI).rem_euclid(TAU) - PI;
                previous += delta;
                previous
            })
        })
        .collect()
}

/// Rest-to-rest trapezoidal time over each chord, and enough time to turn the heading.
fn initial_durations(
    start: &TrajectoryPoint,
    waypoints: &[Waypoint],
    yaws: &[Option<f64>],
    limits: &DynamicLimits,
) -> Result<Vec<f64>, PlanError> {
    let mut previous_position = start.position;
    let mut previous_yaw = start.yaw;
    let mut durations = Vec::with_capacity(waypoints.len());
    for (index, (waypoint, yaw)) in waypoints.iter().zip(yaws).enumerate() {
        let distance = waypoint.position.distance(previous_position);
        let turn = yaw.map_or(0.0, |y| (y - previous_yaw).abs());
        if distance < 1e-6 && turn < 1e-6 {
            return Err(PlanError::CoincidentWaypoints { index });
        }
        let travel = limits.rest_to_rest_time(distance);
        durations.push(travel.max(turn / limits.max_yaw_rate).max(0.05));
        previous_position = waypoint.position;
        if let Some(y) = yaw {
            previous_yaw = *y;
        }
    }
    Ok(durations)
}

/// The minimum-snap trajectory for the given durations: x, y, z and the heading, the start's
/// jerk as `jerk` says (the heading's start jerk is zero when held, as its start has none; free
/// with the position's, so that the four outputs share one factorisation whenever every
/// waypoint has a heading).
fn solve(
    start: &TrajectoryPoint,
    waypoints: &[Waypoint],
    yaws: &[Option<f64>],
    durations: &[f64],
    jerk: StartJerk,
) -> Result<PiecewisePolynomial, PlanError> {
    let last = waypoints.len();
    let held = jerk == StartJerk::Held;
    let joints = |start_values: [Option<f64>; 4], at: &dyn Fn(usize) -> Option<f64>| {
        let mut values = Vec::with_capacity(last + 1);
        values.push(start_values);
        for i in 0..last {
            let at_rest = if i + 1 == last { Some(0.0) } else { None };
            values.push([at(i), at_rest, at_rest, at_rest]);
        }
        JointConstraints { values }
    };
    let mut outputs: Vec<JointConstraints> = (0..3)
        .map(|axis| {
            joints(
                [
                    Some(start.position[axis]),
                    Some(start.velocity[axis]),
                    Some(start.acceleration[axis]),
                    held.then_some(start.jerk[axis]),
                ],
                &|i| Some(waypoints[i].position[axis]),
            )
        })
        .collect();
    outputs.push(joints(
        [
            Some(start.yaw),
            Some(start.yaw_rate),
            Some(start.yaw_acceleration),
            held.then_some(0.0),
        ],
        &|i| yaws[i],
    ));
    let [x, y, z, yaw]: [Vec<[f64; 4]>; 4] = solve_outputs(durations, &outputs)?
        .try_into()
        .expect("four outputs solved");
    trajectory_of(durations, &[x, y, z, yaw])
}

/// The trajectory of the given joint derivatives.
fn trajectory_of(
    durations: &[f64],
    outputs: &[Vec<[f64; 4]>; 4],
) -> Result<PiecewisePolynomial, PlanError> {
    PiecewisePolynomial::new(build_segments(durations, outputs)).map_err(PlanError::Internal)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::trajectory::tests::limits;
    use uavex_components::trajectory::Trajectory;

    /// A tour that keeps leaving free space however many midpoints it gets (free space is
    /// only the tour's own legs: a smooth trajectory cuts every corner) fails as still blocked
    /// after the last insertion, not as a time allocation that missed the limits.
    #[test]
    fn a_tour_still_blocked_after_every_insertion_says_so() {
        let corner = DVec3::new(4.0, 0.0, 0.0);
        let end = DVec3::new(4.0, 4.0, 0.0);
        let off_the_legs = |p: DVec3| {
            let first = p.y.abs() > 1e-6 || p.x < -1e-6 || p.x > 4.0 + 1e-6;
            let second = (p.x - 4.0).abs() > 1e-6 || p.y < -1e-6 || p.y > 4.0 + 1e-6;
            first && second
        };
        let start = TrajectoryPoint::default();
        let tour = [Waypoint::new(corner), Waypoint::new(end)];
        let result = plan_collision_free(&start, &tour, &limits(), &off_the_legs, 0.05);
        match result {
            Err(PlanError::StillBlocked {
                added, position, ..
            }) => {
                assert_eq!(added, 8 * tour.len() + 16);
                assert!(off_the_legs(position), "{position}");
            }
            other => panic!("expected StillBlocked, got {other:?}"),
        }
    }

    /// A start as a decision meets it in flight: turning (acceleration across the velocity),
    /// the turn tightening fast (jerk), from a Pillars mission's failed plans.
    fn turning_start() -> TrajectoryPoint {
        TrajectoryPoint {
            position: DVec3::ZERO,
            velocity: DVec3::new(1.7, 1.0, 0.0),
            acceleration: DVec3::new(1.3, 1.9, 0.0),
            jerk: DVec3::new(6.0, -5.5, 0.0),
            ..Default::default()
        }
    }

    /// Plans `waypoints` from `start`, checks it joins the start up to acceleration and keeps
    /// the limits (dense samples), and returns its jerk at the start.
    fn start_jerk_of_plan(start: &TrajectoryPoint, waypoints: &[Waypoint]) -> DVec3 {
        let trajectory = plan_min_snap(start, waypoints, &limits()).unwrap();
        let first = trajectory.sample(0.0);
        assert!(first.position.distance(start.position) < 1e-9);
        assert!(first.velocity.distance(start.velocity) < 1e-9);
        assert!(first.acceleration.distance(start.acceleration) < 1e-9);
        let samples = 20_000;
        for i in 0..=samples {
            let p = trajectory.sample(trajectory.duration() * i as f64 / samples as f64);
            assert!(p.velocity.length() <= 5.0 * (1.0 + 1e-6), "{p:?}");
            assert!(p.acceleration.length() <= 4.0 * (1.0 + 1e-6), "{p:?}");
        }
        first.jerk
    }

    #[test]
    fn a_start_jerk_that_makes_the_limits_unreachable_is_left_free() {
        let start = turning_start();
        // Back against the motion: held, the start's jerk drives the acceleration past 4 m/s^2
        // whatever the durations.
        let waypoints = [Waypoint::new(DVec3::new(-3.0, 0.0, 0.0))];
        let yaws = unwrapped_yaws(start.yaw, &waypoints);
        let held = allocate(&start, &waypoints, &yaws, &limits(), StartJerk::Held).unwrap();
        assert!(held.is_none());
        let jerk = start_jerk_of_plan(&start, &waypoints);
        assert!(jerk.distance(start.jerk) > 1.0, "{jerk}");
    }

    #[test]
    fn a_start_jerk_that_allows_the_limits_is_held() {
        let start = turning_start();
        let jerk = start_jerk_of_plan(&start, &[Waypoint::new(DVec3::new(3.0, 0.0, 0.0))]);
        assert!(jerk.distance(start.jerk) < 1e-9, "{jerk}");
    }
}
