//! Exploration runs (eaae.md): the `explore` behaviour's scenario settings ([`spec`]), what a
//! run needs to explore ([`setup`]: the UAV's components, the frontier, planning and decision
//! resources, the systems), and what it reports ([`log`]: the decision log as CSV, the
//! summary keys).

pub mod log;
pub mod setup;
pub mod spec;

pub use log::{ExplorationSummary, decision_timings_csv, decisions_csv};
pub use setup::{add_exploration, explorer_components};
pub use spec::{AllCandidates, BudgetSpec, CandidateCount, Evaluate, ExploreSpec, StrategyName};
