//! Energy-aware coverage path planning (Di Franco and Buttazzo, ICARSC 2015; coverage.md): plan a
//! photogrammetry survey of a known polygon at a required ground resolution with the least energy,
//! decide whether the battery suffices, and trade spare energy for resolution.
//!
//! - [`camera`]: footprint, altitude from the required resolution, spacing, speed limit.
//! - [`polygon`]: the surveyed area, validated.
//! - [`path`]: the three-part back-and-forth with recursion into concavities (`sweep` cuts the
//!   polygon into the cell a back-and-forth covers and the parts beyond it; `spacing` counts
//!   and places the shots and stripes).
//! - [`energy_model`]: the speed-based energy model ([`power_curve`] holds its polynomials), the
//!   IRIS preset, `E(d, v)`, `t(d, v)` and `v*(d)`.
//! - [`mission`]: the mission energy (eq. 18) of a plan, feasibility and the altitude search.
//! - [`fit`]: fitting a model from measurements by least squares.

pub mod camera;
pub mod energy_model;
pub mod fit;
pub mod mission;
pub mod path;
pub mod polygon;
pub mod power_curve;
mod spacing;
mod sweep;

#[cfg(test)]
mod path_tests;

pub use camera::{Camera, CameraError, Footprint, Overlaps, SurveyGeometry};
pub use energy_model::{
    EnergyModelError, SpeedEnergyModel, StraightFlight, Turning, VerticalFlight,
};
pub use fit::{
    CurveFit, FitDegrees, FitError, FitReport, FittedModel, MeanFit, Measurement, Phase, RateFit,
    fit_model,
};
pub use mission::{
    AltitudeOutcome, AltitudeSearch, AltitudeTrial, CoverageProblem, LegPlan, MissionError,
    MissionPlan, TurnPlan, Verdict, plan_mission, search_altitude,
};
pub use path::{CoveragePath, Leg, MAX_SHOTS, PathError, ScanDirection, Waypoint, plan_path};
pub use polygon::{Polygon, PolygonError};
pub use power_curve::PowerCurve;
