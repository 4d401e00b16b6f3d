//! Frontier detection (eaae.md step 1), kept incrementally per chunk.
//!
//! **Definition** (decided for uavex): a frontier voxel is a known-*free* voxel with at least one
//! *unknown* 6-neighbour *inside the map*. Neighbours outside the map's box are never observed
//! (common.md §1: voxels outside it are never created), so counting them as unknown would make
//! the top layer and every face of the box frontier forever; they are not counted.
//!
//! A voxel's status depends on itself and its six neighbours only, so when a scan changes a
//! chunk, the voxels whose status may change lie in that chunk and in the face layers of its six
//! face-neighbour chunks, of those only whose face a changed brick touches
//! ([`StateChange::reaches`] within one voxel). [`update_frontier_set`] re-examines exactly
//! those chunks, whole, with the row-parallel [`chunk_frontier`]: 16 voxels (one x-row) per
//! machine word, the x neighbours by shifts and the y/z neighbours as adjacent rows, read from
//! the chunk arrays (no per-key lookups).

use super::super::mapping::{OccupancyMap, StateChange};
use glam::IVec3;
use uavex_components::frontier::{FrontierSet, VoxelMask};
use uavex_components::map::{CHUNK_EDGE, ChunkCoord, VoxelChunk, VoxelState};

/// Padded edge: the chunk's 16 voxels plus one neighbour layer on each side.
const PADDED: usize = CHUNK_EDGE as usize + 2;
const EDGE: usize = CHUNK_EDGE as usize;

/// Whether `key` is a frontier voxel of `map`: known free with an unknown 6-neighbour inside the
/// map (see the module documentation). The per-voxel reference of [`chunk_frontier`].
pub fn is_frontier(map: &impl OccupancyMap, key: IVec3) -> bool {
    if map.state(key) != VoxelState::Free {
        return false;
    }
    let config = map.config();
    NEIGHBOURS.iter().any(|&d| {
        let n = key + d;
        config.contains_key(n) && map.state(n) == VoxelState::Unknown
    })
}

/// The six face neighbours' offsets.
pub const NEIGHBOURS: [IVec3; 6] = [
    IVec3::NEG_X,
    IVec3::X,
    IVec3::NEG_Y,
    IVec3::Y,
    IVec3::NEG_Z,
    IVec3::Z,
];

/// Unknown bits of row (y, z) of a neighbour chunk; a chunk never created is all unknown.
fn unknown_row(chunk: Option<&VoxelChunk>, y: usize, z: usize) -> u16 {
    chunk.map_or(u16::MAX, |c| c.row_states(y + EDGE * z).unknown)
}

/// Whether voxel (x, y, z) of a neighbour chunk is unknown.
fn unknown_voxel(chunk: Option<&VoxelChunk>, x: usize, y: usize, z: usize) -> bool {
    chunk.is_none_or(|c| c.voxels()[x + EDGE * (y + EDGE * z)].is_unknown())
}

/// The frontier voxels of the chunk at `coord` (see the module documentation).
pub fn chunk_frontier(map: &impl OccupancyMap, coord: ChunkCoord) -> VoxelMask {
    let mut out = VoxelMask::EMPTY;
    // A chunk never created holds no known voxel, hence no free one.
    let Some(chunk) = map.chunk(coord) else {
        return out;
    };
    // unknown[pz][py]: bit px of the padded row (local coordinates shifted by +1), only for the
    // interior rows and the six face layers (edges and corners are no 6-neighbour of the chunk).
    let mut free = [0u16; EDGE * EDGE];
    let mut unknown = [[0u32; PADDED]; PADDED];
    for z in 0..EDGE {
        for y in 0..EDGE {
            let states = chunk.row_states(y + EDGE * z);
            free[y + EDGE * z] = states.free();
            unknown[z + 1][y + 1] = u32::from(states.unknown) << 1;
        }
    }
    if free.iter().all(|&r| r == 0) {
        return out;
    }
    let neighbour = |d: IVec3| map.chunk(ChunkCoord(coord.0 + d));
    let (nx, px) = (neighbour(IVec3::NEG_X), neighbour(IVec3::X));
    for z in 0..EDGE {
        for y in 0..EDGE {
            let low = u32::from(unknown_voxel(nx, EDGE - 1, y, z));
            let high = u32::from(unknown_voxel(px, 0, y, z)) << (EDGE + 1);
            unknown[z + 1][y + 1] |= low | high;
        }
    }
    let (ny, py) = (neighbour(IVec3::NEG_Y), neighbour(IVec3::Y));
    let (nz, pz) = (neighbour(IVec3::NEG_Z), neighbour(IVec3::Z));
    for i in 0..EDGE {
        // Row i of the y faces is z = i; of the z faces, y = i.
        unknown[i + 1][0] = u32::from(unknown_row(ny, EDGE - 1, i)) << 1;
        unknown[i + 1][PADDED - 1] = u32::from(unknown_row(py, 0, i)) << 1;
        unknown[0][i + 1] = u32::from(unknown_row(nz, i, EDGE - 1)) << 1;
        unknown[PADDED - 1][i + 1] = u32::from(unknown_row(pz, i, 0)) << 1;
    }

    // Only voxels inside the map count as unknown neighbours.
    let config = map.config();
    let first = coord.first_key();
    let lo = (config.key_min() - first + IVec3::ONE).max(IVec3::ZERO);
    let hi = (config.key_max() - first + IVec3::ONE).min(IVec3::splat(PADDED as i32 - 1));
    let x_mask = if lo.x > hi.x {
        0
    } else {
        (u32::MAX >> (31 - hi.x as u32)) & (u32::MAX << lo.x as u32)
    };
    for (pz, plane) in unknown.iter_mut().enumerate() {
        for (py, row) in plane.iter_mut().enumerate() {
            let inside =
                (lo.y..=hi.y).contains(&(py as i32)) && (lo.z..=hi.z).contains(&(pz as i32));
            *row = if inside { *row & x_mask } else { 0 };
        }
    }

    for z in 0..EDGE {
        for y in 0..EDGE {
            let f = free[y + EDGE * z];
            if f == 0 {
                continue;
            }
            let (pz, py) = (z + 1, y + 1);
            let u = unknown[pz][py];
            let near = (u << 1)
                | (u >> 1)
                | unknown[pz][py - 1]
                | unknown[pz][py + 1]
                | unknown[pz - 1][py]
                | unknown[pz + 1][py];
            // Padded bit x + 1 is local x.
            out.0[y + EDGE * z] = f & (near >> 1) as u16;
        }
    }
    out
}

/// Re-examines the `changed` chunks AND those of their 6 face-neighbour chunks whose face a
/// changed brick touches (a voxel turning known changes the frontier status of its neighbours
/// across a chunk face), and writes their frontier voxels into `set`. `changed` holds
/// [`StateChange`]s, or chunk coordinates (a change anywhere in the chunk). Plain function, no
/// ECS; the order of `changed` does not matter.
pub fn update_frontier_set<C: Copy + Into<StateChange>>(
    set: &mut FrontierSet,
    map: &impl OccupancyMap,
    changed: &[C],
) {
    let grid = map.config().chunk_grid();
    let mut todo: Vec<usize> = Vec::with_capacity(changed.len() * 7);
    for &change in changed {
        let change: StateChange = change.into();
        for &d in [IVec3::ZERO].iter().chain(NEIGHBOURS.iter()) {
            if !change.reaches(d, 1) {
                continue;
            }
            if let Some(flat) = grid.flat(ChunkCoord(change.coord.0 + d)) {
                todo.push(flat);
            }
        }
    }
    todo.sort_unstable();
    todo.dedup();
    for flat in todo {
        let coord = grid.coord(flat);
        // A chunk never created has no frontier; nothing to do unless the set remembers one.
        if map.chunk(coord).is_none() && set.chunk(coord).is_none() {
            continue;
        }
        set.replace_chunk(coord, &chunk_frontier(map, coord));
    }
}
