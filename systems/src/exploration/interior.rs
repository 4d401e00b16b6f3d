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

use crate::frontier::detect::NEIGHBOURS;
use crate::mapping::OccupancyMap;
use glam::IVec3;
use std::collections::VecDeque;
use uavex_components::map::VoxelState;

/// Sets of voxels, asked for membership only (never iterated in an order that matters).
type VoxelSet = std::collections::HashSet<IVec3, foldhash::fast::RandomState>;

/// Largest unknown region (voxels) taken for the inside of an obstacle: a round trunk of 0.7 m
/// radius over 3 m at 0.1 m.
pub const INTERIOR_MAX_VOXELS: usize = 5_000;
/// Least share of an inside's faces toward known voxels that are occupied.
pub const INTERIOR_MIN_OCCUPIED_SHARE: f64 = 0.4;
/// Most unknown voxels one reached goal floods, all regions together (the floods run in the
/// Plan stage; a region too large to be an inside costs [`INTERIOR_MAX_VOXELS`]).
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
    let config = map.config();
    let mut seen = VoxelSet::default();
    seen.insert(seed);
    let mut voxels = vec![seed];
    let mut queue = VecDeque::from([seed]);
    let mut free_boundary = VoxelSet::default();
    let (mut occupied_faces, mut free_faces) = (0usize, 0usize);
    let mut enclosed = true;
    'flood: while let Some(voxel) = queue.pop_front() {
        for d in NEIGHBOURS {
            let next = voxel + d;
            if !config.contains_key(next) {
                continue;
            }
            match map.state(next) {
                VoxelState::Unknown => {
                    if seen.insert(next) {
                        if voxels.len() == INTERIOR_MAX_VOXELS {
                            enclosed = false;
                            break 'flood;
                        }
                        voxels.push(next);
                        queue.push_back(next);
                    }
                }
                VoxelState::Occupied => occupied_faces += 1,
                VoxelState::Free => {
                    free_faces += 1;
                    free_boundary.insert(next);
                }
            }
        }
    }
    let faces = occupied_faces + free_faces;
    let interior = enclosed
        && faces > 0
        && occupied_faces as f64 >= INTERIOR_MIN_OCCUPIED_SHARE * faces as f64;
    let mut free_boundary: Vec<IVec3> = free_boundary.into_iter().collect();
    free_boundary.sort_by_key(|k| (k.z, k.y, k.x));
    UnknownRegion {
        voxels,
        free_boundary,
        interior,
    }
}

/// The free voxels that border the insides of obstacles found behind the frontier voxels
/// `left` (those a reached goal did not clear) and border nothing else unknown: frontier
/// voxels only because of those insides, for the caller to ignore. Sorted.
///
/// Each unknown region is flooded once, and only from an unknown voxel with an occupied face
/// neighbour (an inside is bounded mostly by occupied voxels; the frontier at the edge of the
/// explored space, beside no surface, starts no flood), until [`INTERIOR_FLOOD_BUDGET`]
/// voxels have been flooded.
pub fn around_interiors(map: &impl OccupancyMap, left: &[IVec3]) -> Vec<IVec3> {
    let config = map.config();
    let beside_a_surface = |voxel: IVec3| {
        NEIGHBOURS.iter().any(|&d| {
            let n = voxel + d;
            config.contains_key(n) && map.state(n) == VoxelState::Occupied
        })
    };
    let mut flooded = VoxelSet::default();
    let mut interiors = VoxelSet::default();
    let mut around = Vec::new();
    for &key in left {
        for d in NEIGHBOURS {
            let seed = key + d;
            if flooded.len() >= INTERIOR_FLOOD_BUDGET {
                break;
            }
            if !config.contains_key(seed)
                || flooded.contains(&seed)
                || map.state(seed) != VoxelState::Unknown
                || !beside_a_surface(seed)
            {
                continue;
            }
            let region = unknown_region(map, seed);
            flooded.extend(region.voxels.iter().copied());
            if region.interior {
                interiors.extend(region.voxels);
                around.extend(region.free_boundary);
            }
        }
    }
    around.sort_by_key(|k| (k.z, k.y, k.x));
    around.dedup();
    around.retain(|&free| {
        NEIGHBOURS.iter().all(|&d| {
            let n = free + d;
            !config.contains_key(n) || interiors.contains(&n) || map.state(n) != VoxelState::Unknown
        })
    });
    around
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frontier::tests::{config, set};
    use crate::mapping::ChunkStore;

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
}
