//! Clearances: how far each UAV may fly before rapier's pipeline must look at its contacts.

use super::{FlightWorld, FlyingUav, UavStatus};
use glam::DVec3;
use rapier3d::prelude::*;

/// Farthest a clearance query looks (m); beyond it a UAV is simply "far".
const CLEARANCE_HORIZON: f32 = 50.0;

impl FlightWorld {
    /// Distance (m) a flying UAV may still travel, at its speed over the next step, before
    /// its clearance runs out; and its centre and reach (radius plus that travel).
    pub(super) fn budget(&self, uav: &FlyingUav) -> (f64, DVec3, f64) {
        let body = &self.bodies[uav.body];
        let position = body.translation().as_dvec3();
        let travel = 2.0 * body.linvel().length() as f64 * self.config.dt;
        let budget = uav.clearance - position.distance(uav.clearance_origin) - travel;
        (budget, position, uav.radius + travel)
    }

    /// Whether some flying UAV may come within the margin of geometry, of another UAV or of a
    /// wreck during the next step.
    pub(super) fn any_uav_near(&self) -> bool {
        let margin = self.config.clearance_margin;
        for (i, a) in self.uavs.iter().enumerate() {
            let (budget, position_a, reach_a) = self.budget(a);
            let a_flies = a.status == UavStatus::Flying;
            if a_flies && budget < margin {
                return true;
            }
            // Other UAVs (flying or wrecked) are not in the fixed-collider clearance: test the
            // pairs with at least one flying UAV.
            for b in &self.uavs[i + 1..] {
                if !a_flies && b.status != UavStatus::Flying {
                    continue;
                }
                let (_, position_b, reach_b) = self.budget(b);
                if position_a.distance(position_b) - reach_a - reach_b < margin {
                    return true;
                }
            }
        }
        false
    }

    /// Measures again the clearance of the UAVs whose budget ran low: with twice the margin in
    /// hand, so that a UAV coasting along a wall does not need a query every step before it
    /// actually needs the pipeline.
    pub(super) fn refresh_clearances(&mut self) {
        let margin = self.config.clearance_margin;
        for index in 0..self.uavs.len() {
            let uav = &self.uavs[index];
            if uav.status != UavStatus::Flying || self.budget(uav).0 >= 2.0 * margin {
                continue;
            }
            let position = self.bodies[uav.body].translation().as_dvec3();
            let clearance = self.distance_to_fixed(position) - uav.radius;
            let uav = &mut self.uavs[index];
            uav.clearance = clearance;
            uav.clearance_origin = position;
            self.counts.clearance_queries += 1;
        }
    }

    /// Distance from a point to the nearest fixed collider (0 inside one), at most
    /// [`CLEARANCE_HORIZON`], through rapier's query pipeline.
    pub(super) fn distance_to_fixed(&self, position: DVec3) -> f64 {
        let point = position.as_vec3();
        let query = self.broad_phase.as_query_pipeline(
            self.narrow_phase.query_dispatcher(),
            &self.bodies,
            &self.colliders,
            QueryFilter::only_fixed(),
        );
        match query.project_point(point, CLEARANCE_HORIZON, true) {
            Some((_, projection)) if projection.is_inside => 0.0,
            Some((_, projection)) => (projection.point - point).length() as f64,
            None => CLEARANCE_HORIZON as f64,
        }
    }

    /// Whether `shape` at `pose` intersects a fixed collider (exact shapes).
    pub(super) fn touches_fixed(&self, pose: Pose, shape: &SharedShape) -> bool {
        let query = self.broad_phase.as_query_pipeline(
            self.narrow_phase.query_dispatcher(),
            &self.bodies,
            &self.colliders,
            QueryFilter::only_fixed(),
        );
        query.intersect_shape(pose, shape.as_ref()).next().is_some()
    }
}
