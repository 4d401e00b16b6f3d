//! From a `[[uav.sensor]]` table to the components of a sensor entity.

use super::BuildError;
use crate::scenario::{MapSpec, MountSpec, QualitySpec, RayGridSpec, SensorSpec};
use bevy_ecs::prelude::*;
use glam::{EulerRot, Quat};
use uavex_components::sensor::{Mount, Scan, SensorId, SensorOf, SensorQuality};
use uavex_components::sim::{RunSeed, stream};
use uavex_systems::sensing::{
    LidarBeams, NoiseRng, PatternError, PinholeCamera, RayGrid, RayPattern, SweepSchedule,
    SweepScratch, camera_pattern, lidar_pattern,
};

/// Everything a sensor entity needs for the Sense and Map stages.
#[derive(Bundle)]
pub struct SensorBundle {
    pub of: SensorOf,
    pub id: SensorId,
    pub mount: Mount,
    pub quality: SensorQuality,
    pub pattern: RayPattern,
    pub schedule: SweepSchedule,
    pub noise: NoiseRng,
    pub scratch: SweepScratch,
    pub scan: Scan,
}

/// The body-frame pose of a mount: translation, and roll/pitch/yaw applied yaw first
/// (intrinsic z-y-x, R = Rz(yaw) Ry(pitch) Rx(roll)) as the schema documents.
pub fn mount_from_spec(spec: &MountSpec) -> Mount {
    let [roll, pitch, yaw] = spec.rpy.map(|a| a as f32);
    Mount {
        translation: glam::DVec3::from_array(spec.translation).as_vec3(),
        rotation: Quat::from_euler(EulerRot::ZYX, yaw, pitch, roll),
    }
}

/// The components of the sensor `spec` carried by `uav`. `field` is the sensor's scenario path
/// (`uav[0].sensor[1]`) for errors; `map` gives the resolution of the `auto` ray grid and the
/// hit/miss probabilities of sensors that set none. Range noise draws from
/// `RunSeed::stream(stream::SENSOR_NOISE, id)`.
pub fn sensor_bundle(
    spec: &SensorSpec,
    map: &MapSpec,
    uav: Entity,
    id: SensorId,
    seed: RunSeed,
    field: &str,
) -> Result<SensorBundle, BuildError> {
    let located = |e: PatternError| {
        let path = match e.field {
            "resolution" => "map.resolution".to_owned(),
            other => format!("{field}.{other}"),
        };
        BuildError::new(path, e.message)
    };
    let (pattern, rate_hz, mount, quality) = match spec {
        SensorSpec::DepthCamera {
            width,
            height,
            hfov,
            range_min,
            range_max,
            rate_hz,
            mount,
            ray_grid,
            quality,
        } => {
            let camera = PinholeCamera {
                width: *width,
                height: *height,
                hfov: *hfov,
            };
            let grid = match ray_grid {
                RayGridSpec::Named(_) => RayGrid::Auto {
                    resolution: map.resolution,
                },
                RayGridSpec::Explicit([columns, rows]) => RayGrid::Explicit {
                    columns: *columns,
                    rows: *rows,
                },
            };
            let pattern = camera_pattern(camera, grid, *range_min, *range_max).map_err(located)?;
            (pattern, *rate_hz, mount, quality)
        }
        SensorSpec::Lidar {
            hfov,
            beams_h,
            vfov,
            beams_v,
            range_min,
            range_max,
            rate_hz,
            mount,
            quality,
        } => {
            let beams = LidarBeams {
                hfov: *hfov,
                beams_h: *beams_h,
                vfov: *vfov,
                beams_v: *beams_v,
            };
            let pattern = lidar_pattern(beams, *range_min, *range_max).map_err(located)?;
            (pattern, *rate_hz, mount, quality)
        }
    };
    if !(rate_hz.is_finite() && rate_hz > 0.0) {
        return Err(BuildError::new(
            format!("{field}.rate_hz"),
            format!("must be finite and positive, got {rate_hz}"),
        ));
    }
    Ok(SensorBundle {
        of: SensorOf(uav),
        id,
        mount: mount_from_spec(mount),
        quality: sensor_quality(quality, map, field)?,
        pattern,
        schedule: SweepSchedule::from_rate(rate_hz),
        noise: NoiseRng(seed.stream(stream::SENSOR_NOISE, u64::from(id.0))),
        scratch: SweepScratch::default(),
        scan: Scan::default(),
    })
}

/// Hit/miss probabilities (the sensor's own, else the map's defaults) and range noise.
fn sensor_quality(
    quality: &QualitySpec,
    map: &MapSpec,
    field: &str,
) -> Result<SensorQuality, BuildError> {
    let p_hit = quality.p_hit.unwrap_or(map.p_hit);
    let p_miss = quality.p_miss.unwrap_or(map.p_miss);
    let (hit_path, miss_path) = match (quality.p_hit, quality.p_miss) {
        (Some(_), Some(_)) => (
            format!("{field}.quality.p_hit"),
            format!("{field}.quality.p_miss"),
        ),
        (Some(_), None) => (format!("{field}.quality.p_hit"), "map.p_miss".to_owned()),
        (None, Some(_)) => ("map.p_hit".to_owned(), format!("{field}.quality.p_miss")),
        (None, None) => ("map.p_hit".to_owned(), "map.p_miss".to_owned()),
    };
    // A hit must raise the occupancy and a miss lower it (common.md §1).
    if !(p_hit > 0.5 && p_hit < 1.0) {
        return Err(BuildError::new(
            hit_path,
            format!("must lie in (0.5, 1), got {p_hit}"),
        ));
    }
    if !(p_miss > 0.0 && p_miss < 0.5) {
        return Err(BuildError::new(
            miss_path,
            format!("must lie in (0, 0.5), got {p_miss}"),
        ));
    }
    let std = quality.range_noise_std;
    if !(std.is_finite() && std >= 0.0) {
        return Err(BuildError::new(
            format!("{field}.quality.range_noise_std"),
            format!("must be finite and >= 0, got {std}"),
        ));
    }
    Ok(SensorQuality::from_probabilities(
        p_hit as f32,
        p_miss as f32,
        std as f32,
    ))
}
