//! uavex behaviour: one module per pipeline stage. Each module holds its algorithm as plain
//! functions over plain data (unit-tested without a World) and the thin ECS systems that apply
//! them.
pub mod behaviour;
pub mod coverage;
pub mod flight;
pub mod mapping;
pub mod sensing;
pub mod stages;
pub mod trajectory;
