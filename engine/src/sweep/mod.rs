//! Monte-Carlo sweeps: a plan (scenarios x a grid of overrides x seeds) expanded into runs with
//! stable ids, run in parallel on rayon, resumable, split into shards for a cluster and merged
//! back (DESIGN.md, "Runs, sweeps and scale").
//!
//! - [`plan`]: the plan file (TOML) and its checks;
//! - [`path`] and [`apply`]: field paths and how an override edits a scenario's text;
//! - [`expand`](mod@expand): runs, their ids, shards;
//! - [`execute`]: running a plan into a results folder, with [`schedule`] ordering the runs;
//! - [`merge`](mod@merge): joining shard folders;
//! - [`validate`]: checking a plan's scenario variants without running them.
//!
//! A run is a pure function of its scenario (with overrides) and seed, and nothing a run
//! computes depends on the thread that runs it or on the other runs, so a sweep gives the same
//! per-run results on any `--jobs` and in any shard split.

pub mod apply;
pub mod execute;
pub mod expand;
pub mod merge;
pub mod path;
pub mod plan;
pub mod schedule;
pub mod validate;

pub use apply::{Override, OverrideError, apply_overrides};
pub use execute::{SweepError, SweepOptions, SweepReport, is_finished, run_sweep};
pub use expand::{RunCoordinates, RunSpec, Shard, expand};
pub use merge::{MergeReport, merge};
pub use path::OverridePath;
pub use plan::{Plan, PlanError};
pub use validate::{FileKind, PlanCheck, RefusedVariant, check_plan};
