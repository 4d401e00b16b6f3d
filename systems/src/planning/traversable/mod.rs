//! Where the UAV may be: the occupancy map's known free space, shrunk by the UAV's radius
//! (EAAE step 6, "A* or JPS on the voxel grid with obstacle inflation").
//!
//! Rules (decided for this project):
//! - A voxel is **traversable** when it is known free (common.md §1: observed, l < 0) and no
//!   **blocking** voxel lies within the inflation radius, measured Euclidean between voxel
//!   centres (a voxel exactly at the radius counts as within, with a 1e-9 relative tolerance
//!   so that 0.2 m at 0.1 m is 2 voxels whatever the rounding).
//! - Blocking: known occupied, or unknown with at least one unknown 6-neighbour. The body thus
//!   stays in known free space (letting unknown voxels come close flew the UAV into a pillar
//!   face it had never looked at: flying along a face, the camera looks ahead and the face
//!   beside the path stays unknown), except for lone unknown voxels: the holes a matched ray
//!   grid leaves between its rays in space it has seen, which would otherwise block all of it.
//! - The inflation radius is the body's radius and a margin of at least one voxel
//!   ([`inflation_radius`]): distances between voxel centres can understate the true gap
//!   between the UAV and an obstacle face by half a voxel on each side.
//! - Voxels **outside the map box count as occupied** for inflation: the boxes hug the
//!   enclosure walls, whose surface hits may fall just outside the box. (There is no ceiling in
//!   the EAAE scenes; staying a radius below the box top is harmless.)
//! - Goals on the frontier itself are therefore never traversable; the search attaches them to
//!   the nearest open cell (see `super::search`).
//!
//! The grid is kept per map chunk and never recomputed from scratch per query: a changed map
//! chunk marks itself and the chunks the inflation reaches dirty ([`TraversableGrid::mark_changed`]),
//! and [`TraversableGrid::refresh`] recomputes only those, when a planner needs the grid.
//!
//! One chunk's refresh, the inflation by the exact Euclidean ball in bit rows, is the `refresh`
//! module.

mod refresh;

use super::lattice::Lattice;
use crate::mapping::{OccupancyMap, StateChange};
use glam::{DVec3, IVec3};
use uavex_components::map::{CHUNK_EDGE, ChunkCoord, ChunkGrid, MapConfig, floor_to_key};

/// Largest inflation, in voxels: a chunk plus its halo and one voxel more must fit a 64-bit
/// row (16 + 2 x (23 + 1)). Larger radii are clamped (2.3 m at 0.1 m, far beyond any UAV).
pub const MAX_INFLATION_VOXELS: i32 = 23;
const EDGE: i32 = CHUNK_EDGE;
const ROWS: usize = (CHUNK_EDGE * CHUNK_EDGE) as usize;

/// The inflation radius (m) for a body of `body_radius_m` on a map of `resolution`: the radius
/// and a margin of `margin_m` or one voxel, whichever is larger.
///
/// Why at least a voxel: traversability is measured between voxel centres, and face-on to an
/// obstacle a centre lies up to half a voxel from the UAV inside its voxel, and the obstacle's
/// face up to half a voxel from the centre of its own. A margin of one voxel keeps the body off
/// the face whatever the resolution; the tour's 0.1 m margin did so at the thesis' 0.1 m map,
/// not at 0.2 m (7 of 96 missions crashed there; none of 96 with a voxel's margin).
pub fn inflation_radius(body_radius_m: f64, margin_m: f64, resolution: f64) -> f64 {
    body_radius_m + margin_m.max(resolution)
}

/// Traversable flags of one chunk: `rows[y + 16 z]` bit `x` (local coordinates).
type ChunkRows = [u16; ROWS];

/// The traversability of every voxel of a map, as of the last [`TraversableGrid::refresh`].
#[derive(Debug, Clone)]
pub struct TraversableGrid {
    resolution: f64,
    key_min: IVec3,
    key_max: IVec3,
    chunk_grid: ChunkGrid,
    inflation_m: f64,
    /// Inflation in whole voxels (the halo width).
    reach: i32,
    /// The inflation ball's rows ([`BallRow`]) as offsets into `dilated` from the halo's
    /// first row: `half_width` planes up, `reach + dy` rows and `reach + dz` row planes on.
    ball: Vec<usize>,
    /// Per chunk, by flat index; `None` when nothing in it is traversable.
    chunks: Vec<Option<Box<ChunkRows>>>,
    /// Voxels known free without a sensor (see [`TraversableGrid::assume_free_ball`]), per
    /// chunk as rows; `None` when none.
    assumed_free: Vec<Option<Box<ChunkRows>>>,
    dirty_flags: Vec<bool>,
    dirty: Vec<usize>,
    lattice: Lattice,
    /// Halo blocking rows, and the same dilated along x by 0..=reach.
    occupied: Vec<u64>,
    /// Occupied and unknown rows over the halo widened by one voxel (see `gather`).
    gathered_occupied: Vec<u64>,
    gathered_unknown: Vec<u64>,
    dilated: Vec<u64>,
}

impl TraversableGrid {
    /// An empty grid (nothing traversable) for the map of `config`, inflating obstacles by
    /// `inflation_m`. A negative or non-finite radius is taken as 0; radii above
    /// [`MAX_INFLATION_VOXELS`] voxels are clamped to it ([`Self::inflation_m`] tells).
    pub fn new(config: &MapConfig, inflation_m: f64) -> Self {
        let resolution = config.resolution();
        let max = f64::from(MAX_INFLATION_VOXELS) * resolution;
        let inflation_m = if inflation_m.is_finite() && inflation_m > 0.0 {
            inflation_m.min(max)
        } else {
            0.0
        };
        let (reach, ball) = refresh::ball_rows(inflation_m / resolution);
        let chunk_grid = config.chunk_grid();
        let n = chunk_grid.len();
        let width = (EDGE + 2 * reach) as usize;
        let ball = ball
            .iter()
            .map(|row| {
                let (hy, hz) = ((reach + row.dy) as usize, (reach + row.dz) as usize);
                row.half_width as usize * width * width + hy + width * hz
            })
            .collect();
        Self {
            resolution,
            key_min: config.key_min(),
            key_max: config.key_max(),
            chunk_grid,
            inflation_m,
            reach,
            ball,
            chunks: vec![None; n],
            assumed_free: vec![None; n],
            dirty_flags: vec![false; n],
            dirty: Vec::new(),
            lattice: Lattice::new(config.key_min(), config.key_max()),
            occupied: vec![0; width * width],
            gathered_occupied: vec![0; (width + 2) * (width + 2)],
            gathered_unknown: vec![0; (width + 2) * (width + 2)],
            dilated: vec![0; (reach as usize + 1) * width * width],
        }
    }

    /// The inflation radius in use (m).
    pub fn inflation_m(&self) -> f64 {
        self.inflation_m
    }

    pub fn resolution(&self) -> f64 {
        self.resolution
    }

    /// Whether this grid was built for a map of `config`'s geometry.
    pub fn matches(&self, config: &MapConfig) -> bool {
        self.resolution == config.resolution()
            && self.key_min == config.key_min()
            && self.key_max == config.key_max()
    }

    /// A map chunk changed anywhere: it and every chunk the inflation reaches from it become
    /// dirty. Chunks outside the map's chunk grid are ignored.
    pub fn mark_changed(&mut self, chunk: ChunkCoord) {
        self.mark_state_change(chunk.into());
    }

    /// Voxel states changed in some bricks of a map chunk: it and every chunk the inflation
    /// reaches from those bricks become dirty. Chunks outside the map's chunk grid are ignored.
    pub fn mark_state_change(&mut self, change: StateChange) {
        if self.chunk_grid.flat(change.coord).is_none() {
            return;
        }
        // The inflation reaches `reach` voxels, and whether an unknown voxel blocks depends on
        // its neighbours one voxel further.
        let margin = self.reach + 1;
        let span = (margin + EDGE - 1) / EDGE;
        for dz in -span..=span {
            for dy in -span..=span {
                for dx in -span..=span {
                    let offset = IVec3::new(dx, dy, dz);
                    if !change.reaches(offset, margin) {
                        continue;
                    }
                    if let Some(flat) = self.chunk_grid.flat(ChunkCoord(change.coord.0 + offset)) {
                        self.mark_flat(flat);
                    }
                }
            }
        }
    }

    /// Takes the voxels whose centres lie within `radius_m` of `center` as known free, whatever
    /// the map says, from now on: the space the UAV's body occupies at its start, which the
    /// scenario checks against the true geometry. (A forward camera never sees beside and
    /// below itself: without this, the whole-body rule would leave the start untraversable.)
    pub fn assume_free_ball(&mut self, center: DVec3, radius_m: f64) {
        if !(center.is_finite() && radius_m.is_finite() && radius_m >= 0.0) {
            return;
        }
        let r = radius_m / self.resolution;
        let c = center / self.resolution;
        let lo = floor_to_key(c - DVec3::splat(r)).max(self.key_min);
        let hi = floor_to_key(c + DVec3::splat(r)).min(self.key_max);
        let mut touched = Vec::new();
        for z in lo.z..=hi.z {
            for y in lo.y..=hi.y {
                for x in lo.x..=hi.x {
                    let key = IVec3::new(x, y, z);
                    if (key.as_dvec3() + DVec3::splat(0.5)).distance(c) > r {
                        continue;
                    }
                    let coord = ChunkCoord::of_key(key);
                    let flat = self.chunk_grid.flat_unchecked(coord);
                    let rows = self.assumed_free[flat].get_or_insert_with(|| Box::new([0; ROWS]));
                    let l = key & (EDGE - 1);
                    rows[(l.y + EDGE * l.z) as usize] |= 1 << l.x;
                    if !touched.contains(&coord) {
                        touched.push(coord);
                    }
                }
            }
        }
        for coord in touched {
            self.mark_changed(coord);
        }
    }

    /// Every chunk dirty (a grid created for a map that already holds chunks).
    pub fn mark_all(&mut self) {
        for flat in 0..self.chunk_grid.len() {
            self.mark_flat(flat);
        }
    }

    /// Number of chunks waiting for a refresh.
    pub fn dirty_chunks(&self) -> usize {
        self.dirty_flags.iter().filter(|&&dirty| dirty).count()
    }

    fn mark_flat(&mut self, flat: usize) {
        if !self.dirty_flags[flat] {
            self.dirty_flags[flat] = true;
            self.dirty.push(flat);
        }
    }

    /// Recomputes the dirty chunks from `map` (see `follow_geometry` for a map of
    /// another geometry).
    pub fn refresh(&mut self, map: &impl OccupancyMap) {
        self.follow_geometry(map);
        let mut dirty = std::mem::take(&mut self.dirty);
        dirty.sort_unstable();
        for &flat in &dirty {
            // Chunks brought up to date one by one since they were marked are skipped.
            if std::mem::take(&mut self.dirty_flags[flat]) {
                self.refresh_chunk(map, flat);
            }
        }
        dirty.clear();
        self.dirty = dirty;
    }

    /// Recomputes the chunk holding `p` if it is dirty, so that queries of the voxels of that
    /// chunk are up to date (a chunk's traversability reads the map only, never its
    /// neighbours' traversability). Points outside the map or not finite are ignored.
    pub fn refresh_at(&mut self, map: &impl OccupancyMap, p: DVec3) {
        self.follow_geometry(map);
        if !p.is_finite() {
            return;
        }
        let key = self.key_of(p);
        if key.cmplt(self.key_min).any() || key.cmpgt(self.key_max).any() {
            return;
        }
        let flat = self.chunk_grid.flat_unchecked(ChunkCoord::of_key(key));
        if std::mem::take(&mut self.dirty_flags[flat]) {
            self.refresh_chunk(map, flat);
        }
    }

    /// A map of another geometry (e.g. after a change of resolution) rebuilds the grid from
    /// scratch for it, with the same inflation radius, every chunk dirty.
    fn follow_geometry(&mut self, map: &impl OccupancyMap) {
        if !self.matches(map.config()) {
            *self = Self::new(map.config(), self.inflation_m);
            self.mark_all();
        }
    }

    /// Whether voxel `key` is traversable (false outside the map).
    #[inline]
    pub fn is_traversable(&self, key: IVec3) -> bool {
        if key.cmplt(self.key_min).any() || key.cmpgt(self.key_max).any() {
            return false;
        }
        self.rows_of(ChunkCoord::of_key(key))
            .is_some_and(|rows| row_bit(rows, key))
    }

    /// The traversable rows of the chunk at `coord` (inside the map), if any voxel of it is.
    #[inline]
    fn rows_of(&self, coord: ChunkCoord) -> Option<&ChunkRows> {
        self.chunks[self.chunk_grid.flat_unchecked(coord)].as_deref()
    }

    /// Whether the voxel holding `p` is traversable (false for non-finite points).
    #[inline]
    pub fn is_traversable_point(&self, p: DVec3) -> bool {
        p.is_finite() && self.is_traversable(self.key_of(p))
    }

    /// Key of the voxel holding `p` (`floor(p / resolution)`, as the map's keys).
    #[inline]
    pub fn key_of(&self, p: DVec3) -> IVec3 {
        floor_to_key(p / self.resolution)
    }

    /// The search lattice over this grid (see [`super::lattice`]).
    pub fn lattice(&self) -> &Lattice {
        &self.lattice
    }

    /// Whether every voxel from `a` to `b` (world points) on the straight segment is
    /// traversable (the voxel traversal of `crate::mapping::dda`, 6-connected, so a segment
    /// through an edge or corner also needs a voxel beside it).
    pub fn line_of_sight(&self, a: DVec3, b: DVec3) -> bool {
        if !(a.is_finite() && b.is_finite()) {
            return false;
        }
        if !self.is_traversable_point(a) || !self.is_traversable_point(b) {
            return false;
        }
        let (ua, ub) = (a / self.resolution, b / self.resolution);
        // The walk stays in the map's keys and in one chunk for up to 16 steps: the chunk's
        // rows are looked up when it changes, not at every voxel.
        let first = ChunkCoord::of_key(self.key_of(a));
        let mut chunk = (first, self.rows_of(first));
        crate::mapping::dda::all_keys(ua, ub, self.key_min, self.key_max, |key| {
            let coord = ChunkCoord::of_key(key);
            if coord != chunk.0 {
                chunk = (coord, self.rows_of(coord));
            }
            chunk.1.is_some_and(|rows| row_bit(rows, key))
        })
    }
}

/// Bit of voxel `key` in its chunk's rows.
#[inline]
fn row_bit(rows: &ChunkRows, key: IVec3) -> bool {
    let l = key & (EDGE - 1);
    rows[(l.y + EDGE * l.z) as usize] >> l.x & 1 == 1
}
