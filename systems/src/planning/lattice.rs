//! The search lattice: cells of 2 x 2 x 2 voxels over the traversability grid.
//!
//! Why not search the 0.1 m voxels themselves: a Pillars-sized map (22 x 22 x 2.5 m) holds about
//! a million free voxels, and one Dijkstra over all of them with 26 neighbours costs some 100 ms,
//! far above the few milliseconds a decision may spend planning to every frontier cluster. Cells
//! of 2 voxels per edge have 8x fewer nodes; a cell is traversable when all 8 of its voxels are.
//! This costs at most one voxel (0.1 m) of extra clearance on each side, and any corridor of 3
//! traversable voxels (an opening 0.3 m wider than the UAV's inflated diameter) still holds a
//! line of aligned cells, so no passage a 0.1 m search would use and a 0.2 m one would not is
//! wider than that. (A stride of 3 voxels would lose 4-voxel corridors for one alignment in
//! three.)
//!
//! Moves are 26-connected. A move from cell `a` to `a + d` (d in {-1, 0, 1}^3) is allowed when
//! every cell of the box spanned by `a` and `a + d` is traversable (1, 3 or 7 cells besides `a`):
//! the straight segment between the two cell centres lies inside that box, so it only crosses
//! traversable voxels (no corner cutting).
//!
//! The lattice is stored densely with a border of one never-traversable cell on every side, so
//! that neighbour indices are plain offsets with no bounds checks.
//!
//! Each open cell also keeps the set of moves allowed from it (one bit per move), refreshed
//! around every cell whose flag changes: a search reads one word per cell it expands instead
//! of its 27 neighbours' flags and 26 box tests, which were a third of a Dijkstra's work.

use glam::{DVec3, IVec3};

/// Voxels per cell edge.
pub const CELL_VOXELS: i32 = 2;
/// Largest lattice (cells, border included) kept: 1 GiB of flags. Larger maps (over 2^33 voxels
/// in the box) get no lattice, and every search on them finds nothing.
pub const MAX_LATTICE_CELLS: u64 = 1 << 30;

/// Integer cost of an axis, face-diagonal and space-diagonal move: 1, sqrt 2 and sqrt 3 cells
/// in thousandths (rounded, an error below 2e-4). Small integer costs let the searches use a
/// bucket queue (Dial's algorithm) instead of a binary heap, and make equal costs exact.
pub const MOVE_COSTS: [u64; 3] = [1000, 1414, 1732];

/// Every move (bit `k` for move `k` of [`Lattice::moves`]): the allowed moves of a cell whose
/// 26 neighbours are all open.
pub const ALL_MOVES: u32 = (1 << 26) - 1;

/// One of the 26 moves: the cell offset, its index offset, the neighbours its box needs open
/// (target included) as a mask over [`Lattice::open_neighbours`], and its cost.
#[derive(Debug, Clone, Copy)]
pub struct Move {
    pub delta: IVec3,
    pub offset: isize,
    pub box_mask: u32,
    pub cost: u64,
}

/// Bit of the neighbour at `d` (in {-1, 0, 1}^3) in a neighbourhood mask.
const fn neighbour_bit(d: IVec3) -> u32 {
    1 << ((d.x + 1) + 3 * (d.y + 1) + 9 * (d.z + 1))
}

/// The dense, padded lattice of cell flags.
#[derive(Debug, Clone)]
pub struct Lattice {
    /// Cell coordinate of index 0 (one below the smallest map cell on every axis).
    origin: IVec3,
    /// Cells per axis, border included (all zero when the map is too large for a lattice).
    dims: IVec3,
    /// 1 where the cell is traversable.
    cells: Vec<u8>,
    /// Per cell, bit `k` set when move `k` of [`Self::moves`] is allowed from it (0 for a
    /// closed cell).
    allowed: Vec<u32>,
    /// Map cells (border excluded): `cell_min..=cell_max`.
    cell_min: IVec3,
    cell_max: IVec3,
    moves: Vec<Move>,
    /// Index offsets of the 27 cells of a neighbourhood, by bit of [`neighbour_bit`].
    neighbourhood: [isize; 27],
}

impl Lattice {
    /// An all-blocked lattice over the map keys `key_min..=key_max`.
    pub fn new(key_min: IVec3, key_max: IVec3) -> Self {
        let cell_min = key_min >> 1i32;
        let cell_max = key_max >> 1i32;
        let dims = cell_max - cell_min + IVec3::splat(3);
        let count = dims.as_u64vec3().element_product();
        let (dims, cells, allowed) = if count <= MAX_LATTICE_CELLS {
            (dims, vec![0u8; count as usize], vec![0u32; count as usize])
        } else {
            (IVec3::ZERO, Vec::new(), Vec::new())
        };
        let mut lattice = Self {
            origin: cell_min - IVec3::ONE,
            dims,
            cells,
            allowed,
            cell_min,
            cell_max,
            moves: Vec::new(),
            neighbourhood: [0; 27],
        };
        lattice.moves = lattice.build_moves();
        let (sy, sz) = (dims.x as isize, dims.x as isize * dims.y as isize);
        for (bit, offset) in lattice.neighbourhood.iter_mut().enumerate() {
            let b = bit as isize;
            *offset = (b % 3 - 1) + (b / 3 % 3 - 1) * sy + (b / 9 - 1) * sz;
        }
        lattice
    }

    /// Whether the map had room for a lattice (see `MAX_LATTICE_CELLS`).
    pub fn is_available(&self) -> bool {
        !self.cells.is_empty()
    }

    pub fn len(&self) -> usize {
        self.cells.len()
    }

    pub fn is_empty(&self) -> bool {
        self.cells.is_empty()
    }

    /// The cell holding voxel `key`.
    #[inline]
    pub fn cell_of_key(key: IVec3) -> IVec3 {
        key >> 1i32
    }

    /// Index of a cell of the map (border excluded), or `None` outside it.
    #[inline]
    pub fn index(&self, cell: IVec3) -> Option<usize> {
        if !self.is_available()
            || cell.cmplt(self.cell_min).any()
            || cell.cmpgt(self.cell_max).any()
        {
            return None;
        }
        let r = (cell - self.origin).as_uvec3();
        let d = self.dims.as_uvec3();
        Some(r.x as usize + d.x as usize * (r.y as usize + d.y as usize * r.z as usize))
    }

    /// Cell coordinate of an index (inverse of [`Self::index`]).
    pub fn cell(&self, index: usize) -> IVec3 {
        let (dx, dy) = (self.dims.x as usize, self.dims.y as usize);
        self.origin
            + IVec3::new(
                (index % dx) as i32,
                ((index / dx) % dy) as i32,
                (index / (dx * dy)) as i32,
            )
    }

    /// Centre of a cell in world coordinates: the shared corner of its 8 voxels.
    pub fn centre(&self, cell: IVec3, resolution: f64) -> DVec3 {
        (cell * CELL_VOXELS + IVec3::ONE).as_dvec3() * resolution
    }

    #[inline]
    pub fn is_open(&self, index: usize) -> bool {
        self.cells[index] != 0
    }

    /// Sets one map cell's flag (cells outside the map are ignored: they are never traversable,
    /// as they hold voxels outside the map's box), and refreshes the allowed moves around it
    /// if it changed.
    pub fn set(&mut self, cell: IVec3, open: bool) {
        self.set_rows(cell, 1, |_, _| u32::from(open));
    }

    /// Sets the flags of the cube of `edge` cells per side from `first`, row by row (bit `x`
    /// of `row(y, z)` opens cell `first + (x, y, z)`; cells outside the map are ignored), then
    /// refreshes the allowed moves once, over the box around the cells that changed.
    pub fn set_rows(&mut self, first: IVec3, edge: i32, row: impl Fn(i32, i32) -> u32) {
        let (mut low, mut high) = (IVec3::MAX, IVec3::MIN);
        let x_first = first.x.max(self.cell_min.x);
        let x_last = (first.x + edge - 1).min(self.cell_max.x);
        for z in 0..edge {
            for y in 0..edge {
                let row_first = IVec3::new(x_first, first.y + y, first.z + z);
                let Some(start) = self.index(row_first).filter(|_| x_first <= x_last) else {
                    continue;
                };
                let bits = row(y, z) >> (x_first - first.x);
                for (i, x) in (start..).zip(x_first..=x_last) {
                    let flag = (bits >> (x - x_first) & 1) as u8;
                    if self.cells[i] != flag {
                        self.cells[i] = flag;
                        let cell = IVec3::new(x, row_first.y, row_first.z);
                        low = low.min(cell);
                        high = high.max(cell);
                    }
                }
            }
        }
        if low.cmple(high).all() {
            self.refresh_allowed(low - IVec3::ONE, high + IVec3::ONE);
        }
    }

    /// Recomputes the allowed moves of the map cells in `low..=high` (clamped to the map).
    fn refresh_allowed(&mut self, low: IVec3, high: IVec3) {
        let (low, high) = (low.max(self.cell_min), high.min(self.cell_max));
        for z in low.z..=high.z {
            for y in low.y..=high.y {
                let first = self.index(IVec3::new(low.x, y, z)).expect("a map cell");
                for i in first..=first + (high.x - low.x) as usize {
                    self.allowed[i] = if self.is_open(i) {
                        self.moves_within(self.open_neighbours(i))
                    } else {
                        0
                    };
                }
            }
        }
    }

    /// The moves whose whole box is open in the neighbourhood mask `open`, as bits by index in
    /// [`Self::moves`].
    fn moves_within(&self, open: u32) -> u32 {
        self.moves.iter().enumerate().fold(0, |allowed, (k, mv)| {
            allowed | u32::from(open & mv.box_mask == mv.box_mask) << k
        })
    }

    /// The moves allowed from the cell at `index` (bit `k`: move `k` of [`Self::moves`]); none
    /// from a closed cell.
    #[inline]
    pub fn allowed_moves(&self, index: usize) -> u32 {
        self.allowed[index]
    }

    /// The 26 moves, in a fixed order (z, then y, then x offset ascending).
    pub fn moves(&self) -> &[Move] {
        &self.moves
    }

    fn build_moves(&self) -> Vec<Move> {
        let (sx, sy) = (1isize, self.dims.x as isize);
        let sz = sy * self.dims.y as isize;
        let offset = |d: IVec3| d.x as isize * sx + d.y as isize * sy + d.z as isize * sz;
        let mut moves = Vec::with_capacity(26);
        for dz in -1..=1 {
            for dy in -1..=1 {
                for dx in -1..=1 {
                    let d = IVec3::new(dx, dy, dz);
                    if d == IVec3::ZERO {
                        continue;
                    }
                    // Every non-zero corner of the box between 0 and d.
                    let mut box_mask = 0;
                    for corner in 1..8 {
                        let e = IVec3::new(
                            if corner & 1 != 0 { dx } else { 0 },
                            if corner & 2 != 0 { dy } else { 0 },
                            if corner & 4 != 0 { dz } else { 0 },
                        );
                        if e != IVec3::ZERO {
                            box_mask |= neighbour_bit(e);
                        }
                    }
                    let axes = (dx != 0) as usize + (dy != 0) as usize + (dz != 0) as usize;
                    moves.push(Move {
                        delta: d,
                        offset: offset(d),
                        box_mask,
                        cost: MOVE_COSTS[axes - 1],
                    });
                }
            }
        }
        moves
    }

    /// Lower bound of the move cost between two cells: the obstacle-free lattice distance
    /// (3D octile), which makes A* with it consistent.
    pub fn heuristic(a: IVec3, b: IVec3) -> u64 {
        let d = (a - b).abs();
        let mut s = [d.x as u64, d.y as u64, d.z as u64];
        s.sort_unstable();
        let [low, mid, high] = s;
        low * MOVE_COSTS[2] + (mid - low) * MOVE_COSTS[1] + (high - mid) * MOVE_COSTS[0]
    }

    /// The open cells among the 27 around the (non-border) cell at `index`, as a mask; a move
    /// `mv` is allowed when `mask & mv.box_mask == mv.box_mask`.
    #[inline]
    pub fn open_neighbours(&self, index: usize) -> u32 {
        // Nine rows of three cells consecutive in memory (bits 3r..3r+2 are x = -1, 0, 1 of
        // row r): one bounds check per row, not per cell.
        let mut mask = 0;
        for row in 0..9 {
            let first = index.wrapping_add_signed(self.neighbourhood[3 * row]);
            let cells = &self.cells[first..first + 3];
            let bits = u32::from(cells[0]) | u32::from(cells[1]) << 1 | u32::from(cells[2]) << 2;
            mask |= bits << (3 * row);
        }
        mask
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cells_index_round_trip_and_border_is_excluded() {
        let lattice = Lattice::new(IVec3::new(-3, 0, 1), IVec3::new(8, 5, 4));
        // Keys -3..=8 -> cells -2..=4; 0..=5 -> 0..=2; 1..=4 -> 0..=2; plus 2 border cells.
        assert_eq!(lattice.dims, IVec3::new(9, 5, 5));
        for cell in [
            IVec3::new(-2, 0, 0),
            IVec3::new(4, 2, 2),
            IVec3::new(1, 1, 1),
        ] {
            let i = lattice.index(cell).unwrap();
            assert_eq!(lattice.cell(i), cell);
        }
        assert_eq!(lattice.index(IVec3::new(-3, 0, 0)), None);
        assert_eq!(lattice.index(IVec3::new(0, 3, 0)), None);
        // Centre of cell (1, 1, 1) at 0.1 m: the corner of voxels 2 and 3, at 0.3 m.
        let c = lattice.centre(IVec3::ONE, 0.1);
        assert!((c - DVec3::splat(0.3)).abs().max_element() < 1e-12);
    }

    #[test]
    fn moves_check_their_box() {
        let lattice = Lattice::new(IVec3::ZERO, IVec3::splat(9));
        assert_eq!(lattice.moves().len(), 26);
        let count = |n: u32| {
            lattice
                .moves()
                .iter()
                .filter(|m| m.box_mask.count_ones() == n)
                .count()
        };
        // 6 axis moves (1 cell), 12 face diagonals (3 cells), 8 space diagonals (7 cells).
        assert_eq!((count(1), count(3), count(7)), (6, 12, 8));
        // Octile distance: (3, 1, 0) = 1 diagonal + 2 straight.
        assert_eq!(
            Lattice::heuristic(IVec3::ZERO, IVec3::new(3, -1, 0)),
            MOVE_COSTS[1] + 2 * MOVE_COSTS[0]
        );
        // Consistent (what A* with a bucket queue needs): h(a) <= cost + h(a + d).
        let r = 4;
        for z in -r..=r {
            for y in -r..=r {
                for x in -r..=r {
                    let a = IVec3::new(x, y, z);
                    for mv in lattice.moves() {
                        let (h, h_next) = (
                            Lattice::heuristic(a, IVec3::ZERO),
                            Lattice::heuristic(a + mv.delta, IVec3::ZERO),
                        );
                        assert!(h <= mv.cost + h_next, "{a} {}", mv.delta);
                    }
                }
            }
        }
    }

    #[test]
    fn open_neighbours_see_the_box_of_each_move() {
        let mut lattice = Lattice::new(IVec3::ZERO, IVec3::splat(9));
        let centre = IVec3::splat(2);
        for z in 1..=3 {
            for y in 1..=3 {
                for x in 1..=3 {
                    lattice.set(IVec3::new(x, y, z), true);
                }
            }
        }
        // Close (3, 2, 2): the +x move and every diagonal through it are refused.
        lattice.set(IVec3::new(3, 2, 2), false);
        let mask = lattice.open_neighbours(lattice.index(centre).unwrap());
        assert_eq!(mask.count_ones(), 26);
        for mv in lattice.moves() {
            let allowed = mask & mv.box_mask == mv.box_mask;
            assert_eq!(allowed, mv.delta.x != 1, "{}", mv.delta);
        }
    }

    /// The allowed moves kept per cell stay those of a fresh box test of every move, whatever
    /// the order and batching of the flag changes (a stale mask would let a search cut
    /// through a cell closed since).
    #[test]
    fn allowed_moves_follow_every_change() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        let (key_min, key_max) = (IVec3::new(-4, 0, 2), IVec3::new(9, 11, 7));
        let mut lattice = Lattice::new(key_min, key_max);
        let (low, high) = (key_min >> 1i32, key_max >> 1i32);
        for round in 0..200 {
            let batch: Vec<(IVec3, bool)> = (0..rng.random_range(1..12))
                .map(|_| {
                    let cell = IVec3::new(
                        rng.random_range(low.x - 1..=high.x + 1),
                        rng.random_range(low.y - 1..=high.y + 1),
                        rng.random_range(low.z - 1..=high.z + 1),
                    );
                    (cell, rng.random_bool(0.7))
                })
                .collect();
            if round % 2 == 0 {
                batch
                    .into_iter()
                    .for_each(|(cell, open)| lattice.set(cell, open));
            } else {
                // A cube of cells from the first one's, open where its batch draws fell.
                let first = batch[0].0;
                let opened: Vec<IVec3> = batch.iter().filter(|b| b.1).map(|b| b.0).collect();
                lattice.set_rows(first, 3, |y, z| {
                    (0..3).fold(0, |bits, x| {
                        let cell = first + IVec3::new(x, y, z);
                        bits | u32::from(opened.contains(&cell) || (x + y + z) % 2 == 0) << x
                    })
                });
            }
            for i in 0..lattice.len() {
                let expected = if lattice.is_open(i) {
                    lattice.moves_within(lattice.open_neighbours(i))
                } else {
                    0
                };
                assert_eq!(
                    lattice.allowed_moves(i),
                    expected,
                    "round {round}, cell {i}"
                );
            }
        }
        // Some cells ended up with moves allowed, so the check above compared real masks.
        assert!((0..lattice.len()).any(|i| lattice.allowed_moves(i).count_ones() > 3));
    }
}
