//! Stop, then go: how a moving start that must turn back comes to rest first.
//!
//! A minimum-snap polynomial from a moving start carries the start's velocity, acceleration and
//! jerk, which do not scale with the segment durations. When the path leaves behind the UAV,
//! the first segment must reverse that motion, and it is long (the heading turns half a circle
//! at the yaw rate the allocation allows, and the limits' scale search stretches it further):
//! over a long segment the polynomial keeps going the way the UAV went and comes back late. In
//! an EAAE Pillars mission (seed 2) a UAV at 2.5 m/s, still accelerating away at 3.6 m/s^2,
//! had the plans of a decision to 21 of its 24 clusters run 4.3 m on into a wall before
//! turning, and the waypoints the fit added could not pull them back (60 ms of failed
//! planning, 2 candidates instead of 24).
//!
//! So such a start first brakes to rest straight ahead, and the trajectory goes on from rest
//! there: a rest start scales exactly, and its fit behaves as any other. The braking leg is the
//! minimum-snap trajectory from the start to rest at a point ahead, the nearest of a few
//! distances (multiples of the stopping distance `v^2 / 2 amax`) at which it stops without
//! running past that point: a polynomial stops smoothly, and a start still accelerating away
//! needs several stopping distances (3.1 m in 1.8 s for the start above, against the 0.77 m
//! of `v^2 / 2 amax`). The braking depends on the start alone, so the plans of one decision
//! share it ([`BrakingMemo`]).
//!
//! The leg's stop also says how near the start a trajectory can be pinned: a waypoint short of
//! it lies closer than the start can stop. A candidate whose fit adds one is compared with
//! stopping first, and the local planner stops first when such a fit fails
//! ([`BrakingMemo::pinned_within`], [`super::global`]).

use super::check::first_untraversable;
use super::traversable::TraversableGrid;
use crate::trajectory::{DynamicLimits, Waypoint, plan_min_snap};
use glam::DVec3;
use std::sync::OnceLock;
use uavex_components::trajectory::{PiecewisePolynomial, Trajectory, TrajectoryPoint};

/// Braking distances tried, in multiples of the stopping distance `v^2 / 2 amax`.
pub const STOPPING_MULTIPLES: [f64; 6] = [1.0, 1.5, 2.0, 3.0, 4.0, 6.0];
/// A braking leg may run past its stop point by this fraction of its length (m/m) ...
const OVERRUN_FRACTION: f64 = 0.1;
/// ... plus this much (m).
const OVERRUN_M: f64 = 0.05;
/// Starts slower than this stop within this distance anyway (m): no braking leg.
const MIN_STOPPING_M: f64 = 0.05;
/// Samples of a braking leg to measure its overrun.
const OVERRUN_SAMPLES: usize = 32;

/// A moving start's braking leg: a trajectory to rest straight ahead, in traversable space.
#[derive(Debug, Clone, PartialEq)]
pub struct Braking {
    pub trajectory: PiecewisePolynomial,
    /// Where and how it ends: at rest, the start's heading kept.
    pub stop: TrajectoryPoint,
}

impl Braking {
    /// The braking leg of `start`, if it moves fast enough to need one and one of the
    /// distances of [`STOPPING_MULTIPLES`] gives a leg that stays in traversable space and
    /// stops without overrunning (module doc).
    pub fn of(
        grid: &TraversableGrid,
        start: &TrajectoryPoint,
        limits: &DynamicLimits,
    ) -> Option<Self> {
        let stopping_m = stopping_distance(start, limits);
        // (A non-finite velocity has no braking leg either.)
        if !stopping_m.is_finite() || stopping_m < MIN_STOPPING_M {
            return None;
        }
        let ahead = start.velocity / start.velocity.length();
        for multiple in STOPPING_MULTIPLES {
            let distance = multiple * stopping_m;
            let position = start.position + distance * ahead;
            if !grid.line_of_sight(start.position, position) {
                // Farther stops lie beyond the same obstacle.
                return None;
            }
            let waypoint = Waypoint {
                position,
                yaw: Some(start.yaw),
            };
            let Ok(trajectory) = plan_min_snap(start, &[waypoint], limits) else {
                continue;
            };
            if overrun(&trajectory, start.position, ahead)
                > distance * (1.0 + OVERRUN_FRACTION) + OVERRUN_M
            {
                continue;
            }
            if first_untraversable(grid, &trajectory, 0.0, limits.max_velocity).is_some() {
                continue;
            }
            let stop = TrajectoryPoint::at_rest(position, start.yaw);
            return Some(Self { trajectory, stop });
        }
        None
    }

    /// Whether a path from `start` whose first leg ends at `first` turns back: the start moves
    /// away from that point.
    pub fn turns_back(start: &TrajectoryPoint, first: DVec3) -> bool {
        start.velocity.dot(first - start.position) < 0.0
    }
}

/// The distance a start at its speed stops in at the largest deceleration, `v^2 / 2 amax` (m).
pub fn stopping_distance(start: &TrajectoryPoint, limits: &DynamicLimits) -> f64 {
    let speed = start.velocity.length();
    speed * speed / (2.0 * limits.max_acceleration)
}

/// How far along `ahead` from `origin` the trajectory gets (m).
fn overrun(trajectory: &PiecewisePolynomial, origin: DVec3, ahead: DVec3) -> f64 {
    let duration = trajectory.duration();
    (0..=OVERRUN_SAMPLES)
        .map(|i| {
            let t = duration * i as f64 / OVERRUN_SAMPLES as f64;
            (trajectory.position(t) - origin).dot(ahead)
        })
        .fold(f64::NEG_INFINITY, f64::max)
}

/// The braking leg of one start, found when a plan first needs it and shared by the plans that
/// start there (thread-safe: a decision's plans run in parallel).
#[derive(Debug, Default)]
pub struct BrakingMemo(OnceLock<Option<Braking>>);

impl BrakingMemo {
    pub fn new() -> Self {
        Self::default()
    }

    /// The braking leg of `start` if a waypoint `distance_m` from it lies short of the leg's
    /// stop: a trajectory through it is pinned closer to the start than the start can stop
    /// ([`super::global`]). The leg is computed only for a waypoint within the farthest stop
    /// tried.
    pub fn pinned_within(
        &self,
        grid: &TraversableGrid,
        start: &TrajectoryPoint,
        limits: &DynamicLimits,
        distance_m: f64,
    ) -> Option<&Braking> {
        let farthest_stop_m =
            STOPPING_MULTIPLES[STOPPING_MULTIPLES.len() - 1] * stopping_distance(start, limits);
        // (False for a NaN, and for the infinite distance of a fit that added no waypoint.)
        let within_reach = distance_m < farthest_stop_m;
        within_reach
            .then(|| self.get(grid, start, limits))
            .flatten()
            .filter(|b| distance_m < b.stop.position.distance(start.position))
    }

    /// [`Braking::of`], computed once.
    pub fn get(
        &self,
        grid: &TraversableGrid,
        start: &TrajectoryPoint,
        limits: &DynamicLimits,
    ) -> Option<&Braking> {
        self.0
            .get_or_init(|| Braking::of(grid, start, limits))
            .as_ref()
    }
}
