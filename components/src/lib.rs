//! ECS data of uavex: components, resources and the plain value types they hold.
//!
//! Nothing here has behaviour beyond small accessors; algorithms live in `uavex-systems`.

pub mod airframe;
pub mod exploration;
pub mod frontier;
pub mod map;
pub mod sensor;
pub mod sim;
pub mod trajectory;
pub mod uav;
pub mod world;

/// The one glam every uavex crate uses (the version parry and rapier use through glamx).
pub use glam;
