//! The flight state the controller, the rigid-body equations and the rollout share.
//!
//! Everything we compute ourselves is f64: rollouts integrate thousands of steps and sum
//! energy over hours of flight, where f32 would lose digits. rapier (and the ECS `QuadState`
//! that mirrors it) is f32; the conversions below are the only crossing point.

use glam::{DQuat, DVec3};
use uavex_components::airframe::Airframe;
use uavex_components::uav::QuadState;

/// Pose, velocities and rotor speeds of one quadrotor (f64).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FlightState {
    /// Centre of mass in the world frame (m).
    pub position: DVec3,
    /// World-frame velocity (m/s).
    pub velocity: DVec3,
    /// Rotation from body to world.
    pub attitude: DQuat,
    /// Angular velocity in the body frame (rad/s).
    pub body_rates: DVec3,
    /// Actual rotor speeds (rad/s), in the airframe's rotor order.
    pub rotor_speeds: [f64; 4],
}

impl FlightState {
    /// Hovering at `position` with heading `yaw`: at rest, rotors at the hover speed.
    pub fn hovering(airframe: &Airframe, position: DVec3, yaw: f64) -> Self {
        Self {
            position,
            velocity: DVec3::ZERO,
            attitude: DQuat::from_rotation_z(yaw),
            body_rates: DVec3::ZERO,
            rotor_speeds: [airframe.hover_rotor_speed(); 4],
        }
    }

    /// Whether every number is finite (a diverged integration is not).
    pub fn is_finite(&self) -> bool {
        self.position.is_finite()
            && self.velocity.is_finite()
            && self.attitude.is_finite()
            && self.body_rates.is_finite()
            && self.rotor_speeds.iter().all(|w| w.is_finite())
    }

    /// Heading: the angle of the body x axis projected on the horizontal plane (rad).
    pub fn yaw(&self) -> f64 {
        let forward = self.attitude * DVec3::X;
        forward.y.atan2(forward.x)
    }
}

impl From<&QuadState> for FlightState {
    fn from(state: &QuadState) -> Self {
        Self {
            position: state.position.as_dvec3(),
            velocity: state.velocity.as_dvec3(),
            attitude: state.attitude.as_dquat().normalize(),
            body_rates: state.body_rates.as_dvec3(),
            rotor_speeds: state.rotor_speeds.map(f64::from),
        }
    }
}

impl From<&FlightState> for QuadState {
    fn from(state: &FlightState) -> Self {
        Self {
            position: state.position.as_vec3(),
            velocity: state.velocity.as_vec3(),
            attitude: state.attitude.as_quat(),
            body_rates: state.body_rates.as_vec3(),
            rotor_speeds: state.rotor_speeds.map(|w| w as f32),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hovering_state_and_round_trip_through_quad_state() {
        let airframe = Airframe::kingfisher();
        let state = FlightState::hovering(&airframe, DVec3::new(1.0, -2.0, 1.5), 0.7);
        assert!((state.yaw() - 0.7).abs() < 1e-12);
        assert!((state.rotor_speeds[2] - 1086.43).abs() < 0.01);
        let back = FlightState::from(&QuadState::from(&state));
        assert!((back.position - state.position).length() < 1e-6);
        assert!((back.yaw() - 0.7).abs() < 1e-6);
        assert!(back.is_finite());
    }
}
