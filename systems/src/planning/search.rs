//! Path search on the traversability grid (EAAE step 6: "A* or JPS on the voxel grid with
//! obstacle inflation"): A* to one goal, one Dijkstra to many goals (every frontier cluster in
//! one search, run as far as the goals asked for need: [`PathSearch`]), and the line-of-sight
//! shortening of the result. The searches themselves are `super::best_first`'s.
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
//! line over traversable voxels); a traversable start that sees none within [`SNAP_RADIUS_M`]
//! looks as far as [`START_SEE_RADIUS_M`], and one whose cell is an island of the lattice
//! takes the way out over traversable voxels (`super::escape`). Determinism: candidates are
//! ordered by distance, then by cell index; the queue pops by cost, last in first out among
//! equal costs, and moves are tried in a fixed order; no hash map is iterated.

use super::best_first::Search;
use super::escape::{ESCAPE_RADIUS_M, is_island, way_out};
use super::lattice::Lattice;
use super::traversable::TraversableGrid;
use glam::{DVec3, IVec3};

/// How far (m) a blocked start may be moved to reach the lattice (the trajectory may leave it
/// through untraversable space for this far, see `super::check`).
pub const SNAP_RADIUS_M: f64 = 0.5;
/// How far (m) a traversable start that sees no open cell within [`SNAP_RADIUS_M`] looks for
/// one it sees (a straight leg over traversable voxels, so the trajectory needs no escape). A
/// UAV that stopped at a frontier centroid near a wall, with unobserved voxels 0.3 m below it
/// (the forward camera never sees beneath itself), stood on traversable voxels joined to the
/// whole map, yet the 2-voxel lattice cells around it were closed or hidden behind a sheet of
/// closed voxels: no path left, and the run ended `complete` with 89 % of the reachable volume
/// explored (EAAE Pillars, Nearest, seed 20). Voxels are traversable in finer steps than cells
/// are open, so such a pocket has a way out; a second look a little farther finds it.
pub const START_SEE_RADIUS_M: f64 = 1.0;
/// How far (m) a blocked goal may be moved to reach the lattice. Goals are frontier centroids
/// and viewpoints: they sit on the edge of known space, which the inflated body keeps a radius
/// (and the 2-voxel lattice up to a cell more) away from; any open cell this close still looks
/// at the frontier.
pub const GOAL_SNAP_RADIUS_M: f64 = 1.0;
/// Points closer than this (m) along a path are merged (the trajectory planner refuses
/// coincident waypoints).
pub const MIN_POINT_SEPARATION_M: f64 = 0.01;

/// Where a query point joins the lattice.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Endpoint {
    point: DVec3,
    cell: usize,
    /// Whether `point` itself is traversable (it is then part of the path).
    pub(super) traversable: bool,
}

/// Where `point` joins the lattice (module doc): the open cell nearest to it within `radius`
/// (by distance, then cell index), or for a traversable point the nearest one it sees.
pub(super) fn attach(grid: &TraversableGrid, point: DVec3, radius: f64) -> Option<Endpoint> {
    let around = Around::of(grid, point, radius)?;
    match nearest_open(grid, point, &around, radius) {
        // No open cell within reach: the scan would find none either.
        Nearest::NoneWithin => None,
        Nearest::Cell(cell, centre) if !around.traversable || grid.line_of_sight(point, centre) => {
            Some(Endpoint {
                point,
                cell,
                traversable: around.traversable,
            })
        }
        // The nearest is not seen (or the cube is beyond the table): every candidate in order.
        Nearest::Cell(..) | Nearest::TooFar => attach_by_scan(grid, point, radius, &around),
    }
}

/// Where a start joins the lattice, and the way to its cell when that is not one leg.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Start {
    pub(super) end: Endpoint,
    /// Points between the start and its cell's centre: the way out of a pocket
    /// ([`super::escape`]); empty for a start attached by [`attach`].
    pub(super) lead: Vec<DVec3>,
}

/// Where a start joins the lattice: [`attach`] within [`SNAP_RADIUS_M`], else, for a
/// traversable start, the nearest open cell it sees within [`START_SEE_RADIUS_M`]. When that
/// cell is an island ([`is_island`]) or there is none, a traversable start takes the nearest
/// cell that is not an island and that it reaches over traversable voxels within
/// [`ESCAPE_RADIUS_M`] ([`way_out`]), else the island, else the nearest open cell it reaches
/// at all.
pub(super) fn attach_start(grid: &TraversableGrid, point: DVec3) -> Option<Start> {
    let traversable = grid.is_traversable_point(point);
    let attached = attach(grid, point, SNAP_RADIUS_M)
        .or_else(|| traversable.then(|| attach(grid, point, START_SEE_RADIUS_M))?);
    let lattice = grid.lattice();
    let start = |end| Start {
        end,
        lead: Vec::new(),
    };
    match attached {
        Some(end) if !is_island(lattice, end.cell) => return Some(start(end)),
        _ if !traversable => return attached.map(start),
        _ => {}
    }
    let escape = |accept: &dyn Fn(usize) -> bool| {
        let (lead, cell) = way_out(grid, point, ESCAPE_RADIUS_M, accept)?;
        Some(Start {
            end: Endpoint {
                point,
                cell,
                traversable,
            },
            lead,
        })
    };
    escape(&|cell| !is_island(lattice, cell))
        .or_else(|| attached.map(start))
        .or_else(|| escape(&|_| true))
}

/// Where a query point lies on the lattice.
#[derive(Clone, Copy)]
pub(super) struct Around {
    /// Whether the point itself is traversable.
    traversable: bool,
    /// The cell holding the point.
    home: IVec3,
    /// Half edge (cells) of the cube around `home` that holds every cell within the radius.
    n: i32,
}

impl Around {
    /// `None` for a point that is not finite or a grid without a lattice.
    pub(super) fn of(grid: &TraversableGrid, point: DVec3, radius: f64) -> Option<Self> {
        if !point.is_finite() || !grid.lattice().is_available() {
            return None;
        }
        Some(Self {
            traversable: grid.is_traversable_point(point),
            home: Lattice::cell_of_key(grid.key_of(point)),
            n: (radius / (2.0 * grid.resolution())).ceil() as i32 + 1,
        })
    }
}

/// [`attach`] by a scan of every cell of the cube around the point's, the candidates within
/// `radius` then taken nearest first until one is seen (a traversable point) or at once.
pub(super) fn attach_by_scan(
    grid: &TraversableGrid,
    point: DVec3,
    radius: f64,
    around: &Around,
) -> Option<Endpoint> {
    let (lattice, resolution) = (grid.lattice(), grid.resolution());
    let Around {
        traversable,
        home,
        n,
    } = *around;
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

/// What [`nearest_open`] found.
enum Nearest {
    /// The open cell nearest to the point within the radius (by distance, then index), and
    /// its centre.
    Cell(usize, DVec3),
    NoneWithin,
    /// The cube to search is larger than [`NEAREST_FIRST_REACH`].
    TooFar,
}

/// Half edge (cells) of the cube of offsets [`nearest_first`] orders.
const NEAREST_FIRST_REACH: i32 = 12;

/// The cell offsets of the cube of half edge [`NEAREST_FIRST_REACH`], nearest first (by
/// squared length), each with its length.
fn nearest_first() -> &'static [(f64, IVec3)] {
    static OFFSETS: std::sync::OnceLock<Vec<(f64, IVec3)>> = std::sync::OnceLock::new();
    OFFSETS.get_or_init(|| {
        let r = NEAREST_FIRST_REACH;
        let mut offsets: Vec<IVec3> = (-r..=r)
            .flat_map(|z| (-r..=r).flat_map(move |y| (-r..=r).map(move |x| IVec3::new(x, y, z))))
            .collect();
        offsets.sort_by_key(|d| d.length_squared());
        offsets
            .into_iter()
            .map(|d| (d.as_dvec3().length(), d))
            .collect()
    })
}

/// The open cell nearest to `point` within `radius`, by distance then cell index (the order
/// in which [`attach_by_scan`] takes its candidates), found by looking at the cells around
/// the point's nearest first and stopping once no farther one can be nearer. The nearest open
/// cell is mostly a few cells away, where the scan looks at the whole cube around the point's
/// cell (some 1,000 cells for a goal). A cell at offset `d` from the point's cell lies at
/// least `|d| 2 resolution - |point - centre|` from the point (triangle inequality; a
/// nanometre of margin for rounding).
fn nearest_open(grid: &TraversableGrid, point: DVec3, around: &Around, radius: f64) -> Nearest {
    let Around { home, n, .. } = *around;
    if n > NEAREST_FIRST_REACH {
        return Nearest::TooFar;
    }
    let (lattice, resolution) = (grid.lattice(), grid.resolution());
    let slack = lattice.centre(home, resolution).distance(point) + 1e-9;
    let mut best: Option<(f64, usize, DVec3)> = None;
    for &(length, d) in nearest_first() {
        let reach = best.map_or(radius, |b| b.0);
        if length * 2.0 * resolution - slack > reach {
            break;
        }
        let cell = home + d;
        let Some(index) = lattice.index(cell).filter(|&i| lattice.is_open(i)) else {
            continue;
        };
        let centre = lattice.centre(cell, resolution);
        let distance = centre.distance(point);
        let nearer = best.is_none_or(|(bd, bi, _)| distance < bd || (distance == bd && index < bi));
        if distance <= radius && nearer {
            best = Some((distance, index, centre));
        }
    }
    best.map_or(Nearest::NoneWithin, |(_, cell, centre)| {
        Nearest::Cell(cell, centre)
    })
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

fn assemble(grid: &TraversableGrid, from: &Start, cells: &[usize], to: &Endpoint) -> Vec<DVec3> {
    let lattice = grid.lattice();
    let mut path = Vec::with_capacity(from.lead.len() + cells.len() + 2);
    path.push(from.end.point);
    for &p in &from.lead {
        push_point(&mut path, p);
    }
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
    let start = attach_start(grid, from)?;
    let goal = attach(grid, to, GOAL_SNAP_RADIUS_M)?;
    let lattice = grid.lattice();
    let mut search = Search::<true>::new(
        lattice,
        start.end.cell,
        lattice.cell(goal.cell),
        max_expansions,
    );
    search.run(lattice, |cell| cell == goal.cell);
    let cells = search
        .nodes()
        .is_closed(goal.cell)
        .then(|| search.trace(lattice.moves(), goal.cell))?;
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
    let which: Vec<usize> = (0..goals.len()).collect();
    PathSearch::new(grid, from, goals, max_expansions).paths(&which)
}

/// [`find_paths`] for goals asked for a few at a time: the Dijkstra search runs only as far as
/// the goals asked for so far need, and goes on from there for the next ones. Its cells settle
/// in the same order whatever it is asked, so every path is the one [`find_paths`] gives,
/// bit for bit; a decision that ranks its clusters nearest first and finds its candidate
/// among the first ones searches a small part of the map instead of all of it.
pub struct PathSearch<'g> {
    grid: &'g TraversableGrid,
    start: Option<Start>,
    goals: Vec<DVec3>,
    /// Where each goal joins the lattice, found when it is first asked for (attaching every
    /// goal of a decision up front cost 1 % of a mission).
    ends: Vec<Option<Option<Endpoint>>>,
    max_expansions: usize,
    /// One bit per lattice cell, set for the cells of goals asked for and not yet settled:
    /// the test runs for every cell the search settles, and a bit lookup stays in cache where
    /// a search of the goal list is a chain of dependent loads.
    pending: Vec<u64>,
    /// Set bits of `pending`.
    remaining: usize,
    /// Started when a goal is first asked for.
    search: Option<Search<false>>,
}

impl<'g> PathSearch<'g> {
    pub fn new(
        grid: &'g TraversableGrid,
        from: DVec3,
        goals: &[DVec3],
        max_expansions: usize,
    ) -> Self {
        Self {
            grid,
            start: attach_start(grid, from),
            goals: goals.to_vec(),
            ends: vec![None; goals.len()],
            max_expansions,
            pending: Vec::new(),
            remaining: 0,
            search: None,
        }
    }

    /// Cells the search has expanded so far.
    pub fn expanded_cells(&self) -> usize {
        self.search.as_ref().map_or(0, Search::expansions)
    }

    /// The paths to the goals `which` (indices into the goals given), in that order: the
    /// search goes on until each of their cells is settled, or no more can be.
    pub fn paths(&mut self, which: &[usize]) -> Vec<Option<Vec<DVec3>>> {
        let Some(start) = &self.start else {
            return vec![None; which.len()];
        };
        let lattice = self.grid.lattice();
        for &goal in which {
            let (grid, point) = (self.grid, self.goals[goal]);
            self.ends[goal].get_or_insert_with(|| attach(grid, point, GOAL_SNAP_RADIUS_M));
        }
        for end in which.iter().filter_map(|&goal| self.ends[goal].flatten()) {
            if self
                .search
                .as_ref()
                .is_some_and(|s| s.nodes().is_closed(end.cell))
            {
                continue;
            }
            if self.pending.is_empty() {
                self.pending = vec![0u64; lattice.len().div_ceil(64)];
            }
            let (word, bit) = (end.cell / 64, 1 << (end.cell % 64));
            self.remaining += usize::from(self.pending[word] & bit == 0);
            self.pending[word] |= bit;
        }
        if self.remaining > 0 {
            let search = self.search.get_or_insert_with(|| {
                Search::new(lattice, start.end.cell, IVec3::ZERO, self.max_expansions)
            });
            let (pending, remaining) = (&mut self.pending, &mut self.remaining);
            search.run(lattice, |cell| {
                let (word, bit) = (cell / 64, 1 << (cell % 64));
                if pending[word] & bit != 0 {
                    pending[word] &= !bit;
                    *remaining -= 1;
                }
                *remaining == 0
            });
        }
        which
            .iter()
            .map(|&goal| {
                let end = self.ends[goal].flatten()?;
                let search = self.search.as_ref()?;
                let cells = search
                    .nodes()
                    .is_closed(end.cell)
                    .then(|| search.trace(lattice.moves(), end.cell))?;
                Some(assemble(self.grid, start, &cells, &end))
            })
            .collect()
    }
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
