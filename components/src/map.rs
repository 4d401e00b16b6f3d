//! The occupancy map's data (common.md §1): voxel chunks as ECS entities, their per-chunk
//! statistics, and the map-wide resources that describe the grid and index the chunks.
//!
//! - [`MapConfig`] (resource): resolution, the key box the map covers, clamping bounds, the
//!   fixed-point lookup tables, and the key/chunk arithmetic everyone shares.
//! - [`VoxelChunk`] + [`ChunkCoord`] + [`ChunkStats`] (components): one entity per 16^3 block of
//!   voxels, created on first touch by the mapping stage.
//! - [`ChunkIndex`] (resource): chunk coordinate -> entity, a dense table over the chunk grid.
//! - [`MapTotals`] (resource): the sum of all [`ChunkStats`], so that map metrics are O(1).
//! - [`ScanCounter`] (resource): ids of integrated scans and the last sweep seen per sensor.
//!
//! The algorithms (ray traversal, log-odds update, the ECS systems, read access) live in
//! `uavex_systems::mapping`.

mod chunk;
mod config;
mod grid;
mod index;
mod rows;
mod saturation;
mod stats;

pub use chunk::{
    CHUNK_EDGE, CHUNK_VOXELS, ChunkCells, ChunkCoord, ScanId, UNKNOWN_LOG_ODDS, Voxel, VoxelChunk,
    VoxelState, local_index, local_key,
};
pub use config::{
    LogOddsIncrements, MAX_BOX_VOXELS, MapConfig, MapConfigError, MapSettings, floor_to_key,
    log_odds_to_milli, milli_to_log_odds,
};
pub use grid::ChunkGrid;
pub use index::{ChunkIndex, ScanCounter};
pub use rows::{CHUNK_ROWS, ChunkRows, RowStates};
pub use saturation::{
    BRICK_EDGE, BRICK_VOXELS, BrickSaturation, CHUNK_BRICKS, block_bricks, brick_of,
};
pub use stats::{ChunkStats, MapMetrics, MapTotals, STAT_ONE, StatEntry, StatSums, StatTables};
