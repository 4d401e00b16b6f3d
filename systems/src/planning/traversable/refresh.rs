//! One chunk's refresh of the traversable grid (see the parent module for the rules): the
//! occupied voxels of the chunk and a halo of `R = floor(radius / resolution)` voxels around it
//! are gathered as bit rows along x; each row is dilated along x by every half-width the ball
//! has, and a voxel's row is then blocked by the OR, over the ball's (dy, dz) rows, of the
//! neighbouring row dilated by that row's half-width `floor(sqrt(R'^2 - dy^2 - dz^2))`. That is
//! the exact Euclidean ball as a union of x-runs, in a few thousand word operations per chunk.

use super::super::lattice::Lattice;
use super::{ChunkRows, EDGE, MAX_INFLATION_VOXELS, ROWS, TraversableGrid};
use crate::mapping::OccupancyMap;
use glam::IVec3;
use uavex_components::map::ChunkCoord;

/// One row of the inflation ball: voxels at (dx, dy, dz) with |dx| <= half_width.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct BallRow {
    pub(super) dy: i32,
    pub(super) dz: i32,
    pub(super) half_width: i32,
}

impl TraversableGrid {
    pub(super) fn refresh_chunk(&mut self, map: &impl OccupancyMap, flat: usize) {
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
}

/// The inflation ball as x-runs: the whole-voxel reach and every (dy, dz) row with its
/// half-width, for a radius of `radius_voxels` voxels.
pub(super) fn ball_rows(radius_voxels: f64) -> (i32, Vec<BallRow>) {
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
