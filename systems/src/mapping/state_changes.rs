//! Which chunks had voxel *states* change, for consumers that depend on states alone.
//!
//! Frontiers and traversability depend only on whether each voxel is unknown, free or
//! occupied. In flight most chunk writes only move log-odds within a state (free space seen
//! free again), yet they mark the chunk `Changed`. [`StateChanges`] narrows `Changed<VoxelChunk>`
//! to the chunks whose [`VoxelChunk::state_version`] moved since this system last saw them, so
//! such consumers re-examine only what can differ for them.

use bevy_ecs::entity::EntityHashMap;
use bevy_ecs::prelude::*;
use bevy_ecs::system::SystemParam;
use uavex_components::map::{ChunkCoord, VoxelChunk};

/// The state version of every chunk as one system last saw it.
#[derive(Debug, Default, Clone)]
pub struct SeenVersions(EntityHashMap<u32>);

impl SeenVersions {
    /// Whether `version` differs from the one last seen for `chunk` (true the first time), and
    /// remembers it.
    pub fn changed(&mut self, chunk: Entity, version: u32) -> bool {
        self.0.insert(chunk, version) != Some(version)
    }
}

/// System parameter: the chunks whose voxel states changed since the system last ran (chunks
/// spawned since then included), in query order.
#[derive(SystemParam)]
pub struct StateChanges<'w, 's> {
    changed: Query<'w, 's, (Entity, &'static ChunkCoord, &'static VoxelChunk), Changed<VoxelChunk>>,
    seen: Local<'s, SeenVersions>,
}

impl StateChanges<'_, '_> {
    /// Appends the coordinates of the chunks whose states changed to `out`.
    pub fn collect_into(&mut self, out: &mut Vec<ChunkCoord>) {
        for (entity, coord, chunk) in &self.changed {
            if self.seen.changed(entity, chunk.state_version()) {
                out.push(*coord);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::IVec3;

    #[derive(Resource, Default)]
    struct Seen(Vec<ChunkCoord>);

    fn record(mut changes: StateChanges, mut seen: ResMut<Seen>) {
        seen.0.clear();
        changes.collect_into(&mut seen.0);
    }

    #[test]
    fn only_chunks_whose_states_moved_are_reported() {
        let mut world = World::new();
        world.insert_resource(Seen::default());
        let a = world
            .spawn((ChunkCoord(IVec3::ZERO), VoxelChunk::new()))
            .id();
        let b = world.spawn((ChunkCoord(IVec3::X), VoxelChunk::new())).id();
        let mut schedule = Schedule::default();
        schedule.add_systems(record);
        // New chunks are reported once.
        schedule.run(&mut world);
        assert_eq!(world.resource::<Seen>().0.len(), 2);
        schedule.run(&mut world);
        assert!(world.resource::<Seen>().0.is_empty());
        // A write that keeps states (the map update's path) marks `a` changed only.
        let mut chunk = world.get_mut::<VoxelChunk>(a).unwrap();
        chunk.voxels_and_saturation_mut().0[0].log_odds = -500;
        schedule.run(&mut world);
        assert!(world.resource::<Seen>().0.is_empty());
        // A state change reported as such.
        world.get_mut::<VoxelChunk>(b).unwrap().note_state_change();
        schedule.run(&mut world);
        assert_eq!(world.resource::<Seen>().0, vec![ChunkCoord(IVec3::X)]);
        // A write by hand always counts.
        world.get_mut::<VoxelChunk>(a).unwrap().voxels_mut()[1].log_odds = 5;
        schedule.run(&mut world);
        assert_eq!(world.resource::<Seen>().0, vec![ChunkCoord(IVec3::ZERO)]);
    }
}
