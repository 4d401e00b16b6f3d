//! The full bricks around a scan as one dense bit grid, made once per scan for the growth of
//! its free boxes (`super::free_box`) and the walks' runs of full bricks (`super::brick_run`).
//!
//! Why: a box grows a layer of bricks at a time and asks, brick by brick, whether each is full
//! of saturated free voxels; through the chunks that is a chunk lookup and two dependent loads
//! per brick, some 1,500 bricks a scan. Copied once into a bit grid (a few chunks' sets, about
//! a microsecond), each question is one load.

use glam::IVec3;
use uavex_components::map::{BRICK_EDGE, CHUNK_EDGE, ChunkCoord, ChunkGrid};

/// Bricks per chunk edge.
const CHUNK_BRICKS_EDGE: i32 = CHUNK_EDGE / BRICK_EDGE;

/// Which bricks of a box of whole chunks are full of saturated free voxels, one bit per brick
/// (x fastest). Kept from one scan to the next so that gathering allocates nothing.
#[derive(Debug, Clone, Default)]
pub struct FullBricks {
    /// Brick coordinate of bit 0 (the first brick of a chunk).
    lo: IVec3,
    /// Bricks per axis (whole chunks).
    dims: IVec3,
    words: Vec<u64>,
}

impl FullBricks {
    /// Takes the bricks of the chunks that meet the key box `lo..=hi`, where
    /// `full_bricks(flat)` is the set of full bricks of the chunk with flat index `flat` in
    /// `grid` (see [`uavex_components::map::BrickSaturation::full_bricks`]; chunks outside the
    /// grid have none).
    pub fn gather(
        &mut self,
        grid: ChunkGrid,
        lo: IVec3,
        hi: IVec3,
        mut full_bricks: impl FnMut(usize) -> u64,
    ) {
        let (chunk_lo, chunk_hi) = (ChunkCoord::of_key(lo).0, ChunkCoord::of_key(hi).0);
        let chunks = (chunk_hi - chunk_lo + IVec3::ONE).max(IVec3::ZERO);
        let dims = chunks * CHUNK_BRICKS_EDGE;
        let bits = dims.as_uvec3().element_product() as usize;
        self.lo = chunk_lo * CHUNK_BRICKS_EDGE;
        self.dims = dims;
        self.words.clear();
        self.words.resize(bits.div_ceil(64), 0);
        for cz in 0..chunks.z {
            for cy in 0..chunks.y {
                for cx in 0..chunks.x {
                    let coord = ChunkCoord(chunk_lo + IVec3::new(cx, cy, cz));
                    let Some(flat) = grid.flat(coord) else {
                        continue;
                    };
                    let full = full_bricks(flat);
                    if full == 0 {
                        continue;
                    }
                    // Each row of 4 bricks of the chunk is a nibble, at a multiple of 4 bits
                    // in the grid (rows are whole chunks long): it never straddles two words.
                    for row in 0..CHUNK_BRICKS_EDGE * CHUNK_BRICKS_EDGE {
                        let nibble = full >> (4 * row) & 0xF;
                        let (y, z) = (
                            cy * CHUNK_BRICKS_EDGE + row % CHUNK_BRICKS_EDGE,
                            cz * CHUNK_BRICKS_EDGE + row / CHUNK_BRICKS_EDGE,
                        );
                        let bit = (cx * CHUNK_BRICKS_EDGE + dims.x * (y + dims.y * z)) as usize;
                        self.words[bit / 64] |= nibble << (bit % 64);
                    }
                }
            }
        }
    }

    /// The bit of `brick` (brick coordinates), if inside the grid.
    #[inline]
    pub fn bit_of(&self, brick: IVec3) -> Option<i64> {
        let r = brick - self.lo;
        if r.cmplt(IVec3::ZERO).any() || r.cmpge(self.dims).any() {
            return None;
        }
        Some(
            i64::from(r.x)
                + i64::from(self.dims.x)
                    * (i64::from(r.y) + i64::from(self.dims.y) * i64::from(r.z)),
        )
    }

    /// Bit steps for +1 brick along x, y, z.
    #[inline]
    pub fn strides(&self) -> [i64; 3] {
        [
            1,
            i64::from(self.dims.x),
            i64::from(self.dims.x) * i64::from(self.dims.y),
        ]
    }

    /// Whether bit `bit` (inside the grid) is set.
    #[inline(always)]
    pub fn bit(&self, bit: i64) -> bool {
        self.words[(bit as usize) / 64] >> (bit as u64 % 64) & 1 == 1
    }

    /// Whether `brick` (brick coordinates: key / [`BRICK_EDGE`]) is full; `false` outside the
    /// grid. (The tests' reference for [`Self::all_full`].)
    #[cfg(test)]
    pub fn is_full(&self, brick: IVec3) -> bool {
        let r = brick - self.lo;
        if r.cmplt(IVec3::ZERO).any() || r.cmpge(self.dims).any() {
            return false;
        }
        let bit = (r.x + self.dims.x * (r.y + self.dims.y * r.z)) as usize;
        self.words[bit / 64] >> (bit % 64) & 1 == 1
    }

    /// Whether every brick of `lo..=hi` (brick coordinates) is full: a row of bricks along x
    /// is a run of bits, tested a word at a time. `false` if any lies outside the grid; `true`
    /// for an empty box.
    pub fn all_full(&self, lo: IVec3, hi: IVec3) -> bool {
        if lo.cmpgt(hi).any() {
            return true;
        }
        let (r0, r1) = (lo - self.lo, hi - self.lo);
        if r0.cmplt(IVec3::ZERO).any() || r1.cmpge(self.dims).any() {
            return false;
        }
        let run = (r1.x - r0.x) as usize;
        (r0.z..=r1.z).all(|z| {
            (r0.y..=r1.y).all(|y| {
                let first = (r0.x + self.dims.x * (y + self.dims.y * z)) as usize;
                self.all_set(first, first + run)
            })
        })
    }

    /// Whether bits `first..=last` are all set.
    #[inline]
    fn all_set(&self, first: usize, last: usize) -> bool {
        (first / 64..=last / 64).all(|word| {
            let from = if word == first / 64 { first % 64 } else { 0 };
            let to = if word == last / 64 { last % 64 } else { 63 };
            let mask = (u64::MAX >> (63 - to)) & (u64::MAX << from);
            self.words[word] & mask == mask
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// The chunks -1..=1 on x and y, 0..=1 on z, each brick full with probability `p`.
    fn grid_and_bricks(rng: &mut ChaCha8Rng, p: f64) -> (ChunkGrid, Vec<u64>) {
        let grid = ChunkGrid {
            min: IVec3::new(-1, -1, 0),
            dims: IVec3::new(3, 3, 2),
        };
        let full = (0..grid.len())
            .map(|_| (0..64).fold(0u64, |set, b| set | u64::from(rng.random_bool(p)) << b))
            .collect();
        (grid, full)
    }

    /// Whether brick `brick` is full in the chunks' own sets.
    fn full_in_chunks(grid: &ChunkGrid, full: &[u64], brick: IVec3) -> bool {
        let coord = ChunkCoord(brick.div_euclid(IVec3::splat(CHUNK_BRICKS_EDGE)));
        let local = brick.rem_euclid(IVec3::splat(CHUNK_BRICKS_EDGE));
        grid.flat(coord)
            .is_some_and(|flat| full[flat] >> (local.x + 4 * local.y + 16 * local.z) & 1 == 1)
    }

    #[test]
    fn the_grid_holds_the_full_bricks_of_every_chunk_the_key_box_meets() {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let mut bricks = FullBricks::default();
        for round in 0..2 {
            let (grid, full) = grid_and_bricks(&mut rng, 0.5);
            // Keys -5..=40 x -16..=3 x 0..=17: chunks -1..=2, -1..=0, 0..=1, and past the
            // grid's x range none (chunk 2 has no bricks). The second round reuses the grid
            // of the first: nothing of it may remain.
            let (lo, hi) = (IVec3::new(-5, -16, 0), IVec3::new(40, 3, 17));
            bricks.gather(grid, lo, hi, |flat| full[flat]);
            assert_eq!(bricks.dims, IVec3::new(16, 8, 8));
            let mut set = 0;
            // One brick beyond the grid on every side too: never full.
            for z in -1..9 {
                for y in -5..5 {
                    for x in -5..13 {
                        let brick = IVec3::new(x, y, z);
                        let expected = full_in_chunks(&grid, &full, brick)
                            && (0..8).contains(&z)
                            && (-4..4).contains(&y);
                        assert_eq!(bricks.is_full(brick), expected, "round {round}, {brick}");
                        set += usize::from(expected);
                    }
                }
            }
            assert!(
                set > 300,
                "only {set} full bricks: the test would show little"
            );
        }
    }

    /// A box of bricks is all full exactly when each of its bricks is, whatever the words its
    /// rows straddle (rows of 12 bits here); a box reaching past the grid is not.
    #[test]
    fn a_box_is_full_when_every_brick_of_it_is() {
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        // Mostly full, so that many boxes are full too.
        let (grid, full) = grid_and_bricks(&mut rng, 0.9);
        let mut bricks = FullBricks::default();
        // Chunks -1..=1 on x: rows of 12 bricks, across word boundaries.
        bricks.gather(
            grid,
            IVec3::new(-16, -16, 0),
            IVec3::new(31, 15, 31),
            |flat| full[flat],
        );
        assert_eq!(bricks.dims, IVec3::new(12, 8, 8));
        let (mut full_boxes, mut open_boxes) = (0, 0);
        for _ in 0..50_000 {
            let lo = IVec3::new(
                rng.random_range(-5..12),
                rng.random_range(-5..4),
                rng.random_range(-1..8),
            );
            let hi = lo + IVec3::from_array([0; 3].map(|_| rng.random_range(0..5)));
            let expected = (lo.z..=hi.z).all(|z| {
                (lo.y..=hi.y).all(|y| (lo.x..=hi.x).all(|x| bricks.is_full(IVec3::new(x, y, z))))
            });
            assert_eq!(bricks.all_full(lo, hi), expected, "{lo}..={hi}");
            if expected {
                full_boxes += 1;
            } else {
                open_boxes += 1;
            }
        }
        assert!(
            full_boxes > 1000 && open_boxes > 1000,
            "{full_boxes} full, {open_boxes} not"
        );
        // An empty box holds no brick that is not full.
        assert!(bricks.all_full(IVec3::new(3, 0, 0), IVec3::new(2, 0, 0)));

        // Exhaustively, one brick not full in a full grid (rows of 12 bits, some across two
        // words): every row through it is not full, the rest of the row on either side is.
        let dims = IVec3::new(12, 8, 8);
        let mut one_open = FullBricks {
            lo: IVec3::ZERO,
            dims,
            words: vec![u64::MAX; 12],
        };
        for bit in 0..(dims.element_product() as usize) {
            one_open.words[bit / 64] &= !(1 << (bit % 64));
            let brick = IVec3::new(bit as i32 % 12, bit as i32 / 12 % 8, bit as i32 / 96);
            let row = |from: i32, to: i32| (brick.with_x(from), brick.with_x(to));
            let (lo, hi) = row(0, 11);
            assert!(!one_open.all_full(lo, hi), "{brick}");
            let (lo, hi) = row(0, brick.x - 1);
            assert!(one_open.all_full(lo, hi), "left of {brick}");
            let (lo, hi) = row(brick.x + 1, 11);
            assert!(one_open.all_full(lo, hi), "right of {brick}");
            one_open.words[bit / 64] = u64::MAX;
        }
    }
}
