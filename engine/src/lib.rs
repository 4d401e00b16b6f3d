//! uavex engine: scenario files, world building, the simulation loop, runs and their outputs.

pub mod coverage;
pub mod exploration;
pub mod flight;
pub mod formats;
pub mod metrics;
pub mod output;
pub mod physics;
pub mod plot;
pub mod reachable;
pub mod record;
pub mod run;
pub mod scenario;
pub mod sim;
pub mod sweep;
pub mod tables;
pub mod world;
