//! Behaviours: what a UAV does. Each kind is its own module and its own systems.

pub mod scripted;
pub mod waypoints;
