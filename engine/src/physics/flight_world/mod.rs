//! The true flight: every UAV a rapier3d dynamic rigid body among the world's static
//! colliders (common.md §3).
//!
//! Each physics step (300 Hz by default) the motors lag toward their commanded speeds
//! (exactly, over the step), the rotor thrusts and yaw torques of the step's mid-point rotor
//! speeds (plus drag) are applied as a force and a torque, the bodies are integrated, and a
//! UAV whose collider intersects world geometry (or another UAV) ends as crashed. Energy is
//! integrated every step from the same mid-point rotor speeds (midpoint rule).
//!
//! What rapier is used for, and what a lone body does not need to pay for:
//! - The rigid-body integration is rapier's: its symplectic Euler on the body
//!   (`RigidBodyForces::integrate`, the explicit momentum-preserving gyroscopic correction
//!   `angvel_with_gyroscopic_forces`, `RigidBodyVelocity::integrate`), the scheme its solver
//!   applies to a body without contacts.
//! - Contacts are rapier's: near geometry every step runs the whole `PhysicsPipeline`
//!   (broad phase, narrow phase, islands, solver), and its intersection graph decides crashes.
//!   UAV colliders are sensors: a crash ends the run, so no contact response is needed, only
//!   the exact "do the shapes touch" answer.
//! - Far from geometry the pipeline would find nothing: each UAV keeps a clearance (distance
//!   from its centre to the nearest fixed collider, through rapier's query pipeline, minus the
//!   radius of its bounding sphere), and while every UAV has travelled less than its clearance
//!   minus a margin since it was measured (and UAVs are far from each other), the step
//!   integrates the bodies directly with the functions above and skips the pipeline. The
//!   clearance is measured again when the budget runs out.
//!
//! Numbers: rapier is f32; our models are f64 (see `uavex_systems::flight::state`). Forces are
//! computed in f64 and handed to rapier in f32; states are read back into f64.

mod clearance;
mod stepping;

use glam::{DQuat, DVec3};
use rapier3d::prelude::*;
use uavex_components::airframe::Airframe;
use uavex_systems::flight::dynamics::QuadrotorModel;
use uavex_systems::flight::power::total_power;
use uavex_systems::flight::{Battery, EnergyMeter, EnergySummary, FlightState};

/// Settings of the true flight.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FlightWorldConfig {
    /// Physics and control step (s): 1/300 (EAAE).
    pub dt: f64,
    /// Distance to geometry (m) below which every step runs rapier's whole pipeline.
    pub clearance_margin: f64,
    /// Run the whole pipeline every step, even far from geometry (for checks and benchmarks).
    pub always_full_pipeline: bool,
}

impl Default for FlightWorldConfig {
    fn default() -> Self {
        Self {
            dt: 1.0 / 300.0,
            clearance_margin: 0.1,
            always_full_pipeline: false,
        }
    }
}

/// Index of a UAV in its [`FlightWorld`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct UavHandle(pub usize);

/// Whether a UAV still flies.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum UavStatus {
    Flying,
    /// Its collider touched world geometry or another UAV.
    Crashed {
        time_s: f64,
        position: DVec3,
    },
    /// Its battery's usable energy is spent.
    BatteryEmpty {
        time_s: f64,
        position: DVec3,
    },
}

/// What a crashed UAV touched.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CrashTarget {
    /// A fixed collider, by its `user_data` (the engine's world colliders carry the index of
    /// their obstacle there).
    Fixed { user_data: u128 },
    /// Another UAV, flying or a wreck.
    Uav(UavHandle),
}

/// Why a flight world or a UAV could not be set up.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PhysicsError {
    #[error("physics step must be finite and > 0, got {0}")]
    InvalidStep(f64),
    #[error("invalid airframe: {0}")]
    InvalidAirframe(String),
    #[error("the start state has non-finite values")]
    NonFiniteStart,
    #[error("the UAV starts inside world geometry at {0}")]
    StartsInCollision(DVec3),
}

/// Counts of what the steps did, for benchmarks and reports.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct StepCounts {
    /// Steps that ran rapier's whole pipeline.
    pub pipeline_steps: u64,
    /// Steps that only integrated the bodies (all UAVs clear of geometry).
    pub free_steps: u64,
    /// Clearance queries against the fixed colliders.
    pub clearance_queries: u64,
}

/// Force and torque (world frame) on one UAV for a step, and its pose before it.
#[derive(Debug, Clone, Copy)]
struct StepInput {
    force: DVec3,
    torque: DVec3,
    pose_before: Pose,
}

/// One UAV of the world.
#[derive(Debug, Clone)]
struct FlyingUav {
    model: QuadrotorModel,
    body: RigidBodyHandle,
    collider: ColliderHandle,
    /// Radius of the sphere around the centre that holds the collider (m).
    radius: f64,
    rotor_speeds: [f64; 4],
    commands: [f64; 4],
    meter: EnergyMeter,
    battery: Battery,
    status: UavStatus,
    /// What it touched, once crashed.
    crashed_into: Option<CrashTarget>,
    /// Total power drawn during the last step (W); 0 once the UAV no longer flies.
    power_w: f64,
    /// Free distance (m) measured at `clearance_origin`: to the nearest fixed collider, minus
    /// `radius`.
    clearance: f64,
    clearance_origin: DVec3,
}

/// rapier's sets and pipeline, the static world and the UAVs (no ECS).
pub struct FlightWorld {
    config: FlightWorldConfig,
    tick: u64,
    gravity: f64,
    params: IntegrationParameters,
    pipeline: PhysicsPipeline,
    islands: IslandManager,
    broad_phase: BroadPhaseBvh,
    narrow_phase: NarrowPhase,
    bodies: RigidBodySet,
    colliders: ColliderSet,
    impulse_joints: ImpulseJointSet,
    multibody_joints: MultibodyJointSet,
    soft_bodies: SoftBodySet,
    ccd_solver: CCDSolver,
    uavs: Vec<FlyingUav>,
    /// What each flying UAV takes into the step being taken; reused buffer.
    inputs: Vec<Option<StepInput>>,
    counts: StepCounts,
}

impl FlightWorld {
    /// A world whose fixed geometry is `static_colliders` (colliders without a parent body,
    /// or attached to fixed bodies in `static_bodies`).
    pub fn new(
        static_bodies: RigidBodySet,
        static_colliders: ColliderSet,
        config: FlightWorldConfig,
    ) -> Result<Self, PhysicsError> {
        if !(config.dt.is_finite() && config.dt > 0.0) {
            return Err(PhysicsError::InvalidStep(config.dt));
        }
        let params = IntegrationParameters {
            dt: config.dt as f32,
            // No contact constraints to solve (UAV colliders are sensors): one solver pass.
            num_solver_iterations: 1,
            ..IntegrationParameters::default()
        };
        let mut pipeline = PhysicsPipeline::new();
        pipeline.counters.disable();
        let mut world = Self {
            config,
            tick: 0,
            gravity: uavex_components::airframe::GRAVITY,
            params,
            pipeline,
            islands: IslandManager::new(),
            broad_phase: BroadPhaseBvh::new(),
            narrow_phase: NarrowPhase::new(),
            bodies: static_bodies,
            colliders: static_colliders,
            impulse_joints: ImpulseJointSet::new(),
            multibody_joints: MultibodyJointSet::new(),
            soft_bodies: SoftBodySet::new(),
            ccd_solver: CCDSolver::new(),
            uavs: Vec::new(),
            inputs: Vec::new(),
            counts: StepCounts::default(),
        };
        world.update_collision_detection();
        Ok(world)
    }

    /// A world of fixed shapes at the given poses.
    pub fn from_shapes(
        shapes: impl IntoIterator<Item = (Pose, SharedShape)>,
        config: FlightWorldConfig,
    ) -> Result<Self, PhysicsError> {
        let mut colliders = ColliderSet::new();
        for (pose, shape) in shapes {
            colliders.insert(ColliderBuilder::new(shape).position(pose));
        }
        Self::new(RigidBodySet::new(), colliders, config)
    }

    /// Adds a UAV of `airframe` in `state`; refused when it starts inside geometry.
    pub fn add_uav(
        &mut self,
        airframe: &Airframe,
        state: &FlightState,
    ) -> Result<UavHandle, PhysicsError> {
        airframe.validate().map_err(PhysicsError::InvalidAirframe)?;
        if !state.is_finite() {
            return Err(PhysicsError::NonFiniteStart);
        }
        let attitude = state.attitude.normalize();
        let pose = Pose::from_parts(state.position.as_vec3(), attitude.as_quat());
        let half = airframe.size.map(|s| (0.5 * s) as f32);
        let shape = SharedShape::cuboid(half[0], half[1], half[2]);
        let clearance = self.distance_to_fixed(state.position) - airframe.bounding_radius();
        self.counts.clearance_queries += 1;
        if clearance <= 0.0 && self.touches_fixed(pose, &shape) {
            return Err(PhysicsError::StartsInCollision(state.position));
        }
        let body = RigidBodyBuilder::dynamic()
            .pose(pose)
            .linvel(state.velocity.as_vec3())
            .angvel((attitude * state.body_rates).as_vec3())
            .additional_mass_properties(MassProperties::new(
                Vector::ZERO,
                airframe.mass as f32,
                Vector::from_array(airframe.inertia.map(|i| i as f32)),
            ))
            .can_sleep(false)
            .build();
        let body = self.bodies.insert(body);
        // A sensor: its intersections are reported, nothing pushes back (a touch is a crash).
        let collider = ColliderBuilder::new(shape)
            .density(0.0)
            .sensor(true)
            .build();
        let collider = self
            .colliders
            .insert_with_parent(collider, body, &mut self.bodies);
        let mut meter = EnergyMeter::default();
        meter.start_at(state.position);
        let uav = FlyingUav {
            model: QuadrotorModel::new(airframe),
            body,
            collider,
            radius: airframe.bounding_radius(),
            rotor_speeds: state.rotor_speeds,
            commands: state.rotor_speeds,
            meter,
            battery: Battery::new(&airframe.battery),
            status: UavStatus::Flying,
            crashed_into: None,
            power_w: total_power(&airframe.power, &state.rotor_speeds),
            clearance,
            clearance_origin: state.position,
        };
        self.uavs.push(uav);
        // rapier computes the body's world mass properties and enters the collider in the
        // broad phase when it handles user changes, inside a pipeline step.
        self.update_collision_detection();
        Ok(UavHandle(self.uavs.len() - 1))
    }

    /// Sets the rotor speed commands (rad/s) the motors follow from the next step on.
    pub fn set_commands(&mut self, uav: UavHandle, commands: [f64; 4]) {
        self.uavs[uav.0].commands = commands;
    }

    /// Advances every flying UAV by one physics step.
    ///
    /// A crash is reported at the time and pose at which rapier's narrow phase, which runs at
    /// the start of a pipeline step, found the intersection; the wreck is left there.
    pub fn step(&mut self) {
        let dt = self.config.dt;
        let time_before = self.tick as f64 * dt;
        let time_after = (self.tick + 1) as f64 * dt;
        // Motors, then the wrench of the step's mid-point rotor speeds.
        let mut inputs = std::mem::take(&mut self.inputs);
        inputs.clear();
        for uav in &mut self.uavs {
            if uav.status != UavStatus::Flying {
                uav.power_w = 0.0;
                inputs.push(None);
                continue;
            }
            let motor = uav.model.motor;
            let mut middle = [0.0; 4];
            for ((speed, mid), &command) in uav
                .rotor_speeds
                .iter_mut()
                .zip(middle.iter_mut())
                .zip(&uav.commands)
            {
                *mid = motor.advance(*speed, command, 0.5 * dt);
                *speed = motor.advance(*speed, command, dt);
            }
            let body = &self.bodies[uav.body];
            let state = read_state(body, uav.rotor_speeds);
            let wrench = uav.model.rotor_wrench(&middle);
            uav.power_w = total_power(&uav.model.power, &middle);
            inputs.push(Some(StepInput {
                force: uav.model.aerodynamic_force(&state, wrench.thrust),
                torque: state.attitude * wrench.torque,
                pose_before: *body.position(),
            }));
        }

        let full = self.config.always_full_pipeline || self.any_uav_near();
        if inputs.iter().all(Option::is_none) {
            // Nothing flies: time passes, nothing moves.
        } else if full {
            self.pipeline_step(&inputs);
        } else {
            self.free_step(&inputs);
        }

        self.tick += 1;
        for (index, input) in inputs.iter().enumerate() {
            let Some(input) = input else {
                continue;
            };
            let crashed_into = if full {
                self.first_intersection(self.uavs[index].collider)
            } else {
                None
            };
            let state = self.state(UavHandle(index));
            let uav = &mut self.uavs[index];
            let body = &mut self.bodies[uav.body];
            if crashed_into.is_some() {
                // The crash step's energy is not drawn (the step did not happen as flown).
                uav.power_w = 0.0;
                uav.crashed_into = crashed_into;
                body.set_position(input.pose_before, false);
                uav.status = UavStatus::Crashed {
                    time_s: time_before,
                    position: input.pose_before.translation.as_dvec3(),
                };
            } else {
                uav.meter.record(dt, uav.power_w, state.position);
                uav.battery.draw(uav.power_w * dt);
                if uav.battery.is_spent() {
                    uav.status = UavStatus::BatteryEmpty {
                        time_s: time_after,
                        position: state.position,
                    };
                }
            }
            if uav.status != UavStatus::Flying {
                // The wreck stays where it is, an obstacle for the others: a dynamic body at
                // rest without gravity, so that rapier's sets keep their structure (turning it
                // into a fixed body after bodies were moved outside the pipeline trips an
                // index panic in rapier 0.36.1's island manager).
                body.set_linvel(Vector::ZERO, false);
                body.set_angvel(Vector::ZERO, false);
                body.set_gravity_scale(0.0, false);
                body.reset_forces(false);
                body.reset_torques(false);
            }
        }
        self.inputs = inputs;
        self.refresh_clearances();
    }

    /// Simulation time (s) after the steps so far.
    pub fn time_s(&self) -> f64 {
        self.tick as f64 * self.config.dt
    }

    pub fn config(&self) -> &FlightWorldConfig {
        &self.config
    }

    /// The UAV's state, read from its rigid body (centre of mass at the body origin).
    pub fn state(&self, uav: UavHandle) -> FlightState {
        let uav = &self.uavs[uav.0];
        read_state(&self.bodies[uav.body], uav.rotor_speeds)
    }

    pub fn status(&self, uav: UavHandle) -> UavStatus {
        self.uavs[uav.0].status
    }

    /// What the UAV crashed into, if it crashed.
    pub fn crashed_into(&self, uav: UavHandle) -> Option<CrashTarget> {
        self.uavs[uav.0].crashed_into
    }

    /// Energy integrated so far for this UAV.
    pub fn meter(&self, uav: UavHandle) -> &EnergyMeter {
        &self.uavs[uav.0].meter
    }

    pub fn battery(&self, uav: UavHandle) -> &Battery {
        &self.uavs[uav.0].battery
    }

    /// Total rotor power drawn during the last step (W): the power its energy was integrated
    /// with; 0 in the step a UAV crashed and after it stopped flying.
    pub fn power_w(&self, uav: UavHandle) -> f64 {
        self.uavs[uav.0].power_w
    }

    /// The energy summary of this UAV's flight so far.
    pub fn summary(&self, uav: UavHandle) -> EnergySummary {
        let uav = &self.uavs[uav.0];
        EnergySummary::new(&uav.meter, &uav.battery)
    }

    pub fn uav_count(&self) -> usize {
        self.uavs.len()
    }

    pub fn counts(&self) -> StepCounts {
        self.counts
    }
}

/// A rigid body's state in f64 (body rates in the body frame).
fn read_state(body: &RigidBody, rotor_speeds: [f64; 4]) -> FlightState {
    let attitude: DQuat = body.rotation().as_dquat().normalize();
    FlightState {
        position: body.translation().as_dvec3(),
        velocity: body.linvel().as_dvec3(),
        attitude,
        body_rates: attitude.inverse() * body.angvel().as_dvec3(),
        rotor_speeds,
    }
}
