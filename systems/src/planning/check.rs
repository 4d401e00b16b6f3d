//! Whether a trajectory stays in traversable space: the acceptance test of every plan, and the
//! replanning trigger of the local planner (EAAE step 9: replan "whenever the map makes the
//! current trajectory collide").
//!
//! Samples are taken every `spacing / max_speed` seconds (`crate::trajectory::collision`): a
//! reference moving at most `max_speed` moves at most `spacing` between two samples, and with
//! [`COLLISION_SAMPLE_SPACING_M`] = half a 0.1 m voxel no voxel the path crosses goes unseen.
//!
//! Samples in open space are skipped, none of them checked differently: a traversable sample
//! whose lattice cell can make all 26 moves lies inside a cube of 6 x 6 x 6 traversable
//! voxels (that cell and its 26 neighbours, all open: `super::lattice`), at least a voxel
//! from its faces, so a reference moving at most `max_speed` stays in traversable space for
//! its distance to them over `max_speed`; the samples before then are traversable and are
//! not taken. The first untraversable sample is the one every sample would find.
//!
//! Escape rule: a trajectory whose first sample is not traversable (the reference starts next
//! to a wall, or the map changed around it) may leave that place, as long as it stays within
//! [`SNAP_RADIUS_M`] of its first sample until it reaches traversable space; from there on,
//! every sample must be traversable. Without it, a UAV pushed 5 cm too close to a wall could
//! never plan again.

use super::lattice::{ALL_MOVES, Lattice};
use super::search::SNAP_RADIUS_M;
use super::traversable::TraversableGrid;
use crate::behaviour::waypoints::COLLISION_SAMPLE_SPACING_M;
use crate::mapping::OccupancyMap;
use glam::{DVec3, IVec3};
use uavex_components::trajectory::Trajectory;

/// The first sample from `t0` on that breaks the traversability (with the escape rule of the
/// module doc), as (time, position); `None` when there is none. Non-positive or non-finite
/// `max_speed` or times count as a failure at `t0`. Samples positions only
/// ([`Trajectory::position`]: a fifth of a full sample's work for a polynomial).
pub fn first_untraversable(
    grid: &TraversableGrid,
    trajectory: &(impl Trajectory + ?Sized),
    t0: f64,
    max_speed: f64,
) -> Option<(f64, DVec3)> {
    let end = trajectory.duration();
    let Some(times) = sample_times(end, t0, max_speed) else {
        return Some((t0, trajectory.position(0.0)));
    };
    let origin = trajectory.position(t0.clamp(0.0, end));
    let mut escaping = !grid.is_traversable_point(origin);
    // Samples 5 cm apart fall in the same 0.1 m voxel half the time: its answer is kept.
    let mut last: Option<(IVec3, bool)> = None;
    // The key of a traversable point (`None` for the others).
    let mut traversable = |p: DVec3| {
        if !p.is_finite() {
            return None;
        }
        let key = grid.key_of(p);
        let answer = match last {
            Some((seen, answer)) if seen == key => answer,
            _ => last.insert((key, grid.is_traversable(key))).1,
        };
        answer.then_some(key)
    };
    let mut segment = 0;
    // Samples before this time are traversable (module doc).
    let mut clear_until = f64::NEG_INFINITY;
    for t in times {
        if t < clear_until {
            continue;
        }
        let p = trajectory.position_onward(t, &mut segment);
        if let Some(key) = traversable(p) {
            escaping = false;
            clear_until = t + open_clearance(grid, key, p) / max_speed;
        } else if !escaping || p.distance(origin) > SNAP_RADIUS_M {
            return Some((t, p));
        }
    }
    None
}

/// How far from the traversable point `p` (in voxel `key`) every point is traversable as far
/// as its lattice cell tells (module doc): the distance to the faces of the cube of that cell
/// and its 26 neighbours when all are open, less 1 % for rounding; 0 otherwise.
fn open_clearance(grid: &TraversableGrid, key: IVec3, p: DVec3) -> f64 {
    let lattice = grid.lattice();
    let cell = Lattice::cell_of_key(key);
    match lattice.index(cell) {
        Some(index) if lattice.allowed_moves(index) == ALL_MOVES => {
            let resolution = grid.resolution();
            let offset = (p - lattice.centre(cell, resolution)).abs().max_element();
            // The cube's half edge is 3 voxels; `p` lies in the middle cell, within a voxel
            // of its centre on every axis.
            0.99 * (3.0 * resolution - offset)
        }
        _ => 0.0,
    }
}

/// The sample times of the checks: every `COLLISION_SAMPLE_SPACING_M / max_speed` from `t0`
/// (clamped to `0..=end`) to `end`, both included; `None` for non-positive or non-finite
/// `max_speed` or times.
fn sample_times(end: f64, t0: f64, max_speed: f64) -> Option<impl Iterator<Item = f64>> {
    let valid = max_speed.is_finite() && max_speed > 0.0 && t0.is_finite() && end.is_finite();
    if !valid {
        return None;
    }
    let step = COLLISION_SAMPLE_SPACING_M / max_speed;
    let t0 = t0.clamp(0.0, end);
    let samples = ((end - t0) / step).ceil() as u64;
    Some((0..=samples).map(move |i| (t0 + i as f64 * step).min(end)))
}

/// Brings the grid up to date where [`remains_traversable`] will look along `trajectory`
/// from `t0` (the chunks under its samples), leaving the rest of the grid's dirty chunks for
/// the next full [`TraversableGrid::refresh`]: a periodic check of the flown trajectory need
/// not pay for the whole map's changes.
pub fn refresh_along(
    grid: &mut TraversableGrid,
    map: &impl OccupancyMap,
    trajectory: &(impl Trajectory + ?Sized),
    t0: f64,
    max_speed: f64,
) {
    let end = trajectory.duration();
    grid.refresh_at(map, trajectory.position(t0.clamp(0.0, end.max(0.0))));
    for t in sample_times(end, t0, max_speed).into_iter().flatten() {
        grid.refresh_at(map, trajectory.position(t));
    }
}

/// Whether the rest of `trajectory` from `t0` is still traversable on the latest grid (the
/// local planner's replanning trigger). `max_speed` bounds the trajectory's speed (the
/// airframe's vmax for planned trajectories).
pub fn remains_traversable(
    grid: &TraversableGrid,
    trajectory: &(impl Trajectory + ?Sized),
    t0: f64,
    max_speed: f64,
) -> bool {
    first_untraversable(grid, trajectory, t0, max_speed).is_none()
}
