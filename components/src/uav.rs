//! The UAV entity: identity and kinematic/dynamic state.

use bevy_ecs::prelude::*;
use glam::{Quat, Vec3};

/// Marks a UAV entity. `index` is its position in the scenario's `[[uav]]` list, which fixes
/// every per-UAV order (sensing, seeding, output rows) independently of ECS storage order.
#[derive(Component, Debug, Clone)]
pub struct Uav {
    pub name: String,
    pub index: usize,
}

/// The full state of a quadrotor: pose, velocity, body rates and rotor speeds.
///
/// The kinematic `scripted` behaviour writes position, velocity and attitude directly; flight
/// dynamics (rapier) own it otherwise.
#[derive(Component, Debug, Clone, Copy, PartialEq)]
pub struct QuadState {
    /// Position of the centre of mass in the world frame (m).
    pub position: Vec3,
    /// Linear velocity in the world frame (m/s).
    pub velocity: Vec3,
    /// Attitude: rotation from body frame to world frame.
    pub attitude: Quat,
    /// Angular velocity in the body frame (rad/s).
    pub body_rates: Vec3,
    /// Actual rotor speeds (rad/s), rotor order as in the airframe.
    pub rotor_speeds: [f32; 4],
}

impl QuadState {
    /// At rest at `position`, heading `yaw` (rad about +z).
    pub fn at_rest(position: Vec3, yaw: f32) -> Self {
        Self {
            position,
            velocity: Vec3::ZERO,
            attitude: Quat::from_rotation_z(yaw),
            body_rates: Vec3::ZERO,
            rotor_speeds: [0.0; 4],
        }
    }
}

/// How a UAV's run ended, when it ended before the mission did.
#[derive(Component, Debug, Clone, PartialEq)]
pub enum UavEnded {
    /// Finished its behaviour (e.g. the last scripted waypoint).
    Finished,
    /// Touched world geometry.
    Crashed { time_s: f64, position: Vec3 },
    /// Flew home because no further goal was affordable within its energy budget, and
    /// arrived (exploration with a budget).
    ReturnedHome { time_s: f64 },
    /// Drew the usable energy of its battery (flight dynamics only).
    BatteryEmpty { time_s: f64, position: Vec3 },
}

/// A behaviour's own prediction of its mission, made before flying it (e.g. a coverage plan's
/// energy from its speed-based model, coverage.md eq. 18), reported beside the flown figures.
#[derive(Component, Debug, Clone, Copy, PartialEq)]
pub struct PredictedMission {
    pub energy_j: f64,
    pub time_s: f64,
}
