//! Range sensors (depth cameras, lidars) and the scans they produce.
//!
//! A sensor is an entity of its own, tied to its UAV by the [`SensorOf`] relationship, so a UAV
//! may carry any number of sensors and a multi-UAV scenario is just more entities.

use bevy_ecs::prelude::*;
use glam::{Quat, Vec3};

/// Ties a sensor to the UAV that carries it.
#[derive(Component, Debug, Clone, Copy, PartialEq, Eq)]
#[relationship(relationship_target = Sensors)]
pub struct SensorOf(pub Entity);

/// The sensors a UAV carries (maintained by bevy from [`SensorOf`]).
#[derive(Component, Debug, Default)]
#[relationship_target(relationship = SensorOf)]
pub struct Sensors(Vec<Entity>);

impl Sensors {
    pub fn entities(&self) -> &[Entity] {
        &self.0
    }
}

/// Pose of a sensor in its UAV's body frame. The sensor looks along its local +x axis
/// (forward), with +y left and +z up, as a ROS body frame.
#[derive(Component, Debug, Clone, Copy, PartialEq)]
pub struct Mount {
    pub translation: Vec3,
    pub rotation: Quat,
}

impl Default for Mount {
    fn default() -> Self {
        Self {
            translation: Vec3::ZERO,
            rotation: Quat::IDENTITY,
        }
    }
}

/// How a sensor's measurements update the map (common.md section 1), as log-odds increments,
/// plus an optional Gaussian range noise.
#[derive(Component, Debug, Clone, Copy, PartialEq)]
pub struct SensorQuality {
    /// Log-odds added to a voxel a ray ends in: ln(p_hit / (1 - p_hit)).
    pub log_odds_hit: f32,
    /// Log-odds added to a voxel a ray passes through: ln(p_miss / (1 - p_miss)), negative.
    pub log_odds_miss: f32,
    /// Standard deviation of the range noise (m); 0 for perfect measurements.
    pub range_noise_std: f32,
}

impl SensorQuality {
    pub fn from_probabilities(p_hit: f32, p_miss: f32, range_noise_std: f32) -> Self {
        Self {
            log_odds_hit: logit(p_hit),
            log_odds_miss: logit(p_miss),
            range_noise_std,
        }
    }
}

/// ln(p / (1 - p)).
pub fn logit(p: f32) -> f32 {
    (p / (1.0 - p)).ln()
}

/// Stable order of a sensor within the run (scenario order: UAV index, then sensor index).
/// Scans are integrated in this order so that a run does not depend on ECS storage order.
#[derive(Component, Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct SensorId(pub u32);

/// The rays of the latest sweep of one sensor, in the world frame, ready for the map.
///
/// Buffers are reused from sweep to sweep (no allocation per tick). The mapping stage integrates
/// a scan when its `sequence` is newer than the one it integrated last.
#[derive(Component, Debug, Default, Clone)]
pub struct Scan {
    /// Sensor origin in the world frame at the time of the sweep.
    pub origin: Vec3,
    /// Where each valid ray ends: on a surface (`hit[i]`), or cut at the sensor's max range.
    /// Rays whose surface lies closer than the min range are dropped (no depth, no update).
    pub endpoints: Vec<Vec3>,
    /// Whether ray `i` ended on a surface (its end voxel is occupied) or was cut at max range
    /// (it marks free space only).
    pub hit: Vec<bool>,
    /// Sweep counter of this sensor; 0 means no sweep yet.
    pub sequence: u64,
    /// Simulation time of the sweep (s).
    pub time_s: f64,
}
