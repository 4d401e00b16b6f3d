//! Offline rollout (common.md §4, EAAE 4.3.2): fly a trajectory with the same controller and
//! the same quadrotor equations as the true flight, without rapier and without the world, and
//! return its energy, duration, tracking error and peak rotor speed.
//!
//! A rollout is a pure function of (airframe, start state, trajectory, configuration): no
//! shared mutable state, so [`rollout_batch`] runs any number in parallel.
//!
//! Integration: the closed loop (controller, mixer, motor lag, rigid body and power) is one
//! ODE, stepped at the configured step (EAAE: 0.02 s). The controller is evaluated at every
//! stage, i.e. in continuous time, which the 300 Hz sample-and-hold of the true flight
//! approximates. Two schemes ([`Integrator`]):
//! - the explicit midpoint method (default), with the energy of the step taken at the midpoint
//!   rotor speeds: the midpoint rule the EAAE estimator used at 0.02 s, two evaluations of
//!   the closed loop per step;
//! - classic Runge-Kutta 4, with energy integrated as a state (Simpson's rule on the stages),
//!   four evaluations per step, for reference.
//!
//! With the kingfisher's fastest closed-loop pole near 30 1/s (the motors), `30 x 0.02 = 0.6`
//! lies inside both stability regions (2 and 2.78 on the real axis).

use super::FlightError;
use super::controller::{ControllerGains, GeometricController};
use super::dynamics::{FlightDerivative, QuadrotorModel};
use super::power::total_power;
use super::state::FlightState;
use glam::DVec3;
use rayon::prelude::*;
use uavex_components::airframe::Airframe;
use uavex_components::trajectory::{Trajectory, TrajectoryPoint};

/// When a flown trajectory counts as done: at or after its end, once the UAV is close to the
/// end point and slow; or, failing that, `settle_timeout` after the end. The true flight uses
/// the same rule, so their durations compare.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Completion {
    /// Distance to the trajectory's end point (m).
    pub position_tolerance: f64,
    /// Speed (m/s).
    pub speed_tolerance: f64,
    /// Longest wait after the trajectory's end (s).
    pub settle_timeout: f64,
}

impl Default for Completion {
    fn default() -> Self {
        Self {
            position_tolerance: 0.1,
            speed_tolerance: 0.25,
            settle_timeout: 5.0,
        }
    }
}

/// Where a flight stands against its [`Completion`] rule.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Progress {
    Flying,
    /// Reached the end point and slowed down.
    Arrived,
    /// The settle timeout passed without arriving.
    TimedOut,
}

impl Completion {
    pub fn progress(
        &self,
        time_s: f64,
        trajectory: &dyn Trajectory,
        state: &FlightState,
    ) -> Progress {
        let end_time = trajectory.duration();
        if time_s < end_time - 1e-9 {
            return Progress::Flying;
        }
        let end = trajectory.sample(end_time);
        if state.position.distance(end.position) <= self.position_tolerance
            && state.velocity.length() <= self.speed_tolerance
        {
            Progress::Arrived
        } else if time_s >= end_time + self.settle_timeout - 1e-9 {
            Progress::TimedOut
        } else {
            Progress::Flying
        }
    }
}

/// Integration scheme of a rollout (module doc).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Integrator {
    /// Explicit midpoint method with midpoint-rule energy (EAAE).
    #[default]
    Midpoint,
    /// Classic fourth-order Runge-Kutta.
    RungeKutta4,
}

/// How to roll out.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RolloutConfig {
    /// Integration step (s); EAAE: 0.02.
    pub step: f64,
    pub integrator: Integrator,
    pub gains: ControllerGains,
    pub completion: Completion,
}

impl Default for RolloutConfig {
    fn default() -> Self {
        Self {
            step: 0.02,
            integrator: Integrator::Midpoint,
            gains: ControllerGains::default(),
            completion: Completion::default(),
        }
    }
}

/// What a rollout predicts.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RolloutResult {
    /// Electrical energy of the four rotors (J).
    pub energy_j: f64,
    /// Time until the trajectory counted as flown (s), see [`Completion`].
    pub duration_s: f64,
    /// Root mean square over time of the distance to the reference position (m).
    pub rms_tracking_error_m: f64,
    pub max_tracking_error_m: f64,
    /// Highest rotor speed reached (rad/s).
    pub peak_rotor_speed: f64,
    /// Highest total power at a step end (W).
    pub peak_power_w: f64,
    /// Whether the UAV arrived (else the settle timeout ended the rollout).
    pub arrived: bool,
    pub final_state: FlightState,
}

/// Predicts the energy and duration of flying `trajectory` from `start` (see module doc).
pub fn rollout(
    airframe: &Airframe,
    start: &FlightState,
    trajectory: &dyn Trajectory,
    config: &RolloutConfig,
) -> Result<RolloutResult, FlightError> {
    rollout_observed(airframe, start, trajectory, config, &mut |_, _| {})
}

/// [`rollout`], calling `observe(time, state)` after every step (for time series and tests).
pub fn rollout_observed(
    airframe: &Airframe,
    start: &FlightState,
    trajectory: &dyn Trajectory,
    config: &RolloutConfig,
    observe: &mut dyn FnMut(f64, &FlightState),
) -> Result<RolloutResult, FlightError> {
    airframe.validate().map_err(FlightError::InvalidAirframe)?;
    let h = config.step;
    if !(h.is_finite() && h > 0.0) {
        return Err(FlightError::InvalidStep(h));
    }
    let duration = trajectory.duration();
    if !(duration.is_finite() && duration >= 0.0) {
        return Err(FlightError::InvalidTrajectory(format!(
            "duration {duration}"
        )));
    }
    if !start.is_finite() {
        return Err(FlightError::NonFiniteStart);
    }
    // Two samples a step: the prepared form (the same samples, to the bit) pays off at once.
    let prepared = trajectory.prepared();
    let trajectory = prepared.as_deref().unwrap_or(trajectory);
    let model = QuadrotorModel::new(airframe);
    let controller = GeometricController::new(airframe, config.gains)
        .ok_or_else(|| FlightError::InvalidAirframe("rotor layout cannot be mixed".into()))?;
    let closed_loop =
        |state: &FlightState, reference: &TrajectoryPoint| -> (FlightDerivative, f64) {
            let commands = controller.command(state, reference).rotor_speed_commands;
            (
                model.derivative(state, &commands),
                total_power(&model.power, &state.rotor_speeds),
            )
        };

    let mut state = *start;
    let mut t = 0.0;
    let mut energy = 0.0;
    let mut tracking = Tracking {
        peak_rotor_speed: start.rotor_speeds.iter().cloned().fold(0.0, f64::max),
        ..Tracking::default()
    };
    let mut peak_power = total_power(&model.power, &start.rotor_speeds);
    let mut reference = trajectory.sample(0.0);
    let max_steps = ((duration + config.completion.settle_timeout) / h).ceil() as u64 + 1;
    let mut progress = config.completion.progress(0.0, trajectory, &state);
    let mut steps = 0;
    while progress == Progress::Flying && steps < max_steps {
        let mid_reference = trajectory.sample(t + 0.5 * h);
        let end_reference = trajectory.sample(t + h);
        let (k1, p1) = closed_loop(&state, &reference);
        match config.integrator {
            Integrator::Midpoint => {
                let (k2, p2) = closed_loop(&advance(&state, &k1, 0.5 * h), &mid_reference);
                state = advance(&state, &k2, h);
                state.attitude = state.attitude.normalize();
                energy += h * p2;
            }
            Integrator::RungeKutta4 => {
                let (k2, p2) = closed_loop(&advance(&state, &k1, 0.5 * h), &mid_reference);
                let (k3, p3) = closed_loop(&advance(&state, &k2, 0.5 * h), &mid_reference);
                let (k4, p4) = closed_loop(&advance(&state, &k3, h), &end_reference);
                state = rk4_combine(&state, [&k1, &k2, &k3, &k4], h);
                energy += h / 6.0 * (p1 + 2.0 * p2 + 2.0 * p3 + p4);
            }
        }
        t += h;
        steps += 1;
        if !state.is_finite() {
            return Err(FlightError::Diverged { time_s: t });
        }
        observe(t, &state);
        reference = end_reference;
        tracking.record(&state, reference.position, h);
        peak_power = peak_power.max(total_power(&model.power, &state.rotor_speeds));
        progress = config.completion.progress(t, trajectory, &state);
    }
    Ok(RolloutResult {
        energy_j: energy,
        duration_s: t,
        rms_tracking_error_m: tracking.rms_error(t),
        max_tracking_error_m: tracking.max_error_m,
        peak_rotor_speed: tracking.peak_rotor_speed,
        peak_power_w: peak_power,
        arrived: progress == Progress::Arrived,
        final_state: state,
    })
}

/// How closely a flight followed its reference, accumulated step by step (a rollout's, and a
/// flight of the true quadrotor's in the engine).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Tracking {
    /// Integral over time of the squared distance to the reference position (m^2 s).
    pub squared_error_integral: f64,
    pub max_error_m: f64,
    /// Highest rotor speed seen (rad/s).
    pub peak_rotor_speed: f64,
}

impl Tracking {
    /// Adds a step of `dt` ending in `state`, whose reference position was `reference`.
    pub fn record(&mut self, state: &FlightState, reference: DVec3, dt: f64) {
        let error = state.position.distance(reference);
        self.squared_error_integral += error * error * dt;
        self.max_error_m = self.max_error_m.max(error);
        self.peak_rotor_speed = state
            .rotor_speeds
            .iter()
            .cloned()
            .fold(self.peak_rotor_speed, f64::max);
    }

    /// Root mean square of the error over a flight of `duration` (s); 0 for none.
    pub fn rms_error(&self, duration: f64) -> f64 {
        if duration > 0.0 {
            (self.squared_error_integral / duration).sqrt()
        } else {
            0.0
        }
    }
}

/// Rolls out many (start, trajectory) pairs in parallel (rayon); results in input order.
pub fn rollout_batch(
    airframe: &Airframe,
    jobs: &[(FlightState, &dyn Trajectory)],
    config: &RolloutConfig,
) -> Vec<Result<RolloutResult, FlightError>> {
    jobs.par_iter()
        .map(|(start, trajectory)| rollout(airframe, start, *trajectory, config))
        .collect()
}

/// `state + h * derivative` (a stage; the attitude is renormalised at the end of a step only).
fn advance(state: &FlightState, d: &FlightDerivative, h: f64) -> FlightState {
    FlightState {
        position: state.position + d.velocity * h,
        velocity: state.velocity + d.acceleration * h,
        attitude: state.attitude + d.attitude_rate * h,
        body_rates: state.body_rates + d.angular_acceleration * h,
        rotor_speeds: std::array::from_fn(|i| state.rotor_speeds[i] + d.rotor_acceleration[i] * h),
    }
}

/// The RK4 update `y + h/6 (k1 + 2 k2 + 2 k3 + k4)`, attitude renormalised.
fn rk4_combine(state: &FlightState, k: [&FlightDerivative; 4], h: f64) -> FlightState {
    let w = [h / 6.0, h / 3.0, h / 3.0, h / 6.0];
    let mut next = *state;
    for (weight, d) in w.iter().zip(k) {
        next.position += d.velocity * *weight;
        next.velocity += d.acceleration * *weight;
        next.attitude += d.attitude_rate * *weight;
        next.body_rates += d.angular_acceleration * *weight;
        for (speed, rate) in next.rotor_speeds.iter_mut().zip(d.rotor_acceleration) {
            *speed += rate * *weight;
        }
    }
    next.attitude = next.attitude.normalize();
    next
}
