//! A map held outside the ECS: the chunks in a dense table over the chunk grid. Used by tests,
//! benchmarks and offline tools; the running engine keeps chunks as entities instead.

use super::integrate::ChunkAccess;
use super::read::OccupancyMap;
use super::state_changes::StateChange;
use uavex_components::map::{ChunkCoord, ChunkGrid, MapConfig, StatSums, VoxelChunk};

/// Chunks with their statistics, by flat chunk index, plus which chunks were written since
/// [`ChunkStore::take_written`] was last called.
#[derive(Debug, Clone)]
pub struct ChunkStore {
    config: MapConfig,
    chunks: Vec<Option<(VoxelChunk, StatSums)>>,
    written_flags: Vec<bool>,
    written: Vec<usize>,
    /// Per chunk, the state version [`ChunkStore::take_state_changes`] last saw.
    seen_versions: Vec<Option<u32>>,
}

impl ChunkStore {
    pub fn new(config: &MapConfig) -> Self {
        let n = config.chunk_grid().len();
        Self {
            config: config.clone(),
            chunks: vec![None; n],
            written_flags: vec![false; n],
            written: Vec::new(),
            seen_versions: vec![None; n],
        }
    }

    fn grid(&self) -> ChunkGrid {
        self.config.chunk_grid()
    }

    /// Number of chunks created.
    pub fn chunk_count(&self) -> usize {
        self.chunks.iter().filter(|c| c.is_some()).count()
    }

    /// The incrementally kept statistics of the chunk at `coord`.
    pub fn stats(&self, coord: ChunkCoord) -> Option<&StatSums> {
        let flat = self.grid().flat(coord)?;
        self.chunks[flat].as_ref().map(|(_, stats)| stats)
    }

    /// Chunks written since the last call, in the order first written; clears the record.
    pub fn take_written(&mut self) -> Vec<ChunkCoord> {
        let grid = self.grid();
        for &flat in &self.written {
            self.written_flags[flat] = false;
        }
        self.written
            .drain(..)
            .map(|flat| grid.coord(flat))
            .collect()
    }

    /// The chunks written since the last call whose voxel states changed, and where (as the
    /// engine's `StateChanges` reports them; every brick the first time a chunk is seen);
    /// clears the record of written chunks.
    pub fn take_state_changes(&mut self) -> Vec<StateChange> {
        let grid = self.grid();
        let mut changes = Vec::new();
        for coord in self.take_written() {
            let flat = grid.flat_unchecked(coord);
            let Some((chunk, _)) = &self.chunks[flat] else {
                continue;
            };
            let seen = self.seen_versions[flat].replace(chunk.state_version());
            let bricks = chunk.state_changed_bricks_since(seen);
            if bricks != 0 {
                changes.push(StateChange { coord, bricks });
            }
        }
        changes
    }
}

impl ChunkAccess for ChunkStore {
    #[inline]
    fn chunk_mut(&mut self, flat: usize, coord: ChunkCoord) -> (&mut VoxelChunk, &mut StatSums) {
        let config = &self.config;
        let (chunk, stats) = self.chunks[flat].get_or_insert_with(|| {
            let chunk = VoxelChunk::in_map(coord, config.key_min(), config.key_max());
            (chunk, StatSums::default())
        });
        (chunk, stats)
    }

    fn full_bricks(&self, flat: usize) -> u64 {
        self.chunks[flat]
            .as_ref()
            .map_or(0, |(chunk, _)| chunk.saturation().full_bricks())
    }

    #[inline]
    fn mark_written(&mut self, flat: usize) {
        if !self.written_flags[flat] {
            self.written_flags[flat] = true;
            self.written.push(flat);
        }
    }
}

impl OccupancyMap for ChunkStore {
    fn config(&self) -> &MapConfig {
        &self.config
    }

    fn chunk(&self, coord: ChunkCoord) -> Option<&VoxelChunk> {
        let flat = self.grid().flat(coord)?;
        self.chunks[flat].as_ref().map(|(chunk, _)| chunk)
    }

    fn chunks(&self) -> impl Iterator<Item = (ChunkCoord, &VoxelChunk)> {
        let grid = self.grid();
        self.chunks
            .iter()
            .enumerate()
            .filter_map(move |(flat, c)| c.as_ref().map(|(chunk, _)| (grid.coord(flat), chunk)))
    }
}
