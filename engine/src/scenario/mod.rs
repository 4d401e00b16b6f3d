//! Scenario files: the schema (TOML, serde), loading with located diagnostics, validation.

pub mod schema;

pub use schema::*;
