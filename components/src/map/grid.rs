//! The grid of chunks covering the map, and its dense flat index.

use super::chunk::ChunkCoord;
use glam::IVec3;

/// The grid of chunks covering the map's key box, with the dense flat index
/// `x + dims.x (y + dims.y z)` of chunk coordinates relative to `min`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ChunkGrid {
    /// Smallest chunk coordinate.
    pub min: IVec3,
    /// Chunks along each axis.
    pub dims: IVec3,
}

impl ChunkGrid {
    /// Number of chunks in the grid.
    pub fn len(&self) -> usize {
        (self.dims.x as usize) * (self.dims.y as usize) * (self.dims.z as usize)
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Flat index of `coord`, or `None` outside the grid.
    #[inline]
    pub fn flat(&self, coord: ChunkCoord) -> Option<usize> {
        let r = coord.0 - self.min;
        if r.cmplt(IVec3::ZERO).any() || r.cmpge(self.dims).any() {
            return None;
        }
        Some(self.flat_unchecked(coord))
    }

    /// Flat index of a coordinate known to lie in the grid (meaningless otherwise).
    #[inline]
    pub fn flat_unchecked(&self, coord: ChunkCoord) -> usize {
        let r = coord.0 - self.min;
        r.x as usize + self.dims.x as usize * (r.y as usize + self.dims.y as usize * r.z as usize)
    }

    /// Chunk coordinate of flat index `flat` (inverse of [`Self::flat`]).
    pub fn coord(&self, flat: usize) -> ChunkCoord {
        let (dx, dy) = (self.dims.x as usize, self.dims.y as usize);
        let r = IVec3::new(
            (flat % dx) as i32,
            ((flat / dx) % dy) as i32,
            (flat / (dx * dy)) as i32,
        );
        ChunkCoord(self.min + r)
    }
}

#[cfg(test)]
mod tests {
    use super::super::config::tests::config;
    use super::*;

    #[test]
    fn chunk_grid_flat_round_trips() {
        let c = config(-3.3, 5.1, 0.1);
        let grid = c.chunk_grid();
        for flat in 0..grid.len() {
            assert_eq!(grid.flat(grid.coord(flat)), Some(flat));
        }
        assert_eq!(grid.flat(ChunkCoord(grid.min - IVec3::X)), None);
        assert_eq!(grid.flat(ChunkCoord(grid.min + grid.dims)), None);
    }
}
