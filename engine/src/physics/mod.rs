//! True flight on rapier3d as plain structs (no ECS): a [`FlightWorld`] holds rapier's sets
//! with the world's fixed colliders and one dynamic body per UAV, applies the rotor forces
//! every physics step, integrates energy, and reports crashes; [`fly_trajectory`] flies a
//! trajectory on it with the geometric controller.

mod flight_world;
mod fly;

#[cfg(test)]
mod tests;

pub use flight_world::{
    CrashTarget, FlightWorld, FlightWorldConfig, PhysicsError, StepCounts, UavHandle, UavStatus,
};
pub use fly::{FlightRecord, fly_trajectory};
