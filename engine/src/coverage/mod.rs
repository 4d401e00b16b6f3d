//! Coverage planning in the engine (coverage.md): the scenario's coverage settings ([`spec`]),
//! users' fields from GeoJSON and WKT ([`field`]), measurement logs as CSV ([`measurements`]),
//! energy models by preset name or file ([`model_io`]), and the plan written as CSV, GeoJSON and
//! a picture ([`outputs`], [`picture`]) with text reports for `uavex energy`, `uavex cover` and
//! fitting ([`report`]). The coverage UAV of a scenario file ([`scenario`]); the model's motions
//! as a trajectory ([`profile`]) flown on the true quadrotor ([`flight`]: calibration logs and
//! predicted against flown energy), the paper's calibration experiments ([`mod@calibrate`]) and the
//! behaviour in `uavex run` ([`behaviour`]). The planner and the energy model themselves live in
//! [`uavex_systems::coverage`].

pub mod behaviour;
pub mod calibrate;
pub mod field;
pub mod flight;
pub mod measurements;
pub mod model_io;
pub mod outputs;
pub mod picture;
pub mod profile;
pub mod report;
pub mod scenario;
pub mod spec;

pub use calibrate::{Calibration, CalibrationPlan, LegCheck, calibrate, check_legs};
pub use field::{Coordinates, Field, LocalProjection, read_field};
pub use flight::{FlownProfile, PlanComparison, fly_plan, fly_profile, plan_profile};
pub use measurements::{fit_measurements, read_measurements, write_measurements};
pub use model_io::{load_energy_model, save_fitted_model};
pub use outputs::{PlanFiles, write_geojson, write_legs_csv, write_plan, write_waypoints_csv};
pub use picture::write_picture;
pub use report::{cover_report, energy_report, fit_report};
pub use scenario::{CoverageScenario, read_coverage_scenario};
pub use spec::{AreaSpec, CoverageSetup, CoverageSpec};

use crate::scenario::ScenarioErrors;
use std::path::PathBuf;
use thiserror::Error;
use uavex_systems::coverage::{EnergyModelError, FitError, MissionError, PolygonError};

/// Anything that goes wrong reading coverage inputs or writing coverage outputs, with the file.
#[derive(Debug, Error)]
pub enum CoverageIoError {
    #[error("{path}: {source}")]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    /// The file is readable but its content is not what was expected.
    #[error("{path}: {message}")]
    Content { path: PathBuf, message: String },
    #[error("{path}: {source}")]
    Polygon { path: PathBuf, source: PolygonError },
    /// A coverage setting that makes no sense.
    #[error("{path}: coverage {field}: {message}")]
    Spec {
        path: PathBuf,
        field: String,
        message: String,
    },
    #[error("{path}: cannot fit an energy model: {source}")]
    Fit { path: PathBuf, source: FitError },
    /// The fit succeeded but gives a model the model loader refuses (power not positive over
    /// the measured speeds, non-finite coefficients); `path` names the data it came from.
    #[error("{path}: the model fitted from these measurements is unusable: {source}")]
    UnusableFit {
        path: PathBuf,
        source: EnergyModelError,
    },
    #[error("{path}: drawing failed: {message}")]
    Picture { path: PathBuf, message: String },
    #[error(transparent)]
    Mission(#[from] MissionError),
    /// Planning failed because of a coverage setting (`field`, below the behaviour). No file is
    /// named: the caller knows the scenario (`uavex cover` puts it in front).
    #[error("coverage {field}: {source}")]
    Plan { field: String, source: MissionError },
    /// Problems of a scenario file, each at its line and field (`uavex cover`).
    #[error(transparent)]
    Scenario(#[from] ScenarioErrors),
    /// A simulated flight (calibration or flying a plan) failed.
    #[error("simulated flight: {0}")]
    Flight(String),
}
