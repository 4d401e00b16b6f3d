//! Frontier detection on hand-made grids (a [`ChunkStore`], no World), and incremental update
//! against the per-voxel definition.

use super::*;
use crate::mapping::tests::{integrate_random_scan, integrate_rays};
use crate::mapping::{ChunkAccess, ChunkStore, OccupancyMap};
use glam::{DVec3, IVec3, Vec3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use uavex_components::frontier::FrontierSet;
use uavex_components::map::{
    ChunkCoord, MapConfig, MapSettings, ScanCounter, UNKNOWN_LOG_ODDS, VoxelState,
};

mod cluster_tests;
mod filter_tests;
mod system_tests;

/// Keys -32..=29 on each axis at 0.1 m (chunks -2..=1): the -faces of the map are chunk faces,
/// the +faces lie inside chunk 1 (keys 16..=31), so both kinds of map edge are exercised.
pub(crate) fn config() -> MapConfig {
    MapConfig::new(&MapSettings {
        bounds_min: DVec3::splat(-3.2),
        bounds_max: DVec3::splat(2.95),
        ..MapSettings::default()
    })
    .unwrap()
}

/// Writes a voxel's state directly (a hand-made grid); returns its chunk.
pub(crate) fn set(store: &mut ChunkStore, key: IVec3, state: VoxelState) -> ChunkCoord {
    let coord = ChunkCoord::of_key(key);
    let (flat, local) = store.config().address_of(key).expect("key in map");
    let (chunk, _) = store.chunk_mut(flat, coord);
    chunk.voxels_mut()[local].log_odds = match state {
        VoxelState::Unknown => UNKNOWN_LOG_ODDS,
        VoxelState::Free => -405,
        VoxelState::Occupied => 847,
    };
    coord
}

/// Every frontier voxel by the per-voxel definition, sorted by (x, y, z).
fn reference(map: &impl OccupancyMap) -> Vec<IVec3> {
    let (lo, hi) = (map.config().key_min(), map.config().key_max());
    let mut out = Vec::new();
    for x in lo.x..=hi.x {
        for y in lo.y..=hi.y {
            for z in lo.z..=hi.z {
                let key = IVec3::new(x, y, z);
                if is_frontier(map, key) {
                    out.push(key);
                }
            }
        }
    }
    out
}

fn sorted(set: &FrontierSet) -> Vec<IVec3> {
    let mut keys: Vec<IVec3> = set.iter().collect();
    keys.sort_unstable_by_key(|k| k.to_array());
    keys
}

fn all_chunks(map: &impl OccupancyMap) -> Vec<ChunkCoord> {
    let grid = map.config().chunk_grid();
    (0..grid.len()).map(|f| grid.coord(f)).collect()
}

#[test]
fn free_voxel_next_to_unknown_is_frontier_and_enclosed_one_is_not() {
    let mut store = ChunkStore::new(&config());
    // A 3x3x3 block of free voxels in unknown space: all but the centre touch unknown.
    let mut changed = Vec::new();
    for x in 0..3 {
        for y in 0..3 {
            for z in 0..3 {
                changed.push(set(&mut store, IVec3::new(x, y, z), VoxelState::Free));
            }
        }
    }
    let mut set_ = FrontierSet::default();
    update_frontier_set(&mut set_, &store, &changed);
    assert_eq!(set_.len(), 26);
    assert!(!set_.contains(IVec3::ONE));
    assert!(set_.contains(IVec3::ZERO));
    assert!(!is_frontier(&store, IVec3::ONE));
    // The centre's neighbours are free or occupied: still not frontier. An occupied voxel is
    // never frontier, even next to unknown.
    set(&mut store, IVec3::new(1, 1, 0), VoxelState::Occupied);
    let g = set_.generation();
    update_frontier_set(&mut set_, &store, &[ChunkCoord(IVec3::ZERO)]);
    assert_eq!(set_.len(), 25);
    assert!(!set_.contains(IVec3::new(1, 1, 0)));
    assert!(!set_.contains(IVec3::ONE));
    assert_eq!(set_.generation(), g + 1);
    // Unknown voxels are never frontier either.
    assert!(!is_frontier(&store, IVec3::new(5, 5, 5)));
    assert_eq!(sorted(&set_), reference(&store));
}

#[test]
fn neighbours_outside_the_map_do_not_count_as_unknown() {
    let mut store = ChunkStore::new(&config());
    let mut changed = Vec::new();
    // The corner (29, 29, 29) of the map (+faces inside chunk 1) and (-32, -32, -32) (-faces on
    // chunk faces, whose outer neighbour chunk is outside the grid), each with its three
    // in-map neighbours known: not frontier, though half their neighbours are outside.
    for (corner, step) in [(IVec3::splat(29), -1), (IVec3::splat(-32), 1)] {
        changed.push(set(&mut store, corner, VoxelState::Free));
        for axis in [IVec3::X, IVec3::Y, IVec3::Z] {
            changed.push(set(&mut store, corner + axis * step, VoxelState::Occupied));
        }
    }
    let mut fs = FrontierSet::default();
    update_frontier_set(&mut fs, &store, &changed);
    assert!(!is_frontier(&store, IVec3::splat(29)));
    assert!(!is_frontier(&store, IVec3::splat(-32)));
    assert!(fs.is_empty());
    // Unknown inside the map does count: one in-map neighbour of the top corner turns unknown.
    let c = set(&mut store, IVec3::new(28, 29, 29), VoxelState::Unknown);
    update_frontier_set(&mut fs, &store, &[c]);
    assert_eq!(fs.iter().collect::<Vec<_>>(), vec![IVec3::splat(29)]);
}

#[test]
fn a_change_across_a_chunk_face_updates_the_neighbour_chunk() {
    // For each axis and both sides: voxel `a` in one chunk, its neighbour `b` across the chunk
    // face in the next. `a` and all its neighbours known except `b`: `a` is frontier. Then `b`
    // turns free and only b's chunk is reported changed: `a` must stop being frontier (its
    // chunk is re-examined as a neighbour) and `b` becomes frontier (its far side is unknown).
    for (a, d) in [
        (IVec3::new(15, 3, 4), IVec3::X),
        (IVec3::new(3, 15, 4), IVec3::Y),
        (IVec3::new(3, 4, 15), IVec3::Z),
        (IVec3::new(0, 3, 4), IVec3::NEG_X),
        (IVec3::new(3, 0, 4), IVec3::NEG_Y),
        (IVec3::new(3, 4, 0), IVec3::NEG_Z),
    ] {
        let mut store = ChunkStore::new(&config());
        let b = a + d;
        assert_ne!(ChunkCoord::of_key(a), ChunkCoord::of_key(b));
        let mut changed = vec![set(&mut store, a, VoxelState::Free)];
        for n in detect::NEIGHBOURS {
            if n != d {
                changed.push(set(&mut store, a + n, VoxelState::Occupied));
            }
        }
        let mut fs = FrontierSet::default();
        update_frontier_set(&mut fs, &store, &changed);
        assert_eq!(fs.iter().collect::<Vec<_>>(), vec![a], "{d}");
        let cb = set(&mut store, b, VoxelState::Free);
        update_frontier_set(&mut fs, &store, &[cb]);
        assert_eq!(fs.iter().collect::<Vec<_>>(), vec![b], "{d}");
    }
}

#[test]
fn chunk_rows_agree_with_the_definition_on_random_grids() {
    // Random states everywhere except two chunks never created, so every face kind (missing
    // neighbour chunk, map edge mid-chunk, map edge on a chunk face) is met.
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let mut store = ChunkStore::new(&config());
    let (lo, hi) = (store.config().key_min(), store.config().key_max());
    let skipped = [ChunkCoord(IVec3::ZERO), ChunkCoord(IVec3::new(-1, 0, 1))];
    for x in lo.x..=hi.x {
        for y in lo.y..=hi.y {
            for z in lo.z..=hi.z {
                let key = IVec3::new(x, y, z);
                if skipped.contains(&ChunkCoord::of_key(key)) {
                    continue;
                }
                let state = match rng.random_range(0..10) {
                    0..5 => VoxelState::Unknown,
                    5..9 => VoxelState::Free,
                    _ => VoxelState::Occupied,
                };
                set(&mut store, key, state);
            }
        }
    }
    let mut fs = FrontierSet::default();
    update_frontier_set(&mut fs, &store, &all_chunks(&store));
    let expected = reference(&store);
    assert!(expected.len() > 50_000, "{}", expected.len());
    assert_eq!(sorted(&fs), expected);
    assert_eq!(fs.len(), expected.len());
}

/// A scan that writes only one chunk still ends a frontier across that chunk's face: the
/// neighbour whose face the changed brick touches is re-examined, though not written.
#[test]
fn a_scan_that_writes_one_chunk_updates_the_frontier_across_its_face() {
    let mut store = ChunkStore::new(&config());
    let mut counter = ScanCounter::default();
    // Chunk 0 (keys 0..=15): voxel (15, 8, 8) and its neighbours in chunk 0 free, so that its
    // one unknown neighbour is (16, 8, 8), in chunk 1.
    // Chunk 1 exists already (a voxel far from its face is known), so that the scan below
    // reports where in it states changed.
    let edge = IVec3::new(15, 8, 8);
    let known = [
        edge,
        edge - IVec3::X,
        edge + IVec3::Y,
        edge - IVec3::Y,
        edge + IVec3::Z,
    ];
    for key in known
        .into_iter()
        .chain([edge - IVec3::Z, IVec3::new(28, 8, 8)])
    {
        let coord = set(&mut store, key, VoxelState::Free);
        store.mark_written(store.config().chunk_grid().flat(coord).unwrap());
    }
    let mut incremental = FrontierSet::default();
    let changes = store.take_state_changes();
    assert_eq!(changes.len(), 2);
    update_frontier_set(&mut incremental, &store, &changes);
    assert!(incremental.contains(edge));
    // A ray from inside chunk 1 hits (16, 8, 8): only chunk 1 is written.
    let centre = |x: f32| Vec3::new(x, 0.85, 0.85);
    integrate_rays(
        &mut store,
        &mut counter,
        centre(2.45),
        &[(centre(1.65), true)],
    );
    let changes = store.take_state_changes();
    assert_eq!(changes.len(), 1);
    assert_eq!(changes[0].coord, ChunkCoord(IVec3::new(1, 0, 0)));
    assert_ne!(changes[0].bricks, u64::MAX);
    update_frontier_set(&mut incremental, &store, &changes);
    assert!(!incremental.contains(edge));
    assert_eq!(sorted(&incremental), reference(&store));
}

#[test]
fn incremental_equals_from_scratch_after_random_scans() {
    let mut store = ChunkStore::new(&config());
    let mut counter = ScanCounter::default();
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let mut incremental = FrontierSet::default();
    let mut neighbours_skipped = false;
    // Few rays per scan: a changed chunk's neighbours are often unchanged themselves.
    for scan in 0..40 {
        integrate_random_scan(&mut store, &mut counter, &mut rng, 2.5, 6);
        // Where states changed, as the engine reports it (`StateChanges`): face neighbours
        // are re-examined only where a changed brick touches them.
        let changes = store.take_state_changes();
        neighbours_skipped |= changes.iter().any(|c| !c.reaches(IVec3::X, 1));
        update_frontier_set(&mut incremental, &store, &changes);
        if scan % 4 == 3 {
            let mut scratch = FrontierSet::default();
            update_frontier_set(&mut scratch, &store, &all_chunks(&store));
            let expected = reference(&store);
            assert!(!expected.is_empty());
            assert_eq!(sorted(&incremental), expected, "scan {scan}");
            assert_eq!(
                incremental.iter().collect::<Vec<_>>(),
                scratch.iter().collect::<Vec<_>>()
            );
        }
    }
    assert!(neighbours_skipped);
}
