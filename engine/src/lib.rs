//! uavex engine: scenario files, world building, the simulation loop, runs and their outputs.

pub mod coverage;
pub mod scenario;
