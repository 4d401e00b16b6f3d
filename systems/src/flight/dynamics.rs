//! The quadrotor's rigid-body equations (common.md §3): rotor forces and torques from rotor
//! speeds, optional linear drag, Newton-Euler motion, motor lag.
//!
//! The true flight hands the same wrench to rapier, which integrates the rigid body; the
//! offline rollout integrates [`QuadrotorModel::derivative`] itself. Both therefore fly the
//! same quadrotor.

use super::motor::MotorModel;
use super::state::FlightState;
use glam::{DQuat, DVec3};
use uavex_components::airframe::{Airframe, GRAVITY, LinearDrag, Rotor, RotorPowerModel};

/// Collective thrust along body +z and torque about the body axes, from the rotors.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Wrench {
    /// N.
    pub thrust: f64,
    /// N m, body frame.
    pub torque: DVec3,
}

/// Time derivative of a [`FlightState`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FlightDerivative {
    pub velocity: DVec3,
    pub acceleration: DVec3,
    /// dq/dt of the body-to-world quaternion.
    pub attitude_rate: DQuat,
    /// dOmega/dt, body frame.
    pub angular_acceleration: DVec3,
    /// dw/dt of each rotor.
    pub rotor_acceleration: [f64; 4],
}

/// Everything the equations of motion need from an airframe, in f64, ready to evaluate.
#[derive(Debug, Clone, PartialEq)]
pub struct QuadrotorModel {
    pub mass: f64,
    /// Principal inertia (kg m^2).
    pub inertia: DVec3,
    pub gravity: f64,
    pub thrust_coefficient: f64,
    pub torque_coefficient: f64,
    pub rotors: [Rotor; 4],
    pub drag: LinearDrag,
    pub motor: MotorModel,
    pub power: RotorPowerModel,
}

impl QuadrotorModel {
    /// The model of `airframe` under standard gravity (the airframe should be validated).
    pub fn new(airframe: &Airframe) -> Self {
        Self {
            mass: airframe.mass,
            inertia: DVec3::from_array(airframe.inertia),
            gravity: GRAVITY,
            thrust_coefficient: airframe.thrust_coefficient,
            torque_coefficient: airframe.torque_coefficient,
            rotors: airframe.rotors,
            drag: airframe.drag,
            motor: MotorModel::new(airframe),
            power: airframe.power,
        }
    }

    /// Thrust of each rotor, `f = k_f w^2` (N).
    pub fn rotor_thrusts(&self, speeds: &[f64; 4]) -> [f64; 4] {
        speeds.map(|w| self.thrust_coefficient * w * w)
    }

    /// Wrench of the four rotors: thrusts add up along body z; a thrust at (x, y) gives the
    /// torque (y f, -x f, 0) = r x f; each rotor adds its reaction yaw torque `+-kappa f`.
    pub fn rotor_wrench(&self, speeds: &[f64; 4]) -> Wrench {
        let thrusts = self.rotor_thrusts(speeds);
        let mut wrench = Wrench::default();
        for (rotor, f) in self.rotors.iter().zip(thrusts) {
            wrench.thrust += f;
            wrench.torque += DVec3::new(
                rotor.y * f,
                -rotor.x * f,
                rotor.yaw_sign * self.torque_coefficient * f,
            );
        }
        wrench
    }

    /// Linear drag in the world frame (N): body drag `-c v` plus rotor drag
    /// `-m R diag(d_xy, d_xy, d_z) R^T v` (Faessler et al. 2018). Zero without drag.
    pub fn drag_force(&self, attitude: DQuat, velocity: DVec3) -> DVec3 {
        let drag = &self.drag;
        if drag.body == 0.0 && drag.rotor_xy == 0.0 && drag.rotor_z == 0.0 {
            return DVec3::ZERO;
        }
        let body_velocity = attitude.inverse() * velocity;
        let rotor =
            attitude * (body_velocity * DVec3::new(drag.rotor_xy, drag.rotor_xy, drag.rotor_z));
        -(drag.body * velocity) - self.mass * rotor
    }

    /// Force on the centre of mass in the world frame, gravity excluded (N): rotor thrust
    /// along body z plus drag.
    pub fn aerodynamic_force(&self, state: &FlightState, thrust: f64) -> DVec3 {
        state.attitude * DVec3::new(0.0, 0.0, thrust)
            + self.drag_force(state.attitude, state.velocity)
    }

    /// Newton-Euler with motor lag, for rotor speed commands held over the derivative:
    /// `m dv/dt = R (0, 0, T) + F_drag - m g e3`, `J dOmega/dt = M - Omega x J Omega`,
    /// `dq/dt = q (0, Omega) / 2`, `dw/dt = (w_cmd - w) / tau`.
    pub fn derivative(&self, state: &FlightState, commands: &[f64; 4]) -> FlightDerivative {
        let wrench = self.rotor_wrench(&state.rotor_speeds);
        let force = self.aerodynamic_force(state, wrench.thrust);
        let acceleration = force / self.mass - DVec3::new(0.0, 0.0, self.gravity);
        let omega = state.body_rates;
        let angular_momentum = self.inertia * omega;
        let angular_acceleration = (wrench.torque - omega.cross(angular_momentum)) / self.inertia;
        let omega_quat = DQuat::from_xyzw(omega.x, omega.y, omega.z, 0.0);
        let attitude_rate = (state.attitude * omega_quat) * 0.5;
        let mut rotor_acceleration = [0.0; 4];
        for (rate, (&w, &command)) in rotor_acceleration
            .iter_mut()
            .zip(state.rotor_speeds.iter().zip(commands))
        {
            *rate = self.motor.rate(w, command);
        }
        FlightDerivative {
            velocity: state.velocity,
            acceleration,
            attitude_rate,
            angular_acceleration,
            rotor_acceleration,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hover_speeds_balance_gravity_without_torque() {
        let airframe = Airframe::kingfisher();
        let model = QuadrotorModel::new(&airframe);
        let state = FlightState::hovering(&airframe, DVec3::ZERO, 0.3);
        let wrench = model.rotor_wrench(&state.rotor_speeds);
        assert!((wrench.thrust - 0.752 * 9.81).abs() < 1e-9);
        assert!(wrench.torque.length() < 1e-12);
        let d = model.derivative(&state, &state.rotor_speeds);
        assert!(d.acceleration.length() < 1e-9);
        assert!(d.angular_acceleration.length() < 1e-9);
        assert_eq!(d.rotor_acceleration, [0.0; 4]);
    }

    #[test]
    fn rotor_torques_follow_the_lever_arms() {
        let airframe = Airframe::kingfisher();
        let model = QuadrotorModel::new(&airframe);
        // Only rotor 0 (front right, x = 0.075, y = -0.10, yaw sign -1) at 1000 rad/s:
        // f = 1.562522 N; torque = (-0.10 f, -0.075 f, -0.022 f).
        let wrench = model.rotor_wrench(&[1000.0, 0.0, 0.0, 0.0]);
        let f = 1.562522;
        assert!((wrench.thrust - f).abs() < 1e-12);
        let expected = DVec3::new(-0.10 * f, -0.075 * f, -0.022 * f);
        assert!(
            (wrench.torque - expected).length() < 1e-12,
            "{:?}",
            wrench.torque
        );
    }

    #[test]
    fn drag_opposes_velocity() {
        let mut airframe = Airframe::kingfisher();
        airframe.drag = LinearDrag {
            body: 0.1,
            rotor_xy: 0.4,
            rotor_z: 0.2,
        };
        let model = QuadrotorModel::new(&airframe);
        // Level attitude, 2 m/s along x: -(0.1 * 2) - 0.752 * 0.4 * 2 = -0.8016 N.
        let force = model.drag_force(DQuat::IDENTITY, DVec3::new(2.0, 0.0, 0.0));
        assert!(
            (force - DVec3::new(-0.8016, 0.0, 0.0)).length() < 1e-12,
            "{force:?}"
        );
        // Climbing at 1 m/s: -(0.1) - 0.752 * 0.2 = -0.2504 N.
        let force = model.drag_force(DQuat::IDENTITY, DVec3::new(0.0, 0.0, 1.0));
        assert!((force.z + 0.2504).abs() < 1e-12);
    }

    #[test]
    fn gyroscopic_term_couples_the_axes() {
        let airframe = Airframe::kingfisher();
        let model = QuadrotorModel::new(&airframe);
        let mut state = FlightState::hovering(&airframe, DVec3::ZERO, 0.0);
        state.body_rates = DVec3::new(1.0, 0.0, 2.0);
        let d = model.derivative(&state, &state.rotor_speeds);
        // dOmega/dt = -(Omega x J Omega) / J with
        // Omega x (J Omega) = (1,0,2) x (2.5e-3, 0, 8.6e-3) = (0, 2*2.5e-3 - 1*8.6e-3, 0)
        //                   = (0, -3.6e-3, 0); divided by Jyy = 2.1e-3 -> +1.7143 rad/s^2.
        assert!((d.angular_acceleration.y - 3.6e-3 / 2.1e-3).abs() < 1e-9);
        assert!(d.angular_acceleration.x.abs() < 1e-9 && d.angular_acceleration.z.abs() < 1e-9);
    }
}
