//! Global trajectories (EAAE step 6): a path search on the inflated grid, shortened by line of
//! sight, turned into a minimum-snap trajectory (Richter, Bry & Roy 2013; `crate::trajectory`)
//! that is dynamically feasible (|v| <= vmax, |a| <= amax everywhere, by the time allocation of
//! `plan_min_snap`) and stays in traversable space (every sample, see [`super::check`]).
//!
//! When the polynomial leaves traversable space (it bulges off the straight chords at corners),
//! a waypoint is added to the segment where it does: the middle one of the original path's
//! points that the shortening dropped there, or, when there are none, the midpoint of the
//! segment's chord (Richter et al. §IV), and the problem is solved again, times re-allocated.
//! With every original point back in, the polynomial is pinned to lattice points 0.2 to 0.35 m
//! apart, all in traversable space; chord midpoints then halve what is left. (Putting every
//! dropped point back at once was tried: solves with many waypoints cost far more than the
//! bisection saves, up to seconds per decision.)
//!
//! A decision's candidate whose path turns back from a moving start first brakes to rest
//! straight ahead, and the trajectory goes on from there ([`super::braking`]): a polynomial
//! that must reverse the start's motion within one long segment runs on the way the UAV went.
//! The local planner does so only when it finds no other trajectory.
//!
//! A fit may add waypoints closer to a moving start than the start's braking leg stops. Such a
//! waypoint pins the polynomial near the start; the start's motion must loop to pass it, and
//! the time allocation, which scales every segment alike, stretches the whole trajectory. A
//! decision's candidate so pinned is also planned stopping first, and the faster of the two is
//! kept: in the decisions of five EAAE Pillars missions (decision bench) 65 of 7,228
//! candidates had lasted more than three times the rest-to-rest time of their paths, up to 40
//! times; with stopping first 27 of 7,394, at most 5.8 times. The rest stretch for a reason:
//! a short hop with a half turn of the heading, or a fast start whose goal lies behind it. The
//! local planner stops first when pinned only if its fit fails: keeping the faster plan there
//! too, and so braking in flight, made the missions of a forest 4-11 % longer
//! (docs/performance.md, fifty-second session).
//!
//! Headings: the heading turns smoothly from the start's to `end_yaw` (without one, to the
//! direction of the path's last leg); the waypoints between leave it free, and the time
//! allocation holds its rate within `max_yaw_rate`. Facing the direction of travel at every
//! waypoint was the rule before: where a path turns back, neighbouring waypoints a short hop
//! apart then differ in heading by pi. Without a rate limit the heading's polynomial overshot
//! there (a reference turning at 9 rad/s made a UAV spin and crash in the EAAE protocol); with
//! the limit those turns stretched the trajectories, and the protocol's missions took up to
//! 8 % longer (docs/performance.md, forty-eighth session).

use super::braking::{Braking, BrakingMemo, stopping_distance};
use super::check::first_untraversable;
use super::search::{MIN_POINT_SEPARATION_M, find_path, path_length, shortcut_indices};
use super::sight::SightMemo;
use super::traversable::TraversableGrid;
use crate::behaviour::waypoints::follow_headings;
use crate::trajectory::{DynamicLimits, PlanError, Waypoint, plan_min_snap};
use glam::DVec3;
use uavex_components::trajectory::{PiecewisePolynomial, Trajectory, TrajectoryPoint};

/// A planned global trajectory and the path it follows.
#[derive(Debug, Clone, PartialEq)]
pub struct GlobalPlan {
    /// The shortened path, from the start position to the end.
    pub path: Vec<DVec3>,
    /// Length of `path` (m).
    pub path_length_m: f64,
    pub trajectory: PiecewisePolynomial,
}

/// A dynamically feasible, collision-free minimum-snap trajectory from `start` (which may be
/// moving) along `path` (e.g. from [`super::find_paths`]; its leading points within 1 cm of
/// the start are dropped), ending at rest at the path's end with heading `end_yaw` (None: the
/// direction of the last leg). Waypoints are added until every sample is traversable (module
/// doc). When no such trajectory is found and the path turns back from the start's motion, or
/// the fit pinned the trajectory near the start, the start stops first ([`super::braking`]).
/// `Err(Collision)` or `Err(StillBlocked)` when the waypoints do not converge,
/// `Err(NoWaypoints)` when the path does not leave the start.
///
/// The local planner, which replans its flight several times a second, plans this way: it
/// keeps a smooth continuation wherever there is one (stopping first whenever the path turned
/// back made the protocol's missions longer: see the README's design decisions).
pub fn plan_along(
    grid: &TraversableGrid,
    start: &TrajectoryPoint,
    path: &[DVec3],
    end_yaw: Option<f64>,
    limits: &DynamicLimits,
) -> Result<GlobalPlan, PlanError> {
    let sees = |a, b| grid.line_of_sight(a, b);
    let braking = BrakingMemo::new();
    let stop_first = StopFirst::WhenStuck;
    plan_along_by(
        grid, sees, &braking, stop_first, start, path, end_yaw, limits,
    )
}

/// [`plan_along`] on the grid of `sight`, asking it the lines of sight of the path's
/// shortening, for a decision's candidates: when the path turns back from the start's motion
/// the start stops first, whether or not a smooth trajectory exists, so that a candidate
/// behind the UAV is priced stopping and turning, never by a polynomial that runs far on
/// before it turns. `braking` holds the braking leg of `start`. The plans of one decision share
/// both memos, and its paths most of their questions (see [`super::sight`]).
pub fn plan_along_seen(
    sight: &mut SightMemo,
    braking: &BrakingMemo,
    start: &TrajectoryPoint,
    path: &[DVec3],
    end_yaw: Option<f64>,
    limits: &DynamicLimits,
) -> Result<GlobalPlan, PlanError> {
    let grid = sight.grid();
    let sees = |a, b| sight.line_of_sight(a, b);
    let stop_first = StopFirst::WhenTurningBack;
    plan_along_by(
        grid, sees, braking, stop_first, start, path, end_yaw, limits,
    )
}

/// When a moving start stops first ([`super::braking`]): when its path turns back from its
/// motion, or when the fit pinned the trajectory closer to it than it can stop (module doc).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum StopFirst {
    /// Always when the path turns back, and when pinned if that is faster (a decision's
    /// candidates: [`plan_along_seen`]).
    WhenTurningBack,
    /// Only when no trajectory goes on smoothly (the local planner: [`plan_along`]).
    WhenStuck,
}

/// [`plan_along`] with `sees(a, b)` the line of sight of the shortening and the braking leg of
/// `braking`, stopping first as `stop_first` says.
#[allow(clippy::too_many_arguments)]
fn plan_along_by(
    grid: &TraversableGrid,
    mut sees: impl FnMut(DVec3, DVec3) -> bool,
    braking: &BrakingMemo,
    stop_first: StopFirst,
    start: &TrajectoryPoint,
    path: &[DVec3],
    end_yaw: Option<f64>,
    limits: &DynamicLimits,
) -> Result<GlobalPlan, PlanError> {
    if let Some(i) = path.iter().position(|p| !p.is_finite()) {
        return Err(PlanError::NonFinite(format!("path point {i}")));
    }
    let skip = path
        .iter()
        .take_while(|p| p.distance(start.position) < MIN_POINT_SEPARATION_M)
        .count();
    let mut original = Vec::with_capacity(path.len() + 2);
    original.push(start.position);
    original.extend_from_slice(&path[skip..]);
    if original.len() < 2 {
        return Err(PlanError::NoWaypoints);
    }
    let kept = shortcut_indices(&original, &mut sees);
    let turns_back = Braking::turns_back(start, original[kept[1]]);
    if stop_first == StopFirst::WhenTurningBack
        && turns_back
        && let Some(braking) = braking.get(grid, start, limits)
    {
        return stop_then_go(grid, sees, braking, start, original, end_yaw, limits);
    }
    let kept = beyond_stopping(&kept, &original, start, limits);
    let fitted = fit(grid, start, &original, &kept, end_yaw, limits);
    let smooth = fitted.trajectory.map(|trajectory| {
        let shortened: Vec<DVec3> = kept.iter().map(|&i| original[i]).collect();
        GlobalPlan {
            path_length_m: path_length(&shortened),
            path: shortened,
            trajectory,
        }
    });
    match stop_first {
        // A candidate pinned closer to its start than the start can stop: stopping first may
        // be faster (module doc).
        StopFirst::WhenTurningBack => {
            let Some(braking) = braking.pinned_within(grid, start, limits, fitted.nearest_added_m)
            else {
                return smooth;
            };
            let stopped = stop_then_go(grid, sees, braking, start, original, end_yaw, limits);
            match (smooth, stopped) {
                (Ok(smooth), Ok(stopped)) => Ok(faster(smooth, stopped)),
                (Ok(plan), Err(_)) | (Err(_), Ok(plan)) => Ok(plan),
                (Err(error), Err(_)) => Err(error),
            }
        }
        // The local planner: stuck turning back, or pinned near the start, it stops first
        // after all.
        StopFirst::WhenStuck => {
            let error = match smooth {
                Ok(plan) => return Ok(plan),
                Err(error) => error,
            };
            let braking = if turns_back {
                braking.get(grid, start, limits)
            } else {
                braking.pinned_within(grid, start, limits, fitted.nearest_added_m)
            };
            match braking {
                Some(braking) => {
                    stop_then_go(grid, sees, braking, start, original, end_yaw, limits)
                        .map_err(|_| error)
                }
                None => Err(error),
            }
        }
    }
}

/// The shorter in time of two plans (the first on a tie).
fn faster(a: GlobalPlan, b: GlobalPlan) -> GlobalPlan {
    if b.trajectory.duration() < a.trajectory.duration() {
        b
    } else {
        a
    }
}

/// The braking leg of a moving start, then the trajectory from rest where it stops along
/// `original` (the start, then the path), which now begins at the stop ([`super::braking`]).
fn stop_then_go(
    grid: &TraversableGrid,
    sees: impl FnMut(DVec3, DVec3) -> bool,
    braking: &Braking,
    start: &TrajectoryPoint,
    mut original: Vec<DVec3>,
    end_yaw: Option<f64>,
    limits: &DynamicLimits,
) -> Result<GlobalPlan, PlanError> {
    original.insert(0, braking.stop.position);
    let kept = shortcut_indices(&original, sees);
    let onward = fit(grid, &braking.stop, &original, &kept, end_yaw, limits).trajectory?;
    let mut segments = braking.trajectory.segments().to_vec();
    segments.extend_from_slice(onward.segments());
    let trajectory = PiecewisePolynomial::new(segments).map_err(PlanError::Internal)?;
    let shortened: Vec<DVec3> = std::iter::once(start.position)
        .chain(kept.iter().map(|&i| original[i]))
        .collect();
    Ok(GlobalPlan {
        path_length_m: path_length(&shortened),
        path: shortened,
        trajectory,
    })
}

/// The kept path indices without the inner points within the stopping distance of a moving
/// start (v^2 / 2 amax); the start (index 0) and the end stay.
///
/// Why: a moving start cannot turn on the spot, so a waypoint within its stopping distance
/// pins the polynomial to a place it must overshoot to reach, and the overshoot grows the
/// closer the waypoint is (in a Pillars mission one 1 cm behind a UAV at 2.5 m/s sent the
/// polynomial 4 m on before it came back, and every fit of that decision failed, 1.5 s of
/// planning). The fit puts path points back where the trajectory needs them.
pub fn beyond_stopping(
    kept: &[usize],
    original: &[DVec3],
    start: &TrajectoryPoint,
    limits: &DynamicLimits,
) -> Vec<usize> {
    let stopping_m = stopping_distance(start, limits);
    let Some((&last, inner)) = kept.split_last() else {
        return Vec::new();
    };
    let near = |i: usize| i > 0 && original[i].distance(start.position) < stopping_m;
    inner
        .iter()
        .copied()
        .filter(|&i| !near(i))
        .chain([last])
        .collect()
}

/// [`find_path`] from the start's position to `goal`, then [`plan_along`].
pub fn plan_global(
    grid: &TraversableGrid,
    start: &TrajectoryPoint,
    goal: DVec3,
    end_yaw: Option<f64>,
    limits: &DynamicLimits,
) -> Result<GlobalPlan, PlanError> {
    let path =
        find_path(grid, start.position, goal, usize::MAX).ok_or(PlanError::NoPath { goal })?;
    plan_along(grid, start, &path, end_yaw, limits)
}

/// A fit's trajectory, and how close to its start the fit pinned it.
struct Fit {
    trajectory: Result<PiecewisePolynomial, PlanError>,
    /// Distance from the start to the nearest waypoint the fit added (m; infinite when none).
    nearest_added_m: f64,
}

/// The minimum-snap fit through the kept points of `original`, with waypoints added where it
/// leaves traversable space (module doc).
fn fit(
    grid: &TraversableGrid,
    start: &TrajectoryPoint,
    original: &[DVec3],
    kept: &[usize],
    end_yaw: Option<f64>,
    limits: &DynamicLimits,
) -> Fit {
    let mut nearest_added_m = f64::INFINITY;
    // Waypoints (the start excluded) and the index in `original` each came from, if any.
    let mut positions: Vec<DVec3> = kept[1..].iter().map(|&i| original[i]).collect();
    let mut origins: Vec<Option<usize>> = kept[1..].iter().map(|&i| Some(i)).collect();
    // Waypoints added at most, one per fit that left traversable space (the fits tried are
    // one more).
    let max_insertions = 4 * original.len() + 15;
    let mut added = 0;
    let trajectory = loop {
        // The heading is fixed at the end only (module doc).
        let end_heading = end_yaw.or_else(|| {
            follow_headings(start.position, start.yaw, &positions)
                .last()
                .copied()
        });
        let waypoints: Vec<Waypoint> = positions
            .iter()
            .enumerate()
            .map(|(i, &position)| Waypoint {
                position,
                yaw: end_heading.filter(|_| i + 1 == positions.len()),
            })
            .collect();
        let trajectory = match plan_min_snap(start, &waypoints, limits) {
            Ok(trajectory) => trajectory,
            Err(error) => break Err(error),
        };
        let Some((time_s, position)) =
            first_untraversable(grid, &trajectory, 0.0, limits.max_velocity)
        else {
            break Ok(trajectory);
        };
        if added == max_insertions {
            break Err(PlanError::StillBlocked {
                added,
                time_s,
                position,
            });
        }
        let (segment, _) = trajectory.locate(time_s);
        let (from, from_origin) = if segment == 0 {
            (start.position, Some(0))
        } else {
            (positions[segment - 1], origins[segment - 1])
        };
        let (point, origin) = match (from_origin, origins[segment]) {
            (Some(a), Some(b)) if b > a + 1 => (original[(a + b) / 2], Some((a + b) / 2)),
            _ => (0.5 * (from + positions[segment]), None),
        };
        let separated = point.distance(from) >= MIN_POINT_SEPARATION_M
            && point.distance(positions[segment]) >= MIN_POINT_SEPARATION_M;
        if !separated || !grid.is_traversable_point(point) {
            break Err(PlanError::Collision { time_s, position });
        }
        nearest_added_m = nearest_added_m.min(point.distance(start.position));
        positions.insert(segment, point);
        origins.insert(segment, origin);
        added += 1;
    };
    Fit {
        trajectory,
        nearest_added_m,
    }
}
