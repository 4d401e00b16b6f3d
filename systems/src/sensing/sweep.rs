//! One sweep of one sensor: place its rays in the world, cast them, turn distances into the
//! endpoints and hit flags of a [`Scan`] (common.md §1-2).

use super::RayPattern;
use bevy_ecs::prelude::*;
use glam::{Quat, Vec3};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use uavex_components::sensor::{Mount, Scan};
use uavex_components::uav::QuadState;
use uavex_components::world::WorldGeometry;

/// Where a sensor is and how it is turned, in the world frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SensorPose {
    pub origin: Vec3,
    /// Rotation from the sensor frame to the world frame.
    pub rotation: Quat,
}

impl SensorPose {
    /// The sensor's world pose = UAV pose * mount: the mount is given in the body frame.
    pub fn of(body: &QuadState, mount: &Mount) -> Self {
        Self {
            origin: body.position + body.attitude * mount.translation,
            rotation: (body.attitude * mount.rotation).normalize(),
        }
    }
}

/// When a sensor sweeps: every `period_s`, the first at t = 0.
///
/// Sweep times are `k * period_s` computed from the sweep count, not accumulated, so they never
/// drift; a sweep is due at the first tick at or after its time (within 1 ns, so that a 30 Hz
/// camera on a 300 Hz clock sweeps every 10th tick despite rounding of both time grids).
#[derive(Component, Debug, Clone, PartialEq)]
pub struct SweepSchedule {
    pub period_s: f64,
    /// Index of the next sweep; it is due at `next * period_s`.
    pub next: u64,
}

const SCHEDULE_TOLERANCE_S: f64 = 1e-9;

impl SweepSchedule {
    /// A schedule at `rate_hz` (> 0, finite; the scenario checks guarantee it).
    pub fn from_rate(rate_hz: f64) -> Self {
        Self {
            period_s: 1.0 / rate_hz,
            next: 0,
        }
    }

    pub fn next_time_s(&self) -> f64 {
        self.next as f64 * self.period_s
    }

    pub fn is_due(&self, time_s: f64) -> bool {
        time_s + SCHEDULE_TOLERANCE_S >= self.next_time_s()
    }

    /// Marks the sweep at `time_s` done: the next one is the first sweep time after it (sweeps
    /// missed by a coarse clock are skipped, never replayed).
    pub fn advance(&mut self, time_s: f64) {
        let done = ((time_s + SCHEDULE_TOLERANCE_S) / self.period_s).floor();
        self.next = (done.max(0.0) as u64 + 1).max(self.next + 1);
    }
}

/// The random stream of one sensor's range noise (`RunSeed::stream(SENSOR_NOISE, sensor id)`),
/// kept per sensor so that one sensor's draws never shift another's.
#[derive(Component, Debug, Clone)]
pub struct NoiseRng(pub ChaCha8Rng);

/// Per-sensor buffers reused from sweep to sweep (no allocation per tick after the first sweep).
#[derive(Component, Debug, Default, Clone)]
pub struct SweepScratch {
    world_directions: Vec<Vec3>,
    distances: Vec<Option<f32>>,
}

/// Gaussian range noise: standard deviation (m) and the sensor's stream to draw from.
pub struct RangeNoise<'a> {
    pub std_m: f32,
    pub rng: &'a mut ChaCha8Rng,
}

/// Casts the pattern's rays from `pose` into `world` and fills `scan` in place
/// (common.md §1-2):
/// - a surface within range gives an endpoint on it, `hit = true` (its voxel becomes occupied);
/// - with noise, the measured range is the true one plus N(0, std^2), drawn in ray order;
/// - a measured range below `range_min` gives no depth: the ray is dropped;
/// - a measured range beyond `range_max`, or no surface at all, cuts the ray at `range_max` with
///   `hit = false` (free space only).
///
/// With noise, rays are cast `4 std` beyond `range_max`, so that a surface just out of range may
/// be measured inside it, as a real sensor would.
pub fn sweep(
    pattern: &RayPattern,
    pose: SensorPose,
    world: &WorldGeometry,
    mut noise: Option<RangeNoise<'_>>,
    scratch: &mut SweepScratch,
    scan: &mut Scan,
    time_s: f64,
) {
    let std_m = noise.as_ref().map_or(0.0, |n| n.std_m.max(0.0));
    let gaussian = Normal::new(0.0f32, std_m).ok().filter(|_| std_m > 0.0);
    let cast_range = pattern.range_max + 4.0 * std_m;

    scratch.world_directions.clear();
    scratch
        .world_directions
        .extend(pattern.directions.iter().map(|d| pose.rotation * *d));
    world.cast_rays(
        pose.origin,
        &scratch.world_directions,
        cast_range,
        &mut scratch.distances,
    );

    scan.origin = pose.origin;
    scan.endpoints.clear();
    scan.hit.clear();
    for (dir, distance) in scratch.world_directions.iter().zip(&scratch.distances) {
        let measured = match (distance, &gaussian, noise.as_mut()) {
            (Some(d), Some(g), Some(n)) => Some(d + g.sample(n.rng)),
            (d, _, _) => *d,
        };
        match measured {
            Some(range) if range < pattern.range_min => {}
            Some(range) if range <= pattern.range_max => {
                scan.endpoints.push(pose.origin + *dir * range);
                scan.hit.push(true);
            }
            _ => {
                scan.endpoints.push(pose.origin + *dir * pattern.range_max);
                scan.hit.push(false);
            }
        }
    }
    scan.sequence += 1;
    scan.time_s = time_s;
}
