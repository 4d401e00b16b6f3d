//! The states of a chunk's voxels by x-row (unknown, occupied; free is neither), kept up to
//! date by the map update.
//!
//! Frontiers and traversability work on 16 voxels at a time: a frontier is a free voxel with an
//! unknown 6-neighbour, a traversable voxel one with no blocking voxel within the UAV's radius,
//! both bit operations on rows. Reading a row's states from its 16 voxels takes about 10 ns,
//! and they read many: the traversability of one chunk reads every row of the chunk and of a
//! halo around it (some 1,000 rows), the frontier update every row of a changed chunk, each
//! time some voxel of them changed. Kept as bits instead, a row is one load, and keeping them
//! costs one bit write per state change: a voxel changes state a few times in a mission (it
//! becomes known once, and crosses l = 0 rarely), against the thousands of reads.

use super::chunk::{CHUNK_EDGE, CHUNK_VOXELS, Voxel};

/// Rows in one chunk: `row = y + 16 z` (local coordinates).
pub const CHUNK_ROWS: usize = CHUNK_VOXELS / CHUNK_EDGE as usize;

/// The states of the 16 voxels of one x-row of a chunk, bit x for voxel x
/// ([`super::VoxelChunk::row_states`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RowStates {
    pub unknown: u16,
    pub occupied: u16,
}

impl RowStates {
    /// Every voxel unknown (a new chunk's rows).
    pub const UNKNOWN: Self = Self {
        unknown: u16::MAX,
        occupied: 0,
    };

    /// The states of `voxels` (one row, voxel x at position x), read voxel by voxel.
    #[inline]
    pub fn of(voxels: &[Voxel]) -> Self {
        let (mut unknown, mut occupied) = (0u16, 0u16);
        for (x, v) in voxels.iter().take(CHUNK_EDGE as usize).enumerate() {
            unknown |= u16::from(v.is_unknown()) << x;
            occupied |= u16::from(v.is_occupied()) << x;
        }
        Self { unknown, occupied }
    }

    /// The free voxels: known and not occupied.
    #[inline]
    pub fn free(self) -> u16 {
        !(self.unknown | self.occupied)
    }
}

/// The [`RowStates`] of every row of one chunk.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ChunkRows([RowStates; CHUNK_ROWS]);

impl ChunkRows {
    /// The rows of a chunk of unknown voxels.
    pub const UNKNOWN: Self = Self([RowStates::UNKNOWN; CHUNK_ROWS]);

    /// The rows of a chunk of unknown voxels.
    pub fn unknown() -> Self {
        Self::UNKNOWN
    }

    /// The rows of `voxels`, read voxel by voxel.
    pub fn of(voxels: &[Voxel; CHUNK_VOXELS]) -> Self {
        let mut rows = Self::unknown();
        for (row, states) in rows.0.iter_mut().enumerate() {
            *states = RowStates::of(&voxels[row * CHUNK_EDGE as usize..]);
        }
        rows
    }

    /// The states of row `row` (taken modulo [`CHUNK_ROWS`]).
    #[inline]
    pub fn get(&self, row: usize) -> RowStates {
        self.0[row % CHUNK_ROWS]
    }

    /// Voxel `index` (a local index, taken modulo [`CHUNK_VOXELS`]) is now known, occupied or
    /// free: the map update calls this whenever it changes a voxel's state.
    #[inline(always)]
    pub fn set_known(&mut self, index: usize, occupied: bool) {
        let index = index % CHUNK_VOXELS;
        let row = &mut self.0[index / CHUNK_EDGE as usize];
        let bit = 1u16 << (index % CHUNK_EDGE as usize);
        row.unknown &= !bit;
        row.occupied = (row.occupied & !bit) | (u16::from(occupied) * bit);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn set_known_changes_one_bit_of_one_row() {
        let mut rows = ChunkRows::unknown();
        // Voxel (x 3, y 2, z 1): row 2 + 16 = 18.
        let index = 3 + 16 * (2 + 16);
        rows.set_known(index, true);
        assert_eq!(
            rows.get(18),
            RowStates {
                unknown: !(1 << 3),
                occupied: 1 << 3
            }
        );
        rows.set_known(index, false);
        assert_eq!(rows.get(18).free(), 1 << 3);
        assert_eq!(rows.get(18).occupied, 0);
        for row in (0..CHUNK_ROWS).filter(|&r| r != 18) {
            assert_eq!(rows.get(row), RowStates::UNKNOWN);
        }
    }
}
