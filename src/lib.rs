//! uavex: a simulation engine for energy-aware UAV missions.
//!
//! This facade re-exports the three crates: [`components`] (ECS data), [`systems`] (behaviour,
//! one module per pipeline stage) and [`engine`] (scenarios, world building, runs and outputs).

pub use uavex_components as components;
pub use uavex_engine as engine;
pub use uavex_systems as systems;
