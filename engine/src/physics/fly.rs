//! Flying a trajectory on the true (rapier) quadrotor: the geometric controller at the physics
//! rate (sample and hold), until the trajectory counts as flown or the UAV stops flying.
//! The ECS control system does the same per tick; this loop serves tests, benchmarks and
//! single-UAV studies (e.g. comparing a rollout's prediction with the flight).

use super::flight_world::{FlightWorld, UavHandle, UavStatus};
use uavex_components::trajectory::Trajectory;
use uavex_systems::flight::{Completion, FlightState, GeometricController, Progress, Tracking};

/// What a flight of one trajectory measured.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FlightRecord {
    pub status: UavStatus,
    /// Whether the UAV arrived (see [`Completion`]); false after a timeout, crash or empty
    /// battery.
    pub arrived: bool,
    /// Time from the start of the trajectory to its end as [`Completion`] defines it (s).
    pub duration_s: f64,
    /// Energy drawn during this flight (J).
    pub energy_j: f64,
    /// Root mean square over time of the distance to the reference position (m).
    pub rms_tracking_error_m: f64,
    pub max_tracking_error_m: f64,
    /// Highest actual rotor speed (rad/s).
    pub peak_rotor_speed: f64,
}

/// Flies `trajectory` (time 0 = now) with `controller` on `uav`, stepping the whole world;
/// `observe(time since start, state, power)` is called after every step.
pub fn fly_trajectory(
    world: &mut FlightWorld,
    uav: UavHandle,
    controller: &GeometricController,
    trajectory: &dyn Trajectory,
    completion: &Completion,
    observe: &mut dyn FnMut(f64, &FlightState, f64),
) -> FlightRecord {
    let dt = world.config().dt;
    let energy_before = world.meter(uav).energy_j;
    let mut steps: u64 = 0;
    let mut tracking = Tracking::default();
    let mut state = world.state(uav);
    let mut progress = completion.progress(0.0, trajectory, &state);
    let max_steps = ((trajectory.duration() + completion.settle_timeout) / dt).ceil() as u64 + 1;
    while progress == Progress::Flying
        && world.status(uav) == UavStatus::Flying
        && steps < max_steps
    {
        let t = steps as f64 * dt;
        let command = controller.command(&state, &trajectory.sample(t));
        world.set_commands(uav, command.rotor_speed_commands);
        world.step();
        steps += 1;
        let t = steps as f64 * dt;
        state = world.state(uav);
        tracking.record(&state, trajectory.sample(t).position, dt);
        observe(t, &state, world.power_w(uav));
        progress = completion.progress(t, trajectory, &state);
    }
    let duration = steps as f64 * dt;
    FlightRecord {
        status: world.status(uav),
        arrived: progress == Progress::Arrived,
        duration_s: duration,
        energy_j: world.meter(uav).energy_j - energy_before,
        rms_tracking_error_m: tracking.rms_error(duration),
        max_tracking_error_m: tracking.max_error_m,
        peak_rotor_speed: tracking.peak_rotor_speed,
    }
}
