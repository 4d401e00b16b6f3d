//! The UAVs in the recording: each one's pose (a transform of its body box and axes) and the
//! path it flew (line strips, one per stretch of [`super::path::SEGMENT_S`] of simulated time).

use super::entity_path;
use re_chunk::EntityPath;
use re_sdk_types::archetypes::{Boxes3D, LineStrips3D, Transform3D, TransformAxes3D};
use re_sdk_types::components::{Color, Radius};
use re_sdk_types::datatypes::Quaternion;
use uavex_components::airframe::Airframe;
use uavex_components::uav::QuadState;

/// `world/uavs/NAME/body`: the pose over time, the airframe's box and axes.
pub fn body_entity(uav: &str) -> EntityPath {
    entity_path(&["world", "uavs", uav, "body"])
}

/// `world/uavs/NAME/path/KKK`: the path flown in stretch `k`.
pub fn path_entity(uav: &str, segment: usize) -> EntityPath {
    entity_path(&["world", "uavs", uav, "path", &format!("{segment:03}")])
}

/// The body's pose: its position and attitude in the world.
pub fn body_pose(state: &QuadState) -> Transform3D {
    Transform3D::from_translation_rotation(
        state.position.to_array(),
        Quaternion::from_xyzw(state.attitude.to_array()),
    )
}

/// The airframe's box and axes in the body frame (logged once; the pose moves them).
pub fn body_shape(airframe: &Airframe) -> (Boxes3D, TransformAxes3D) {
    let half = airframe.size.map(|s| (s / 2.0) as f32);
    let body = Boxes3D::from_half_sizes([half]).with_colors([Color::from_rgb(30, 144, 255)]);
    let axes = TransformAxes3D::new(2.0 * half[0].max(half[1]));
    (body, axes)
}

/// A path strip in the UAV's colour.
pub fn path_strip(points: &[[f32; 3]]) -> LineStrips3D {
    LineStrips3D::new([points.to_vec()])
        .with_colors([Color::from_rgb(30, 144, 255)])
        .with_radii([Radius::new_scene_units(0.02)])
}
