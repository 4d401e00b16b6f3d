//! The two ways a step moves the bodies: rapier's whole pipeline (near geometry), or rapier's
//! integration functions on each body (far from it); and the narrow-phase queries around them.

use super::{CrashTarget, FlightWorld, StepInput, UavHandle};
use glam::DVec3;
use rapier3d::prelude::*;

impl FlightWorld {
    /// Applies the wrenches as forces and runs rapier's whole pipeline.
    pub(super) fn pipeline_step(&mut self, inputs: &[Option<StepInput>]) {
        for (uav, input) in self.uavs.iter().zip(inputs) {
            let Some(StepInput { force, torque, .. }) = input else {
                continue;
            };
            let body = &mut self.bodies[uav.body];
            body.reset_forces(false);
            body.reset_torques(false);
            body.add_force(force.as_vec3(), true);
            body.add_torque(torque.as_vec3(), true);
        }
        self.run_pipeline(self.params);
        self.counts.pipeline_steps += 1;
    }

    /// Integrates each flying body with rapier's integration functions (module doc).
    pub(super) fn free_step(&mut self, inputs: &[Option<StepInput>]) {
        let dt = self.params.dt;
        for (uav, input) in self.uavs.iter().zip(inputs) {
            let Some(StepInput { force, torque, .. }) = input else {
                continue;
            };
            let gravity = DVec3::new(0.0, 0.0, -self.gravity * uav.model.mass);
            let body = &mut self.bodies[uav.body];
            let forces = RigidBodyForces {
                force: (*force + gravity).as_vec3(),
                torque: torque.as_vec3(),
                ..RigidBodyForces::default()
            };
            let before = RigidBodyVelocity {
                linvel: body.linvel(),
                angvel: body.angvel(),
            };
            let after = forces.integrate(dt, &before, body.mass_properties());
            body.set_linvel(after.linvel, false);
            body.set_angvel(after.angvel, false);
            let angvel = body.angvel_with_gyroscopic_forces(dt);
            body.set_angvel(angvel, false);
            let velocity = RigidBodyVelocity {
                linvel: after.linvel,
                angvel,
            };
            let local_com = body.mass_properties().local_mprops.local_com;
            let pose = velocity.integrate(dt, body.position(), &local_com);
            body.set_position(pose, false);
        }
        self.counts.free_steps += 1;
    }

    /// What the narrow phase reports this collider intersecting, if anything (the first
    /// pair in the intersection graph's order, which is deterministic).
    pub(super) fn first_intersection(&self, collider: ColliderHandle) -> Option<CrashTarget> {
        let (a, b, _) = self
            .narrow_phase
            .intersection_pairs_with(collider)
            .find(|&(_, _, intersecting)| intersecting)?;
        let other = if a == collider { b } else { a };
        if let Some(index) = self.uavs.iter().position(|uav| uav.collider == other) {
            return Some(CrashTarget::Uav(UavHandle(index)));
        }
        let user_data = self.colliders.get(other).map_or(0, |c| c.user_data);
        Some(CrashTarget::Fixed { user_data })
    }

    /// A zero-length pipeline step: inserts the colliders into the broad phase and updates
    /// the narrow phase without moving anything.
    pub(super) fn update_collision_detection(&mut self) {
        self.run_pipeline(IntegrationParameters {
            dt: 0.0,
            ..self.params
        });
    }

    /// One step of rapier's pipeline over the whole world with `params`, under gravity.
    fn run_pipeline(&mut self, params: IntegrationParameters) {
        self.pipeline.step(
            Vector::new(0.0, 0.0, -self.gravity as f32),
            &params,
            &mut self.islands,
            &mut self.broad_phase,
            &mut self.narrow_phase,
            &mut self.bodies,
            &mut self.colliders,
            &mut self.impulse_joints,
            &mut self.multibody_joints,
            &mut self.soft_bodies,
            &mut self.ccd_solver,
            &(),
            &(),
        );
    }
}
