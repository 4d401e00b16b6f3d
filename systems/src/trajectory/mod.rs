//! Trajectory generation: minimum-snap polynomials through waypoints with a feasible time
//! allocation (Richter, Bry & Roy 2013), their collision check against a blocked-point
//! predicate, and analytic references (circle, figure-eight) for controller studies.

pub mod analytic;
mod banded;
pub mod collision;
pub mod limits;
pub mod min_snap;
pub mod planner;
pub mod retime;
pub mod yaw_rate;

#[cfg(test)]
mod tests;

pub use analytic::{CurveReference, PlanarCurve};
pub use collision::{first_blocked, is_collision_free};
pub use planner::{
    DynamicLimits, Waypoint, min_snap_with_durations, plan_collision_free, plan_min_snap,
};

use glam::DVec3;

/// Why no trajectory could be planned.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PlanError {
    #[error("no waypoints to fly through")]
    NoWaypoints,
    #[error("non-finite value in {0}")]
    NonFinite(String),
    #[error("invalid limits: {0}")]
    InvalidLimits(String),
    #[error("the start state already exceeds the limits ({0})")]
    StartExceedsLimits(String),
    #[error("waypoint {index} coincides with the point before it")]
    CoincidentWaypoints { index: usize },
    #[error("the start position is blocked")]
    StartBlocked,
    #[error("waypoint {index} at {position} is blocked")]
    WaypointBlocked { index: usize, position: DVec3 },
    #[error("the trajectory is blocked at t = {time_s:.3} s near {position}")]
    Collision { time_s: f64, position: DVec3 },
    #[error("no time allocation met the speed and acceleration limits")]
    LimitsUnreachable,
    #[error(
        "the trajectory still leaves free space at t = {time_s:.3} s near {position} after \
         {added} added waypoints"
    )]
    StillBlocked {
        added: usize,
        time_s: f64,
        position: DVec3,
    },
    #[error("the minimum-snap system is singular")]
    Singular,
    #[error("no path through known free space leads to {goal}")]
    NoPath { goal: DVec3 },
    #[error("internal error: {0}")]
    Internal(String),
}
