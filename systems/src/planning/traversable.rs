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
//! One chunk's refresh: the occupied voxels of the chunk and a halo of `R = floor(radius /
//! resolution)` voxels around it are gathered as bit rows along x; each row is dilated along x
//! by every half-width the ball has, and a voxel's row is then blocked by the OR, over the
//! ball's (dy, dz) rows, of the neighbouring row dilated by that row's half-width
//! `floor(sqrt(R'^2 - dy^2 - dz^2))`. That is the exact Euclidean ball as a union of x-runs, in
//! a few thousand word operations per chunk.

use super::lattice::Lattice;
use crate::mapping::{OccupancyMap, StateChange};
use glam::{DVec3, IVec3};
use uavex_components::map::{CHUNK_EDGE, ChunkCoord, ChunkGrid, MapConfig, floor_to_key};

/// Largest inflation, in voxels: a chunk plus its halo and one voxel more must fit a 64-bit
/// row (16 + 2 x (23 + 1)). Larger radii are clamped (2.3 m at 0.1 m, far beyond any UAV).
pub const MAX_INFLATION_VOXELS: i32 = 23;
const EDGE: i32 = CHUNK_EDGE;
const ROWS: usize = (CHUNK_EDGE * CHUNK_EDGE) as usize;

/// Traversable flags of one chunk: `rows[y + 16 z]` bit `x` (local coordinates).
type ChunkRows = [u16; ROWS];

/// One row of the inflation ball: voxels at (dx, dy, dz) with |dx| <= half_width.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct BallRow {
    dy: i32,
    dz: i32,
    half_width: i32,
}

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
        let (reach, ball) = ball_rows(inflation_m / resolution);
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

    fn refresh_chunk(&mut self, map: &impl OccupancyMap, flat: usize) {
        let coord = self.chunk_grid.coord(flat);
        let first = coord.first_key();
        let mut free = match map.chunk(coord) {
            Some(chunk) => self.free_rows(chunk, first),
            None => [0; ROWS],
        };
        if let Some(assumed) = &self.assumed_free[flat] {
            free.iter_mut()
                .zip(assumed.iter())
                .for_each(|(f, a)| *f |= a);
        }
        let rows = if free.iter().any(|&r| r != 0) {
            let blocked = self.blocked_rows(map, first);
            let mut rows = free;
            rows.iter_mut()
                .zip(blocked.iter())
                .for_each(|(r, b)| *r &= !b);
            rows.iter().any(|&r| r != 0).then_some(rows)
        } else {
            None
        };
        self.update_lattice(first, rows.as_ref());
        match (&mut self.chunks[flat], rows) {
            (Some(stored), Some(rows)) => **stored = rows,
            (slot, rows) => *slot = rows.map(Box::new),
        }
    }

    /// Known-free voxels of the chunk inside the map box, as rows.
    fn free_rows(&self, chunk: &uavex_components::map::VoxelChunk, first: IVec3) -> ChunkRows {
        let mut rows = [0u16; ROWS];
        // Bits of x keys inside the box.
        let mut x_mask = 0u16;
        for lx in 0..EDGE {
            let x = first.x + lx;
            if (self.key_min.x..=self.key_max.x).contains(&x) {
                x_mask |= 1 << lx;
            }
        }
        for lz in 0..EDGE {
            for ly in 0..EDGE {
                let (y, z) = (first.y + ly, first.z + lz);
                if !(self.key_min.y..=self.key_max.y).contains(&y)
                    || !(self.key_min.z..=self.key_max.z).contains(&z)
                {
                    continue;
                }
                let row = (ly + EDGE * lz) as usize;
                rows[row] = chunk.row_states(row).free() & x_mask;
            }
        }
        rows
    }

    /// Voxels of the chunk with a blocking voxel (see the module doc) within the radius.
    fn blocked_rows(&mut self, map: &impl OccupancyMap, first: IVec3) -> ChunkRows {
        let r = self.reach;
        let width = EDGE + 2 * r;
        let w = width as usize;
        self.gather(map, first);
        // Blocking voxels of the inflation halo: occupied, or unknown with an unknown
        // 6-neighbour (the gathered grid is one voxel wider on every side for these).
        let gw = w + 2;
        let mask = if width == 64 {
            u64::MAX
        } else {
            (1u64 << width) - 1
        };
        for z in 1..=w {
            for y in 1..=w {
                let i = y + gw * z;
                let u = self.gathered_unknown[i];
                let neighbours = u << 1
                    | u >> 1
                    | self.gathered_unknown[i - 1]
                    | self.gathered_unknown[i + 1]
                    | self.gathered_unknown[i - gw]
                    | self.gathered_unknown[i + gw];
                let blocking = self.gathered_occupied[i] | (u & neighbours);
                self.occupied[(y - 1) + w * (z - 1)] = (blocking >> 1) & mask;
            }
        }
        // Dilation along x by each half-width 0..=r.
        let plane = w * w;
        self.dilated[..plane].copy_from_slice(&self.occupied);
        for s in 1..=r as usize {
            for i in 0..plane {
                let o = self.occupied[i];
                self.dilated[s * plane + i] = self.dilated[(s - 1) * plane + i] | o << s | o >> s;
            }
        }
        // A voxel row (ly, lz) is blocked by the OR of the ball's rows: the dilated rows at
        // `ly + w lz + offset`. The 16 rows of one lz take their terms from 16 consecutive
        // words for every offset, so they are ORed together, a plane at a time, from one slice
        // each (row by row, the fold was a bounds-checked load per term).
        const E: usize = EDGE as usize;
        let mut blocked = [0u16; ROWS];
        for (lz, out) in blocked.chunks_exact_mut(E).enumerate() {
            let mut bits = [0u64; E];
            for &offset in &self.ball {
                let at = offset + w * lz;
                let rows: &[u64; E] = self.dilated[at..at + E]
                    .try_into()
                    .expect("a slice of E words");
                for (b, row) in bits.iter_mut().zip(rows) {
                    *b |= row;
                }
            }
            for (o, b) in out.iter_mut().zip(bits) {
                *o = (b >> r) as u16;
            }
        }
        blocked
    }

    /// Gathers, over the chunk and a halo of `reach + 1` voxels, the occupied voxels (known
    /// occupied, or outside the box) and the unknown ones (in the box, never observed, not
    /// assumed free) as bit rows along x.
    fn gather(&mut self, map: &impl OccupancyMap, first: IVec3) {
        let g = self.reach + 1;
        let width = EDGE + 2 * g;
        let gw = width as usize;
        let halo_min = first - IVec3::splat(g);
        let halo_max = first + IVec3::splat(EDGE - 1 + g);
        let all = if width == 64 {
            u64::MAX
        } else {
            (1u64 << width) - 1
        };
        let mut outside_x = 0u64;
        for hx in 0..width {
            if !(self.key_min.x..=self.key_max.x).contains(&(halo_min.x + hx)) {
                outside_x |= 1 << hx;
            }
        }
        for hz in 0..width {
            for hy in 0..width {
                let (y, z) = (halo_min.y + hy, halo_min.z + hz);
                let in_yz = (self.key_min.y..=self.key_max.y).contains(&y)
                    && (self.key_min.z..=self.key_max.z).contains(&z);
                let i = hy as usize + gw * hz as usize;
                // Out of the box: occupied. In it: unknown until observed.
                self.gathered_occupied[i] = if in_yz { outside_x } else { all };
                self.gathered_unknown[i] = if in_yz { all & !outside_x } else { 0 };
            }
        }
        let (c_lo, c_hi) = (
            ChunkCoord::of_key(halo_min).0,
            ChunkCoord::of_key(halo_max).0,
        );
        for cz in c_lo.z..=c_hi.z {
            for cy in c_lo.y..=c_hi.y {
                for cx in c_lo.x..=c_hi.x {
                    let coord = ChunkCoord(IVec3::new(cx, cy, cz));
                    let chunk = map.chunk(coord);
                    let assumed = self
                        .chunk_grid
                        .flat(coord)
                        .and_then(|flat| self.assumed_free[flat].as_deref());
                    if chunk.is_none() && assumed.is_none() {
                        continue;
                    }
                    let c_first = coord.first_key();
                    let lo = halo_min.max(c_first).max(self.key_min);
                    let hi = halo_max
                        .min(c_first + IVec3::splat(EDGE - 1))
                        .min(self.key_max);
                    if lo.cmpgt(hi).any() {
                        continue;
                    }
                    // The chunk's x range inside the halo and the box, as bits of its rows,
                    // and where its bit 0 lands in a halo row (left of it for a chunk that
                    // starts before the halo).
                    let (lx_lo, lx_hi) = ((lo.x - c_first.x) as u32, (hi.x - c_first.x) as u32);
                    let in_range = ((1u32 << (lx_hi + 1)) - (1u32 << lx_lo)) as u16;
                    let shift = c_first.x - halo_min.x;
                    let to_halo = |bits: u16| {
                        let bits = u64::from(bits & in_range);
                        if shift >= 0 {
                            bits << shift
                        } else {
                            bits >> -shift
                        }
                    };
                    for z in lo.z..=hi.z {
                        for y in lo.y..=hi.y {
                            let local_row = ((y - c_first.y) + EDGE * (z - c_first.z)) as usize;
                            let i = (y - halo_min.y) as usize + gw * (z - halo_min.z) as usize;
                            let assumed_row = assumed.map_or(0, |a| a[local_row]);
                            let (known, occupied) = chunk.map_or((0, 0), |chunk| {
                                let states = chunk.row_states(local_row);
                                (!states.unknown, states.occupied)
                            });
                            // An assumed-free voxel is known and not occupied, whatever the map
                            // holds.
                            self.gathered_unknown[i] &= !to_halo(known | assumed_row);
                            self.gathered_occupied[i] |= to_halo(occupied & !assumed_row);
                        }
                    }
                }
            }
        }
    }

    /// Writes the chunk's cells into the lattice (a cell is open when all 8 voxels are).
    fn update_lattice(&mut self, first: IVec3, rows: Option<&ChunkRows>) {
        let first_cell = Lattice::cell_of_key(first);
        // Bit 2x of a voxel row pair's AND with itself shifted: voxels 2x and 2x + 1 free.
        // The even bits, packed (bit 2x to bit x) in three shift-and-mask steps.
        let cell_bits = |pair: u16| {
            let even = u32::from(pair) & 0x5555;
            let two = (even | even >> 1) & 0x3333;
            let four = (two | two >> 2) & 0x0f0f;
            (four | four >> 4) & 0x00ff
        };
        self.lattice.set_rows(first_cell, EDGE / 2, |cy, cz| {
            rows.map_or(0, |rows| {
                let at = |y: i32, z: i32| rows[(y + EDGE * z) as usize];
                let (y, z) = (2 * cy, 2 * cz);
                let r = at(y, z) & at(y + 1, z) & at(y, z + 1) & at(y + 1, z + 1);
                cell_bits(r & (r >> 1))
            })
        });
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

/// The inflation ball as x-runs: the whole-voxel reach and every (dy, dz) row with its
/// half-width, for a radius of `radius_voxels` voxels.
fn ball_rows(radius_voxels: f64) -> (i32, Vec<BallRow>) {
    let limit = radius_voxels * radius_voxels * (1.0 + 1e-9) + 1e-9;
    let within = |d2: i32| f64::from(d2) <= limit;
    let mut reach = 0;
    while reach < MAX_INFLATION_VOXELS && within((reach + 1) * (reach + 1)) {
        reach += 1;
    }
    let mut rows = Vec::new();
    for dz in -reach..=reach {
        for dy in -reach..=reach {
            let yz = dy * dy + dz * dz;
            if !within(yz) {
                continue;
            }
            let mut half_width = 0;
            while half_width < reach && within(yz + (half_width + 1) * (half_width + 1)) {
                half_width += 1;
            }
            rows.push(BallRow { dy, dz, half_width });
        }
    }
    (reach, rows)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ball_rows_of_two_voxels() {
        // Radius 2: offsets with dx^2 + dy^2 + dz^2 <= 4. Rows (dy, dz): (0, 0) half-width 2;
        // the four (+-1, 0), (0, +-1): 1 (1 + 1 <= 4, 1 + 4 > 4); the four (+-1, +-1): 1
        // (2 + 1 <= 4); the four (+-2, 0), (0, +-2): 0. 13 rows, 33 voxels in the ball.
        let (reach, rows) = ball_rows(2.0);
        assert_eq!(reach, 2);
        assert_eq!(rows.len(), 13);
        let voxels: i32 = rows.iter().map(|r| 2 * r.half_width + 1).sum();
        assert_eq!(voxels, 5 + 4 * 3 + 4 * 3 + 4);
        // 0.2 m / 0.1 m is 2.0000000000000004 or 1.9999999999999998 depending on the path: the
        // tolerance keeps the boundary voxel.
        assert_eq!(ball_rows(1.999_999_999_999_999_8).0, 2);
        assert_eq!(
            ball_rows(0.0),
            (
                0,
                vec![BallRow {
                    dy: 0,
                    dz: 0,
                    half_width: 0
                }]
            )
        );
    }
}
