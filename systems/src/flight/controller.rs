//! Geometric tracking controller on SE(3) (Lee, Leok & McClamroch, CDC 2010), with the
//! Agilicious gains of common.md §3, as Agilicious uses it: position and velocity errors give a
//! desired acceleration, hence a collective thrust and a thrust direction; the attitude error
//! on SO(3) gives body torques; the [`Mixer`] turns both into rotor speed commands.
//!
//! Frames: world z up (Lee et al. use z down; the signs below are theirs turned over).
//! Gains are normalised by mass and inertia, as Agilicious' are, so one set fits every
//! airframe:
//! - `a_des = -kp_acc e_p - kd_acc e_v + a_ref + g e3`, thrust `f = m a_des . b3` (Lee eq. 15);
//! - `b3d = a_des / |a_des|`, `b1d` from the reference yaw ([`desired_attitude`]);
//! - `e_R = vee(Rd^T R - R^T Rd) / 2`, `e_W = W - R^T Rd Wd` (Lee eq. 10-11);
//! - `M = J (-kp_att e_R - kd_att e_W) + W x J W - J (W x R^T Rd Wd)` (Lee eq. 16, with the
//!   angular-acceleration feed-forward `dWd/dt` left out, as Agilicious does);
//! - `Wd` follows from the reference jerk by differential flatness (Mellinger & Kumar 2011):
//!   `h = (j - (b3d . j) b3d) / |a_des|`, `Wd = (-h . b2d, h . b1d, yaw_rate b3d . e3)`.
//!
//! Why the attitude loop outputs torques and has a rate gain Agilicious does not list:
//! Agilicious' `kp_att` (150 for roll/pitch, 3 for yaw, common.md) multiplies the attitude
//! error into a body-rate command for the flight controller's fast rate loop. Here the motors
//! lag by 0.033 s, and a rate loop behind that lag cannot carry an attitude gain above
//! `1 / tau = 30 1/s` (Routh: `tau s^3 + s^2 + K s + K kp` is stable only for `kp < 1 / tau`,
//! whatever the rate gain K). Used as Lee's proportional attitude gain instead
//! (rad/s^2 per rad), with a rate gain `kd_att` of 20 1/s for roll/pitch, the loop with motor
//! lag `tau s^3 + s^2 + 20 s + 150` has poles at -11.7 and -9.3 +- 17.4i (damping 0.47), well
//! faster than the position loop `s^2 + 6 s + 10` (poles -3 +- i).

use super::dynamics::{QuadrotorModel, Wrench};
use super::mixer::Mixer;
use super::state::FlightState;
use glam::{DMat3, DVec3};
use serde::{Deserialize, Serialize};
use uavex_components::airframe::Airframe;
use uavex_components::trajectory::TrajectoryPoint;

/// Gains of the geometric controller, normalised by mass (position) and inertia (attitude).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ControllerGains {
    /// Position error to acceleration (1/s^2). Agilicious: 10.
    pub kp_acc: f64,
    /// Velocity error to acceleration (1/s). Agilicious: 6.
    pub kd_acc: f64,
    /// Roll/pitch attitude error to angular acceleration (1/s^2). Agilicious: 150.
    pub kp_att_xy: f64,
    /// Yaw attitude error to angular acceleration (1/s^2). Agilicious: 3.
    pub kp_att_z: f64,
    /// Roll/pitch rate error to angular acceleration (1/s); see the module doc.
    pub kd_att_xy: f64,
    /// Yaw rate error to angular acceleration (1/s): critical damping of `kp_att_z`
    /// (2 sqrt(3) = 3.46).
    pub kd_att_z: f64,
}

impl Default for ControllerGains {
    fn default() -> Self {
        Self {
            kp_acc: 10.0,
            kd_acc: 6.0,
            kp_att_xy: 150.0,
            kp_att_z: 3.0,
            kd_att_xy: 20.0,
            kd_att_z: 3.5,
        }
    }
}

/// What the controller decided at one instant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ControlOutput {
    /// Collective thrust and body torques asked of the rotors (before the mixer's limits).
    pub wrench: Wrench,
    /// Attitude the controller steers toward (body to world).
    pub desired_attitude: DMat3,
    /// Rotor speed commands (rad/s) after the mixer, for the motors.
    pub rotor_speed_commands: [f64; 4],
}

/// The controller for one airframe: gains, mass, inertia and mixer.
#[derive(Debug, Clone, PartialEq)]
pub struct GeometricController {
    pub gains: ControllerGains,
    mass: f64,
    inertia: DVec3,
    gravity: f64,
    mixer: Mixer,
}

impl GeometricController {
    /// `None` if the airframe's rotors cannot be mixed (a validated airframe always can).
    pub fn new(airframe: &Airframe, gains: ControllerGains) -> Option<Self> {
        let model = QuadrotorModel::new(airframe);
        Some(Self {
            gains,
            mass: model.mass,
            inertia: model.inertia,
            gravity: model.gravity,
            mixer: Mixer::new(airframe)?,
        })
    }

    pub fn mixer(&self) -> &Mixer {
        &self.mixer
    }

    /// Rotor speed commands that steer `state` toward `reference`.
    pub fn command(&self, state: &FlightState, reference: &TrajectoryPoint) -> ControlOutput {
        let g = &self.gains;
        let rotation = DMat3::from_quat(state.attitude);
        let b3 = rotation.z_axis;
        let position_error = state.position - reference.position;
        let velocity_error = state.velocity - reference.velocity;
        let desired_acceleration = -g.kp_acc * position_error - g.kd_acc * velocity_error
            + reference.acceleration
            + DVec3::new(0.0, 0.0, self.gravity);
        let thrust = self.mass * desired_acceleration.dot(b3);

        let norm = desired_acceleration.length();
        let b3d = if norm > 1e-9 {
            desired_acceleration / norm
        } else {
            b3
        };
        let desired = desired_attitude(b3d, reference.yaw).unwrap_or(rotation);

        // Desired body rates from the jerk (differential flatness), in the desired frame.
        let jerk = reference.jerk;
        let h = if norm > 1e-9 {
            (jerk - b3d.dot(jerk) * b3d) / norm
        } else {
            DVec3::ZERO
        };
        let desired_rates = DVec3::new(
            -h.dot(desired.y_axis),
            h.dot(desired.x_axis),
            reference.yaw_rate * b3d.z,
        );

        // Lee eq. 10-11 and 16.
        let attitude_error = attitude_error(&desired, &rotation);
        let desired_rates_body = rotation.transpose() * (desired * desired_rates);
        let rate_error = state.body_rates - desired_rates_body;
        let kp = DVec3::new(g.kp_att_xy, g.kp_att_xy, g.kp_att_z);
        let kd = DVec3::new(g.kd_att_xy, g.kd_att_xy, g.kd_att_z);
        let omega = state.body_rates;
        let j = self.inertia;
        let torque = j * (-kp * attitude_error - kd * rate_error) + omega.cross(j * omega)
            - j * omega.cross(desired_rates_body);

        let wrench = Wrench { thrust, torque };
        ControlOutput {
            wrench,
            desired_attitude: desired,
            rotor_speed_commands: self.mixer.speed_commands(&wrench),
        }
    }
}

/// The rotation whose z axis is `thrust_direction` (unit) and whose x axis lies in the
/// vertical plane of the heading `yaw`, as Agilicious builds it (`x_B = y_C x z_B` with
/// `y_C = (-sin yaw, cos yaw, 0)`), so that the rotation's yaw angle is exactly `yaw`.
/// `None` when the thrust direction lies along `y_C` (a 90-degree sideways tilt), where the
/// heading does not fix the rotation.
pub fn desired_attitude(thrust_direction: DVec3, yaw: f64) -> Option<DMat3> {
    let lateral = DVec3::new(-yaw.sin(), yaw.cos(), 0.0);
    let b1 = lateral.cross(thrust_direction);
    let length = b1.length();
    if length < 1e-9 || !length.is_finite() {
        return None;
    }
    let b1 = b1 / length;
    let b2 = thrust_direction.cross(b1);
    Some(DMat3::from_cols(b1, b2, thrust_direction))
}

/// Lee's attitude error `e_R = vee(Rd^T R - R^T Rd) / 2` (eq. 10), from the six entries of
/// `M = Rd^T R` it needs: `M_ij = rd_i . r_j` (columns), and `vee(M - M^T)` =
/// `(M_21 - M_12, M_02 - M_20, M_10 - M_01)`.
fn attitude_error(desired: &DMat3, rotation: &DMat3) -> DVec3 {
    let (d, r) = (desired, rotation);
    0.5 * DVec3::new(
        d.z_axis.dot(r.y_axis) - d.y_axis.dot(r.z_axis),
        d.x_axis.dot(r.z_axis) - d.z_axis.dot(r.x_axis),
        d.y_axis.dot(r.x_axis) - d.x_axis.dot(r.y_axis),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn controller() -> (Airframe, GeometricController) {
        let airframe = Airframe::kingfisher();
        let controller = GeometricController::new(&airframe, ControllerGains::default()).unwrap();
        (airframe, controller)
    }

    #[test]
    fn hover_on_reference_commands_hover_speeds() {
        let (airframe, controller) = controller();
        let state = FlightState::hovering(&airframe, DVec3::new(0.0, 0.0, 1.0), 0.4);
        let reference = TrajectoryPoint::at_rest(DVec3::new(0.0, 0.0, 1.0), 0.4);
        let out = controller.command(&state, &reference);
        assert!((out.wrench.thrust - 0.752 * 9.81).abs() < 1e-9);
        assert!(out.wrench.torque.length() < 1e-12);
        for w in out.rotor_speed_commands {
            assert!((w - 1086.43).abs() < 0.01);
        }
    }

    #[test]
    fn position_error_tilts_toward_the_reference() {
        let (airframe, controller) = controller();
        let state = FlightState::hovering(&airframe, DVec3::ZERO, 0.0);
        // Reference 1 m ahead (+x): a_des = (10, 0, 9.81), the thrust axis leans forward by
        // atan(10 / 9.81) = 45.55 deg, i.e. a rotation about +y.
        let reference = TrajectoryPoint::at_rest(DVec3::new(1.0, 0.0, 0.0), 0.0);
        let out = controller.command(&state, &reference);
        let axis = out.desired_attitude * DVec3::Z;
        let tilt = axis.x.atan2(axis.z);
        assert!((tilt - (10.0f64).atan2(9.81)).abs() < 1e-9);
        // Attitude error about body y is negative (R must turn positively about y): the
        // torque pushes +y: e_R = (0, -sin 45.55 deg, 0), M_y = 2.1e-3 * 150 * 0.7139.
        assert!(
            (out.wrench.torque.y - 2.1e-3 * 150.0 * 0.713_883).abs() < 1e-5,
            "{:?}",
            out.wrench
        );
        // Thrust keeps the projection on the current (level) axis: m g.
        assert!((out.wrench.thrust - 0.752 * 9.81).abs() < 1e-9);
    }

    #[test]
    fn yaw_error_turns_about_z() {
        let (airframe, controller) = controller();
        let state = FlightState::hovering(&airframe, DVec3::ZERO, 0.0);
        let reference = TrajectoryPoint::at_rest(DVec3::ZERO, 0.5);
        let out = controller.command(&state, &reference);
        // e_R = (0, 0, -sin 0.5); M_z = 4.3e-3 * 3 * sin 0.5.
        assert!((out.wrench.torque.z - 4.3e-3 * 3.0 * 0.5f64.sin()).abs() < 1e-12);
        assert!(out.wrench.torque.x.abs() < 1e-12 && out.wrench.torque.y.abs() < 1e-12);
    }

    #[test]
    fn desired_attitude_is_a_rotation_with_the_given_heading() {
        let axis = DVec3::new(0.3, -0.2, 1.0).normalize();
        let r = desired_attitude(axis, 1.0).unwrap();
        assert!((r.determinant() - 1.0).abs() < 1e-12);
        assert!((r.z_axis - axis).length() < 1e-12);
        // Its x axis lies in the vertical plane of the heading.
        let heading_normal = DVec3::new(-(1.0f64).sin(), 1.0f64.cos(), 0.0);
        assert!(r.x_axis.dot(heading_normal).abs() < 1e-12);
        assert!(desired_attitude(DVec3::Y, 0.0).is_none());
    }
}
