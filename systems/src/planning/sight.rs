//! Lines of sight remembered over one planning pass on an unchanging grid.
//!
//! A decision fits a trajectory to every cluster along paths from one search tree: the paths
//! to a cluster's centroid and viewpoints differ only near their ends, and paths to different
//! clusters share their trunk near the UAV. The line-of-sight shortening of each path
//! (`search::shortcut_indices`) therefore asks the same questions again and again:
//! in the slowest replayed decisions of a Pillars mission, 7,800-10,100 line-of-sight tests of
//! which 1,600-1,800 were distinct, 7-9 ms of a 18-21 ms planning pass. [`SightMemo`] answers
//! a question it has seen from memory.
//!
//! The memo borrows the grid, so the grid cannot change while it is alive; answers are the
//! grid's own, so a plan is the same whether or not (and in whichever order) a memo saw the
//! question first.

use super::traversable::TraversableGrid;
use glam::DVec3;
use std::collections::HashMap;

/// [`TraversableGrid::line_of_sight`] with its answers kept (module doc).
#[derive(Debug)]
pub struct SightMemo<'a> {
    grid: &'a TraversableGrid,
    /// Keyed by the exact bits of both end points.
    answers: HashMap<[u64; 6], bool, foldhash::fast::RandomState>,
}

impl<'a> SightMemo<'a> {
    pub fn new(grid: &'a TraversableGrid) -> Self {
        Self {
            grid,
            answers: HashMap::default(),
        }
    }

    /// The grid the answers are about.
    pub fn grid(&self) -> &'a TraversableGrid {
        self.grid
    }

    /// Whether `a` sees `b` ([`TraversableGrid::line_of_sight`]).
    pub fn line_of_sight(&mut self, a: DVec3, b: DVec3) -> bool {
        let key = [a.x, a.y, a.z, b.x, b.y, b.z].map(f64::to_bits);
        *self
            .answers
            .entry(key)
            .or_insert_with(|| self.grid.line_of_sight(a, b))
    }

    /// Distinct questions answered so far.
    pub fn len(&self) -> usize {
        self.answers.len()
    }

    pub fn is_empty(&self) -> bool {
        self.answers.is_empty()
    }
}
