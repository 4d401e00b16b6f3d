//! uavex behaviour: one module per pipeline stage. Each module holds its algorithm as plain
//! functions over plain data (unit-tested without a World) and the thin ECS systems that apply
//! them.
pub mod behaviour;
pub mod coverage;
pub mod exploration;
pub mod flight;
pub mod frontier;
pub mod mapping;
pub mod planning;
pub mod sensing;
pub mod stage_clock;
pub mod stages;
pub mod trajectory;
