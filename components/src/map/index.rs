//! Map-wide bookkeeping resources: which entity holds each chunk, and which scans were
//! integrated.

use super::chunk::{ChunkCoord, ScanId};
use super::config::MapConfig;
use super::grid::ChunkGrid;
use crate::sensor::SensorId;
use bevy_ecs::prelude::*;
use std::collections::BTreeMap;

/// Chunk coordinate -> chunk entity, as a dense table over the chunk grid covering the map (no
/// hashing: a lookup is an index computation). Filled by the mapping stage as chunks are
/// spawned on first touch.
#[derive(Resource, Debug, Clone, PartialEq, Eq)]
pub struct ChunkIndex {
    grid: ChunkGrid,
    entities: Vec<Option<Entity>>,
    registered: usize,
}

impl ChunkIndex {
    /// An empty index over `config`'s chunk grid.
    pub fn new(config: &MapConfig) -> Self {
        let grid = config.chunk_grid();
        Self {
            grid,
            entities: vec![None; grid.len()],
            registered: 0,
        }
    }

    pub fn grid(&self) -> ChunkGrid {
        self.grid
    }

    /// Entity of the chunk at `coord`, if it exists.
    #[inline]
    pub fn get(&self, coord: ChunkCoord) -> Option<Entity> {
        self.grid.flat(coord).and_then(|flat| self.get_flat(flat))
    }

    /// Entity of the chunk with flat index `flat` (see [`ChunkGrid::flat`]), if it exists.
    #[inline]
    pub fn get_flat(&self, flat: usize) -> Option<Entity> {
        self.entities.get(flat).copied().flatten()
    }

    /// Registers the chunk entity at flat index `flat`; returns the entity it replaced. Ignored
    /// (returns `None`) for an index outside the grid.
    pub fn set_flat(&mut self, flat: usize, entity: Entity) -> Option<Entity> {
        let slot = self.entities.get_mut(flat)?;
        let old = slot.replace(entity);
        if old.is_none() {
            self.registered += 1;
        }
        old
    }

    /// Number of chunks registered.
    pub fn len(&self) -> usize {
        self.registered
    }

    pub fn is_empty(&self) -> bool {
        self.registered == 0
    }

    /// Registered chunks in flat-index order (deterministic, independent of ECS storage).
    pub fn iter(&self) -> impl Iterator<Item = (ChunkCoord, Entity)> + '_ {
        self.entities
            .iter()
            .enumerate()
            .filter_map(|(flat, e)| e.map(|e| (self.grid.coord(flat), e)))
    }
}

/// Gives each integrated scan its [`ScanId`] and remembers, per sensor, the last sweep
/// (`Scan::sequence`) integrated, so that a scan is integrated exactly once.
#[derive(Resource, Debug, Clone, Default, PartialEq, Eq)]
pub struct ScanCounter {
    last: Option<ScanId>,
    integrated: BTreeMap<SensorId, u64>,
}

impl ScanCounter {
    /// Id of the next scan to integrate.
    pub fn next_id(&mut self) -> ScanId {
        let id = ScanId::after(self.last);
        self.last = Some(id);
        id
    }

    /// The last id handed out.
    pub fn last_id(&self) -> Option<ScanId> {
        self.last
    }

    /// Sequence number of the last sweep of `sensor` integrated (0 if none).
    pub fn integrated_sequence(&self, sensor: SensorId) -> u64 {
        self.integrated.get(&sensor).copied().unwrap_or(0)
    }

    pub fn set_integrated_sequence(&mut self, sensor: SensorId, sequence: u64) {
        self.integrated.insert(sensor, sequence);
    }
}

#[cfg(test)]
mod tests {
    use super::super::config::MapSettings;
    use super::*;
    use glam::{DVec3, IVec3};

    #[test]
    fn index_registers_and_lists_in_grid_order() {
        let config = MapConfig::new(&MapSettings {
            bounds_min: DVec3::splat(-3.2),
            bounds_max: DVec3::splat(3.2),
            ..MapSettings::default()
        })
        .unwrap();
        // Keys -32..=31 -> chunks -2..=1: a 4^3 grid.
        let mut index = ChunkIndex::new(&config);
        assert_eq!(index.grid().dims, IVec3::splat(4));
        let (a, b) = (
            Entity::from_raw_u32(7).unwrap(),
            Entity::from_raw_u32(9).unwrap(),
        );
        let ca = ChunkCoord(IVec3::new(1, -2, 0));
        let cb = ChunkCoord(IVec3::new(-2, -2, -2));
        assert_eq!(index.set_flat(index.grid().flat(ca).unwrap(), a), None);
        assert_eq!(index.set_flat(index.grid().flat(cb).unwrap(), b), None);
        assert_eq!(index.set_flat(usize::MAX, b), None);
        assert_eq!(index.len(), 2);
        assert_eq!(index.get(ca), Some(a));
        assert_eq!(index.get(ChunkCoord(IVec3::new(2, 0, 0))), None);
        let listed: Vec<_> = index.iter().collect();
        assert_eq!(listed, vec![(cb, b), (ca, a)]);
    }

    #[test]
    fn counter_hands_out_increasing_ids_and_tracks_sequences() {
        let mut counter = ScanCounter::default();
        let (first, second) = (counter.next_id(), counter.next_id());
        assert!(first < second);
        assert_eq!(counter.last_id(), Some(second));
        assert_eq!(counter.integrated_sequence(SensorId(3)), 0);
        counter.set_integrated_sequence(SensorId(3), 12);
        assert_eq!(counter.integrated_sequence(SensorId(3)), 12);
    }
}
