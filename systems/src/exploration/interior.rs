//! Frontier around the inside of an obstacle, which no flight can clear.
//!
//! A frontier voxel is free with an unknown face neighbour (eaae.md step 1). Round obstacles
//! leave such voxels around their insides: a voxel that a trunk's surface cuts at a slant is
//! crossed by more rays than end in it, so the map calls it free, while the voxel behind it,
//! wholly inside the trunk, is never entered (every ray toward it ends at the surface first).
//! Passes along a trunk make more of them (grazing rays clear the voxels the surface only
//! touches, and the next layer in becomes the unknown neighbour) faster than the rule of two
//! reached goals (`super::execute`) retires them. In a 16 x 16 m forest of round trunks, 13 of
//! 24 missions flew from one such sliver to the next until their batteries were empty, with
//! 99.98-100 % of the reachable volume explored (one had explored 98.1 % of its box by 250 s,
//! and gained 0.14 % in the 350 s after).
//!
//! What gives the inside of an obstacle away, in the map alone: the unknown voxels behind such
//! a frontier voxel form a small region that the map encloses (every face neighbour known, or
//! outside the map), and the region's faces toward known voxels are mostly occupied, its
//! surface seen face-on. A pocket of air the camera has not looked into yet (behind a trunk,
//! seen around) is enclosed too, but bounded by free voxels. Measured on that forest: at
//! 300 s every region behind the frontier left was enclosed, 30 to 1,700 voxels, and 49 to
//! 89 % occupied on its faces (every one inside a trunk by the ground truth), but for two
//! pockets of air of 31 and 43 voxels with no occupied face; at 60 s the enclosed pockets of
//! air (up to 4,300 voxels) had 0 to 35 % occupied faces. Regions larger than
//! [`INTERIOR_MAX_VOXELS`] are never taken for insides (and their flood stops there).
//!
//! Where to look: when a goal is reached, behind the goal's frontier voxels left and behind
//! every other frontier voxel within the sensor's range of the UAV ([`frontier_near`]), the
//! space its camera has just seen. Searched behind the goal's voxels alone, each sliver drew
//! the UAV to it once before it was ignored: over 72 missions in that forest (seeds 13-36, three
//! strategies), the last 0.13 % of the box took 85-166 s on average of missions of 318-400 s,
//! and one ran to its 600 s limit.

use crate::frontier::detect::NEIGHBOURS;
use crate::mapping::{NearbyStates, OccupancyMap};
use glam::{IVec3, Vec3};
use std::cell::Cell;
use std::collections::{HashMap, VecDeque};
use uavex_components::frontier::{FrontierSet, VoxelMask};
use uavex_components::map::{ChunkCoord, VoxelState, local_index, local_key};

/// Largest unknown region (voxels) taken for the inside of an obstacle: a round trunk of 0.7 m
/// radius over 3 m at 0.1 m.
pub const INTERIOR_MAX_VOXELS: usize = 5_000;
/// Least share of an inside's faces toward known voxels that are occupied.
pub const INTERIOR_MIN_OCCUPIED_SHARE: f64 = 0.4;
/// Most unknown voxels one search floods, all regions together (a search runs in the Plan
/// stage when a goal is reached; a region too large to be an inside costs
/// [`INTERIOR_MAX_VOXELS`]).
pub const INTERIOR_FLOOD_BUDGET: usize = 4 * INTERIOR_MAX_VOXELS;

/// The face-connected region of unknown voxels holding `seed`, as far as it was flooded.
#[derive(Debug, Clone, PartialEq)]
pub struct UnknownRegion {
    /// Its voxels (all of them unless the flood stopped at [`INTERIOR_MAX_VOXELS`]).
    pub voxels: Vec<IVec3>,
    /// The known free voxels that bound it (the frontier voxels it makes), sorted.
    pub free_boundary: Vec<IVec3>,
    /// Whether it is the inside of an obstacle (module doc).
    pub interior: bool,
}

/// Floods the unknown region of `map` holding `seed` (an unknown voxel inside the map), up to
/// [`INTERIOR_MAX_VOXELS`] voxels, and judges whether it is the inside of an obstacle: fully
/// flooded, and at least [`INTERIOR_MIN_OCCUPIED_SHARE`] of its faces toward known voxels
/// occupied. Faces toward outside the map count for neither side.
pub fn unknown_region(map: &impl OccupancyMap, seed: IVec3) -> UnknownRegion {
    Floods::new(map).flood(seed)
}

/// The free voxels that border the insides of obstacles found behind the frontier voxels
/// `frontier` and border nothing else unknown: frontier voxels only because of those insides,
/// for the caller to ignore. Sorted.
///
/// Each unknown region is flooded once, and only from an unknown voxel with an occupied face
/// neighbour (an inside is bounded mostly by occupied voxels; the frontier at the edge of the
/// explored space, beside no surface, starts no flood), in the order of `frontier`, until
/// [`INTERIOR_FLOOD_BUDGET`] voxels have been flooded.
pub fn around_interiors(map: &impl OccupancyMap, frontier: &[IVec3]) -> Vec<IVec3> {
    let mut floods = Floods::new(map);
    let mut interiors = KeyBits::default();
    let mut around = Vec::new();
    let mut flooded = 0;
    'frontier: for &key in frontier {
        for d in NEIGHBOURS {
            if flooded >= INTERIOR_FLOOD_BUDGET {
                break 'frontier;
            }
            let seed = key + d;
            if floods.states.state(seed) != Some(VoxelState::Unknown)
                || floods.earlier.contains(seed)
                || !floods.beside_a_surface(seed)
            {
                continue;
            }
            let region = floods.flood(seed);
            flooded += region.voxels.len();
            for &voxel in &region.voxels {
                floods.earlier.insert(voxel);
            }
            if region.interior {
                for &voxel in &region.voxels {
                    interiors.insert(voxel);
                }
                around.extend(region.free_boundary);
            }
        }
    }
    around.sort_by_key(|k| (k.z, k.y, k.x));
    around.dedup();
    around.retain(|&free| {
        NEIGHBOURS
            .iter()
            .all(|&d| match floods.states.state(free + d) {
                Some(VoxelState::Unknown) => interiors.contains(free + d),
                _ => true,
            })
    });
    around
}

/// The frontier voxels within `radius_m` of `position` (voxel centres), the chunks nearest to
/// it first (in a chunk, in key order): where a UAV that has just reached a goal has looked.
pub fn frontier_near(
    frontier: &FrontierSet,
    resolution: f32,
    position: Vec3,
    radius_m: f32,
) -> Vec<IVec3> {
    let chunk_m = resolution * uavex_components::map::CHUNK_EDGE as f32;
    let mut chunks: Vec<(f32, ChunkCoord, &VoxelMask)> = frontier
        .chunks()
        .map(|(coord, mask)| {
            let lo = coord.0.as_vec3() * chunk_m;
            let gap = position.clamp(lo, lo + Vec3::splat(chunk_m)) - position;
            (gap.length(), coord, mask)
        })
        .filter(|&(gap, ..)| gap <= radius_m)
        .collect();
    // Stable: chunks at equal distances stay in the set's (grid) order.
    chunks.sort_by(|a, b| a.0.total_cmp(&b.0));
    chunks
        .into_iter()
        .flat_map(|(_, coord, mask)| mask.iter().map(move |i| local_key(coord, i)))
        .filter(|key| ((key.as_vec3() + 0.5) * resolution).distance(position) <= radius_m)
        .collect()
}

/// The floods of one search: the voxel states, read chunk by chunk, and the voxels the search
/// flooded so far.
struct Floods<'m, M> {
    states: NearbyStates<'m, M>,
    earlier: KeyBits,
}

impl<'m, M: OccupancyMap> Floods<'m, M> {
    fn new(map: &'m M) -> Self {
        Self {
            states: NearbyStates::new(map),
            earlier: KeyBits::default(),
        }
    }

    /// Whether `voxel` has an occupied face neighbour.
    fn beside_a_surface(&mut self, voxel: IVec3) -> bool {
        NEIGHBOURS
            .iter()
            .any(|&d| self.states.state(voxel + d) == Some(VoxelState::Occupied))
    }

    /// [`unknown_region`], breadth first. A flood that meets a voxel an earlier flood of the
    /// search reached is in that flood's region, which was too large to be an inside (else it
    /// would hold this seed, which the search does not flood again): it stops there.
    fn flood(&mut self, seed: IVec3) -> UnknownRegion {
        let mut seen = KeyBits::default();
        seen.insert(seed);
        let mut voxels = vec![seed];
        let mut queue = VecDeque::from([seed]);
        let mut free_boundary = Vec::new();
        let (mut occupied_faces, mut free_faces) = (0usize, 0usize);
        let mut enclosed = true;
        'flood: while let Some(voxel) = queue.pop_front() {
            for d in NEIGHBOURS {
                let next = voxel + d;
                match self.states.state(next) {
                    None => {}
                    Some(VoxelState::Unknown) => {
                        if self.earlier.contains(next) {
                            enclosed = false;
                            break 'flood;
                        }
                        if seen.insert(next) {
                            if voxels.len() == INTERIOR_MAX_VOXELS {
                                enclosed = false;
                                break 'flood;
                            }
                            voxels.push(next);
                            queue.push_back(next);
                        }
                    }
                    Some(VoxelState::Occupied) => occupied_faces += 1,
                    Some(VoxelState::Free) => {
                        free_faces += 1;
                        free_boundary.push(next);
                    }
                }
            }
        }
        let faces = occupied_faces + free_faces;
        let interior = enclosed
            && faces > 0
            && occupied_faces as f64 >= INTERIOR_MIN_OCCUPIED_SHARE * faces as f64;
        free_boundary.sort_by_key(|k| (k.z, k.y, k.x));
        free_boundary.dedup();
        UnknownRegion {
            voxels,
            free_boundary,
            interior,
        }
    }
}

/// A set of voxel keys, one bit per voxel of the chunks it touches: a flood tests and sets
/// several per voxel, and a bit in the chunk of the last key is several times cheaper than a
/// hashed key.
#[derive(Default)]
struct KeyBits {
    slots: HashMap<ChunkCoord, usize, foldhash::fast::RandomState>,
    masks: Vec<VoxelMask>,
    /// The chunk of the last key asked for, and its mask's slot.
    last: Cell<Option<(ChunkCoord, usize)>>,
}

impl KeyBits {
    #[inline]
    fn slot(&self, coord: ChunkCoord) -> Option<usize> {
        match self.last.get() {
            Some((last, slot)) if last == coord => Some(slot),
            _ => {
                let slot = *self.slots.get(&coord)?;
                self.last.set(Some((coord, slot)));
                Some(slot)
            }
        }
    }

    #[inline]
    fn contains(&self, key: IVec3) -> bool {
        self.slot(ChunkCoord::of_key(key))
            .is_some_and(|slot| self.masks[slot].contains(local_index(key)))
    }

    /// Adds `key`: whether it was not in the set.
    #[inline]
    fn insert(&mut self, key: IVec3) -> bool {
        let coord = ChunkCoord::of_key(key);
        let slot = self.slot(coord).unwrap_or_else(|| {
            let slot = self.masks.len();
            self.masks.push(VoxelMask::EMPTY);
            self.slots.insert(coord, slot);
            self.last.set(Some((coord, slot)));
            slot
        });
        let (mask, index) = (&mut self.masks[slot], local_index(key));
        let new = !mask.contains(index);
        mask.insert(index);
        new
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frontier::tests::{config, set};
    use crate::mapping::ChunkStore;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;
    use std::collections::HashSet;

    fn fill(store: &mut ChunkStore, lo: IVec3, hi: IVec3, state: VoxelState) {
        for z in lo.z..=hi.z {
            for y in lo.y..=hi.y {
                for x in lo.x..=hi.x {
                    set(store, IVec3::new(x, y, z), state);
                }
            }
        }
    }

    /// A known box of free voxels around a column of 4 x 4 x 10 unknown voxels (keys 0..=3,
    /// 0..=3, 0..=9), whose face neighbours are occupied but for those `shell_free` picks; the
    /// rest of the map unknown.
    fn column(shell_free: impl Fn(IVec3) -> bool) -> (ChunkStore, Vec<IVec3>) {
        let mut store = ChunkStore::new(&config());
        fill(
            &mut store,
            IVec3::splat(-3),
            IVec3::new(6, 6, 12),
            VoxelState::Free,
        );
        let (lo, hi) = (IVec3::ZERO, IVec3::new(3, 3, 9));
        fill(&mut store, lo, hi, VoxelState::Unknown);
        let mut free_shell = Vec::new();
        for z in lo.z - 1..=hi.z + 1 {
            for y in lo.y - 1..=hi.y + 1 {
                for x in lo.x - 1..=hi.x + 1 {
                    let key = IVec3::new(x, y, z);
                    let outside =
                        key.cmplt(lo).bitmask().count_ones() + key.cmpgt(hi).bitmask().count_ones();
                    if outside != 1 {
                        continue; // inside the column, or an edge or corner of its shell
                    }
                    if shell_free(key) {
                        free_shell.push(key);
                    } else {
                        set(&mut store, key, VoxelState::Occupied);
                    }
                }
            }
        }
        free_shell.sort_by_key(|k| (k.z, k.y, k.x));
        (store, free_shell)
    }

    /// A third of the shell free, as a round trunk's slanted surface leaves it.
    fn trunk_shell(key: IVec3) -> bool {
        (key.x + key.y + key.z).rem_euclid(3) == 0
    }

    #[test]
    fn the_inside_of_a_trunk_is_an_interior_and_a_pocket_of_air_is_not() {
        let (trunk, free_shell) = column(trunk_shell);
        let region = unknown_region(&trunk, IVec3::new(1, 2, 5));
        assert_eq!(region.voxels.len(), 160);
        assert!(region.interior, "two thirds of its faces are occupied");
        assert_eq!(region.free_boundary, free_shell);

        // The same column bounded by free voxels only: air the camera has not looked into.
        let (pocket, _) = column(|_| true);
        let region = unknown_region(&pocket, IVec3::new(1, 2, 5));
        assert_eq!(region.voxels.len(), 160);
        assert!(!region.interior);

        // Occupied on under 40 % of its faces: not an inside either.
        let (mostly_free, _) = column(|k| (k.x + k.y + k.z).rem_euclid(5) != 0);
        assert!(!unknown_region(&mostly_free, IVec3::new(1, 2, 5)).interior);
    }

    #[test]
    fn the_unknown_beyond_the_known_box_is_never_an_interior() {
        let (store, _) = column(trunk_shell);
        let region = unknown_region(&store, IVec3::new(-10, 0, 0));
        assert!(!region.interior);
        assert_eq!(region.voxels.len(), INTERIOR_MAX_VOXELS);
    }

    /// The free voxels around the inside are returned, but not one that also borders other
    /// unknown voxels (here a lone unknown voxel in the free box, a pocket of air).
    #[test]
    fn around_interiors_spares_a_voxel_that_borders_other_unknown() {
        let (mut store, free_shell) = column(trunk_shell);
        // A free voxel under the column's bottom; the voxel below it is free, in the box.
        let shared = free_shell[0];
        assert_eq!(shared.z, -1);
        set(&mut store, shared - IVec3::Z, VoxelState::Unknown);
        let mut expected = free_shell.clone();
        expected.retain(|&k| k != shared);
        // Floods start only from unknown voxels beside an occupied one: asked from the whole
        // free shell, some are.
        assert_eq!(around_interiors(&store, &free_shell), expected);
        // Asked from a voxel that borders no inside: nothing.
        assert!(around_interiors(&store, &[IVec3::new(6, 6, 12)]).is_empty());
    }

    /// A flood that runs into the region of an earlier flood of the search, which stopped at
    /// [`INTERIOR_MAX_VOXELS`], stops at once and finds no inside: the region is the same.
    #[test]
    fn a_flood_into_an_earlier_floods_open_region_stops_at_once() {
        let (store, _) = column(trunk_shell);
        let mut floods = Floods::new(&store);
        let first = floods.flood(IVec3::new(-10, 0, 0));
        assert_eq!(first.voxels.len(), INTERIOR_MAX_VOXELS);
        assert!(!first.interior);
        for &voxel in &first.voxels {
            floods.earlier.insert(voxel);
        }
        // Another seed of the same open unknown beyond the known box, one the first flood did
        // not reach (it went breadth first from a voxel 20 away, and stopped nearer).
        let seed = IVec3::new(-10, 0, 20);
        assert!(!floods.earlier.contains(seed));
        let second = floods.flood(seed);
        assert!(
            second.voxels.len() < INTERIOR_MAX_VOXELS / 10,
            "{}",
            second.voxels.len()
        );
        assert!(!second.interior);
        // Alone, that seed's flood runs to the cap.
        assert_eq!(
            unknown_region(&store, seed).voxels.len(),
            INTERIOR_MAX_VOXELS
        );
        // The inside of the column is still found by the same search.
        let inside = floods.flood(IVec3::new(1, 2, 5));
        assert!(inside.interior);
        assert_eq!(inside.voxels.len(), 160);
    }

    fn random_key(rng: &mut ChaCha8Rng, range: std::ops::Range<i32>) -> IVec3 {
        IVec3::from_array(std::array::from_fn(|_| rng.random_range(range.clone())))
    }

    #[test]
    fn key_bits_hold_what_a_hash_set_holds() {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let mut bits = KeyBits::default();
        let mut reference = HashSet::new();
        for _ in 0..20_000 {
            // Keys across chunk borders on both sides of zero, many of them repeated.
            let key = random_key(&mut rng, -40..40);
            if rng.random_bool(0.5) {
                assert_eq!(bits.insert(key), reference.insert(key), "{key}");
            } else {
                assert_eq!(bits.contains(key), reference.contains(&key), "{key}");
            }
        }
    }

    /// Voxel states read chunk by chunk are the map's, and `None` outside it.
    #[test]
    fn nearby_states_read_what_the_map_holds() {
        let mut store = ChunkStore::new(&config());
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let states = [VoxelState::Unknown, VoxelState::Free, VoxelState::Occupied];
        // Keys of the map (-32..=29 on each axis) and a few outside it.
        let keys = |rng: &mut ChaCha8Rng| random_key(rng, -36..34);
        for _ in 0..5_000 {
            let key = keys(&mut rng);
            if store.config().contains_key(key) {
                set(&mut store, key, states[rng.random_range(0..3)]);
            }
        }
        let mut nearby = NearbyStates::new(&store);
        let mut walk = IVec3::ZERO;
        for i in 0..20_000 {
            // Now a jump, now a step: both the kept chunk and a new one are read.
            walk = if i % 7 == 0 {
                keys(&mut rng)
            } else {
                walk + NEIGHBOURS[rng.random_range(0..6)]
            };
            let expected = store.config().contains_key(walk).then(|| store.state(walk));
            assert_eq!(nearby.state(walk), expected, "{walk}");
        }
    }

    #[test]
    fn frontier_near_keeps_the_voxels_in_range_nearest_chunks_first() {
        let mut frontier = FrontierSet::default();
        let keys = [
            IVec3::new(-20, 0, 0), // centre at x = -1.95 m: out of range
            IVec3::new(1, 1, 1),
            IVec3::new(20, 0, 0), // 2.05 m: out of range
            IVec3::new(5, 0, 0),
            IVec3::new(-2, 0, 0),
            IVec3::new(-15, 0, 0), // 1.45 m, its chunk 0.05 m away: out of range
        ];
        for key in keys {
            let coord = ChunkCoord::of_key(key);
            let mut mask = frontier.chunk(coord).cloned().unwrap_or_default();
            mask.insert(local_index(key));
            frontier.replace_chunk(coord, &mask);
        }
        let near = frontier_near(&frontier, 0.1, Vec3::splat(0.05), 1.0);
        // The chunk holding the position first (its voxels in key order), then the one beside.
        assert_eq!(
            near,
            [
                IVec3::new(5, 0, 0),
                IVec3::new(1, 1, 1),
                IVec3::new(-2, 0, 0)
            ]
        );
        assert!(frontier_near(&frontier, 0.1, Vec3::splat(0.05), 0.0).is_empty());
    }
}
