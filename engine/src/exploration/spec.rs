//! The exploration behaviour's settings as they appear in a scenario file (eaae.md), under
//! `[uav.behaviour] kind = "explore"`:
//!
//! ```toml
//! [uav.behaviour]
//! kind = "explore"
//! strategy = "eaae"          # or "classic" (largest frontier), "nearest" (nearest frontier),
//!                            # "tour" (first cluster of the least-energy tour through the
//!                            # candidates)
//! candidates = 3             # EAAE: clusters of largest IG weighed by energy (the tour's
//!                            # stops); or "all"
//! evaluate = "needed"        # plan and roll out only the clusters the choice needs; "all":
//!                            # every cluster (the decision log then prices every option)
//! unified = false            # fly the evaluated candidate itself while it stays free
//! replan_hz = 2.0            # local planner's regular replanning rate
//! energy_budget = { reserve_j = 5000.0 }   # optional: return home before the battery runs low
//! standoff_m = 2.5           # optional, beyond the thesis: fly to a viewpoint this far from
//!                            # a cluster's centroid, level with it and facing it, before
//!                            # trying the centroid (absent: the thesis' centroid first);
//!                            # at most the depth camera's range_max
//! frontier_viewpoint = false # beyond the thesis: after a cluster's viewpoints, try its
//!                            # frontier voxel nearest to its centroid (for cameras whose
//!                            # clusters are large: see the README)
//! ```
//! Everything but `strategy` has the default shown.

use serde::{Deserialize, Serialize};

/// The strategies a scenario can name.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum StrategyName {
    /// Least predicted energy among the `candidates` clusters of largest IG (eaae.md step 8).
    Eaae,
    /// Largest information gain (eaae.md "Baselines").
    Classic,
    /// Nearest centroid (eaae.md "Baselines").
    Nearest,
    /// The first cluster of the least-energy tour through the `candidates` clusters of largest
    /// IG (the thesis' suggested next step, eaae.md "Known weaknesses").
    Tour,
}

/// How many clusters EAAE weighs by energy: a number, or `"all"`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum CandidateCount {
    Count(u32),
    Named(AllCandidates),
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum AllCandidates {
    All,
}

impl CandidateCount {
    /// `None` for all.
    pub fn limit(self) -> Option<usize> {
        match self {
            CandidateCount::Count(n) => Some(n as usize),
            CandidateCount::Named(AllCandidates::All) => None,
        }
    }
}

/// Which clusters a decision plans and rolls out (`uavex_components::exploration::CandidateScope`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Evaluate {
    /// Those the strategy's choice needs (EAAE: its `candidates` of largest IG that are
    /// feasible; the baselines: the first feasible one in their order): the same pick, less work.
    #[default]
    Needed,
    /// Every cluster, so that the decision log holds the predicted energy of every option.
    All,
}

/// The energy budget: keep this much in reserve beyond the predicted flight home.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BudgetSpec {
    pub reserve_j: f64,
}

/// `kind = "explore"`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ExploreSpec {
    pub strategy: StrategyName,
    /// EAAE's N (the thesis: 3), and the tour's stops; ignored by the baselines, which choose
    /// among all feasible.
    #[serde(default = "default_candidates")]
    pub candidates: CandidateCount,
    #[serde(default)]
    pub evaluate: Evaluate,
    #[serde(default)]
    pub unified: bool,
    #[serde(default = "default_replan_hz")]
    pub replan_hz: f64,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub energy_budget: Option<BudgetSpec>,
    /// Distance (m) of the standoff viewpoints (`ExplorerSettings::standoff_m`); `None`: the
    /// thesis' goals.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub standoff_m: Option<f64>,
    /// Whether a cluster's frontier voxel nearest to its centroid is tried after its
    /// viewpoints (`ExplorerSettings::frontier_viewpoint`).
    #[serde(default)]
    pub frontier_viewpoint: bool,
}

fn default_candidates() -> CandidateCount {
    CandidateCount::Count(3)
}

fn default_replan_hz() -> f64 {
    2.0
}
