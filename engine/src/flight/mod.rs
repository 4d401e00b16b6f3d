//! Dynamic flight in a run (issue 3): each UAV's airframe from its scenario entry, the
//! `waypoints` behaviour's plan made when the run is built, and the [`Physics`] resource with
//! the systems that step the true (rapier) flight and end a run on a crash or an empty battery.
//!
//! Kinematic (`scripted`) UAVs get their airframe too (its radius is their clearance at the
//! start) but no body: they have no dynamics and no energy account.

mod setup;
mod systems;

pub use setup::{airframe_of, dynamic_flight, plan_waypoints, waypoint_flight};
pub use systems::{Physics, PhysicsBody, end_on_empty_battery, step_physics};
