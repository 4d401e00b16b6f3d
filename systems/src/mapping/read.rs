//! Read access to the map for every other stage (frontiers, planning, metrics, exports): one
//! trait, [`OccupancyMap`], implemented by the ECS view [`MapReader`] and by the plain
//! [`super::ChunkStore`], so algorithms over the map are tested without a World.

use bevy_ecs::prelude::*;
use bevy_ecs::system::SystemParam;
use glam::IVec3;
use uavex_components::map::{
    BRICK_EDGE, CHUNK_EDGE, CHUNK_VOXELS, ChunkCoord, ChunkIndex, MapConfig, UNKNOWN_LOG_ODDS,
    VoxelChunk, VoxelState, local_index, local_key, milli_to_log_odds,
};
use uavex_components::world::WorldGeometry;

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

/// Voxel states read one after another close together (a flood fill): the chunk of the last
/// voxel read is kept, so a voxel in the same chunk, most of them, costs no chunk lookup
/// (through [`MapReader`] a lookup is an entity query, several times the rest of the read).
pub struct NearbyStates<'m, M> {
    map: &'m M,
    last: Option<(ChunkCoord, Option<&'m VoxelChunk>)>,
}

impl<'m, M: OccupancyMap> NearbyStates<'m, M> {
    pub fn new(map: &'m M) -> Self {
        Self { map, last: None }
    }

    /// The state of voxel `key` ([`OccupancyMap::state`]), `None` outside the map.
    #[inline]
    pub fn state(&mut self, key: IVec3) -> Option<VoxelState> {
        if !self.map.config().contains_key(key) {
            return None;
        }
        let coord = ChunkCoord::of_key(key);
        let chunk = match self.last {
            Some((last, chunk)) if last == coord => chunk,
            _ => {
                let chunk = self.map.chunk(coord);
                self.last = Some((coord, chunk));
                chunk
            }
        };
        Some(chunk.map_or(VoxelState::Unknown, |chunk| chunk.state(local_index(key))))
    }
}

/// The truth a map is measured against ([`map_accuracy`]): any `Fn(IVec3) -> bool` telling
/// whether a voxel key is occupied, or [`WorldVoxels`].
pub trait GroundTruth {
    /// Whether voxel `key` is occupied.
    fn occupied(&self, key: IVec3) -> bool;

    /// Whether some voxel of the keys `lo..=hi` may be occupied; false only if none is (a
    /// quick answer for a block of voxels, so that open space is not asked voxel by voxel).
    fn may_be_occupied(&self, _lo: IVec3, _hi: IVec3) -> bool {
        true
    }
}

impl<F: Fn(IVec3) -> bool> GroundTruth for F {
    fn occupied(&self, key: IVec3) -> bool {
        self(key)
    }
}

/// The world's obstacles as the ground truth of a map of voxels of edge `resolution`
/// ([`WorldGeometry::voxel_key_occupied`]).
pub struct WorldVoxels<'a> {
    pub geometry: &'a WorldGeometry,
    pub resolution: f32,
}

impl GroundTruth for WorldVoxels<'_> {
    fn occupied(&self, key: IVec3) -> bool {
        self.geometry.voxel_key_occupied(key, self.resolution)
    }

    fn may_be_occupied(&self, lo: IVec3, hi: IVec3) -> bool {
        self.geometry
            .voxel_keys_may_be_occupied(lo, hi, self.resolution)
    }
}

/// Fraction of known voxels whose state agrees with the ground truth; `None` while no voxel
/// is known. Brick by brick: a brick the truth says is all free is not asked voxel by voxel.
pub fn map_accuracy(map: &impl OccupancyMap, truth: impl GroundTruth) -> Option<f64> {
    let (mut known, mut agree) = (0u64, 0u64);
    let bricks = CHUNK_EDGE / BRICK_EDGE;
    for (coord, chunk) in map.chunks() {
        for b in 0..bricks * bricks * bricks {
            let brick = IVec3::new(b % bricks, b / bricks % bricks, b / (bricks * bricks));
            let lo = coord.first_key() + brick * BRICK_EDGE;
            let hi = lo + IVec3::splat(BRICK_EDGE - 1);
            let open = !truth.may_be_occupied(lo, hi);
            for z in lo.z..=hi.z {
                for y in lo.y..=hi.y {
                    for x in lo.x..=hi.x {
                        let key = IVec3::new(x, y, z);
                        let l = chunk.log_odds_milli(local_index(key));
                        if l == UNKNOWN_LOG_ODDS {
                            continue;
                        }
                        known += 1;
                        let occupied = !open && truth.occupied(key);
                        agree += u64::from((l >= 0) == occupied);
                    }
                }
            }
        }
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
