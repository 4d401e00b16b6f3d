//! Trajectory planning on the voxel map (EAAE steps 6 and 9).
//!
//! - [`traversable`]: the map's known free space shrunk by the UAV's radius, kept per chunk and
//!   refreshed lazily where the map changed ([`TraversableGrid`]).
//! - [`lattice`]: the 2-voxel search lattice over it.
//! - `best_first`: the searches' engine (Dijkstra or A* on the lattice, a bucket queue, cell
//!   state kept from one search to the next), which can pause at a settled cell and go on.
//! - [`search`]: A* ([`find_path`]), one Dijkstra to many goals ([`find_paths`], or as far as
//!   the goals asked for so far need: [`PathSearch`]), and the line-of-sight [`shortcut`].
//! - `escape`: the way out of a pocket of traversable voxels no open cell is seen from.
//! - [`braking`]: how a moving start that must turn back stops first ([`Braking`]).
//! - [`global`]: a feasible, collision-free minimum-snap trajectory along a path
//!   ([`plan_along`], [`plan_global`]).
//! - [`local`]: the receding-horizon planner that flies toward the chosen goal ([`plan_local`]).
//! - [`check`]: whether a trajectory stays traversable ([`remains_traversable`]).
//!
//! ECS: the grid is the resource [`Traversability`]; [`track_traversability`] (Frontier stage)
//! marks the chunks the map stage changed dirty, and the systems that plan call
//! `grid.0.refresh(&map)` before they search, so the grid is recomputed only where the map
//! changed and only when someone needs it.

mod best_first;
pub mod braking;
pub mod check;
mod escape;
pub mod global;
pub mod lattice;
pub mod local;
mod pruning;
pub mod search;
pub mod sight;
pub mod traversable;

#[cfg(test)]
mod tests;
#[cfg(test)]
mod tests_braking;
#[cfg(test)]
mod tests_planner;
#[cfg(test)]
mod tests_search;

pub use braking::{Braking, BrakingMemo};
pub use check::{first_untraversable, refresh_along, remains_traversable};
pub use global::{GlobalPlan, plan_along, plan_along_seen, plan_global};
pub use local::{LocalPlan, plan_local};
pub use search::{PathSearch, SNAP_RADIUS_M, find_path, find_paths, path_length, shortcut};
pub use sight::SightMemo;
pub use traversable::{TraversableGrid, inflation_radius};

use crate::mapping::{StateChange, StateChanges};
use bevy_ecs::prelude::*;

/// The traversability grid of the shared map, as a resource.
#[derive(Resource, Debug, Clone)]
pub struct Traversability(pub TraversableGrid);

/// Frontier stage: marks every map chunk whose voxel states changed since this system last ran
/// (and the chunks its inflation reaches) dirty in the [`Traversability`] grid: traversability
/// depends on states alone. Does nothing while the resource is absent (runs that do not plan on
/// the map).
pub fn track_traversability(
    grid: Option<ResMut<Traversability>>,
    mut changes: StateChanges,
    mut scratch: Local<Vec<StateChange>>,
) {
    let Some(mut grid) = grid else {
        return;
    };
    scratch.clear();
    changes.collect_into(&mut scratch);
    for change in scratch.iter() {
        grid.0.mark_state_change(*change);
    }
}
