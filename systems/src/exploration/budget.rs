//! The energy budget (beyond the thesis): a goal is affordable when the predicted energy of
//! flying there plus the predicted energy of flying home from there fits in what the battery
//! has left minus a reserve. When nothing is affordable the UAV flies home.
//!
//! The return is predicted like any candidate: a path from home to every candidate's goal
//! (one multi-goal search; paths on the grid are reversible), flown backwards as a
//! minimum-snap trajectory from rest at the goal, rolled out through the quadrotor model.

use super::propose::{MAX_EXPANSIONS, PlannedCandidate};
use crate::flight::{FlightState, RolloutConfig, rollout};
use crate::planning::{TraversableGrid, find_paths, plan_along, plan_global};
use crate::trajectory::DynamicLimits;
use glam::DVec3;
use rayon::prelude::*;
use std::sync::Arc;
use uavex_components::airframe::Airframe;
use uavex_components::trajectory::{PiecewisePolynomial, TrajectoryPoint};

/// The predicted energy (J) of flying home from each candidate's goal (hovering there), `None`
/// where no feasible way home was found.
pub fn return_energies(
    grid: &TraversableGrid,
    airframe: &Airframe,
    home: DVec3,
    home_yaw: f64,
    planned: &[PlannedCandidate],
    limits: &DynamicLimits,
    config: &RolloutConfig,
) -> Vec<Option<f64>> {
    let goals: Vec<DVec3> = planned.iter().map(|c| c.goal).collect();
    let paths = find_paths(grid, home, &goals, MAX_EXPANSIONS);
    planned
        .par_iter()
        .zip(paths.par_iter())
        .map(|(candidate, path)| {
            let mut back: Vec<DVec3> = path.as_ref()?.iter().rev().copied().collect();
            if back.len() < 2 {
                // Already home: nothing to fly back.
                return Some(0.0);
            }
            *back.last_mut()? = home;
            let from = TrajectoryPoint::at_rest(candidate.goal, candidate.goal_yaw);
            let plan = plan_along(grid, &from, &back, Some(home_yaw), limits).ok()?;
            let hover = FlightState::hovering(airframe, candidate.goal, candidate.goal_yaw);
            rollout(airframe, &hover, &plan.trajectory, config)
                .ok()
                .map(|r| r.energy_j)
        })
        .collect()
}

/// The way home when no goal is affordable.
#[derive(Debug, Clone)]
pub struct ReturnHome {
    pub trajectory: Arc<PiecewisePolynomial>,
}

/// A trajectory from `start` home, if one is feasible (else the UAV stays where it is).
pub fn plan_home(
    grid: &TraversableGrid,
    start: &TrajectoryPoint,
    home: DVec3,
    home_yaw: f64,
    limits: &DynamicLimits,
) -> Option<ReturnHome> {
    plan_global(grid, start, home, Some(home_yaw), limits)
        .ok()
        .map(|plan| ReturnHome {
            trajectory: Arc::new(plan.trajectory),
        })
}
