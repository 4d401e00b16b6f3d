//! The recorder: the open recording and what it remembers between logs (which chunks changed,
//! what each showed when last logged, the flown paths, this tick's decisions).

use super::candidates::CandidateSketch;
use super::path::FlownPath;
use super::writer::RrdWriter;
use crate::metrics::Cadence;
use bevy_ecs::prelude::*;
use glam::IVec3;
use re_chunk::EntityPath;
use re_sdk_types::AsComponents;
use std::collections::{BTreeMap, BTreeSet};
use uavex_components::frontier::VoxelMask;
use uavex_components::map::ChunkCoord;

/// One decision as recorded: whose it was and its candidates in the order they were proposed.
#[derive(Debug, Clone, PartialEq)]
pub struct DecisionSketch {
    /// `Uav::index`.
    pub uav: usize,
    pub candidates: Vec<CandidateSketch>,
}

/// The recording of a run in progress (a resource, present only while recording).
#[derive(Resource)]
pub struct Recorder {
    writer: RrdWriter,
    /// Regular log times; decisions are logged when they happen, besides.
    pub cadence: Cadence,
    /// UAV names by `Uav::index` (their entity paths).
    pub names: Vec<String>,
    /// Chunks whose voxels changed since the last log, in a fixed order (coordinates as
    /// `[z, y, x]`, the chunk grid's order).
    changed: BTreeSet<[i32; 3]>,
    /// Each chunk's occupied voxels as last logged.
    shown: BTreeMap<[i32; 3], VoxelMask>,
    /// Each UAV's flown path, by `Uav::index`.
    pub paths: Vec<FlownPath>,
    /// Decisions made this tick, waiting for the Account stage's log.
    pub decisions: Vec<DecisionSketch>,
}

impl Recorder {
    pub fn new(writer: RrdWriter, rate_hz: f64, names: Vec<String>) -> Self {
        Self {
            writer,
            cadence: Cadence::new(rate_hz),
            paths: vec![FlownPath::default(); names.len()],
            names,
            changed: BTreeSet::new(),
            shown: BTreeMap::new(),
            decisions: Vec::new(),
        }
    }

    /// Whether anything is to be logged at `time_s`.
    pub fn due(&self, time_s: f64) -> bool {
        self.cadence.is_due(time_s) || !self.decisions.is_empty()
    }

    pub fn log(&mut self, entity: &EntityPath, time_s: f64, archetype: &dyn AsComponents) {
        self.writer.log(entity, time_s, archetype);
    }

    pub fn log_static(&mut self, entity: &EntityPath, archetype: &dyn AsComponents) {
        self.writer.log_static(entity, archetype);
    }

    /// Notes that the voxels of chunk `coord` changed.
    pub fn note_changed(&mut self, coord: ChunkCoord) {
        self.changed.insert(grid_order(coord));
    }

    /// The chunks changed since the last call, in chunk grid order.
    pub fn take_changed(&mut self) -> Vec<ChunkCoord> {
        std::mem::take(&mut self.changed)
            .into_iter()
            .map(|[z, y, x]| ChunkCoord(IVec3::new(x, y, z)))
            .collect()
    }

    /// Remembers `mask` as what chunk `coord` shows; false if it already showed exactly that
    /// (nothing to log).
    pub fn show(&mut self, coord: ChunkCoord, mask: VoxelMask) -> bool {
        let key = grid_order(coord);
        if self.shown.get(&key) == Some(&mask)
            || (mask.is_empty() && !self.shown.contains_key(&key))
        {
            return false;
        }
        self.shown.insert(key, mask);
        true
    }

    /// Closes the file; its size in bytes.
    pub fn finish(self) -> Result<u64, String> {
        self.writer.finish()
    }
}

fn grid_order(coord: ChunkCoord) -> [i32; 3] {
    [coord.0.z, coord.0.y, coord.0.x]
}
