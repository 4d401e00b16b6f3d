//! Best-first search over the lattice of [`super::lattice`]: Dijkstra, or A* toward a target
//! with the octile heuristic; the engine of [`super::search`]. A search can stop at a cell it
//! settles and go on later from there (Dijkstra's cells settle in the same order whatever it
//! is asked for, so what it finds does not depend on where it paused).

use super::lattice::{Lattice, MAX_LATTICE_CELLS, MOVE_COSTS, Move};
use super::pruning::dominated;
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
/// cost in the low [`Word::COST_BITS`], the mark above): the search is bound by the latency of
/// these reads, scattered over the lattice, so the words are kept as small as they can be
/// ([`Word`]: 4 bytes per cell, 0.75 MB for a Pillars map) and the arrivals, written only when
/// a cost improves, apart.
pub(super) struct Nodes<W> {
    words: Vec<W>,
    /// The move by which each reached cell was reached at its cost (its parent is the cell
    /// that move came from), or [`START`].
    arrivals: Vec<u8>,
    /// The mark of cells reached by the current search; `reached + 1` marks closed ones.
    reached: u64,
}

/// A cell's word: its cost in the low [`Self::COST_BITS`], its mark above. A reached cell's
/// cost is at most that of a shortest path through every lattice cell plus one move, below
/// `cells x MOVE_COSTS[2]`: lattices for which that bound fits in a `u32`'s cost bits (up to
/// ~310,000 cells, the EAAE scenes' ~190,000-220,000) use `u32` words, larger ones `u64`.
/// (Half the bytes: `find_paths/40_goals` of benches/planning.rs 12-27 % faster on a 2-core
/// AMD EPYC with 512 KB of L2 per core, where the 1.5 MB of `u64` words did not fit.)
pub(super) trait Word: Copy + Default {
    /// Bits of the word that hold the cost; the rest hold the mark.
    const COST_BITS: u32;
    /// Bits of the word.
    const BITS: u32;
    fn get(self) -> u64;
    /// The word of `bits` (below `2^BITS`).
    fn of(bits: u64) -> Self;
}

impl Word for u32 {
    /// Three bits of mark: three searches between clearings.
    const COST_BITS: u32 = 29;
    const BITS: u32 = 32;
    #[inline(always)]
    fn get(self) -> u64 {
        u64::from(self)
    }
    #[inline(always)]
    fn of(bits: u64) -> Self {
        bits as u32
    }
}

impl Word for u64 {
    const COST_BITS: u32 = 42;
    const BITS: u32 = 64;
    #[inline(always)]
    fn get(self) -> u64 {
        self
    }
    #[inline(always)]
    fn of(bits: u64) -> Self {
        bits
    }
}
const _: () = assert!(MAX_LATTICE_CELLS.saturating_mul(MOVE_COSTS[2]) < 1 << u64::COST_BITS);

/// Whether a lattice of `cells` cells can use `u32` words ([`Word`]).
fn narrow_words(cells: usize) -> bool {
    (cells as u64).saturating_mul(MOVE_COSTS[2]) < 1 << u32::COST_BITS
}

impl<W: Word> Nodes<W> {
    const COST_MASK: u64 = (1 << W::COST_BITS) - 1;

    fn new() -> Self {
        Self {
            words: Vec::new(),
            arrivals: Vec::new(),
            reached: 0,
        }
    }

    /// Starts a search over `len` cells: none reached.
    fn begin(&mut self, len: usize) {
        if self.words.len() != len || self.reached + 2 >= 1 << (W::BITS - W::COST_BITS) {
            self.words.clear();
            self.words.resize(len, W::default());
            self.arrivals.clear();
            self.arrivals.resize(len, START);
            self.reached = 0;
        }
        self.reached += 2;
    }

    /// The smallest word of a cell reached by this search.
    #[inline]
    fn reached_base(&self) -> u64 {
        self.reached << W::COST_BITS
    }

    /// The cost a cell's `word` holds, given the search's [`Self::reached_base`].
    #[inline]
    fn cost_of(word: W, base: u64) -> u64 {
        let word = word.get();
        if word >= base {
            word & Self::COST_MASK
        } else {
            u64::MAX
        }
    }

    #[inline]
    fn close(&mut self, cell: usize) {
        let word = &mut self.words[cell];
        *word = W::of((word.get() & Self::COST_MASK) | (self.reached + 1) << W::COST_BITS);
    }

    #[inline]
    fn reach(&mut self, cell: usize, cost: u64, arrival: u8) {
        self.reach_with(cell, cost, arrival, self.reached_base());
    }

    /// [`Self::reach`] given the search's [`Self::reached_base`].
    #[inline]
    fn reach_with(&mut self, cell: usize, cost: u64, arrival: u8, base: u64) {
        debug_assert!(cost <= Self::COST_MASK);
        self.words[cell] = W::of(base | cost);
        self.arrivals[cell] = arrival;
    }
}

/// What is read of a search's cells, whatever the width of their words: the search itself
/// reads [`Nodes`] of one width directly, the callers through [`Search::nodes`].
pub(super) trait Cells {
    /// The cost of `cell` so far (`u64::MAX` if not reached by this search).
    fn cost(&self, cell: usize) -> u64;
    /// The move that reached `cell` (a cell reached by this search), none for the start.
    fn arrival(&self, cell: usize) -> Option<usize>;
    /// Whether `cell` is closed: its cost is final.
    fn is_closed(&self, cell: usize) -> bool;
}

impl<W: Word> Cells for Nodes<W> {
    #[inline]
    fn cost(&self, cell: usize) -> u64 {
        Self::cost_of(self.words[cell], self.reached_base())
    }

    #[inline]
    fn arrival(&self, cell: usize) -> Option<usize> {
        debug_assert!(self.words[cell].get() >= self.reached_base());
        let arrival = self.arrivals[cell];
        (arrival != START).then_some(usize::from(arrival))
    }

    #[inline]
    fn is_closed(&self, cell: usize) -> bool {
        self.words[cell].get() >> W::COST_BITS == self.reached + 1
    }
}

/// What a thread keeps between searches.
struct Scratch {
    /// The cells of lattices small enough for `u32` words ([`Word`]), and of the others.
    narrow: Nodes<u32>,
    wide: Nodes<u64>,
    queue: BucketQueue,
}

impl Scratch {
    fn new() -> Self {
        Self {
            narrow: Nodes::new(),
            wide: Nodes::new(),
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
    /// Whether the cells are in the scratch's `u64` words (a large lattice, see [`Word`]).
    wide: bool,
    state: RunState,
}

/// Where a [`Search`] stands between runs.
struct RunState {
    target: IVec3,
    max_expansions: usize,
    expansions: usize,
    /// The cell the search stopped at, closed but not yet expanded: it is expanded first when
    /// the search goes on, so that it goes on exactly as if it had not stopped.
    unexpanded: Option<usize>,
    /// The queue ran empty, or the expansions ran out: no cell will settle any more.
    done: bool,
    /// Whether expansions skip the moves that cannot lower a cost ([`dominated`]); off only
    /// in the test that checks the skipping changes nothing.
    prune: bool,
}

impl<const ASTAR: bool> Search<ASTAR> {
    pub(super) fn new(
        lattice: &Lattice,
        start: usize,
        target: IVec3,
        max_expansions: usize,
    ) -> Self {
        let wide = !narrow_words(lattice.len());
        Self::with_words(lattice, start, target, max_expansions, wide)
    }

    /// [`Self::new`] on `u64` words if `wide`, else on `u32` ones (which the lattice must
    /// allow: [`narrow_words`]).
    fn with_words(
        lattice: &Lattice,
        start: usize,
        target: IVec3,
        max_expansions: usize,
        wide: bool,
    ) -> Self {
        debug_assert!(wide || narrow_words(lattice.len()));
        let mut scratch = SCRATCH
            .with_borrow_mut(Option::take)
            .unwrap_or_else(Scratch::new);
        if wide {
            scratch.wide.begin(lattice.len());
            scratch.wide.reach(start, 0, START);
        } else {
            scratch.narrow.begin(lattice.len());
            scratch.narrow.reach(start, 0, START);
        }
        let queue = &mut scratch.queue;
        queue.reset(Self::heuristic(lattice.cell(start), target));
        queue.push(queue.current, start);
        Self {
            scratch: Some(scratch),
            wide,
            state: RunState {
                target,
                max_expansions,
                expansions: 0,
                unexpanded: None,
                done: false,
                prune: true,
            },
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
        self.state.expansions.min(self.state.max_expansions)
    }

    /// The cells' state.
    pub(super) fn nodes(&self) -> &dyn Cells {
        let scratch = self.scratch.as_ref().expect("held until dropped");
        if self.wide {
            &scratch.wide
        } else {
            &scratch.narrow
        }
    }

    /// Closes cells in order of cost, calling `settled` on each as it is closed, until it
    /// returns true (that cell is left unexpanded until the next run), the reachable space is
    /// exhausted, or more than `max_expansions` cells were expanded (over all runs).
    pub(super) fn run(&mut self, lattice: &Lattice, settled: impl FnMut(usize) -> bool) {
        let Scratch {
            narrow,
            wide,
            queue,
        } = self.scratch.as_mut().expect("held until dropped");
        if self.wide {
            Self::run_on(lattice, wide, queue, &mut self.state, settled);
        } else {
            Self::run_on(lattice, narrow, queue, &mut self.state, settled);
        }
    }

    /// [`Self::run`] on the search's cells.
    fn run_on<W: Word>(
        lattice: &Lattice,
        nodes: &mut Nodes<W>,
        queue: &mut BucketQueue,
        state: &mut RunState,
        mut settled: impl FnMut(usize) -> bool,
    ) {
        let RunState {
            target,
            max_expansions,
            expansions,
            unexpanded,
            done,
            prune,
        } = state;
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
            expand::<ASTAR, W>(lattice, nodes, queue, index, *target, *prune);
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
fn expand<const ASTAR: bool, W: Word>(
    lattice: &Lattice,
    nodes: &mut Nodes<W>,
    queue: &mut BucketQueue,
    index: usize,
    target: IVec3,
    prune: bool,
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
    if let Some(arrival) = nodes.arrival(index).filter(|_| prune) {
        let parent_allowed =
            || lattice.allowed_moves(index.wrapping_add_signed(-moves[arrival].offset));
        allowed &= !dominated(arrival, allowed, parent_allowed);
    }
    while allowed != 0 {
        let k = allowed.trailing_zeros();
        let mv = &moves[k as usize];
        allowed &= allowed - 1;
        let next = index.wrapping_add_signed(mv.offset);
        let g_next = g + mv.cost;
        // A closed cell already has a cost <= g (consistent heuristic): no closed check.
        if g_next < Nodes::<W>::cost_of(nodes.words[next], base) {
            nodes.reach_with(next, g_next, k as u8, base);
            queue.push(
                g_next + Search::<ASTAR>::heuristic(cell + mv.delta, target),
                next,
            );
        }
    }
}

/// The cost of every cell from `start` (`u64::MAX` where unreached), by a Dijkstra on `u64`
/// words if `wide`, else on `u32` ones.
#[cfg(test)]
pub(super) fn all_costs(lattice: &Lattice, start: usize, wide: bool) -> Vec<u64> {
    let mut search = Search::<false>::with_words(lattice, start, IVec3::ZERO, usize::MAX, wide);
    search.run(lattice, |_| false);
    (0..lattice.len())
        .map(|cell| search.nodes().cost(cell))
        .collect()
}

/// The cells a Dijkstra from `start` closes, in order, each with its cost and arrival; with
/// every move relaxed if not `prune`.
#[cfg(test)]
pub(super) fn closing_order(
    lattice: &Lattice,
    start: usize,
    prune: bool,
) -> Vec<(usize, u64, Option<usize>)> {
    let mut search = Search::<false>::new(lattice, start, IVec3::ZERO, usize::MAX);
    search.state.prune = prune;
    let mut closed = Vec::new();
    search.run(lattice, |cell| {
        closed.push(cell);
        false
    });
    let nodes = search.nodes();
    closed
        .into_iter()
        .map(|cell| (cell, nodes.cost(cell), nodes.arrival(cell)))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn narrow_words_hold_any_cost_of_the_lattices_they_are_used_for() {
        // 2^29 / 1732 = 309,971.6 cells.
        assert!(narrow_words(309_971));
        assert!(!narrow_words(309_972));
        assert!(!narrow_words(usize::MAX));
    }
}
