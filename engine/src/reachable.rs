//! The reachable volume: the part of the map box an exploring UAV can possibly observe, the
//! denominator of "explored to >= 95 % of the reachable volume" (exploration issue).
//!
//! The exploration rate of common.md §5 divides by the whole map box, but part of a box can
//! never be seen: the inside of a closed room, the inside of solid obstacles. Here "reachable"
//! is **the connected free space the start lies in**: ground-truth free voxels
//! ([`WorldGeometry::voxel_key_occupied`]) joined to the start voxel by 6-connected steps through
//! ground-truth free voxels, inside the map box. A closed room's inside is therefore not
//! reachable, while every free voxel of the open space is, however narrow the gap that leads to
//! it: a camera sees through gaps a UAV cannot fly through, so no clearance radius is applied.
//! Occupied voxels are not counted either (they are surfaces, not volume to explore).
//!
//! The ground truth is evaluated in bulk: a voxel whose cube lies more than one voxel away from
//! every obstacle's bounding box is free without asking parry (its query would find no candidate
//! in the hierarchy anyway), so exact queries run only near obstacles, z-layer by z-layer in
//! parallel. The flood fill then walks a bitset of the box.

use glam::{IVec3, Vec3};
use rayon::prelude::*;
use uavex_components::map::{CHUNK_VOXELS, MapConfig, UNKNOWN_LOG_ODDS, local_key};
use uavex_components::world::WorldGeometry;
use uavex_systems::mapping::OccupancyMap;

/// Largest box the flood fill accepts (2^32 voxels: two bitsets of 512 MiB each). The map itself
/// allows up to 2^36 voxels because it stores only touched chunks; a flood over the whole box
/// cannot be sparse.
pub const MAX_FLOOD_VOXELS: u64 = 1 << 32;

/// Why the reachable volume cannot be computed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ReachableError {
    #[error("the start ({x}, {y}, {z}) lies outside the map box", x = .0.x, y = .0.y, z = .0.z)]
    StartOutsideMap(Vec3),
    #[error(
        "the start ({x}, {y}, {z}) lies in a voxel occupied by an obstacle",
        x = .0.x, y = .0.y, z = .0.z
    )]
    StartOccupied(Vec3),
    #[error("map box of {0} voxels is too large to flood (limit {MAX_FLOOD_VOXELS})")]
    TooLarge(u64),
}

/// A set of voxels of the map box as bits, one x-row per whole number of 64-bit words so that
/// z-layers can be filled independently.
#[derive(Debug, Clone, PartialEq, Eq)]
struct BoxBits {
    key_min: IVec3,
    /// Voxels along each axis.
    dims: IVec3,
    /// Words per x-row.
    row_words: usize,
    words: Vec<u64>,
}

impl BoxBits {
    fn empty(key_min: IVec3, dims: IVec3) -> Self {
        let row_words = (dims.x as usize).div_ceil(64);
        let len = row_words * dims.y as usize * dims.z as usize;
        Self {
            key_min,
            dims,
            row_words,
            words: vec![0; len],
        }
    }

    fn layer_words(&self) -> usize {
        self.row_words * self.dims.y as usize
    }

    /// Word index and bit of box-relative voxel `r` (must lie in the box).
    #[inline]
    fn slot(&self, r: IVec3) -> (usize, u64) {
        let row = r.y as usize + self.dims.y as usize * r.z as usize;
        let x = r.x as usize;
        (row * self.row_words + x / 64, 1 << (x % 64))
    }

    /// Box-relative coordinates of `key`, `None` outside the box.
    #[inline]
    fn relative(&self, key: IVec3) -> Option<IVec3> {
        let r = key - self.key_min;
        (r.cmpge(IVec3::ZERO).all() && r.cmplt(self.dims).all()).then_some(r)
    }

    #[inline]
    fn get(&self, r: IVec3) -> bool {
        let (word, bit) = self.slot(r);
        self.words[word] & bit != 0
    }

    /// Sets the bit of `r`; whether it was clear before.
    #[inline]
    fn insert(&mut self, r: IVec3) -> bool {
        let (word, bit) = self.slot(r);
        let was_clear = self.words[word] & bit == 0;
        self.words[word] |= bit;
        was_clear
    }
}

/// The voxels of the map box reachable from the start (see the module documentation).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ReachableVolume {
    bits: BoxBits,
    len: u64,
}

impl ReachableVolume {
    /// Floods the ground-truth free space of `config`'s box from the voxel holding `start`.
    /// Refuses a start outside the box or in an occupied voxel (the engine already refuses
    /// starts within the UAV's radius of an obstacle, so a scenario that runs never hits these).
    pub fn flood(
        config: &MapConfig,
        geometry: &WorldGeometry,
        start: Vec3,
    ) -> Result<Self, ReachableError> {
        if config.box_voxels() > MAX_FLOOD_VOXELS {
            return Err(ReachableError::TooLarge(config.box_voxels()));
        }
        let start_key = config
            .key_of(start)
            .ok_or(ReachableError::StartOutsideMap(start))?;
        let blocked = occupied_voxels(config, geometry);
        let start = blocked
            .relative(start_key)
            .filter(|&r| !blocked.get(r))
            .ok_or(ReachableError::StartOccupied(start))?;
        Ok(flood_fill(blocked, start))
    }

    /// Number of reachable voxels.
    pub fn len(&self) -> u64 {
        self.len
    }

    /// Never true for a volume built by [`Self::flood`] (the start voxel is reachable).
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Whether voxel `key` is reachable (false outside the map box).
    pub fn contains(&self, key: IVec3) -> bool {
        self.bits.relative(key).is_some_and(|r| self.bits.get(r))
    }

    /// Percentage (0..=100) of reachable voxels that are known in `map` (free or occupied): a
    /// reachable voxel is ground-truth free, so a map that marks it occupied has still observed
    /// it. Walks the map's chunks, so the cost follows the explored part, not the box.
    pub fn explored_pct(&self, map: &impl OccupancyMap) -> f64 {
        if self.len == 0 {
            return 0.0;
        }
        let known: u64 = map
            .chunks()
            .map(|(coord, chunk)| {
                (0..CHUNK_VOXELS)
                    .filter(|&i| {
                        chunk.log_odds_milli(i) != UNKNOWN_LOG_ODDS
                            && self.contains(local_key(coord, i))
                    })
                    .count() as u64
            })
            .sum();
        100.0 * known as f64 / self.len as f64
    }
}

/// Ground truth over the whole box as bits (set = occupied), with exact queries only for voxels
/// within one voxel of some obstacle's bounding box; every other voxel is free, since its
/// shrunk cube cannot overlap any bounding box in the world's hierarchy.
fn occupied_voxels(config: &MapConfig, geometry: &WorldGeometry) -> BoxBits {
    let (key_min, key_max) = (config.key_min(), config.key_max());
    let mut bits = BoxBits::empty(key_min, key_max - key_min + IVec3::ONE);
    let resolution = config.resolution();
    // Candidate key boxes, widened by one voxel against rounding of the bounds and keys.
    let candidates: Vec<(IVec3, IVec3)> = geometry
        .obstacles()
        .iter()
        .filter_map(|obstacle| {
            let aabb = obstacle.aabb();
            let lo = config.raw_key_of(aabb.mins) - IVec3::ONE;
            let hi = config.raw_key_of(aabb.maxs) + IVec3::ONE;
            let (lo, hi) = (lo.max(key_min), hi.min(key_max));
            lo.cmple(hi).all().then_some((lo, hi))
        })
        .collect();
    let res = resolution as f32;
    let layer_words = bits.layer_words();
    let row_words = bits.row_words;
    bits.words
        .par_chunks_mut(layer_words)
        .enumerate()
        .for_each(|(z, layer)| {
            let kz = key_min.z + z as i32;
            for &(lo, hi) in candidates
                .iter()
                .filter(|(lo, hi)| lo.z <= kz && kz <= hi.z)
            {
                for ky in lo.y..=hi.y {
                    let row = (ky - key_min.y) as usize * row_words;
                    for kx in lo.x..=hi.x {
                        let x = (kx - key_min.x) as usize;
                        let (word, bit) = (row + x / 64, 1u64 << (x % 64));
                        if layer[word] & bit == 0
                            && geometry.voxel_key_occupied(IVec3::new(kx, ky, kz), res)
                        {
                            layer[word] |= bit;
                        }
                    }
                }
            }
        });
    bits
}

/// 6-connected flood fill from `start` through the clear bits of `blocked`; the bits it sets
/// (and only those) form the reachable volume.
fn flood_fill(mut blocked: BoxBits, start: IVec3) -> ReachableVolume {
    const STEPS: [IVec3; 6] = [
        IVec3::X,
        IVec3::NEG_X,
        IVec3::Y,
        IVec3::NEG_Y,
        IVec3::Z,
        IVec3::NEG_Z,
    ];
    let mut reached = BoxBits::empty(blocked.key_min, blocked.dims);
    let dims = blocked.dims;
    blocked.insert(start);
    reached.insert(start);
    let mut len = 1u64;
    let mut stack = vec![start];
    while let Some(r) = stack.pop() {
        for step in STEPS {
            let n = r + step;
            if n.cmpge(IVec3::ZERO).all() && n.cmplt(dims).all() && blocked.insert(n) {
                reached.insert(n);
                len += 1;
                stack.push(n);
            }
        }
    }
    ReachableVolume { bits: reached, len }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::load;
    use crate::world::build_world;
    use glam::{DVec3, Quat};
    use parry3d::math::Pose;
    use parry3d::shape::SharedShape;
    use std::collections::HashSet;
    use std::path::Path;
    use uavex_components::map::{ChunkCoord, MapSettings, local_index};
    use uavex_components::sim::RunSeed;
    use uavex_components::world::Obstacle;
    use uavex_systems::mapping::{ChunkAccess, ChunkStore};

    const RES: f64 = 0.1;

    fn config(min: [f64; 3], max: [f64; 3]) -> MapConfig {
        MapConfig::new(&MapSettings {
            resolution: RES,
            bounds_min: DVec3::from_array(min),
            bounds_max: DVec3::from_array(max),
            ..MapSettings::default()
        })
        .unwrap()
    }

    /// A box covering the voxel keys `lo..=hi` exactly (faces on voxel boundaries).
    fn voxel_box(lo: [i32; 3], hi: [i32; 3]) -> Obstacle {
        let (lo, hi) = (
            IVec3::from_array(lo).as_vec3(),
            IVec3::from_array(hi).as_vec3(),
        );
        let (min, max) = (lo * RES as f32, (hi + 1.0) * RES as f32);
        let half = 0.5 * (max - min);
        Obstacle::new(
            "box",
            "test",
            Pose::from_translation(0.5 * (min + max)),
            SharedShape::cuboid(half.x, half.y, half.z),
        )
    }

    /// A 10 x 6 x 3 voxel box (x 0..1 m, y 0..0.6 m, z 0..0.3 m) holding two rooms joined by a
    /// door, and a closed room:
    /// - the closed room: a one-voxel shell over keys x 5..=9, y 0..=4, z 0..=2 (floor, roof and
    ///   four walls): 5 * 5 * 3 - 3 * 3 * 1 = 66 occupied voxels around 9 free ones inside;
    /// - a wall at x = 2 over y 0..=4 (15 voxels) splits the open space into a room x 0..=1 and
    ///   a room x 3..=4, joined through the door at y = 5 (open when `door` is true).
    fn rooms(door: bool) -> WorldGeometry {
        let shell = [
            voxel_box([5, 0, 0], [9, 4, 0]),
            voxel_box([5, 0, 2], [9, 4, 2]),
            voxel_box([5, 0, 1], [5, 4, 1]),
            voxel_box([9, 0, 1], [9, 4, 1]),
            voxel_box([6, 0, 1], [8, 0, 1]),
            voxel_box([6, 4, 1], [8, 4, 1]),
        ];
        let divider = voxel_box([2, 0, 0], [2, if door { 4 } else { 5 }, 2]);
        WorldGeometry::new(shell.into_iter().chain([divider]).collect()).unwrap()
    }

    fn rooms_config() -> MapConfig {
        config([0.0; 3], [1.0, 0.6, 0.3])
    }

    #[test]
    fn the_inside_of_a_closed_room_is_not_reachable() {
        let config = rooms_config();
        assert_eq!(config.box_voxels(), 180);
        let volume =
            ReachableVolume::flood(&config, &rooms(true), Vec3::new(0.05, 0.05, 0.15)).unwrap();
        // 180 voxels - 66 shell - 15 divider - 9 inside the closed room = 90: the room x 0..=1
        // (2 * 6 * 3 = 36), the door column (1 * 1 * 3 = 3), the room x 3..=4 (2 * 6 * 3 = 36)
        // and the strip y = 5 past the closed room (5 * 1 * 3 = 15).
        assert_eq!(volume.len(), 90);
        assert!(volume.contains(IVec3::new(0, 0, 0)));
        assert!(volume.contains(IVec3::new(2, 5, 1)), "the door");
        assert!(volume.contains(IVec3::new(9, 5, 2)), "past the closed room");
        assert!(
            !volume.contains(IVec3::new(7, 2, 1)),
            "inside the closed room"
        );
        assert!(!volume.contains(IVec3::new(2, 0, 0)), "the divider");
        assert!(!volume.contains(IVec3::new(5, 2, 1)), "the shell");
        assert!(!volume.contains(IVec3::new(-1, 0, 0)), "outside the box");
        assert!(!volume.contains(IVec3::new(0, 6, 0)), "outside the box");
    }

    #[test]
    fn a_closed_door_leaves_one_room() {
        let volume =
            ReachableVolume::flood(&rooms_config(), &rooms(false), Vec3::new(0.05, 0.55, 0.25))
                .unwrap();
        // Only the room x 0..=1: 2 * 6 * 3.
        assert_eq!(volume.len(), 36);
        assert!(!volume.contains(IVec3::new(3, 5, 0)));
    }

    #[test]
    fn from_inside_the_closed_room_only_its_inside_is_reachable() {
        let volume =
            ReachableVolume::flood(&rooms_config(), &rooms(true), Vec3::new(0.75, 0.25, 0.15))
                .unwrap();
        assert_eq!(volume.len(), 9);
        assert!(volume.contains(IVec3::new(6, 1, 1)) && volume.contains(IVec3::new(8, 3, 1)));
        assert!(!volume.contains(IVec3::new(0, 0, 0)));
    }

    #[test]
    fn bad_starts_are_refused() {
        let (map, world) = (rooms_config(), rooms(true));
        let outside = Vec3::new(0.05, 0.65, 0.15);
        assert_eq!(
            ReachableVolume::flood(&map, &world, outside),
            Err(ReachableError::StartOutsideMap(outside))
        );
        let in_wall = Vec3::new(0.25, 0.05, 0.15);
        assert_eq!(
            ReachableVolume::flood(&map, &world, in_wall),
            Err(ReachableError::StartOccupied(in_wall))
        );
        // A box of 2^33 voxels at 0.1 m is a valid map but too large to flood.
        let huge = config([0.0; 3], [204.8; 3]);
        assert_eq!(huge.box_voxels(), 1 << 33);
        assert_eq!(
            ReachableVolume::flood(&huge, &WorldGeometry::empty(), Vec3::splat(1.0)),
            Err(ReachableError::TooLarge(1 << 33))
        );
    }

    /// The bulk ground truth and bitset flood agree with a plain flood that asks
    /// `voxel_key_occupied` of every voxel, on a box at negative keys with yawed, round and
    /// off-grid obstacles and rows wider than one 64-bit word.
    #[test]
    fn bulk_flood_matches_a_per_voxel_flood() {
        let config = config([-4.03, -1.57, -0.21], [3.31, 1.12, 0.64]);
        let world = WorldGeometry::new(vec![
            Obstacle::new(
                "yawed wall",
                "test",
                Pose::from_parts(Vec3::new(-1.0, 0.0, 0.2), Quat::from_rotation_z(1.0)),
                SharedShape::cuboid(2.0, 0.07, 0.6),
            ),
            Obstacle::new(
                "ball",
                "test",
                Pose::from_translation(Vec3::new(1.7, 0.4, 0.2)),
                SharedShape::ball(0.45),
            ),
            Obstacle::new(
                "slab crossing the box edge",
                "test",
                Pose::from_translation(Vec3::new(3.2, -1.0, 0.0)),
                SharedShape::cuboid(0.5, 0.8, 0.13),
            ),
        ])
        .unwrap();
        let start = Vec3::new(-3.5, -1.2, 0.1);
        let volume = ReachableVolume::flood(&config, &world, start).unwrap();

        let res = RES as f32;
        let free = |k: IVec3| config.contains_key(k) && !world.voxel_key_occupied(k, res);
        let mut seen = HashSet::from([config.key_of(start).unwrap()]);
        let mut stack: Vec<IVec3> = seen.iter().copied().collect();
        while let Some(k) = stack.pop() {
            for step in [
                IVec3::X,
                IVec3::NEG_X,
                IVec3::Y,
                IVec3::NEG_Y,
                IVec3::Z,
                IVec3::NEG_Z,
            ] {
                let n = k + step;
                if free(n) && seen.insert(n) {
                    stack.push(n);
                }
            }
        }
        assert_eq!(volume.len(), seen.len() as u64);
        let (lo, hi) = (config.key_min(), config.key_max());
        for z in lo.z..=hi.z {
            for y in lo.y..=hi.y {
                for x in lo.x..=hi.x {
                    let k = IVec3::new(x, y, z);
                    assert_eq!(volume.contains(k), seen.contains(&k), "{k}");
                }
            }
        }
        // The wall cuts the box in two: neither side is all of the free space.
        let occupied = (lo.z..=hi.z)
            .flat_map(|z| (lo.y..=hi.y).flat_map(move |y| (lo.x..=hi.x).map(move |x| (x, y, z))))
            .filter(|&(x, y, z)| world.voxel_key_occupied(IVec3::new(x, y, z), res))
            .count() as u64;
        assert!(occupied > 0 && volume.len() < config.box_voxels() - occupied);
    }

    #[test]
    fn explored_pct_counts_known_reachable_voxels_only() {
        let config = rooms_config();
        let volume =
            ReachableVolume::flood(&config, &rooms(true), Vec3::new(0.05, 0.05, 0.15)).unwrap();
        let mut map = ChunkStore::new(&config);
        assert_eq!(volume.explored_pct(&map), 0.0);
        let mut set = |key: [i32; 3], log_odds: i16| {
            let key = IVec3::from_array(key);
            let coord = ChunkCoord::of_key(key);
            let flat = config.chunk_grid().flat(coord).unwrap();
            map.chunk_mut(flat, coord).0.voxels_mut()[local_index(key)].log_odds = log_odds;
        };
        // Nine reachable voxels known: eight free, one (wrongly) occupied, still observed.
        for x in 0..2 {
            for y in 0..4 {
                set([x, y, 0], -405);
            }
        }
        set([9, 5, 2], 847);
        // Known but not reachable: the shell, the divider, inside the closed room.
        set([5, 0, 0], 847);
        set([2, 3, 1], 847);
        set([7, 2, 1], -405);
        // 9 of 90.
        assert!((volume.explored_pct(&map) - 10.0).abs() < 1e-12);
    }

    /// The shipped scene `file`'s map and world, flooded from its first UAV's start.
    fn shipped_scene(file: &str) -> (MapConfig, ReachableVolume) {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenarios");
        let loaded = load(dir.join(file)).unwrap();
        let scenario = &loaded.scenario;
        let start = Vec3::from_array(scenario.uavs[0].start.position.map(|c| c as f32));
        let world =
            build_world(&scenario.world, RunSeed(1), &[start], &[], &loaded.base_dir).unwrap();
        let config = MapConfig::new(&MapSettings {
            resolution: scenario.map.resolution,
            bounds_min: DVec3::from_array(scenario.world.bounds.min),
            bounds_max: DVec3::from_array(scenario.world.bounds.max),
            p_min: scenario.map.p_min,
            p_max: scenario.map.p_max,
        })
        .unwrap();
        let volume = ReachableVolume::flood(&config, &world, start).unwrap();
        (config, volume)
    }

    /// The Pillars scene: the map box is 215 x 223 x 25 voxels = 1,198,625 (keys x -109..=105,
    /// y -110..=112, z 0..=24). Its outermost x and y voxel rows reach past the walls' inner
    /// faces (e.g. voxel x = 105 spans 10.5..10.6 m, the east wall starts at 10.5891 m), so the
    /// walls occupy the box's side shell: 25 * (215 * 223 - 213 * 221) = 21,800 voxels. Each
    /// 2 m pillar sits off the grid and covers 21 x 21 keys over all 25 layers: 3 * 11,025 =
    /// 33,075. Nothing else is closed off, so 1,198,625 - 21,800 - 33,075 = 1,143,750.
    const PILLARS_REACHABLE: u64 = 1_143_750;

    #[test]
    fn pillars_scene_reachable_volume() {
        let (config, volume) = shipped_scene("eaae_pillars.toml");
        assert_eq!(config.box_voxels(), 1_198_625);
        assert_eq!(volume.len(), PILLARS_REACHABLE);
        assert!(!volume.contains(IVec3::new(105, 0, 10)), "east wall");
        assert!(volume.contains(IVec3::new(104, 0, 10)));
        assert!(!volume.contains(IVec3::new(-4, -64, 0)), "pillar 1");
    }

    /// The closed-room scene is Pillars plus a room whose outer faces lie on voxel boundaries
    /// (x 4.5..7.5, y -7.5..-4.5, z 0..2.5): its 30 x 30 x 25 = 22,500 voxels (walls, roof and
    /// the 26 x 26 x 23 inside) all drop out of the reachable volume.
    #[test]
    fn closed_room_scene_excludes_the_room() {
        let (_, volume) = shipped_scene("eaae_closed_room.toml");
        assert_eq!(volume.len(), PILLARS_REACHABLE - 22_500);
        assert!(!volume.contains(IVec3::new(60, -60, 10)), "inside the room");
        assert!(
            volume.contains(IVec3::new(44, -60, 10)),
            "just west of the room"
        );
        assert!(
            volume.contains(IVec3::new(75, -76, 24)),
            "past its south-east corner"
        );
    }
}
