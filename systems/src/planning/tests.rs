//! Tests of the traversability grid and the path searches, on hand-made maps.

use super::*;
use crate::mapping::{ChunkAccess, ChunkStore};
use glam::{DVec3, IVec3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use uavex_components::map::{ChunkCoord, MapConfig, MapSettings, local_index};

/// Clamped free and occupied log-odds (common.md §1 defaults, milli units).
pub(super) const FREE: i16 = -1992;
pub(super) const OCCUPIED: i16 = 3476;

/// A map written voxel by voxel.
pub(super) struct TestMap {
    pub store: ChunkStore,
    pub config: MapConfig,
}

impl TestMap {
    pub fn new(min: DVec3, max: DVec3) -> Self {
        Self::with_resolution(min, max, 0.1)
    }

    pub fn with_resolution(min: DVec3, max: DVec3, resolution: f64) -> Self {
        let config = MapConfig::new(&MapSettings {
            resolution,
            bounds_min: min,
            bounds_max: max,
            ..MapSettings::default()
        })
        .unwrap();
        Self {
            store: ChunkStore::new(&config),
            config,
        }
    }

    pub fn set(&mut self, key: IVec3, log_odds: i16) {
        assert!(self.config.contains_key(key));
        let coord = ChunkCoord::of_key(key);
        let flat = self.config.chunk_grid().flat(coord).unwrap();
        self.store.chunk_mut(flat, coord).0.voxels_mut()[local_index(key)].log_odds = log_odds;
        self.store.mark_written(flat);
    }

    /// Sets every voxel of the key box `lo..=hi` (clipped to the map).
    pub fn fill(&mut self, lo: IVec3, hi: IVec3, log_odds: i16) {
        let (lo, hi) = (lo.max(self.config.key_min()), hi.min(self.config.key_max()));
        for z in lo.z..=hi.z {
            for y in lo.y..=hi.y {
                for x in lo.x..=hi.x {
                    self.set(IVec3::new(x, y, z), log_odds);
                }
            }
        }
    }

    pub fn fill_all(&mut self, log_odds: i16) {
        self.fill(self.config.key_min(), self.config.key_max(), log_odds);
    }

    /// A grid refreshed from the chunks whose states changed since the last call.
    pub fn update(&mut self, grid: &mut TraversableGrid) {
        for change in self.store.take_state_changes() {
            grid.mark_state_change(change);
        }
        grid.refresh(&self.store);
    }

    pub fn grid(&mut self, inflation_m: f64) -> TraversableGrid {
        let mut grid = TraversableGrid::new(&self.config, inflation_m);
        self.update(&mut grid);
        grid
    }
}

fn keys(config: &MapConfig, margin: i32) -> impl Iterator<Item = IVec3> {
    let (lo, hi) = (
        config.key_min() - IVec3::splat(margin),
        config.key_max() + IVec3::splat(margin),
    );
    (lo.z..=hi.z).flat_map(move |z| {
        (lo.y..=hi.y).flat_map(move |y| (lo.x..=hi.x).map(move |x| IVec3::new(x, y, z)))
    })
}

/// The rule, by brute force: known free, and no occupied or out-of-box voxel with
/// |d| <= radius (voxels).
fn expected_traversable(map: &TestMap, key: IVec3, radius_voxels: f64) -> bool {
    use crate::mapping::OccupancyMap;
    if map.store.log_odds_milli(key).is_none_or(|l| l >= 0) {
        return false;
    }
    let r = radius_voxels.floor() as i32;
    for dz in -r..=r {
        for dy in -r..=r {
            for dx in -r..=r {
                let d = IVec3::new(dx, dy, dz);
                if f64::from(d.length_squared()) > radius_voxels * radius_voxels {
                    continue;
                }
                let k = key + d;
                // Occupied or outside the box blocks; unknown does when an unknown
                // 6-neighbour (inside the box) backs it.
                let unknown =
                    |k: IVec3| map.config.contains_key(k) && map.store.log_odds_milli(k).is_none();
                let blocked = !map.config.contains_key(k)
                    || map.store.log_odds_milli(k).is_some_and(|l| l >= 0)
                    || (unknown(k)
                        && [
                            IVec3::X,
                            IVec3::NEG_X,
                            IVec3::Y,
                            IVec3::NEG_Y,
                            IVec3::Z,
                            IVec3::NEG_Z,
                        ]
                        .iter()
                        .any(|&n| unknown(k + n)));
                if blocked {
                    return false;
                }
            }
        }
    }
    true
}

#[test]
fn inflation_blocks_exactly_the_ball_and_the_box_border() {
    // 3.2 m cube, keys 0..=31, all free but voxel (16, 16, 16); radius 0.2 m = 2 voxels.
    let mut map = TestMap::new(DVec3::ZERO, DVec3::splat(3.2));
    map.fill_all(FREE);
    map.set(IVec3::splat(16), OCCUPIED);
    let grid = map.grid(0.2);
    assert_eq!(grid.inflation_m(), 0.2);
    let k = IVec3::new;
    // At the radius (d^2 = 4, 3, 2) blocked; just beyond (d^2 = 5, 9) free.
    for key in [
        k(18, 16, 16),
        k(17, 17, 17),
        k(17, 17, 16),
        k(16, 16, 16),
        k(14, 16, 16),
    ] {
        assert!(!grid.is_traversable(key), "{key}");
    }
    for key in [k(19, 16, 16), k(18, 17, 16), k(16, 13, 16), k(18, 17, 17)] {
        assert!(grid.is_traversable(key), "{key}");
    }
    // Out of box counts as occupied: key 1 is 2 voxels from key -1, key 2 is 3 away; at the
    // top, 29 is 3 voxels from 32, 30 only 2.
    assert!(!grid.is_traversable(k(1, 8, 8)));
    assert!(grid.is_traversable(k(2, 8, 8)));
    assert!(grid.is_traversable(k(8, 29, 8)));
    assert!(!grid.is_traversable(k(8, 8, 30)));
    assert!(!grid.is_traversable(k(-1, 8, 8)));
    // Every key, against the rule: the traversable set is the box 2..=29 without the ball.
    for key in keys(&map.config, 2) {
        let inside = key.cmpge(IVec3::splat(2)).all() && key.cmple(IVec3::splat(29)).all();
        let expected = inside && (key - IVec3::splat(16)).length_squared() > 4;
        assert_eq!(grid.is_traversable(key), expected, "{key}");
    }
    // Points: the voxel holding them; non-finite points never.
    assert!(grid.is_traversable_point(DVec3::new(1.95, 1.65, 1.65)));
    assert!(!grid.is_traversable_point(DVec3::new(1.85, 1.65, 1.65)));
    assert!(!grid.is_traversable_point(DVec3::new(f64::NAN, 1.0, 1.0)));
}

/// Face-on to a wall, every traversable voxel keeps the body's radius between its box and the
/// box of every wall voxel, whatever the resolution: the wall's face may lie anywhere in its
/// voxels, the UAV anywhere in its own. (With the margin fixed at 0.1 m this fails at 0.2 m,
/// where the voxel two off the wall is traversable 0.2 m from it, under the kingfisher's
/// 0.22 m, and at 0.4 m.)
#[test]
fn the_inflation_keeps_the_body_off_a_wall_at_any_resolution() {
    let body = uavex_components::airframe::Airframe::kingfisher().bounding_radius();
    for resolution in [0.05, 0.1, 0.15, 0.2, 0.3, 0.4] {
        let mut map = TestMap::with_resolution(DVec3::ZERO, DVec3::new(6.0, 2.0, 2.0), resolution);
        map.fill_all(FREE);
        let wall = map.config.key_max().x / 2;
        let (min, max) = (map.config.key_min(), map.config.key_max());
        map.fill(
            IVec3::new(wall, min.y, min.z),
            IVec3::new(wall, max.y, max.z),
            OCCUPIED,
        );
        let grid = map.grid(inflation_radius(body, 0.1, resolution));
        let middle = (min + max) / 2;
        let mut traversable = 0;
        for x in min.x..=max.x {
            let key = IVec3::new(x, middle.y, middle.z);
            if grid.is_traversable(key) {
                traversable += 1;
                let gap = f64::from((x - wall).abs() - 1) * resolution;
                assert!(
                    gap >= body - 1e-9,
                    "{resolution} m: voxel {key} is traversable {gap:.2} m from the wall"
                );
            }
        }
        assert!(traversable > 0, "{resolution} m: nothing traversable");
    }
}

#[test]
fn unknown_blocks_like_an_obstacle_unless_it_is_a_lone_hole() {
    let mut map = TestMap::new(DVec3::ZERO, DVec3::splat(1.6));
    map.fill_all(FREE);
    // A lone unknown voxel (a hole between rays): not traversable itself, blocks nothing.
    map.set(IVec3::splat(8), i16::MIN);
    let grid = map.grid(0.2);
    assert!(!grid.is_traversable(IVec3::splat(8)));
    assert!(grid.is_traversable(IVec3::new(9, 8, 8)));
    // Two unknown neighbours (an unseen surface): both block within 2 voxels; 3 away (and 3
    // from the box) is free.
    map.set(IVec3::new(8, 8, 9), i16::MIN);
    let grid = map.grid(0.2);
    assert!(!grid.is_traversable(IVec3::new(10, 8, 8)));
    assert!(!grid.is_traversable(IVec3::new(9, 9, 8)));
    assert!(!grid.is_traversable(IVec3::new(8, 8, 11)));
    assert!(grid.is_traversable(IVec3::new(11, 8, 8)));
    assert!(grid.is_traversable(IVec3::new(10, 10, 8)));
    assert!(grid.is_traversable(IVec3::new(8, 8, 12)));
    // A chunk never created holds nothing traversable.
    let empty = TestMap::new(DVec3::ZERO, DVec3::splat(1.6)).grid(0.2);
    assert!(keys(&map.config, 0).all(|k| !empty.is_traversable(k)));
}

#[test]
fn random_maps_follow_the_rule_and_incremental_refresh_equals_scratch() {
    // Negative keys and chunk borders: keys -11..=22 on x.
    let mut map = TestMap::new(DVec3::new(-1.05, -0.3, 0.0), DVec3::new(2.3, 1.7, 1.2));
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let mut incremental = TraversableGrid::new(&map.config, 0.27);
    let (lo, hi) = (map.config.key_min(), map.config.key_max());
    for round in 0..6 {
        // Free blobs, then occupied specks, then some voxels forgotten to unknown.
        for _ in 0..40 {
            let key = IVec3::new(
                rng.random_range(lo.x..=hi.x),
                rng.random_range(lo.y..=hi.y),
                rng.random_range(lo.z..=hi.z),
            );
            let value = match rng.random_range(0..10) {
                0..6 => FREE,
                6..9 => OCCUPIED,
                _ => i16::MIN,
            };
            let size = if value == FREE { 4 } else { 0 };
            map.fill(key, key + IVec3::splat(size), value);
        }
        map.update(&mut incremental);
        assert_eq!(incremental.dirty_chunks(), 0);
        let mut scratch = TraversableGrid::new(&map.config, 0.27);
        scratch.mark_all();
        scratch.refresh(&map.store);
        let mut traversable = 0;
        for key in keys(&map.config, 1) {
            let expected = expected_traversable(&map, key, 2.7);
            assert_eq!(
                incremental.is_traversable(key),
                expected,
                "round {round} {key}"
            );
            assert_eq!(scratch.is_traversable(key), expected, "round {round} {key}");
            traversable += usize::from(expected);
        }
        assert!(traversable > 0);
    }
}

/// A scan that writes only one chunk still blocks the voxels of the next chunk within the
/// inflation of what it found: that chunk is refreshed, though not written.
#[test]
fn a_scan_that_writes_one_chunk_blocks_across_its_face() {
    use crate::mapping::tests::integrate_rays;
    use glam::Vec3;
    use uavex_components::map::ScanCounter;
    // Chunks 0 and 1 along x, all known free but for a lone unknown voxel (which blocks
    // nothing) at (17, 8, 8), two voxels from chunk 0's face.
    let mut map = TestMap::new(DVec3::ZERO, DVec3::new(3.2, 1.6, 1.6));
    map.fill_all(FREE);
    let hole = IVec3::new(17, 8, 8);
    map.set(hole, i16::MIN);
    let mut incremental = TraversableGrid::new(&map.config, 0.27);
    map.update(&mut incremental);
    let near = IVec3::new(15, 8, 8);
    assert!(incremental.is_traversable(near));
    // A ray from inside chunk 1 hits the hole: occupied now, it blocks `near` (2 voxels away).
    let centre = |x: f32| Vec3::new(x, 0.85, 0.85);
    let mut counter = ScanCounter::default();
    integrate_rays(
        &mut map.store,
        &mut counter,
        centre(2.45),
        &[(centre(1.75), true)],
    );
    map.update(&mut incremental);
    assert!(!incremental.is_traversable(near));
    for key in keys(&map.config, 1) {
        assert_eq!(
            incremental.is_traversable(key),
            expected_traversable(&map, key, 2.7),
            "{key}"
        );
    }
}

#[test]
fn lattice_cells_are_open_when_all_eight_voxels_are() {
    let mut map = TestMap::new(DVec3::ZERO, DVec3::splat(1.6));
    map.fill_all(FREE);
    let mut grid = map.grid(0.0);
    let lattice = grid.lattice();
    let open = |grid: &TraversableGrid, c: IVec3| {
        let lattice = grid.lattice();
        lattice.is_open(lattice.index(c).unwrap())
    };
    assert!(lattice.is_available());
    assert!(open(&grid, IVec3::new(3, 3, 3)));
    map.set(IVec3::new(7, 6, 7), FREE + 1992); // l = 0: occupied
    map.update(&mut grid);
    assert!(!open(&grid, IVec3::new(3, 3, 3)));
    assert!(open(&grid, IVec3::new(4, 3, 3)));
    assert!(grid.is_traversable(IVec3::new(6, 6, 7)));
}

/// A 6.4 x 6.4 x 1.6 m room, all free, with a wall at x 3.0..3.2 m from y = 0 to 4.0 m.
pub(super) fn wall_room() -> TestMap {
    let mut map = TestMap::new(DVec3::ZERO, DVec3::new(6.4, 6.4, 1.6));
    map.fill_all(FREE);
    map.fill(IVec3::new(30, 0, 0), IVec3::new(31, 39, 15), OCCUPIED);
    map
}

#[test]
fn the_ecs_system_marks_changed_chunks_dirty() {
    use bevy_ecs::prelude::*;
    use uavex_components::map::VoxelChunk;
    let map = TestMap::new(DVec3::ZERO, DVec3::new(6.4, 6.4, 1.6));
    let mut world = World::new();
    world.insert_resource(Traversability(TraversableGrid::new(&map.config, 0.27)));
    world.spawn((VoxelChunk::new(), ChunkCoord(IVec3::new(1, 1, 0))));
    let mut schedule = Schedule::default();
    schedule.add_systems(track_traversability);
    schedule.run(&mut world);
    // Chunk (1, 1, 0) and its neighbours in a 4 x 4 x 1 chunk grid: 3 x 3 x 1.
    assert_eq!(world.resource::<Traversability>().0.dirty_chunks(), 9);
    // Nothing changed since: nothing more to mark; without the resource, nothing happens.
    world.resource_mut::<Traversability>().0.refresh(&map.store);
    schedule.run(&mut world);
    assert_eq!(world.resource::<Traversability>().0.dirty_chunks(), 0);
    world.remove_resource::<Traversability>();
    schedule.run(&mut world);
}

/// The assumption holds over what the map says: a voxel observed occupied inside the assumed
/// ball blocks nothing, one just outside it blocks its inflation as usual.
#[test]
fn an_assumed_free_voxel_counts_as_free_even_if_observed_occupied() {
    let mut map = TestMap::new(DVec3::ZERO, DVec3::splat(3.2));
    let centre = IVec3::splat(16);
    // Free everywhere, an occupied voxel inside the ball (1 from the centre) and one outside
    // it (7 from the centre, in the chunk before the centre's along -x: the halo's rows are
    // gathered from both chunks).
    map.fill_all(-2000);
    map.set(centre + IVec3::new(1, 0, 0), 3000);
    map.set(centre - IVec3::new(7, 0, 0), 3000);
    let mut grid = TraversableGrid::new(&map.config, 0.2);
    grid.assume_free_ball((centre.as_dvec3() + 0.5) * 0.1, 0.5);
    map.update(&mut grid);
    // 2-voxel inflation: the centre and its +x neighbour are clear (the occupied voxel inside
    // the ball is assumed free), -5 is blocked by the one at -7, -4 is not.
    for (offset, expected) in [
        (IVec3::ZERO, true),
        (IVec3::new(1, 0, 0), true),
        (IVec3::new(-4, 0, 0), true),
        (IVec3::new(-5, 0, 0), false),
    ] {
        assert_eq!(grid.is_traversable(centre + offset), expected, "{offset}");
    }
}

#[test]
fn a_ball_assumed_free_is_traversable_where_it_holds_the_whole_inflation() {
    // Nothing observed; a ball of 5 voxels assumed free around the centre of voxel 16, with a
    // 2-voxel inflation: voxel k is traversable when every voxel within 2 of it lies within
    // 5 of the centre. (3,0,0): farthest (5,0,0), yes; (4,0,0): no; (2,2,0): at most
    // |(3,3,0)| + ... = 4.47, yes; (3,1,0): (5,1,0) is 5.10 away, no.
    let map = TestMap::new(DVec3::ZERO, DVec3::splat(3.2));
    let mut grid = TraversableGrid::new(&map.config, 0.2);
    let centre = IVec3::splat(16);
    grid.assume_free_ball((centre.as_dvec3() + 0.5) * 0.1, 0.5);
    grid.refresh(&map.store);
    for (offset, expected) in [
        (IVec3::ZERO, true),
        (IVec3::new(3, 0, 0), true),
        (IVec3::new(0, -3, 0), true),
        (IVec3::new(4, 0, 0), false),
        (IVec3::new(2, 2, 0), true),
        (IVec3::new(3, 1, 0), false),
    ] {
        assert_eq!(grid.is_traversable(centre + offset), expected, "{offset}");
    }
}

#[test]
fn the_sight_memo_answers_as_the_grid_does_and_asks_each_question_once() {
    let mut map = wall_room();
    let grid = map.grid(0.0);
    let mut sight = SightMemo::new(&grid);
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let mut point = || {
        DVec3::new(
            rng.random_range(0.0..6.4),
            rng.random_range(0.0..6.4),
            rng.random_range(0.0..1.6),
        )
    };
    let pairs: Vec<(DVec3, DVec3)> = (0..300).map(|_| (point(), point())).collect();
    let (mut seen, mut blocked) = (0, 0);
    for round in 0..2 {
        for &(a, b) in &pairs {
            let expected = grid.line_of_sight(a, b);
            assert_eq!(
                sight.line_of_sight(a, b),
                expected,
                "round {round}: {a} -> {b}"
            );
            blocked += usize::from(!expected);
            seen += 1;
        }
        // The second round adds no question: every answer comes from memory.
        assert_eq!(sight.len(), pairs.len());
    }
    // Both answers occur (the wall at x = 3.0-3.2 m blocks about half the pairs).
    assert!(
        blocked > seen / 10 && blocked < seen * 9 / 10,
        "{blocked} of {seen}"
    );
}
