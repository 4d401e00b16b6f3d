//! Cluster filtering and viewpoints (eaae.md steps 3 and 4).

use super::super::mapping::OccupancyMap;
use glam::{IVec3, Vec3, Vec3Swizzles};
use uavex_components::frontier::{ClusterSettings, Viewpoint};
use uavex_components::map::{MapConfig, VoxelState};

/// EAAE step 3 (first rule): whether a known-occupied voxel lies within `radius_xy` of the
/// centroid in the x-y plane (the cluster is then not reachable).
///
/// - A voxel is "within" when the nearest point of its x-y square is (a voxel partly inside the
///   disc counts, so a 0.1 m radius always examines the centroid's own column and every column
///   the disc reaches into).
/// - z extent: the centroid's voxel layer and one layer above and below. A whole column would
///   always hit the floor or the ceiling; one layer alone would miss an obstacle whose face lies
///   a few centimetres off the centroid's height.
/// - Voxels outside the map are unknown, never occupied.
pub fn occupied_near_centroid(map: &impl OccupancyMap, centroid: Vec3, radius_xy: f32) -> bool {
    let config = map.config();
    let radius = radius_xy.max(0.0);
    // Clipped to the map: nothing outside it is occupied.
    let z = config.raw_key_of(centroid).z;
    let lo = config
        .raw_key_of(centroid - Vec3::new(radius, radius, 0.0))
        .with_z(z.saturating_sub(1))
        .max(config.key_min());
    let hi = config
        .raw_key_of(centroid + Vec3::new(radius, radius, 0.0))
        .with_z(z.saturating_add(1))
        .min(config.key_max());
    for kz in lo.z..=hi.z {
        for ky in lo.y..=hi.y {
            for kx in lo.x..=hi.x {
                let key = IVec3::new(kx, ky, kz);
                if map.state(key) == VoxelState::Occupied
                    && square_distance_xy(config, key, centroid) <= radius
                {
                    return true;
                }
            }
        }
    }
    false
}

/// Distance in the x-y plane from `point` to the nearest point of voxel `key`'s square.
fn square_distance_xy(config: &MapConfig, key: IVec3, point: Vec3) -> f32 {
    let half = (config.resolution() / 2.0) as f32;
    let d = (point.xy() - config.center_of(key).xy()).abs() - half;
    d.max(glam::Vec2::ZERO).length()
}

/// Distance from `point` to the nearest point of voxel `key`'s cube.
fn cube_distance(config: &MapConfig, key: IVec3, point: Vec3) -> f32 {
    let half = (config.resolution() / 2.0) as f32;
    let d = (point - config.center_of(key)).abs() - half;
    d.max(Vec3::ZERO).length()
}

/// Whether a UAV may hover at `position`: its voxel is known free, and no voxel within
/// `clearance` is known occupied or outside the map (the UAV cannot fly where the map does not
/// reach). Unknown voxels nearby are allowed: a viewpoint looks at a frontier, so unknown space
/// is never far; the planner decides whether a trajectory through known free space exists.
pub fn is_clear(map: &impl OccupancyMap, position: Vec3, clearance: f32) -> bool {
    let config = map.config();
    match config.key_of(position) {
        Some(key) if map.state(key) == VoxelState::Free => {}
        _ => return false,
    }
    let clearance = clearance.max(0.0);
    // Clipped to the map plus one layer: the outside voxels nearest to `position` are in it.
    let lo = config
        .raw_key_of(position - Vec3::splat(clearance))
        .max(config.key_min() - IVec3::ONE);
    let hi = config
        .raw_key_of(position + Vec3::splat(clearance))
        .min(config.key_max() + IVec3::ONE);
    for kz in lo.z..=hi.z {
        for ky in lo.y..=hi.y {
            for kx in lo.x..=hi.x {
                let key = IVec3::new(kx, ky, kz);
                let blocked = !config.contains_key(key) || map.state(key) == VoxelState::Occupied;
                if blocked && cube_distance(config, key, position) <= clearance {
                    return false;
                }
            }
        }
    }
    true
}

/// EAAE step 4: the centroid offset by `viewpoint_offset_m` along +x, -x, +y, -y, +z, -z (in
/// that order), each kept if [`is_clear`] with `viewpoint_clearance_m`. The yaw faces the
/// centroid; the two vertical viewpoints have yaw 0 (the centroid is straight below or above
/// them, so no yaw points the forward camera at it, and 0 is as good as any).
pub fn sample_viewpoints(
    map: &impl OccupancyMap,
    centroid: Vec3,
    settings: &ClusterSettings,
) -> Vec<Viewpoint> {
    let offset = settings.viewpoint_offset_m;
    [
        Vec3::X,
        Vec3::NEG_X,
        Vec3::Y,
        Vec3::NEG_Y,
        Vec3::Z,
        Vec3::NEG_Z,
    ]
    .into_iter()
    .filter_map(|axis| {
        let position = centroid + axis * offset;
        if !is_clear(map, position, settings.viewpoint_clearance_m) {
            return None;
        }
        let to_centroid = (centroid - position).xy();
        let yaw = if to_centroid == glam::Vec2::ZERO {
            0.0
        } else {
            to_centroid.y.atan2(to_centroid.x)
        };
        Some(Viewpoint { position, yaw })
    })
    .collect()
}
