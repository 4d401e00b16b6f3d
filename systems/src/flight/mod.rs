//! Flight with energy, as plain data and functions (common.md §3-4): the rotor power model,
//! motor lag, the mixer, the SE(3) geometric controller, the quadrotor's rigid-body equations,
//! energy and battery accounting, and the offline rollout; [`ecs`] holds the components a
//! dynamic UAV carries and the Control-stage system that tracks its reference.
//!
//! The true flight (engine, rapier) and the rollout call the same functions here, so the
//! energy a planner predicts and the energy the flight integrates come from one model.

pub mod controller;
pub mod dynamics;
pub mod ecs;
pub mod energy;
pub mod mixer;
pub mod motor;
pub mod power;
pub mod rollout;
pub mod state;

#[cfg(test)]
mod tests;

pub use controller::{ControlOutput, ControllerGains, GeometricController};
pub use dynamics::{QuadrotorModel, Wrench};
pub use ecs::{
    FlightController, FlightEnergy, ReferenceTrajectory, RotorCommands, track_references,
};
pub use energy::{Battery, EnergyMeter, EnergySummary};
pub use rollout::{
    Completion, Integrator, Progress, RolloutConfig, RolloutResult, Tracking, rollout,
    rollout_batch, rollout_observed,
};
pub use state::FlightState;

/// Why a flight or a rollout could not be run.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FlightError {
    #[error("invalid airframe: {0}")]
    InvalidAirframe(String),
    #[error("integration step must be finite and > 0, got {0}")]
    InvalidStep(f64),
    #[error("invalid trajectory: {0}")]
    InvalidTrajectory(String),
    #[error("the start state has non-finite values")]
    NonFiniteStart,
    #[error("the flight diverged (non-finite state) at t = {time_s} s")]
    Diverged { time_s: f64 },
}
