//! Sense stage: rate-limited raycasting of each sensor into its [`Scan`] (common.md §2).
//!
//! The algorithm lives in plain functions over plain data ([`camera_pattern`], [`lidar_pattern`],
//! [`sweep`]); the [`sense`] system only finds the due sensors and hands them their UAV's pose.
//!
//! The sensing components ([`RayPattern`], [`SweepSchedule`], [`NoiseRng`], [`SweepScratch`]) live
//! here rather than in `uavex-components` because nothing but this stage reads them; the data
//! other stages share (`Scan`, `Mount`, `SensorQuality`) stays in `components::sensor`.

mod box_cast;
mod frustum;
mod packet;
mod pattern;
mod sweep;

pub use frustum::{Frustum, RayTile};

pub use pattern::{
    LidarBeams, MAX_RAYS, PatternError, PinholeCamera, RayGrid, RayPattern, auto_grid,
    camera_pattern, central_step, lidar_pattern,
};
pub use sweep::{NoiseRng, RangeNoise, SensorPose, SweepSchedule, SweepScratch, sweep};

use bevy_ecs::prelude::*;
use uavex_components::sensor::{Mount, Scan, SensorOf, SensorQuality};
use uavex_components::sim::SimClock;
use uavex_components::uav::{QuadState, UavEnded};
use uavex_components::world::WorldGeometry;

/// The Sense stage system: every sensor whose sweep is due casts its rays from its UAV's current
/// pose. UAVs whose run has ended (crashed or finished) no longer sense. Sensors are independent
/// (own noise stream, own scan), so their order does not matter; only due sensors' `Scan`s are
/// marked changed.
#[allow(clippy::type_complexity)]
pub fn sense(
    clock: Res<SimClock>,
    world: Res<WorldGeometry>,
    uavs: Query<&QuadState, Without<UavEnded>>,
    mut sensors: Query<(
        &SensorOf,
        &Mount,
        &SensorQuality,
        &RayPattern,
        &mut SweepSchedule,
        &mut NoiseRng,
        &mut SweepScratch,
        &mut Scan,
    )>,
) {
    let time_s = clock.time_s();
    for (of, mount, quality, pattern, mut schedule, mut rng, mut scratch, mut scan) in &mut sensors
    {
        if !schedule.is_due(time_s) {
            continue;
        }
        let Ok(body) = uavs.get(of.0) else {
            continue;
        };
        schedule.advance(time_s);
        let noise = RangeNoise {
            std_m: quality.range_noise_std,
            rng: &mut rng.0,
        };
        sweep(
            pattern,
            SensorPose::of(body, mount),
            &world,
            Some(noise),
            &mut scratch,
            &mut scan,
            time_s,
        );
    }
}

#[cfg(test)]
mod tests;
