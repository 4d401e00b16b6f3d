//! Which moves out of a cell a best-first search ([`super::best_first`]) can skip: those that
//! cannot lower any cost. Most relaxations fail, and each reads a word scattered over the
//! lattice, which bounds the search; skipping them keeps every cost, arrival and the order in
//! which cells close bit for bit (each table says why).
//!
//! Moves are numbered as [`Lattice::moves`] lists them; the tables work in the 3 x 3 x 3 cube
//! layout of a cell's neighbourhood (bit `(x+1) + 3 (y+1) + 9 (z+1)`, the centre 13 unused).
//!
//! [`Lattice::moves`]: super::lattice::Lattice::moves

use super::lattice::{ALL_MOVES, MOVE_COSTS};

/// The moves out of a cell reached by move `arrival`, whose allowed moves are `allowed`, that
/// cannot lower any cost; `parent_allowed` reads the moves its parent allows (needed only next
/// to obstacles).
#[inline(always)]
pub(super) fn dominated(arrival: usize, allowed: u32, parent_allowed: impl FnOnce() -> u32) -> u32 {
    if allowed == ALL_MOVES {
        DOMINATED_IN_OPEN[arrival]
    } else {
        DOMINATED_BY_TWO_MOVES[arrival] | relaxed_by_parent(arrival, parent_allowed())
    }
}

/// The moves from a cell reached by move `arrival` that cannot lower any cost, given the moves
/// its parent (the cell `arrival` came from) allows: every `e` whose target, `d + e` from the
/// parent, is one of them (the pruning rule of jump-point search, without the jumps).
///
/// Why they cannot: the parent was expanded before the cell, and relaxed its own move `d + e`
/// then, so that target's cost is at most `g(parent) + w(d + e)`, while the move from the
/// cell would offer `g(parent) + w(d) + w(e)`. Any move costs at most twice the cheapest
/// (below), so `w(d + e) <= w(d) + w(e)`, and the strict comparison of the relaxation rejects
/// the offer: the search visits the same cells in the same order, with the same costs and
/// arrivals, bit for bit. Most relaxations fail (a Dijkstra over the Pillars lattice settles
/// ~93,000 cells with 2.2 M relaxations, of which 94,000 lower a cost), and each reads a word
/// scattered over the lattice; this skips 28 % of them (`find_paths/40_goals` of
/// benches/planning.rs: 23.6 allowed moves per expanded cell, 17.0 relaxed). A cell entered
/// along an axis has 17 of its 26 moves covered by its parent, one entered along a space
/// diagonal only 7. A cell whose 26 neighbours are all open skips more
/// ([`DOMINATED_IN_OPEN`]); this rule serves the cells near obstacles, with
/// [`DOMINATED_BY_TWO_MOVES`].
#[inline(always)]
pub(super) fn relaxed_by_parent(arrival: usize, parent_allowed: u32) -> u32 {
    // In the 3 x 3 x 3 cube layout (bit (x+1) + 3 (y+1) + 9 (z+1), the centre 13 unused),
    // move `f = d + e` sits `cube(d) - 13` bits above `e`: a shift lines the parent's moves
    // up with the cell's, and the mask keeps the `e` whose `d + e` stays in the cube.
    let cube = u64::from(to_cube(parent_allowed));
    let shifted = ((cube << 13) >> cube_bit(arrival)) as u32;
    from_cube(shifted & REACH_FROM_ARRIVAL[arrival])
}
const _: () = assert!(MOVE_COSTS[2] <= 2 * MOVE_COSTS[0]);

/// The cube bit of move `k` (the moves run in cube order with the centre left out).
const fn cube_bit(k: usize) -> u32 {
    (k + (k >= 13) as usize) as u32
}

/// Move bits (in [`Lattice::moves`](super::lattice::Lattice::moves) order) to cube bits.
#[inline(always)]
const fn to_cube(moves: u32) -> u32 {
    (moves & 0x1FFF) | (moves >> 13) << 14
}

/// Cube bits (the centre clear) to move bits.
#[inline(always)]
const fn from_cube(cube: u32) -> u32 {
    (cube & 0x1FFF) | (cube >> 14) << 13
}

/// For each arrival `d`, the cube bits of the moves `e` (not zero, not `-d`) with `d + e` in the
/// cube.
const REACH_FROM_ARRIVAL: [u32; 26] = {
    let mut reach = [0; 26];
    let mut k = 0;
    while k < 26 {
        let d = cube_bit(k) as i32;
        let (dx, dy, dz) = (d % 3 - 1, d / 3 % 3 - 1, d / 9 - 1);
        let mut e = 0;
        while e < 27 {
            let (ex, ey, ez) = (e % 3 - 1, e / 3 % 3 - 1, e / 9 - 1);
            let (fx, fy, fz) = (dx + ex, dy + ey, dz + ez);
            let in_cube = fx.abs() <= 1 && fy.abs() <= 1 && fz.abs() <= 1;
            if e != 13 && in_cube && (fx != 0 || fy != 0 || fz != 0) {
                reach[k] |= 1 << e;
            }
            e += 1;
        }
        k += 1;
    }
    reach
};

/// For each arrival `d`, the moves `e` from a cell whose 26 neighbours are all open that cannot
/// lower any cost, whatever the parent allows: those [`relaxed_by_parent`] skips (the parent's
/// own move `d + e` is allowed, as its box lies among the open neighbours), the way back (`-d`),
/// and every `e` whose target a path of two moves from the parent around the cell reaches for
/// strictly less than `w(d) + w(e)` ([`DOMINATED_BY_TWO_MOVES`] says why those cannot).
///
/// A cell entered along a face diagonal relaxes 5 of its moves instead of 15, one entered
/// along a space diagonal 7 instead of 19; ties are left alone (they would change which of two
/// equal paths is kept), so an axis arrival keeps 9.
const DOMINATED_IN_OPEN: [u32; 26] = dominated_moves(true);

/// For each arrival `d`, the moves `e` that cannot lower any cost next to obstacles too: the
/// way back, and every `e` whose target a path of two moves from the parent reaches for
/// strictly less than `w(d) + w(e)` through cells of the boxes of `d` and `e` alone, which are
/// open (the search took `d`, and relaxes `e` only if allowed), so both moves are allowed.
///
/// Why those cannot: the target's final cost is at most `g(parent) + w(a) + w(b)`, below the
/// cell's offer. The offer is never final: without it the target may be reached meanwhile at
/// another cost that is not final either, and pushed once more, but a queue entry above a
/// cell's final cost pops after the cell has closed and is skipped, and the first offer at the
/// final cost comes from the same expansion as before. The search closes the same cells in the
/// same order, with the same costs and arrivals, bit for bit. 6 of the 15 moves a face-diagonal
/// arrival leaves to [`relaxed_by_parent`] are among them, all 12 of the 19 of a space-diagonal
/// one.
const DOMINATED_BY_TWO_MOVES: [u32; 26] = dominated_moves(false);

/// The tables above: with `open` the cell's 26 neighbours are all open, else only the boxes of
/// its arrival and of the move out are known to be.
const fn dominated_moves(open: bool) -> [u32; 26] {
    let mut dominated = [0; 26];
    let mut k = 0;
    while k < 26 {
        let d = cube_offset(cube_bit(k));
        let parent = [-d[0], -d[1], -d[2]];
        let mut j = 0;
        while j < 26 {
            let e = cube_offset(cube_bit(j));
            let offer = move_cost(d) + move_cost(e);
            let direct = [e[0] - parent[0], e[1] - parent[1], e[2] - parent[2]];
            let mut skip = (e[0] == parent[0] && e[1] == parent[1] && e[2] == parent[2])
                || (open && is_move(direct) && move_cost(direct) <= offer);
            let mut y = 0;
            while y < 27 {
                let via = cube_offset(y);
                let a = [via[0] - parent[0], via[1] - parent[1], via[2] - parent[2]];
                let b = [e[0] - via[0], e[1] - via[1], e[2] - via[2]];
                let shorter = is_move(a) && is_move(b) && move_cost(a) + move_cost(b) < offer;
                let known_open = open
                    || (box_is_known(parent, via, parent, e) && box_is_known(via, e, parent, e));
                if y != 13 && shorter && known_open {
                    skip = true;
                }
                y += 1;
            }
            if skip {
                dominated[k] |= 1 << j;
            }
            j += 1;
        }
        k += 1;
    }
    dominated
}

/// Whether every cell of the box spanned by `u` and `v` (offsets in the cube around a cell
/// reached from `parent`) lies in the box from the parent to the cell or in the box from the
/// cell to `e`.
const fn box_is_known(u: [i32; 3], v: [i32; 3], parent: [i32; 3], e: [i32; 3]) -> bool {
    let centre = [0; 3];
    let mut c = 0;
    while c < 27 {
        let cell = cube_offset(c);
        if in_box(cell, u, v) && !in_box(cell, parent, centre) && !in_box(cell, centre, e) {
            return false;
        }
        c += 1;
    }
    true
}

/// Whether `cell` lies in the box spanned by `u` and `v`.
const fn in_box(cell: [i32; 3], u: [i32; 3], v: [i32; 3]) -> bool {
    let mut axis = 0;
    while axis < 3 {
        let (low, high) = if u[axis] < v[axis] {
            (u[axis], v[axis])
        } else {
            (v[axis], u[axis])
        };
        if cell[axis] < low || cell[axis] > high {
            return false;
        }
        axis += 1;
    }
    true
}

/// The offset of cube bit `c` (in {-1, 0, 1}^3).
const fn cube_offset(c: u32) -> [i32; 3] {
    let c = c as i32;
    [c % 3 - 1, c / 3 % 3 - 1, c / 9 - 1]
}

/// Whether offset `m` is one of the 26 moves.
const fn is_move(m: [i32; 3]) -> bool {
    m[0].abs() <= 1 && m[1].abs() <= 1 && m[2].abs() <= 1 && (m[0] != 0 || m[1] != 0 || m[2] != 0)
}

/// The cost of move `m` ([`MOVE_COSTS`] by how many axes it moves along).
const fn move_cost(m: [i32; 3]) -> u64 {
    let axes = (m[0] != 0) as usize + (m[1] != 0) as usize + (m[2] != 0) as usize;
    MOVE_COSTS[axes - 1]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// How many moves each table leaves to relax, by the kind of arrival (the figures of their
    /// documentation): every arrival of a kind is the same up to symmetry.
    #[test]
    fn the_tables_leave_the_moves_their_documentation_counts() {
        for k in 0..26 {
            let axes = cube_offset(cube_bit(k)).iter().filter(|&&c| c != 0).count();
            let in_open = 26 - DOMINATED_IN_OPEN[k].count_ones();
            // Moves left to the parent's rule; then how many of those two moves always beat.
            let by_parent = relaxed_by_parent(k, ALL_MOVES) | 1 << (25 - k);
            let left = 26 - by_parent.count_ones();
            let beaten = (DOMINATED_BY_TWO_MOVES[k] & !by_parent).count_ones();
            assert_eq!(
                (in_open, left, beaten),
                [(9, 9, 0), (5, 15, 6), (7, 19, 12)][axes - 1],
                "arrival {:?}",
                cube_offset(cube_bit(k))
            );
            // The way back is always skipped, and what is skipped next to obstacles is also
            // skipped in the open.
            assert_ne!(DOMINATED_BY_TWO_MOVES[k] & 1 << (25 - k), 0);
            assert_eq!(DOMINATED_BY_TWO_MOVES[k] & !DOMINATED_IN_OPEN[k], 0);
        }
    }
}
