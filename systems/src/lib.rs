pub mod flight;
pub mod trajectory;
