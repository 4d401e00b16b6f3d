
pub mod coverage;
