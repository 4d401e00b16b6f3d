//! Best-first search over the lattice of [`super::lattice`]: Dijkstra, or A* toward a target
//! with the octile heuristic; the engine of [`super::search`]. A search can stop at a cell it
//! settles and go on later from there (Dijkstra's cells settle in the same order whatever it
//! is asked for, so what it finds does not depend on where it paused).

use super::lattice::{Lattice, MAX_LATTICE_CELLS, MOVE_COSTS, Move};
use glam::IVec3;
use std::cell::RefCell;

/// The arrival of the start cell, which has no parent (moves are 0..26).
const START: u8 = 26;

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
pub(super) struct Nodes {
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
    pub(super) fn cost(&self, cell: usize) -> u64 {
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
    pub(super) fn is_closed(&self, cell: usize) -> bool {
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

impl Scratch {
    fn new() -> Self {
        Self {
            nodes: Nodes {
                words: Vec::new(),
                arrivals: Vec::new(),
                reached: 0,
            },
            queue: BucketQueue::new(),
        }
    }
}

thread_local! {
    /// The thread's buffers while no search holds them (a search started while another one
    /// on the same thread is paused makes its own).
    static SCRATCH: RefCell<Option<Scratch>> = const { RefCell::new(None) };
}

/// A best-first search from one start cell (Dijkstra, or with `ASTAR` A* toward `target`):
/// [`Search::run`] closes cells in order of cost until one it is asked about settles, the
/// reachable space is exhausted, or more than `max_expansions` cells were expanded.
pub(super) struct Search<const ASTAR: bool> {
    scratch: Option<Scratch>,
    target: IVec3,
    max_expansions: usize,
    expansions: usize,
    /// The cell the search stopped at, closed but not yet expanded: it is expanded first when
    /// the search goes on, so that it goes on exactly as if it had not stopped.
    unexpanded: Option<usize>,
    /// The queue ran empty, or the expansions ran out: no cell will settle any more.
    done: bool,
}

impl<const ASTAR: bool> Search<ASTAR> {
    pub(super) fn new(
        lattice: &Lattice,
        start: usize,
        target: IVec3,
        max_expansions: usize,
    ) -> Self {
        let mut scratch = SCRATCH
            .with_borrow_mut(Option::take)
            .unwrap_or_else(Scratch::new);
        let Scratch { nodes, queue } = &mut scratch;
        nodes.begin(lattice.len());
        nodes.reach(start, 0, START);
        queue.reset(Self::heuristic(lattice.cell(start), target));
        queue.push(queue.current, start);
        Self {
            scratch: Some(scratch),
            target,
            max_expansions,
            expansions: 0,
            unexpanded: None,
            done: false,
        }
    }

    fn heuristic(cell: IVec3, target: IVec3) -> u64 {
        if ASTAR {
            Lattice::heuristic(cell, target)
        } else {
            0
        }
    }

    /// Cells expanded so far (at most `max_expansions`).
    pub(super) fn expansions(&self) -> usize {
        self.expansions.min(self.max_expansions)
    }

    /// The cells' state.
    pub(super) fn nodes(&self) -> &Nodes {
        &self.scratch.as_ref().expect("held until dropped").nodes
    }

    /// Closes cells in order of cost, calling `settled` on each as it is closed, until it
    /// returns true (that cell is left unexpanded until the next run), the reachable space is
    /// exhausted, or more than `max_expansions` cells were expanded (over all runs).
    pub(super) fn run(&mut self, lattice: &Lattice, mut settled: impl FnMut(usize) -> bool) {
        let Self {
            scratch,
            target,
            max_expansions,
            expansions,
            unexpanded,
            done,
        } = self;
        let Scratch { nodes, queue } = scratch.as_mut().expect("held until dropped");
        let mut next = unexpanded.take();
        while !*done {
            let index = match next.take() {
                Some(index) => index,
                None => match queue.pop() {
                    Some(index) if nodes.is_closed(index) => continue,
                    Some(index) => {
                        nodes.close(index);
                        if settled(index) {
                            *unexpanded = Some(index);
                            return;
                        }
                        index
                    }
                    None => {
                        *done = true;
                        return;
                    }
                },
            };
            *expansions += 1;
            if *expansions > *max_expansions {
                *done = true;
                return;
            }
            expand::<ASTAR>(lattice, nodes, queue, index, *target);
        }
    }

    /// Cells from the start to `goal` (closed) by following the arrivals back.
    pub(super) fn trace(&self, moves: &[Move], goal: usize) -> Vec<usize> {
        let nodes = self.nodes();
        let mut cells = vec![goal];
        let mut at = goal;
        while let Some(arrival) = nodes.arrival(at) {
            at = at.wrapping_add_signed(-moves[arrival].offset);
            cells.push(at);
        }
        cells.reverse();
        cells
    }
}

impl<const ASTAR: bool> Drop for Search<ASTAR> {
    /// Hands the buffers back to the thread for its next search.
    fn drop(&mut self) {
        let scratch = self.scratch.take();
        SCRATCH.with_borrow_mut(|slot| {
            if slot.is_none() {
                *slot = scratch;
            }
        });
    }
}

/// Relaxes the moves out of the closed cell `index`.
#[inline(always)]
fn expand<const ASTAR: bool>(
    lattice: &Lattice,
    nodes: &mut Nodes,
    queue: &mut BucketQueue,
    index: usize,
    target: IVec3,
) {
    let moves = lattice.moves();
    let g = nodes.cost(index);
    let cell = if ASTAR {
        lattice.cell(index)
    } else {
        IVec3::ZERO
    };
    // The allowed moves in their fixed order (lowest bit first). The mark base is read once:
    // the compiler cannot tell that the writes to the cells leave it unchanged.
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
            queue.push(
                g_next + Search::<ASTAR>::heuristic(cell + mv.delta, target),
                next,
            );
        }
    }
}

#[cfg(test)]
pub(super) fn all_costs(lattice: &Lattice, start: usize) -> Vec<u64> {
    let mut search = Search::<false>::new(lattice, start, IVec3::ZERO, usize::MAX);
    search.run(lattice, |_| false);
    (0..lattice.len())
        .map(|cell| search.nodes().cost(cell))
        .collect()
}
