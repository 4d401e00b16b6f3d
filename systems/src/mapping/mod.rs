//! Map stage: integrates range scans into the occupancy map (common.md §1) and keeps the map
//! statistics of common.md §5 up to date.
//!
//! - `axes`: per-axis arithmetic on the walk's arrays, written out lane by lane (why: there).
//! - [`dda`]: Amanatides & Woo voxel traversal, clipped to the map.
//! - [`update`]: the log-odds update of one voxel (stamp, add, clamp, statistics).
//! - [`cube`]: walking past a cube (brick, block, chunk) of saturated free voxels in one move.
//! - `cursor`: the walk's position inside a chunk, index and coordinates in one integer.
//! - [`free_box`]: the box of saturated free bricks around a scan's sensor, which every ray
//!   leaves in one move.
//! - `brick_run`: a walk's move along the run of full bricks ahead of it, on the scan's brick
//!   grid (`full_bricks`).
//! - `rays`: a scan's rays checked, in voxel units, and prepared for the walks.
//! - [`integrate`]: one scan into the map over any [`ChunkAccess`] (plain function).
//! - `walk`: the walk proper, voxel by voxel in a chunk, past the saturated cubes it meets.
//! - [`report`]: [`ScanReport`], what an integration did (and, asked for, how it skipped).
//! - [`store`]: [`ChunkStore`], a map outside the ECS (tests, benchmarks, tools).
//! - [`read`]: [`OccupancyMap`] queries, the [`MapReader`] system parameter, [`NearbyStates`]
//!   (states read chunk by chunk, for floods), map accuracy.
//! - [`state_changes`]: [`StateChanges`], the chunks whose voxel states changed (for consumers
//!   that depend on states alone: frontiers, traversability).
//! - [`system`]: the ECS system [`integrate_scans`] and [`insert_map_resources`].
//!
//! Wiring: insert the resources with [`insert_map_resources`] (plus `RunEnd`), and add
//! [`integrate_scans`] to the Map set after sensing. Chunks it creates are spawned through
//! Commands: systems that read the map later in the same tick must run after a command flush.

mod axes;
mod brick_run;
pub mod cube;
mod cursor;
pub mod dda;
pub mod free_box;
mod full_bricks;
pub mod integrate;
mod rays;
pub mod read;
pub mod report;
pub mod state_changes;
pub mod store;
pub mod system;
pub mod update;
mod walk;

pub use integrate::{ChunkAccess, ScanError, ScanRays, integrate_scan, integrate_scan_tallied};
pub use read::{GroundTruth, MapReader, NearbyStates, OccupancyMap, WorldVoxels, map_accuracy};
pub use report::ScanReport;
pub use state_changes::{StateChange, StateChanges};
pub use store::ChunkStore;
pub use system::{MappingScratch, insert_map_resources, integrate_scans};

#[cfg(test)]
pub(crate) mod tests;
#[cfg(test)]
mod tests_plain;
