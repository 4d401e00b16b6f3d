//! Path search on the traversability grid (EAAE step 6: "A* or JPS on the voxel grid with
//! obstacle inflation"): A* to one goal, one Dijkstra to many goals (every frontier cluster in
//! one search), and the line-of-sight shortening of the result.
//!
//! The searches run on the 2-voxel lattice of [`super::lattice`] (why: see there), 26-connected
//! with Euclidean move costs. Paths are returned in world coordinates: the query point, the
//! centres of the cells visited, and the goal.
//!
//! End points: a point whose voxel is not traversable (tracking error, a UAV or a viewpoint
//! close to a wall) is attached to the nearest open cell within [`SNAP_RADIUS_M`] (a start) or
//! [`GOAL_SNAP_RADIUS_M`] (a goal); the path
//! then starts there with a leg out of the blocked voxel (a start), or ends at that cell's
//! centre (a goal). A traversable point is attached to the nearest open cell it sees (straight
//! line over traversable voxels). Determinism: candidates are ordered by distance, then by
//! cell index; the queue pops by cost, last in first out among equal costs, and moves are
//! tried in a fixed order; no hash map is iterated.

use super::lattice::{Lattice, MAX_LATTICE_CELLS, MOVE_COSTS, Move};
use super::traversable::TraversableGrid;
use glam::{DVec3, IVec3};
use std::cell::RefCell;

/// How far (m) a blocked start may be moved to reach the lattice (the trajectory may leave it
/// through untraversable space for this far, see `super::check`).
pub const SNAP_RADIUS_M: f64 = 0.5;
/// How far (m) a blocked goal may be moved to reach the lattice. Goals are frontier centroids
/// and viewpoints: they sit on the edge of known space, which the inflated body keeps a radius
/// (and the 2-voxel lattice up to a cell more) away from; any open cell this close still looks
/// at the frontier.
pub const GOAL_SNAP_RADIUS_M: f64 = 1.0;
/// Points closer than this (m) along a path are merged (the trajectory planner refuses
/// coincident waypoints).
pub const MIN_POINT_SEPARATION_M: f64 = 0.01;

/// The arrival of the start cell, which has no parent (moves are 0..26).
const START: u8 = 26;

/// Where a query point joins the lattice.
#[derive(Debug, Clone, Copy)]
struct Endpoint {
    point: DVec3,
    cell: usize,
    /// Whether `point` itself is traversable (it is then part of the path).
    traversable: bool,
}

fn attach(grid: &TraversableGrid, point: DVec3, radius: f64) -> Option<Endpoint> {
    let lattice = grid.lattice();
    if !point.is_finite() || !lattice.is_available() {
        return None;
    }
    let resolution = grid.resolution();
    let traversable = grid.is_traversable_point(point);
    let home = Lattice::cell_of_key(grid.key_of(point));
    let n = (radius / (2.0 * resolution)).ceil() as i32 + 1;
    // Planes and rows of cells whose centres all lie farther than `radius` (with a margin for
    // rounding) hold no candidate and are skipped whole.
    let beyond = radius * radius * (1.0 + 1e-9);
    let offset = |d: IVec3| lattice.centre(home + d, resolution) - point;
    let mut candidates = Vec::new();
    for dz in -n..=n {
        let z2 = offset(IVec3::Z * dz).z.powi(2);
        if z2 > beyond {
            continue;
        }
        for dy in -n..=n {
            if z2 + offset(IVec3::Y * dy).y.powi(2) > beyond {
                continue;
            }
            for dx in -n..=n {
                let cell = home + IVec3::new(dx, dy, dz);
                let Some(index) = lattice.index(cell) else {
                    continue;
                };
                if !lattice.is_open(index) {
                    continue;
                }
                let centre = lattice.centre(cell, resolution);
                let distance = centre.distance(point);
                if distance <= radius {
                    candidates.push((distance, index, centre));
                }
            }
        }
    }
    // The nearest candidate first (by distance, then index) that the point sees. The first
    // is nearly always taken, so candidates are picked by selection rather than sorted.
    let order =
        |a: &(f64, usize, DVec3), b: &(f64, usize, DVec3)| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1));
    while let Some(nearest) =
        (0..candidates.len()).min_by(|&a, &b| order(&candidates[a], &candidates[b]))
    {
        let (_, cell, centre) = candidates.swap_remove(nearest);
        if !traversable || grid.line_of_sight(point, centre) {
            return Some(Endpoint {
                point,
                cell,
                traversable,
            });
        }
    }
    None
}

/// Appends `p`, merging it with the last point when closer than [`MIN_POINT_SEPARATION_M`]
/// (the first point, the query's start, is never replaced).
fn push_point(path: &mut Vec<DVec3>, p: DVec3) {
    match path.last() {
        Some(last) if last.distance(p) < MIN_POINT_SEPARATION_M => {
            if path.len() > 1 {
                *path.last_mut().expect("non-empty") = p;
            }
        }
        _ => path.push(p),
    }
}

fn assemble(grid: &TraversableGrid, from: &Endpoint, cells: &[usize], to: &Endpoint) -> Vec<DVec3> {
    let lattice = grid.lattice();
    let mut path = Vec::with_capacity(cells.len() + 2);
    path.push(from.point);
    for &cell in cells {
        push_point(
            &mut path,
            lattice.centre(lattice.cell(cell), grid.resolution()),
        );
    }
    if to.traversable {
        push_point(&mut path, to.point);
    }
    path
}

/// Cells from the start to `goal` by following the arrivals of `nodes` back.
fn trace(nodes: &Nodes, moves: &[Move], goal: usize) -> Vec<usize> {
    let mut cells = vec![goal];
    let mut at = goal;
    while let Some(arrival) = nodes.arrival(at) {
        at = at.wrapping_add_signed(-moves[arrival].offset);
        cells.push(at);
    }
    cells.reverse();
    cells
}

/// Slots of the bucket queue: more than the largest key step, `2 x` the largest move cost
/// for A* (a move raises g by its cost and changes h by at most as much).
const BUCKETS: usize = 4096;

/// Dial's bucket queue: keys pop in non-decreasing order, and every key pushed lies within
/// [`BUCKETS`] of the last key popped. Within a key, last in first out (for A*, the deeper
/// node first, which keeps it on the straight line in open space).
struct BucketQueue {
    buckets: Vec<Vec<u32>>,
    current: u64,
    len: usize,
}

impl BucketQueue {
    fn new() -> Self {
        Self {
            buckets: vec![Vec::new(); BUCKETS],
            current: 0,
            len: 0,
        }
    }

    /// Empties the queue, keeping the buckets' memory.
    fn reset(&mut self, current: u64) {
        if self.len > 0 {
            self.buckets.iter_mut().for_each(Vec::clear);
        }
        self.current = current;
        self.len = 0;
    }

    #[inline]
    fn push(&mut self, key: u64, node: usize) {
        self.buckets[key as usize % BUCKETS].push(node as u32);
        self.len += 1;
    }

    #[inline]
    fn pop(&mut self) -> Option<usize> {
        if self.len == 0 {
            return None;
        }
        loop {
            if let Some(node) = self.buckets[self.current as usize % BUCKETS].pop() {
                self.len -= 1;
                return Some(node as usize);
            }
            self.current += 1;
        }
    }
}

/// The state of every lattice cell, kept from one search to the next on each thread: a search
/// begins by taking two new marks (reached, closed) instead of clearing lattice-sized arrays,
/// which took longer than a short search itself (the local planner's A* expands a few
/// hundred cells of a lattice of ~200,000).
///
/// The relaxation of a move reads the target cell's mark and cost, which share one word (the
/// cost in the low [`COST_BITS`], the mark above): the search is bound by the latency of
/// these reads, scattered over the lattice, so the words are kept as small as they can be
/// (8 bytes per cell, 1.5 MB for a Pillars map) and the arrivals, written only when a cost
/// improves, apart.
struct Nodes {
    words: Vec<u64>,
    /// The move by which each reached cell was reached at its cost (its parent is the cell
    /// that move came from), or [`START`].
    arrivals: Vec<u8>,
    /// The mark of cells reached by the current search; `reached + 1` marks closed ones.
    reached: u64,
}

/// Bits of a cell's word that hold its cost. A reached cell's cost is at most that of a
/// shortest path through every lattice cell plus one move, below `2^41`.
const COST_BITS: u32 = 42;
const COST_MASK: u64 = (1 << COST_BITS) - 1;
const _: () = assert!(MAX_LATTICE_CELLS.saturating_mul(MOVE_COSTS[2]) < COST_MASK);

impl Nodes {
    /// Starts a search over `len` cells: none reached.
    fn begin(&mut self, len: usize) {
        if self.words.len() != len || self.reached + 2 >= 1 << (64 - COST_BITS) {
            self.words.clear();
            self.words.resize(len, 0);
            self.arrivals.clear();
            self.arrivals.resize(len, START);
            self.reached = 0;
        }
        self.reached += 2;
    }

    /// The smallest word of a cell reached by this search.
    #[inline]
    fn reached_base(&self) -> u64 {
        self.reached << COST_BITS
    }

    #[inline]
    fn cost(&self, cell: usize) -> u64 {
        Self::cost_of(self.words[cell], self.reached_base())
    }

    /// The cost a cell's `word` holds, given the search's [`Self::reached_base`].
    #[inline]
    fn cost_of(word: u64, base: u64) -> u64 {
        if word >= base {
            word & COST_MASK
        } else {
            u64::MAX
        }
    }

    /// The move that reached `cell` (a cell reached by this search), none for the start.
    #[inline]
    fn arrival(&self, cell: usize) -> Option<usize> {
        debug_assert!(self.words[cell] >= self.reached_base());
        let arrival = self.arrivals[cell];
        (arrival != START).then_some(usize::from(arrival))
    }

    #[inline]
    fn is_closed(&self, cell: usize) -> bool {
        self.words[cell] >> COST_BITS == self.reached + 1
    }

    #[inline]
    fn close(&mut self, cell: usize) {
        let word = &mut self.words[cell];
        *word = (*word & COST_MASK) | (self.reached + 1) << COST_BITS;
    }

    #[inline]
    fn reach(&mut self, cell: usize, cost: u64, arrival: u8) {
        self.reach_with(cell, cost, arrival, self.reached_base());
    }

    /// [`Self::reach`] given the search's [`Self::reached_base`].
    #[inline]
    fn reach_with(&mut self, cell: usize, cost: u64, arrival: u8, base: u64) {
        debug_assert!(cost <= COST_MASK);
        self.words[cell] = base | cost;
        self.arrivals[cell] = arrival;
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
/// diagonal only 7.
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

/// Move bits (in [`Lattice::moves`] order) to cube bits.
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

/// What a thread keeps between searches.
struct Scratch {
    nodes: Nodes,
    queue: BucketQueue,
}

thread_local! {
    static SCRATCH: RefCell<Scratch> = RefCell::new(Scratch {
        nodes: Nodes {
            words: Vec::new(),
            arrivals: Vec::new(),
            reached: 0,
        },
        queue: BucketQueue::new(),
    });
}

/// Best-first search from `start` (Dijkstra, or with `ASTAR` A* toward `target` with the octile
/// heuristic), calling `settled` on every cell as it is closed (in order of cost) until it
/// returns true, the reachable space is exhausted, or `max_expansions` cells were expanded;
/// then `finish` reads the cells' final state.
fn explore<const ASTAR: bool, R>(
    lattice: &Lattice,
    start: usize,
    target: IVec3,
    max_expansions: usize,
    mut settled: impl FnMut(usize) -> bool,
    finish: impl FnOnce(&Nodes) -> R,
) -> R {
    let heuristic = |cell: IVec3| {
        if ASTAR {
            Lattice::heuristic(cell, target)
        } else {
            0
        }
    };
    SCRATCH.with_borrow_mut(|Scratch { nodes, queue }| {
        nodes.begin(lattice.len());
        nodes.reach(start, 0, START);
        let moves = lattice.moves();
        let start_cell = lattice.cell(start);
        queue.reset(heuristic(start_cell));
        queue.push(queue.current, start);
        let mut expansions = 0usize;
        while let Some(index) = queue.pop() {
            if nodes.is_closed(index) {
                continue;
            }
            nodes.close(index);
            if settled(index) {
                break;
            }
            expansions += 1;
            if expansions > max_expansions {
                break;
            }
            let g = nodes.cost(index);
            let cell = if ASTAR {
                lattice.cell(index)
            } else {
                IVec3::ZERO
            };
            // The allowed moves in their fixed order (lowest bit first). The mark base is read
            // once: the compiler cannot tell that the writes to the cells leave it unchanged.
            let base = nodes.reached_base();
            let mut allowed = lattice.allowed_moves(index);
            if let Some(arrival) = nodes.arrival(index) {
                let parent = index.wrapping_add_signed(-moves[arrival].offset);
                allowed &= !relaxed_by_parent(arrival, lattice.allowed_moves(parent));
            }
            while allowed != 0 {
                let k = allowed.trailing_zeros();
                let mv = &moves[k as usize];
                allowed &= allowed - 1;
                let next = index.wrapping_add_signed(mv.offset);
                let g_next = g + mv.cost;
                // A closed cell already has a cost <= g (consistent heuristic): no closed check.
                if g_next < Nodes::cost_of(nodes.words[next], base) {
                    nodes.reach_with(next, g_next, k as u8, base);
                    queue.push(g_next + heuristic(cell + mv.delta), next);
                }
            }
        }
        finish(nodes)
    })
}

/// Shortest path (A*, 26-connected, Euclidean costs, octile heuristic, which is admissible and
/// consistent) from `from` to `to`, or `None` when there is none or more than `max_expansions`
/// cells would have to be expanded. The path starts at `from`, passes cell centres, and ends at
/// `to` (or where a blocked `to` was attached, see the module doc).
pub fn find_path(
    grid: &TraversableGrid,
    from: DVec3,
    to: DVec3,
    max_expansions: usize,
) -> Option<Vec<DVec3>> {
    let start = attach(grid, from, SNAP_RADIUS_M)?;
    let goal = attach(grid, to, GOAL_SNAP_RADIUS_M)?;
    let lattice = grid.lattice();
    let target = lattice.cell(goal.cell);
    let cells = explore::<true, _>(
        lattice,
        start.cell,
        target,
        max_expansions,
        |cell| cell == goal.cell,
        |nodes| {
            nodes
                .is_closed(goal.cell)
                .then(|| trace(nodes, lattice.moves(), goal.cell))
        },
    )?;
    Some(assemble(grid, &start, &cells, &goal))
}

/// Shortest paths from `from` to every goal with one Dijkstra search, which stops when every
/// goal's cell is settled, the reachable space is exhausted, or `max_expansions` cells were
/// expanded. `result[i]` is the path to `goals[i]` (as [`find_path`] returns it; equal in
/// length, ties may pick another of the equally short paths), or `None`.
pub fn find_paths(
    grid: &TraversableGrid,
    from: DVec3,
    goals: &[DVec3],
    max_expansions: usize,
) -> Vec<Option<Vec<DVec3>>> {
    let mut result = vec![None; goals.len()];
    let Some(start) = attach(grid, from, SNAP_RADIUS_M) else {
        return result;
    };
    let ends: Vec<Option<Endpoint>> = goals
        .iter()
        .map(|&g| attach(grid, g, GOAL_SNAP_RADIUS_M))
        .collect();
    // One bit per lattice cell, set for the goals' cells not yet settled: the test runs for
    // every cell the search settles, and a bit lookup stays in cache where a search of the
    // goal list is a chain of dependent loads.
    let lattice = grid.lattice();
    let mut pending = vec![0u64; lattice.len().div_ceil(64)];
    let mut remaining = 0usize;
    for end in ends.iter().flatten() {
        let (word, bit) = (end.cell / 64, 1 << (end.cell % 64));
        remaining += usize::from(pending[word] & bit == 0);
        pending[word] |= bit;
    }
    if remaining == 0 {
        return result;
    }
    let cells: Vec<Option<Vec<usize>>> = explore::<false, _>(
        lattice,
        start.cell,
        IVec3::ZERO,
        max_expansions,
        |cell| {
            let (word, bit) = (cell / 64, 1 << (cell % 64));
            if pending[word] & bit != 0 {
                pending[word] &= !bit;
                remaining -= 1;
            }
            remaining == 0
        },
        |nodes| {
            ends.iter()
                .map(|end| {
                    let end = end.as_ref()?;
                    nodes
                        .is_closed(end.cell)
                        .then(|| trace(nodes, lattice.moves(), end.cell))
                })
                .collect()
        },
    );
    for ((slot, end), cells) in result.iter_mut().zip(&ends).zip(cells) {
        if let (Some(end), Some(cells)) = (end, cells) {
            *slot = Some(assemble(grid, &start, &cells, end));
        }
    }
    result
}

/// Every lattice cell's cost from `start` after a Dijkstra over all reachable cells
/// (`u64::MAX`: unreached), for the tests of the search itself.
#[cfg(test)]
pub(super) fn all_costs(lattice: &Lattice, start: usize) -> Vec<u64> {
    explore::<false, _>(
        lattice,
        start,
        IVec3::ZERO,
        usize::MAX,
        |_| false,
        |nodes| (0..lattice.len()).map(|cell| nodes.cost(cell)).collect(),
    )
}

/// Indices of the points [`shortcut`] keeps, with `sees(a, b)` the line of sight (the grid's
/// own, or a [`super::SightMemo`]'s when plans share their questions).
pub(crate) fn shortcut_indices(
    path: &[DVec3],
    mut sees: impl FnMut(DVec3, DVec3) -> bool,
) -> Vec<usize> {
    if path.len() <= 2 {
        return (0..path.len()).collect();
    }
    let last = path.len() - 1;
    let mut kept = vec![0];
    let mut anchor = 0;
    for j in 1..last {
        if !sees(path[anchor], path[j + 1]) {
            kept.push(j);
            anchor = j;
        }
    }
    kept.push(last);
    kept
}

/// Line-of-sight shortening ("string pulling") of a path: from each kept point, the path's
/// points are skipped as long as the straight chord to the next one crosses traversable voxels
/// only. Every chord kept is such a chord, or one of the input's own legs (the first leg out
/// of a blocked start, for instance, which no chord can replace). The first and last points
/// are kept.
pub fn shortcut(grid: &TraversableGrid, path: &[DVec3]) -> Vec<DVec3> {
    shortcut_indices(path, |a, b| grid.line_of_sight(a, b))
        .into_iter()
        .map(|i| path[i])
        .collect()
}

/// Length of a polyline (m).
pub fn path_length(path: &[DVec3]) -> f64 {
    path.windows(2).map(|w| w[0].distance(w[1])).sum()
}
