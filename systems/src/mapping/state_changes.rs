//! Which chunks had voxel *states* change, and where, for consumers that depend on states
//! alone.
//!
//! Frontiers and traversability depend only on whether each voxel is unknown, free or
//! occupied. In flight most chunk writes only move log-odds within a state (free space seen
//! free again), yet they mark the chunk `Changed`. [`StateChanges`] narrows `Changed<VoxelChunk>`
//! to the chunks whose [`VoxelChunk::state_version`] moved since this system last saw them, so
//! such consumers re-examine only what can differ for them; and it says in which bricks
//! ([`VoxelChunk::state_changed_bricks_since`]), so that they re-examine a neighbour chunk
//! only when a changed brick lies within their reach of it ([`StateChange::reaches`]). A
//! camera's scan changes states along the surfaces it sees, a few bricks of each chunk: most
//! neighbours are out of reach.

use bevy_ecs::entity::EntityHashMap;
use bevy_ecs::prelude::*;
use bevy_ecs::system::SystemParam;
use glam::IVec3;
use uavex_components::map::{BRICK_EDGE, CHUNK_EDGE, ChunkCoord, VoxelChunk};

/// The state version of every chunk as one system last saw it.
#[derive(Debug, Default, Clone)]
pub struct SeenVersions(EntityHashMap<u32>);

impl SeenVersions {
    /// The bricks of `voxels` (the chunk of entity `chunk`) whose states may have changed since
    /// this was last asked (all of them the first time), remembering its version.
    pub fn changed_bricks(&mut self, chunk: Entity, voxels: &VoxelChunk) -> u64 {
        voxels.state_changed_bricks_since(self.0.insert(chunk, voxels.state_version()))
    }
}

/// The voxel states of chunk `coord` changed in `bricks` (brick bits, as
/// [`uavex_components::map::brick_of`] numbers them).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct StateChange {
    pub coord: ChunkCoord,
    pub bricks: u64,
}

impl From<ChunkCoord> for StateChange {
    /// A change anywhere in the chunk.
    fn from(coord: ChunkCoord) -> Self {
        Self {
            coord,
            bricks: u64::MAX,
        }
    }
}

impl StateChange {
    /// Whether a voxel of the changed bricks lies within `margin` voxels, along every axis, of
    /// the chunk `offset` (in chunks) from this one: whether a property of a voxel that depends
    /// on the states of the voxels up to `margin` away (a box, which holds any ball or
    /// 6-neighbourhood of that radius) can have changed in that chunk.
    pub fn reaches(&self, offset: IVec3, margin: i32) -> bool {
        let near = [0, 1, 2].map(|axis| axis_bricks(axis, near_layers(offset[axis], margin)));
        self.bricks & near[0] & near[1] & near[2] != 0
    }
}

/// The brick layers (bit `b` for brick coordinate `b`, 0..4) along an axis whose voxels lie
/// within `margin` voxels of the chunk `d` chunks away along it: gap < margin, where the gap is
/// the number of voxels strictly between the layer's nearest voxel and that chunk.
fn near_layers(d: i32, margin: i32) -> u32 {
    let layers = CHUNK_EDGE / BRICK_EDGE;
    (0..layers)
        .filter(|&b| {
            let gap = match d.signum() {
                0 => return true,
                -1 => CHUNK_EDGE * (-d - 1) + BRICK_EDGE * b,
                _ => CHUNK_EDGE * (d - 1) + BRICK_EDGE * (layers - 1 - b),
            };
            gap < margin
        })
        .fold(0, |set, b| set | 1 << b)
}

/// The bricks of a chunk whose coordinate along `axis` is in `layers` (bit per coordinate).
fn axis_bricks(axis: usize, layers: u32) -> u64 {
    // Brick (x, y, z) is bit x + 4 y + 16 z: the bricks of layer 0 along each axis.
    const LAYER_0: [u64; 3] = [0x1111_1111_1111_1111, 0x000F_000F_000F_000F, 0xFFFF];
    (0..4)
        .filter(|b| layers >> b & 1 == 1)
        .fold(0, |set, b| set | LAYER_0[axis] << (b << (2 * axis)))
}

/// System parameter: the chunks whose voxel states changed since the system last ran (chunks
/// spawned since then included), in query order.
#[derive(SystemParam)]
pub struct StateChanges<'w, 's> {
    changed: Query<'w, 's, (Entity, &'static ChunkCoord, &'static VoxelChunk), Changed<VoxelChunk>>,
    seen: Local<'s, SeenVersions>,
}

impl StateChanges<'_, '_> {
    /// Appends the chunks whose states changed, and where, to `out`.
    pub fn collect_into(&mut self, out: &mut Vec<StateChange>) {
        for (entity, &coord, chunk) in &self.changed {
            let bricks = self.seen.changed_bricks(entity, chunk);
            if bricks != 0 {
                out.push(StateChange { coord, bricks });
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use uavex_components::map::{ScanId, brick_of, local_index};

    #[derive(Resource, Default)]
    struct Seen(Vec<StateChange>);

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
        chunk.voxels_for_update().0.voxel_mut(0).log_odds = -500;
        schedule.run(&mut world);
        assert!(world.resource::<Seen>().0.is_empty());
        // A state change reported as such.
        world.get_mut::<VoxelChunk>(b).unwrap().note_state_change();
        schedule.run(&mut world);
        assert_eq!(
            world.resource::<Seen>().0,
            vec![StateChange::from(ChunkCoord(IVec3::X))]
        );
        // The map update's path tells the bricks.
        let scan = ScanId::after(None);
        world
            .get_mut::<VoxelChunk>(b)
            .unwrap()
            .note_state_changes_in(scan, 1 << 5 | 1 << 60);
        schedule.run(&mut world);
        let expected = StateChange {
            coord: ChunkCoord(IVec3::X),
            bricks: 1 << 5 | 1 << 60,
        };
        assert_eq!(world.resource::<Seen>().0, vec![expected]);
        // A write by hand always counts.
        world.get_mut::<VoxelChunk>(a).unwrap().voxels_mut()[1].log_odds = 5;
        schedule.run(&mut world);
        assert_eq!(
            world.resource::<Seen>().0,
            vec![StateChange::from(ChunkCoord(IVec3::ZERO))]
        );
    }

    /// `reaches` by hand: a brick in a chunk's corner reaches the face, edge and corner
    /// neighbours at that corner within one voxel, and nothing across the chunk; an inner
    /// brick reaches no neighbour within 4 voxels, the face neighbours within 5.
    #[test]
    fn reaches_by_hand() {
        let corner = StateChange {
            coord: ChunkCoord(IVec3::ZERO),
            bricks: 1, // brick (0, 0, 0): voxels 0..4 on each axis
        };
        assert!(corner.reaches(IVec3::ZERO, 1));
        assert!(corner.reaches(IVec3::NEG_X, 1));
        assert!(corner.reaches(IVec3::new(-1, -1, -1), 1));
        assert!(!corner.reaches(IVec3::X, 1));
        assert!(!corner.reaches(IVec3::X, 12));
        assert!(corner.reaches(IVec3::X, 13)); // voxel 3 to chunk 1's voxel 16: 13 steps
        assert!(!corner.reaches(IVec3::new(-2, 0, 0), 16));
        assert!(corner.reaches(IVec3::new(-2, 0, 0), 17));
        let inner = StateChange {
            coord: ChunkCoord(IVec3::ZERO),
            bricks: 1 << (1 + 4 + 16), // brick (1, 1, 1): voxels 4..8
        };
        let faces = IVec3::AXES.into_iter().flat_map(|axis| [axis, -axis]);
        for offset in faces {
            assert!(!inner.reaches(offset, 4), "{offset}");
            assert!(
                inner.reaches(offset, 5) == (offset.min_element() < 0),
                "{offset}"
            );
        }
    }

    /// `reaches` agrees with the distance from every voxel of the bricks to the neighbour
    /// chunk, for every brick, offset and margin up to two chunks.
    #[test]
    fn reaches_agrees_with_voxel_distances() {
        let edge = CHUNK_EDGE;
        for brick in 0..64 {
            let change = StateChange {
                coord: ChunkCoord(IVec3::ZERO),
                bricks: 1 << brick,
            };
            let voxels: Vec<IVec3> = (0..edge * edge * edge)
                .map(|i| IVec3::new(i % edge, i / edge % edge, i / (edge * edge)))
                .filter(|&l| brick_of(local_index(l)) == brick)
                .collect();
            for offset in (0..125).map(|i| IVec3::new(i % 5, i / 5 % 5, i / 25) - 2) {
                for margin in 0..=2 * edge + 1 {
                    // Per axis, the steps from a voxel to the nearest voxel of the chunk.
                    let steps = |l: i32, d: i32| {
                        let (lo, hi) = (d * edge, d * edge + edge - 1);
                        (lo - l).max(l - hi).max(0)
                    };
                    let expected = voxels
                        .iter()
                        .any(|l| (0..3).all(|a| steps(l[a], offset[a]) <= margin));
                    assert_eq!(
                        change.reaches(offset, margin),
                        expected,
                        "brick {brick}, offset {offset}, margin {margin}"
                    );
                }
            }
        }
    }
}
