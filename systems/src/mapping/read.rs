//! Read access to the map for every other stage (frontiers, planning, metrics, exports): one
//! trait, [`OccupancyMap`], implemented by the ECS view [`MapReader`] and by the plain
//! [`super::ChunkStore`], so algorithms over the map are tested without a World.

use bevy_ecs::prelude::*;
use bevy_ecs::system::SystemParam;
use glam::IVec3;
use uavex_components::map::{
    CHUNK_VOXELS, ChunkCoord, ChunkIndex, MapConfig, UNKNOWN_LOG_ODDS, VoxelChunk, VoxelState,
    local_index, local_key, milli_to_log_odds,
};

/// Read-only occupancy queries (common.md §1 semantics: unknown until observed, occupied when
/// l >= 0, free otherwise).
pub trait OccupancyMap {
    fn config(&self) -> &MapConfig;

    /// The chunk at `coord`, if it exists.
    fn chunk(&self, coord: ChunkCoord) -> Option<&VoxelChunk>;

    /// All existing chunks, in chunk-grid order (deterministic).
    fn chunks(&self) -> impl Iterator<Item = (ChunkCoord, &VoxelChunk)>;

    /// Stored log-odds (milli units) of voxel `key`; `None` if unknown or outside the map.
    fn log_odds_milli(&self, key: IVec3) -> Option<i16> {
        if !self.config().contains_key(key) {
            return None;
        }
        let l = self
            .chunk(ChunkCoord::of_key(key))?
            .log_odds_milli(local_index(key));
        (l != UNKNOWN_LOG_ODDS).then_some(l)
    }

    /// State of voxel `key` (outside the map: unknown, as nothing is ever observed there).
    fn state(&self, key: IVec3) -> VoxelState {
        self.log_odds_milli(key)
            .map_or(VoxelState::Unknown, VoxelState::of_milli)
    }

    /// Log-odds of voxel `key`, `None` if unknown.
    fn log_odds(&self, key: IVec3) -> Option<f32> {
        self.log_odds_milli(key).map(milli_to_log_odds)
    }

    /// Occupancy probability p = 1 - 1 / (1 + exp(l)) of voxel `key`, `None` if unknown.
    fn probability(&self, key: IVec3) -> Option<f32> {
        self.log_odds(key).map(|l| 1.0 - 1.0 / (1.0 + l.exp()))
    }

    /// Every known voxel as `(key, log-odds)`, chunk by chunk in grid order, for exports and
    /// accuracy metrics. Voxels of border chunks outside the map are never known, so all keys
    /// lie in the map.
    fn known_voxels(&self) -> impl Iterator<Item = (IVec3, f32)> {
        self.chunks().flat_map(|(coord, chunk)| {
            (0..CHUNK_VOXELS).filter_map(move |i| {
                let l = chunk.log_odds_milli(i);
                (l != UNKNOWN_LOG_ODDS).then(|| (local_key(coord, i), milli_to_log_odds(l)))
            })
        })
    }
}

/// Fraction of known voxels whose state agrees with the ground truth `is_occupied(key)`;
/// `None` while no voxel is known.
pub fn map_accuracy(map: &impl OccupancyMap, is_occupied: impl Fn(IVec3) -> bool) -> Option<f64> {
    let (mut known, mut agree) = (0u64, 0u64);
    for (key, log_odds) in map.known_voxels() {
        known += 1;
        agree += u64::from((log_odds >= 0.0) == is_occupied(key));
    }
    (known > 0).then(|| agree as f64 / known as f64)
}

/// The map as a system parameter: the chunk index plus read access to the chunk entities.
#[derive(SystemParam)]
pub struct MapReader<'w, 's> {
    pub config: Res<'w, MapConfig>,
    pub index: Res<'w, ChunkIndex>,
    chunks: Query<'w, 's, &'static VoxelChunk>,
}

impl OccupancyMap for MapReader<'_, '_> {
    fn config(&self) -> &MapConfig {
        &self.config
    }

    fn chunk(&self, coord: ChunkCoord) -> Option<&VoxelChunk> {
        self.chunks.get(self.index.get(coord)?).ok()
    }

    fn chunks(&self) -> impl Iterator<Item = (ChunkCoord, &VoxelChunk)> {
        self.index
            .iter()
            .filter_map(|(coord, entity)| Some((coord, self.chunks.get(entity).ok()?)))
    }
}
