//! A start on an island of the lattice: the way out over traversable voxels.
//!
//! A lattice cell is open only when all 8 of its voxels are traversable (`super::lattice`), so
//! the traversable voxels around a UAV can join the rest of the map through passages too
//! narrow or too crooked for open cells, while the open cells near it form an island that no
//! move leaves. In a forest of round trunks a UAV that reached a viewpoint at 0.7 m between a
//! trunk and unexplored ground stood on traversable voxels, a winding lane two to three voxels
//! wide leading to the open space 1 m away, but the cell it attached to joined no other: every
//! cluster was "no path", and the run ended `complete` with 2.6 % of the reachable volume and
//! clusters of 1,400 frontier voxels left.
//!
//! - [`is_island`]: whether the open cells a cell's moves reach are fewer than
//!   [`ISLAND_CELLS`] (a bounded flood, a few microseconds where the cell is joined to the map).
//! - [`way_out`]: a breadth-first search over face-adjacent traversable voxels (the segment
//!   between two face neighbours' centres crosses those two voxels only) to the nearest voxel
//!   in an open cell that a predicate accepts; the segment from there to the cell's centre
//!   stays in the cell, whose voxels are all traversable. The voxel path is then shortened by
//!   line of sight, so every leg of the way crosses traversable voxels only.

use super::lattice::Lattice;
use super::search::shortcut_indices;
use super::traversable::TraversableGrid;
use crate::frontier::detect::NEIGHBOURS;
use glam::{DVec3, IVec3};
use std::collections::{HashSet, VecDeque};

/// How far (m, on each axis) from the start the way out may lead.
pub const ESCAPE_RADIUS_M: f64 = 2.0;

/// Open cells that a start's cell must reach for it to count as joined to the map (256 cells
/// of 2 x 2 x 2 voxels: 2 m^3 at 0.1 m). The known space at the beginning of a mission can be
/// smaller (the thesis camera's clear capsule leaves about 1.2 m^3, some 150 cells, to the
/// inflated body): an island with nothing better near it is still taken.
pub const ISLAND_CELLS: usize = 256;

/// Whether the open cells reachable by allowed moves from the open cell `cell` (itself
/// included) are fewer than [`ISLAND_CELLS`].
pub(super) fn is_island(lattice: &Lattice, cell: usize) -> bool {
    let mut seen: HashSet<usize, foldhash::fast::RandomState> =
        HashSet::with_capacity_and_hasher(2 * ISLAND_CELLS, Default::default());
    seen.insert(cell);
    let mut stack = vec![cell];
    while let Some(at) = stack.pop() {
        let allowed = lattice.allowed_moves(at);
        for (k, step) in lattice.moves().iter().enumerate() {
            let next = at.wrapping_add_signed(step.offset);
            if allowed >> k & 1 == 1 && seen.insert(next) {
                if seen.len() >= ISLAND_CELLS {
                    return false;
                }
                stack.push(next);
            }
        }
    }
    true
}

/// The way from the traversable point `start` to the nearest open cell that `accept` takes,
/// reachable over traversable voxels within `radius_m` (fewest face steps; ties to the earlier
/// neighbour in [`NEIGHBOURS`] order; `accept` is asked once per cell): the points strictly
/// between `start` and the cell's centre, and the cell's index. `None` when `start` is not
/// traversable, the grid has no lattice, or no such cell is reachable within the radius.
pub(super) fn way_out(
    grid: &TraversableGrid,
    start: DVec3,
    radius_m: f64,
    mut accept: impl FnMut(usize) -> bool,
) -> Option<(Vec<DVec3>, usize)> {
    let lattice = grid.lattice();
    if !grid.is_traversable_point(start) || !lattice.is_available() {
        return None;
    }
    let resolution = grid.resolution();
    let n = (radius_m / resolution).ceil().max(1.0) as i32;
    let side = 2 * n + 1;
    let first = grid.key_of(start);
    let origin = first - IVec3::splat(n);
    let slot = |key: IVec3| {
        let d = key - origin;
        (d.cmpge(IVec3::ZERO).all() && d.cmplt(IVec3::splat(side)).all())
            .then(|| (d.x + side * (d.y + side * d.z)) as usize)
    };
    const UNSEEN: u32 = u32::MAX;
    let mut parent = vec![UNSEEN; (side * side * side) as usize];
    let first_slot = slot(first).expect("the start is the box's centre");
    parent[first_slot] = first_slot as u32;
    let mut queue = VecDeque::from([first]);
    let key_of_slot = |s: usize| {
        let s = s as i32;
        origin + IVec3::new(s % side, (s / side) % side, s / (side * side))
    };
    let mut refused: HashSet<usize, foldhash::fast::RandomState> = HashSet::default();
    while let Some(key) = queue.pop_front() {
        let cell = Lattice::cell_of_key(key);
        let open = lattice
            .index(cell)
            .filter(|&i| lattice.is_open(i) && !refused.contains(&i));
        if let Some(index) = open {
            if accept(index) {
                // The voxels back to the start, then start -> voxel centres -> cell centre.
                let mut at = slot(key).expect("visited keys lie in the box");
                let mut keys = vec![key];
                while parent[at] as usize != at {
                    at = parent[at] as usize;
                    keys.push(key_of_slot(at));
                }
                let centre = |k: IVec3| (k.as_dvec3() + 0.5) * resolution;
                let points: Vec<DVec3> = std::iter::once(start)
                    .chain(keys.into_iter().rev().map(centre))
                    .chain(std::iter::once(lattice.centre(cell, resolution)))
                    .collect();
                let kept = shortcut_indices(&points, |a, b| grid.line_of_sight(a, b));
                let lead = kept[1..kept.len() - 1].iter().map(|&i| points[i]).collect();
                return Some((lead, index));
            }
            refused.insert(index);
        }
        let here = slot(key).expect("visited keys lie in the box") as u32;
        for face in NEIGHBOURS {
            let next = key + face;
            let Some(s) = slot(next) else { continue };
            if parent[s] == UNSEEN && grid.is_traversable(next) {
                parent[s] = here;
                queue.push_back(next);
            }
        }
    }
    None
}
