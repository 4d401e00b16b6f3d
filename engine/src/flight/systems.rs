//! The true flight in the tick: the [`Physics`] resource (the rapier [`FlightWorld`] with the
//! world's colliders and one body per dynamic UAV) and its thin systems.
//!
//! - Physics stage, [`step_physics`]: hands each UAV's rotor commands to its motors, steps the
//!   flight world once (one physics step per tick), and copies state and energy back into
//!   `QuadState` and `FlightEnergy`; a UAV whose collider touched geometry ends `Crashed` and
//!   ends the run as `crashed`, with the time, the position and what it hit.
//! - Account stage, [`end_on_empty_battery`]: a UAV whose battery's usable energy is drawn ends
//!   `BatteryEmpty`, and the run as `battery_empty`.

use crate::physics::{
    CrashTarget, FlightWorld, FlightWorldConfig, PhysicsError, UavHandle, UavStatus,
};
use crate::world::colliders;
use bevy_ecs::prelude::*;
use rapier3d::dynamics::RigidBodySet;
use uavex_components::airframe::Airframe;
use uavex_components::sim::{Outcome, RunEnd, SimClock};
use uavex_components::uav::{QuadState, Uav, UavEnded};
use uavex_components::world::WorldGeometry;
use uavex_systems::flight::{FlightEnergy, FlightState, RotorCommands};

/// The rapier flight world of a run (DESIGN.md: "`Physics` (rapier sets and pipeline)").
#[derive(Resource)]
pub struct Physics {
    pub world: FlightWorld,
    /// Name of the UAV behind each handle, for crash reports.
    names: Vec<String>,
}

/// The body of a dynamic UAV in [`Physics`].
#[derive(Component, Debug, Clone, Copy, PartialEq, Eq)]
pub struct PhysicsBody(pub UavHandle);

impl Physics {
    /// A flight world whose fixed colliders are the obstacles of `geometry` (each carrying its
    /// obstacle's index, so a crash can name it), stepped every `dt` seconds.
    pub fn new(geometry: &WorldGeometry, dt: f64) -> Result<Self, PhysicsError> {
        let config = FlightWorldConfig {
            dt,
            ..FlightWorldConfig::default()
        };
        Ok(Self {
            world: FlightWorld::new(RigidBodySet::new(), colliders(geometry), config)?,
            names: Vec::new(),
        })
    }

    /// Adds the UAV `name` of `airframe` in `state` (refused inside geometry).
    pub fn add(
        &mut self,
        name: &str,
        airframe: &Airframe,
        state: &FlightState,
    ) -> Result<UavHandle, PhysicsError> {
        let handle = self.world.add_uav(airframe, state)?;
        self.names.push(name.to_owned());
        Ok(handle)
    }

    /// What a crashed UAV hit, in words.
    fn describe(&self, target: Option<CrashTarget>, geometry: &WorldGeometry) -> String {
        match target {
            Some(CrashTarget::Fixed { user_data }) => {
                match usize::try_from(user_data)
                    .ok()
                    .and_then(|i| geometry.obstacles().get(i))
                {
                    Some(obstacle) => format!("obstacle '{}'", obstacle.name),
                    None => "world geometry".to_owned(),
                }
            }
            Some(CrashTarget::Uav(other)) => format!("UAV '{}'", self.names[other.0]),
            None => "world geometry".to_owned(),
        }
    }
}

/// Physics stage: motors, one rigid-body step, state and energy back into the UAVs, crashes.
#[allow(clippy::type_complexity)]
pub fn step_physics(
    mut physics: ResMut<Physics>,
    geometry: Res<WorldGeometry>,
    mut run_end: ResMut<RunEnd>,
    mut commands: Commands,
    mut uavs: Query<(
        Entity,
        &Uav,
        &PhysicsBody,
        &RotorCommands,
        &mut QuadState,
        &mut FlightEnergy,
        Option<&UavEnded>,
    )>,
) {
    for (_, _, body, rotor_commands, ..) in &uavs {
        physics.world.set_commands(body.0, rotor_commands.0);
    }
    physics.world.step();
    // The lowest-index UAV's crash names the run's ending (query order is storage order).
    let mut first_crash: Option<(usize, String)> = None;
    let mut first_unstable: Option<(usize, String)> = None;
    for (entity, uav, body, _, mut state, mut energy, ended) in &mut uavs {
        let world = &physics.world;
        let flight = world.state(body.0);
        *state = QuadState::from(&flight);
        energy.meter.clone_from(world.meter(body.0));
        energy.battery = *world.battery(body.0);
        energy.power_w = world.power_w(body.0);
        if !(flight.is_finite() && energy.power_w.is_finite()) && ended.is_none() {
            // A diverged integration would otherwise surface ticks later, far from its cause
            // (as a sensor origin that is not finite), or run on with NaN metrics.
            let reason = format!(
                "UAV '{}' became numerically unstable at t = {:.3} s (its state is no longer                  finite): the airframe (mass, inertia, torque_coefficient, drag) cannot be                  simulated at this physics_rate_hz",
                uav.name,
                world.time_s()
            );
            if first_unstable.as_ref().is_none_or(|(i, _)| uav.index < *i) {
                first_unstable = Some((uav.index, reason));
            }
            continue;
        }
        let UavStatus::Crashed { time_s, position } = world.status(body.0) else {
            continue;
        };
        if matches!(ended, Some(UavEnded::Crashed { .. })) {
            continue;
        }
        commands.entity(entity).insert(UavEnded::Crashed {
            time_s,
            position: position.as_vec3(),
        });
        let what = physics.describe(world.crashed_into(body.0), &geometry);
        let reason = format!(
            "UAV '{}' crashed into {what} at t = {time_s:.3} s at ({:.3}, {:.3}, {:.3})",
            uav.name, position.x, position.y, position.z
        );
        if first_crash.as_ref().is_none_or(|(i, _)| uav.index < *i) {
            first_crash = Some((uav.index, reason));
        }
    }
    if run_end.0.is_none() {
        if let Some((_, reason)) = first_unstable {
            run_end.0 = Some((Outcome::Failed, reason));
        } else if let Some((_, reason)) = first_crash {
            run_end.0 = Some((Outcome::Crashed, reason));
        }
    }
}

/// Account stage: a UAV whose battery has given its usable energy ends, and so does the run.
/// The tick's physics step has been taken, so the time is the end of this tick.
pub fn end_on_empty_battery(
    clock: Res<SimClock>,
    mut run_end: ResMut<RunEnd>,
    mut commands: Commands,
    uavs: Query<(Entity, &Uav, &FlightEnergy, &QuadState, Option<&UavEnded>)>,
) {
    let time_s = clock.time_s() + clock.dt;
    let mut first_empty: Option<(usize, String)> = None;
    for (entity, uav, energy, state, ended) in &uavs {
        let already = matches!(
            ended,
            Some(UavEnded::BatteryEmpty { .. } | UavEnded::Crashed { .. })
        );
        if already || !energy.battery.is_spent() {
            continue;
        }
        commands.entity(entity).insert(UavEnded::BatteryEmpty {
            time_s,
            position: state.position,
        });
        let reason = format!(
            "UAV '{}' drew the usable {:.0} J of its battery at t = {time_s:.3} s at \
             ({:.3}, {:.3}, {:.3})",
            uav.name, energy.battery.usable_j, state.position.x, state.position.y, state.position.z
        );
        if first_empty.as_ref().is_none_or(|(i, _)| uav.index < *i) {
            first_empty = Some((uav.index, reason));
        }
    }
    if let Some((_, reason)) = first_empty
        && run_end.0.is_none()
    {
        run_end.0 = Some((Outcome::BatteryEmpty, reason));
    }
}
