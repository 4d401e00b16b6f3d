//! The flight in the ECS: the components a dynamic UAV carries and the Control-stage system
//! that turns its reference trajectory into rotor speed commands (DESIGN.md "One tick":
//! "Control: geometric controller -> rotor speed commands -> motor lag").
//!
//! The rigid-body step itself (rapier) belongs to the engine, which owns the physics world; it
//! reads [`RotorCommands`] and writes back `QuadState` and [`FlightEnergy`]. Behaviours only
//! set a UAV's [`ReferenceTrajectory`], so any behaviour that plans a trajectory (waypoints
//! today, exploration and coverage later) flies it on the same controller.

use super::controller::GeometricController;
use super::energy::{Battery, EnergyMeter, EnergySummary};
use super::state::FlightState;
use bevy_ecs::prelude::*;
use std::sync::Arc;
use uavex_components::airframe::BatterySpec;
use uavex_components::sim::SimClock;
use uavex_components::trajectory::{Trajectory, TrajectoryPoint};
use uavex_components::uav::QuadState;

/// The geometric controller of one UAV (its gains, mass, inertia and mixer).
#[derive(Component, Debug, Clone)]
pub struct FlightController(pub GeometricController);

/// The trajectory a dynamic UAV tracks, and the simulation time its `t = 0` falls on.
#[derive(Component, Debug, Clone)]
pub struct ReferenceTrajectory {
    pub trajectory: Arc<dyn Trajectory>,
    /// Simulation time (s) of the trajectory's start.
    pub start_s: f64,
}

impl ReferenceTrajectory {
    /// The reference at simulation time `time_s` (the start before it, the end held after).
    pub fn at(&self, time_s: f64) -> TrajectoryPoint {
        self.trajectory.sample(time_s - self.start_s)
    }

    /// Time since the trajectory's start (s).
    pub fn elapsed(&self, time_s: f64) -> f64 {
        time_s - self.start_s
    }
}

/// Rotor speed commands (rad/s) for the motors, set in the Control stage, read by the physics.
#[derive(Component, Debug, Clone, Copy, PartialEq, Default)]
pub struct RotorCommands(pub [f64; 4]);

/// A dynamic UAV's energy account as of the last physics step (common.md §4-5): the meter, the
/// battery, and the power drawn during that step. The physics integrates it; systems read it.
#[derive(Component, Debug, Clone, PartialEq)]
pub struct FlightEnergy {
    pub meter: EnergyMeter,
    pub battery: Battery,
    /// Total rotor power of the last step (W); 0 once the UAV no longer flies.
    pub power_w: f64,
}

impl FlightEnergy {
    /// Nothing drawn yet from a full battery.
    pub fn new(battery: &BatterySpec) -> Self {
        Self {
            meter: EnergyMeter::default(),
            battery: Battery::new(battery),
            power_w: 0.0,
        }
    }

    /// The summary keys of this account (`energy_j`, `avg_power_w`, ...).
    pub fn summary(&self) -> EnergySummary {
        EnergySummary::new(&self.meter, &self.battery)
    }
}

/// Rotor speed commands that steer `state` toward the reference at `time_s`.
pub fn rotor_commands(
    controller: &GeometricController,
    reference: &ReferenceTrajectory,
    state: &QuadState,
    time_s: f64,
) -> [f64; 4] {
    controller
        .command(&FlightState::from(state), &reference.at(time_s))
        .rotor_speed_commands
}

/// Control stage: every UAV with a controller and a reference gets its rotor commands for this
/// step (sample and hold over the physics step, as a flight controller at the physics rate).
/// UAVs whose behaviour has ended keep tracking the end of their reference: they hover there.
pub fn track_references(
    clock: Res<SimClock>,
    mut uavs: Query<(
        &FlightController,
        &ReferenceTrajectory,
        &QuadState,
        &mut RotorCommands,
    )>,
) {
    let time_s = clock.time_s();
    for (controller, reference, state, mut commands) in &mut uavs {
        commands.0 = rotor_commands(&controller.0, reference, state, time_s);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::flight::ControllerGains;
    use glam::{DVec3, Vec3};
    use uavex_components::airframe::Airframe;
    use uavex_components::trajectory::Hold;

    #[test]
    fn a_hovering_uav_on_its_reference_is_commanded_hover_speeds() {
        let airframe = Airframe::kingfisher();
        let controller = GeometricController::new(&airframe, ControllerGains::default()).unwrap();
        let reference = ReferenceTrajectory {
            trajectory: Arc::new(Hold {
                position: DVec3::new(1.0, 2.0, 1.5),
                yaw: 0.3,
                duration: 10.0,
            }),
            start_s: 4.0,
        };
        let state = QuadState::at_rest(Vec3::new(1.0, 2.0, 1.5), 0.3);
        // sqrt(0.752 * 9.81 / (4 * 1.562522e-6)) = 1086.43 rad/s on every rotor.
        for w in rotor_commands(&controller, &reference, &state, 6.0) {
            assert!((w - 1086.43).abs() < 0.05, "{w}");
        }
        assert_eq!(reference.elapsed(6.0), 2.0);
    }

    #[test]
    fn the_system_writes_commands_at_the_clock_time() {
        let airframe = Airframe::kingfisher();
        let controller = GeometricController::new(&airframe, ControllerGains::default()).unwrap();
        let mut world = World::new();
        world.insert_resource(SimClock::new(300.0));
        // 10 cm below the reference: the controller asks for more than the hover thrust,
        // m (g + kp_acc 0.1) = 0.752 (9.81 + 1.0): w = sqrt(8.129 / (4 k_f)) = 1140.4 rad/s.
        let uav = world
            .spawn((
                FlightController(controller),
                ReferenceTrajectory {
                    trajectory: Arc::new(Hold {
                        position: DVec3::new(0.0, 0.0, 1.1),
                        yaw: 0.0,
                        duration: 1.0,
                    }),
                    start_s: 0.0,
                },
                QuadState::at_rest(Vec3::new(0.0, 0.0, 1.0), 0.0),
                RotorCommands::default(),
            ))
            .id();
        let mut schedule = Schedule::default();
        schedule.add_systems(track_references);
        schedule.run(&mut world);
        let commands = world.get::<RotorCommands>(uav).unwrap().0;
        for w in commands {
            assert!((w - 1140.4).abs() < 0.5, "{w}");
        }
    }

    #[test]
    fn energy_account_starts_full() {
        let energy = FlightEnergy::new(&Airframe::kingfisher().battery);
        let summary = energy.summary();
        assert_eq!(summary.energy_j, 0.0);
        assert_eq!(summary.battery_soc_end, 1.0);
        // 26.64 Wh = 95 904 J.
        assert!((energy.battery.capacity_j - 95_904.0).abs() < 1e-6);
    }
}
