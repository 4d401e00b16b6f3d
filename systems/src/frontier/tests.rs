//! Frontier detection on hand-made grids (a [`ChunkStore`], no World), and incremental update
//! against the per-voxel definition.

use super::*;
use crate::mapping::{ChunkAccess, ChunkStore, OccupancyMap, ScanRays, integrate_scan};
use glam::{DVec3, IVec3, Vec3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use uavex_components::frontier::FrontierSet;
use uavex_components::map::{
    ChunkCoord, LogOddsIncrements, MapConfig, MapSettings, ScanCounter, StatSums, UNKNOWN_LOG_ODDS,
    VoxelState,
};

mod cluster_tests;
mod filter_tests;
mod system_tests;

/// Keys -32..=29 on each axis at 0.1 m (chunks -2..=1): the -faces of the map are chunk faces,
/// the +faces lie inside chunk 1 (keys 16..=31), so both kinds of map edge are exercised.
pub(super) fn config() -> MapConfig {
    MapConfig::new(&MapSettings {
        bounds_min: DVec3::splat(-3.2),
        bounds_max: DVec3::splat(2.95),
        ..MapSettings::default()
    })
    .unwrap()
}

/// Writes a voxel's state directly (a hand-made grid); returns its chunk.
pub(super) fn set(store: &mut ChunkStore, key: IVec3, state: VoxelState) -> ChunkCoord {
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

#[test]
fn incremental_equals_from_scratch_after_random_scans() {
    let config = config();
    let mut store = ChunkStore::new(&config);
    let mut totals = StatSums::default();
    let mut counter = ScanCounter::default();
    let inc = LogOddsIncrements {
        hit: 847,
        miss: -405,
    };
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let mut incremental = FrontierSet::default();
    for scan in 0..25 {
        let origin = Vec3::new(
            rng.random_range(-2.5..2.5),
            rng.random_range(-2.5..2.5),
            rng.random_range(-2.5..2.5),
        );
        let mut endpoints = Vec::new();
        let mut hit = Vec::new();
        for _ in 0..60 {
            let dir = Vec3::new(
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
            );
            endpoints.push(origin + dir.normalize_or(Vec3::X) * rng.random_range(0.2..4.0));
            hit.push(rng.random_bool(0.5));
        }
        let rays = ScanRays {
            origin,
            endpoints: &endpoints,
            hit: &hit,
        };
        integrate_scan(
            &config,
            counter.next_id(),
            rays,
            inc,
            &mut store,
            &mut totals,
        )
        .unwrap();
        let written = store.take_written();
        update_frontier_set(&mut incremental, &store, &written);
        if scan % 8 == 0 || scan == 24 {
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
}
