//! The map update's position inside a chunk (`super::integrate`'s walk): the voxel index and
//! the chunk-local coordinates in one integer, so that a step is one add and leaving the chunk
//! one mask test.

use glam::IVec3;
use uavex_components::map::{CHUNK_EDGE, CHUNK_VOXELS, local_index};

/// Index step inside a chunk for a +1 step along x, y, z (see `local_index`).
const STRIDE: [isize; 3] = [1, CHUNK_EDGE as isize, (CHUNK_EDGE * CHUNK_EDGE) as isize];

/// Cursor step for +1 along x, y, z: the voxel index stride in the low 32 bits, and +1 in the
/// byte of the axis' local coordinate in the high 32 bits.
pub(super) const CURSOR_X: i64 = (1 << 32) + STRIDE[0] as i64;
pub(super) const CURSOR_Y: i64 = (1 << 40) + STRIDE[1] as i64;
pub(super) const CURSOR_Z: i64 = (1 << 48) + STRIDE[2] as i64;

/// Position inside a chunk: the voxel index plus [`CHUNK_VOXELS`] in the low 32 bits (so a
/// step out of the chunk never borrows from the high half), and local x, y, z plus 16 in bytes
/// 4, 5, 6 (in 16..=31 inside the chunk, 15 or 32 just outside: the high nibble tells).
#[derive(Clone, Copy)]
pub(super) struct Cursor(pub(super) u64);

impl Cursor {
    const BIAS: u64 = 0x0010_1010_0000_0000 + CHUNK_VOXELS as u64;
    const NIBBLES: u64 = 0x00F0_F0F0_0000_0000;
    const INSIDE: u64 = 0x0010_1010_0000_0000;

    #[inline(always)]
    pub(super) fn at(key: IVec3) -> Self {
        let l = (key & (CHUNK_EDGE - 1)).as_u64vec3();
        Self(Self::BIAS + local_index(key) as u64 + (l.x << 32) + (l.y << 40) + (l.z << 48))
    }

    #[inline(always)]
    pub(super) fn index(self) -> usize {
        (self.0 as usize) & (CHUNK_VOXELS - 1)
    }

    #[inline(always)]
    pub(super) fn left_chunk(self) -> bool {
        self.0 & Self::NIBBLES != Self::INSIDE
    }

    /// Local coordinates inside the chunk (0..16 per axis, while inside).
    #[inline(always)]
    pub(super) fn local_array(self) -> [i64; 3] {
        let byte = |shift: u64| ((self.0 >> shift) & 0xFF) as i64 - i64::from(CHUNK_EDGE);
        [byte(32), byte(40), byte(48)]
    }

    /// Local coordinates (-1 or 16 on the axis just stepped out of the chunk).
    pub(super) fn local(self) -> IVec3 {
        let byte = |shift: u64| ((self.0 >> shift) & 0xFF) as i32 - CHUNK_EDGE;
        IVec3::new(byte(32), byte(40), byte(48))
    }
}
