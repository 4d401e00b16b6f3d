//! The occupancy map in the recording: one entity per map chunk holding its occupied voxels as
//! boxes of the map's resolution, coloured by height, and the map's box as a wireframe.
//!
//! A chunk is logged again only when its set of occupied voxels changed: free-space updates
//! touch every chunk in view at the camera rate, re-sending them would multiply the file.

use super::colour::{Palette, Span};
use super::entity_path;
use re_chunk::EntityPath;
use re_sdk_types::archetypes::Boxes3D;
use re_sdk_types::components::{Color, FillMode};
use uavex_components::frontier::VoxelMask;
use uavex_components::map::{ChunkCoord, MapConfig, VoxelChunk, VoxelState, local_key};

/// The map's box.
pub const BOUNDS: &str = "world/map/bounds";

/// The occupied voxels of `chunk` (log-odds >= 0, the map statistics' rule).
pub fn occupied_mask(chunk: &VoxelChunk) -> VoxelMask {
    let mut mask = VoxelMask::EMPTY;
    for (index, voxel) in chunk.voxels().iter().enumerate() {
        if voxel.state() == VoxelState::Occupied {
            mask.insert(index);
        }
    }
    mask
}

/// `world/map/occupied/X_Y_Z` for chunk (X, Y, Z).
pub fn chunk_entity(coord: ChunkCoord) -> EntityPath {
    let c = coord.0;
    entity_path(&[
        "world",
        "map",
        "occupied",
        &format!("{}_{}_{}", c.x, c.y, c.z),
    ])
}

/// Boxes of the voxels in `mask` of chunk `coord`, coloured by height from the map's floor
/// to its ceiling. An empty mask gives no box (it clears what the chunk showed before).
pub fn occupied_boxes(coord: ChunkCoord, mask: &VoxelMask, config: &MapConfig) -> Boxes3D {
    let floor = f64::from(config.center_of(config.key_min()).z);
    let ceiling = f64::from(config.center_of(config.key_max()).z);
    let heights = Span {
        low: floor,
        high: ceiling,
    };
    let centres: Vec<[f32; 3]> = mask
        .iter()
        .map(|index| config.center_of(local_key(coord, index)).to_array())
        .collect();
    let colours: Vec<Color> = centres
        .iter()
        .map(|c| Color::from(Palette::HEIGHT.at(heights.fraction(f64::from(c[2])))))
        .collect();
    // One half size serves every box; with no centre it must go too, or it draws one box.
    let half = config.resolution() as f32 / 2.0;
    let half_sizes = (!centres.is_empty()).then_some([half; 3]);
    Boxes3D::from_centers_and_half_sizes(centres, half_sizes)
        .with_colors(colours)
        .with_fill_mode(FillMode::Solid)
}

/// The map's box (the mission volume) as a grey wireframe.
pub fn bounds_box(config: &MapConfig) -> Boxes3D {
    let half = config.resolution() as f32 / 2.0;
    let low = config.center_of(config.key_min()) - half;
    let high = config.center_of(config.key_max()) + half;
    Boxes3D::from_centers_and_half_sizes(
        [((low + high) / 2.0).to_array()],
        [((high - low) / 2.0).to_array()],
    )
    .with_colors([Color::from_rgb(160, 160, 160)])
    .with_fill_mode(FillMode::MajorWireframe)
}
