//! Which parts of a chunk are saturated free: per 4^3 brick, how many of its voxels sit at the
//! lower clamping bound, and the set of bricks where all do.
//!
//! A miss cannot change a voxel already at the lower clamping bound (common.md §1: clamping),
//! so a ray crossing a saturated brick, or a 2x2x2 block of them, or a whole chunk of them,
//! changes nothing there: the map update crosses such cubes in one move
//! (`uavex_systems::mapping::cube`). Most of what a camera sees in flight was seen a few
//! frames before: in a Pillars exploration three quarters of the saturated bricks a ray
//! enters lie in a saturated 8^3 block.

use super::chunk::CHUNK_VOXELS;

/// Edge of a brick in voxels: a chunk is tiled by 4 x 4 x 4 bricks of 4^3 voxels.
pub const BRICK_EDGE: i32 = 4;
/// Voxels in one brick.
pub const BRICK_VOXELS: u8 = 64;
/// Bricks in one chunk.
pub const CHUNK_BRICKS: usize = 64;

/// The brick of every local index, looked up rather than computed: the map update asks once per
/// voxel step, and one load costs less than the eight shifts and masks.
static BRICK_OF: [u8; CHUNK_VOXELS] = {
    let mut table = [0u8; CHUNK_VOXELS];
    let mut index = 0;
    while index < CHUNK_VOXELS {
        table[index] = (((index >> 2) & 0x3) | ((index >> 4) & 0xC) | ((index >> 6) & 0x30)) as u8;
        index += 1;
    }
    table
};

/// The brick (0..64, x fastest) holding the voxel with local index `index`
/// ([`super::local_index`]): bits 2-3 of each local coordinate.
#[inline(always)]
pub fn brick_of(index: usize) -> usize {
    usize::from(BRICK_OF[index % CHUNK_VOXELS])
}

/// The bricks of the 8^3 block (2 x 2 x 2 bricks) holding `brick`, as a set of brick bits.
#[inline(always)]
pub fn block_bricks(brick: usize) -> u64 {
    // Bricks (0,0,0), (1,0,0), (0,1,0), (1,1,0) and the same one layer up: bits 0, 1, 4, 5,
    // 16, 17, 20, 21; shifted to the block's first brick (the high bit of each coordinate).
    const FIRST_BLOCK: u64 = 0x0033_0033;
    FIRST_BLOCK << (brick & 0b10_1010)
}

/// Saturation counts of one chunk's bricks, and the set of full bricks (bit `b` of
/// [`Self::full_bricks`] set when all 64 voxels of brick `b` are saturated).
///
/// The counts are a lower bound of the true counts at all times (a write that does not keep
/// them forgets them with [`Self::forget`], and decrements saturate), so a brick reported full
/// is always truly saturated.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct BrickSaturation {
    counts: [u8; CHUNK_BRICKS],
    full: u64,
}

impl Default for BrickSaturation {
    fn default() -> Self {
        Self::NONE
    }
}

impl BrickSaturation {
    /// No voxel known to be saturated.
    pub const NONE: Self = Self {
        counts: [0; CHUNK_BRICKS],
        full: 0,
    };

    /// Counts for a chunk whose voxels with chunk-local coordinates outside `lo..=hi` (per
    /// axis; the range may reach past the chunk or be empty) lie outside the map: those count
    /// as saturated from the start.
    ///
    /// Why: the map update never updates or visits a voxel outside the map (every ray is
    /// clipped to the map's key box, and a cube is crossed only when the ray leaves it before
    /// its clipped end, so every voxel it passes is inside the map). Counted, they let the
    /// bricks, blocks and chunks on the map's border fill up like any other; uncounted, they
    /// could never be full, and every ray reaching a wall or the ceiling of the map walked its
    /// last brick voxel by voxel (in a 2.5 m high scene, the whole upper layer of chunks).
    pub fn outside(lo: [i32; 3], hi: [i32; 3]) -> Self {
        let inside = |axis: usize, brick: i32| {
            let first = brick * BRICK_EDGE;
            let last = first + BRICK_EDGE - 1;
            (hi[axis].min(last) - lo[axis].max(first) + 1).max(0)
        };
        let mut saturation = Self::NONE;
        for brick in 0..CHUNK_BRICKS {
            let [x, y, z] = [brick % 4, (brick / 4) % 4, brick / 16].map(|b| b as i32);
            let outside = i32::from(BRICK_VOXELS) - inside(0, x) * inside(1, y) * inside(2, z);
            saturation.counts[brick] = outside as u8;
            if outside == i32::from(BRICK_VOXELS) {
                saturation.full |= 1 << brick;
            }
        }
        saturation
    }

    /// A voxel of `brick` reached the lower bound.
    #[inline(always)]
    pub fn add(&mut self, brick: usize) {
        let count = &mut self.counts[brick % CHUNK_BRICKS];
        // A lower bound of at most 63 before this voxel: no overflow past the brick.
        debug_assert!(*count < BRICK_VOXELS);
        *count += 1;
        if *count == BRICK_VOXELS {
            self.full |= 1 << (brick % CHUNK_BRICKS);
        }
    }

    /// A voxel of `brick` left the lower bound.
    #[inline(always)]
    pub fn remove(&mut self, brick: usize) {
        let count = &mut self.counts[brick % CHUNK_BRICKS];
        *count = count.saturating_sub(1);
        self.full &= !(1 << (brick % CHUNK_BRICKS));
    }

    /// Forgets every count (still a lower bound, whatever was written).
    pub fn forget(&mut self) {
        *self = Self::NONE;
    }

    /// The saturated voxels counted in `brick`.
    pub fn count(&self, brick: usize) -> u8 {
        self.counts[brick % CHUNK_BRICKS]
    }

    /// The set of full bricks, one bit per brick.
    #[inline(always)]
    pub fn full_bricks(&self) -> u64 {
        self.full
    }

    /// Whether every voxel of `brick` is saturated.
    #[inline(always)]
    pub fn brick_full(&self, brick: usize) -> bool {
        self.full >> (brick % CHUNK_BRICKS) & 1 == 1
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::map::{CHUNK_EDGE, local_index};
    use glam::IVec3;

    #[test]
    fn bricks_tile_the_chunk_by_fours() {
        let mut voxels_per_brick = [0u8; CHUNK_BRICKS];
        for z in 0..CHUNK_EDGE {
            for y in 0..CHUNK_EDGE {
                for x in 0..CHUNK_EDGE {
                    let brick = brick_of(local_index(IVec3::new(x, y, z)));
                    assert_eq!(brick as i32, x / 4 + 4 * (y / 4) + 16 * (z / 4));
                    voxels_per_brick[brick] += 1;
                }
            }
        }
        assert!(voxels_per_brick.iter().all(|&n| n == BRICK_VOXELS));
    }

    #[test]
    fn a_block_is_the_two_by_two_by_two_bricks_sharing_the_high_coordinate_bits() {
        let brick = |x: usize, y: usize, z: usize| x + 4 * y + 16 * z;
        for b in 0..CHUNK_BRICKS {
            let (x, y, z) = (b % 4, (b / 4) % 4, b / 16);
            let expected = (0..CHUNK_BRICKS)
                .filter(|&o| {
                    let (ox, oy, oz) = (o % 4, (o / 4) % 4, o / 16);
                    (ox / 2, oy / 2, oz / 2) == (x / 2, y / 2, z / 2)
                })
                .fold(0u64, |set, o| set | 1 << o);
            assert_eq!(block_bricks(b), expected, "brick {b}");
            assert_eq!(block_bricks(b).count_ones(), 8);
            assert_ne!(block_bricks(b) & 1 << brick(x, y, z), 0);
        }
    }

    #[test]
    fn voxels_outside_the_map_count_as_saturated() {
        // In-map voxels: x 0..=9, y 3..=15, z 0..=16 (past the chunk: all of z).
        let saturation = BrickSaturation::outside([0, 3, 0], [9, 15, 16]);
        let brick = |x: usize, y: usize, z: usize| x + 4 * y + 16 * z;
        // Brick x 0..=3, y 0..=3: rows y = 0, 1, 2 are outside: 64 - 4 * 1 * 4.
        assert_eq!(saturation.count(brick(0, 0, 2)), 48);
        // Brick x 8..=11, y 4..=7: columns x = 10, 11 are outside: 64 - 2 * 4 * 4.
        assert_eq!(saturation.count(brick(2, 1, 0)), 32);
        // Brick x 12..=15 lies wholly outside: full from the start; inner bricks count none.
        assert_eq!(saturation.count(brick(3, 2, 1)), 64);
        assert!(saturation.brick_full(brick(3, 2, 1)));
        assert_eq!(saturation.count(brick(1, 2, 3)), 0);
        let full = (0..4).flat_map(|z| (0..4).map(move |y| brick(3, y, z)));
        assert_eq!(
            saturation.full_bricks(),
            full.fold(0, |set, b| set | 1 << b)
        );
        // A chunk wholly inside the map starts with nothing counted.
        assert_eq!(
            BrickSaturation::outside([-5, 0, 0], [20, 15, 99]),
            BrickSaturation::NONE
        );
    }

    #[test]
    fn a_brick_is_full_from_its_64th_saturated_voxel_until_one_leaves() {
        let mut saturation = BrickSaturation::NONE;
        for _ in 0..63 {
            saturation.add(9);
        }
        assert!(!saturation.brick_full(9));
        saturation.add(9);
        assert!(saturation.brick_full(9));
        assert_eq!(saturation.full_bricks(), 1 << 9);
        saturation.remove(9);
        assert!(!saturation.brick_full(9));
        assert_eq!(saturation.count(9), 63);
        saturation.forget();
        assert_eq!((saturation.count(9), saturation.full_bricks()), (0, 0));
        saturation.remove(9);
        assert_eq!(saturation.count(9), 0, "counts never go below zero");
    }
}
