//! Tour: the first cluster of the least-energy tour through the choosable clusters (the N of
//! largest information gain, as EAAE shortlists them, or all). EAAE's choice is greedy (the
//! thesis names "a tour over all clusters with energy costs (an asymmetric TSP)" as its next
//! step, eaae.md "Known weaknesses"): it goes to the cheapest cluster now even when that
//! leaves a cluster behind that a later decision must fly back for. This strategy orders the
//! clusters it weighs and goes to the first.
//!
//! Costs (our choice; the thesis gives none):
//! - from the UAV to cluster `k`: the candidate's predicted energy `E_k` (the rollout of its
//!   trajectory, eaae.md step 7), as EAAE weighs it;
//! - between the goals of clusters `i` and `j`: `e * l_ij`, with `e = sum E_k / sum L_k` the
//!   energy per metre of path this decision's rollouts predict (the UAV's own airframe,
//!   speeds and hover share), and `l_ij = max(|g_i - g_j|, |L_i - L_j|)` a lower bound of the
//!   path length between the goals `g` (the straight line; and the triangle inequality through
//!   the UAV, on the searched path lengths `L`). Planning and rolling out every pair would
//!   cost `n^2` plans a decision; the bound needs none, and is symmetric.
//!
//! The first leg is asymmetric (it starts from the UAV's motion), the rest are not, which is
//! what [`least_cost_open_tour`] needs. Information gain enters only through the shortlist, as
//! in EAAE: the tour asks in which order to visit the clusters it weighs.

use super::eaae::{EaaeStrategy, largest_gains};
use super::{CandidateQuery, CandidateView, choosable};
use crate::exploration::open_tour::{TourCosts, least_cost_open_tour};
use bevy_ecs::prelude::*;
use uavex_components::exploration::{CandidateScope, Candidates, Chosen, NeedsDecision};

/// Marker of a UAV that explores along the least-energy tour of the clusters.
#[derive(Component, Debug, Clone, Copy, PartialEq, Eq)]
pub struct TourStrategy {
    /// How many candidates of largest IG are the tour's stops (`None`: all).
    pub shortlist: Option<usize>,
}

impl TourStrategy {
    /// What the choice needs evaluated: the stops, chosen as EAAE chooses what it weighs.
    pub fn scope(&self) -> CandidateScope {
        EaaeStrategy {
            shortlist: self.shortlist,
        }
        .scope()
    }
}

/// The first stop of the least-energy tour through the `shortlist` candidates of largest
/// information gain (plain function).
pub fn first_of_tour_among_largest_gain(
    candidates: &[CandidateView],
    shortlist: Option<usize>,
) -> Option<Entity> {
    first_of_least_energy_tour(&largest_gains(candidates, shortlist))
}

/// The first candidate of the least-energy tour through `candidates` (plain function; see the
/// module documentation for the costs).
pub fn first_of_least_energy_tour(candidates: &[CandidateView]) -> Option<Entity> {
    let n = candidates.len();
    if n <= 1 {
        return candidates.first().map(|c| c.entity);
    }
    let energy: f64 = candidates.iter().map(|c| c.energy_j).sum();
    let length: f64 = candidates.iter().map(|c| f64::from(c.path_length_m)).sum();
    // Every candidate's path is longer than the planner's least travel; the guard keeps a
    // degenerate decision from dividing by zero (then only the first legs count).
    let per_metre = if length > 0.0 { energy / length } else { 0.0 };
    let from_start: Vec<f64> = candidates.iter().map(|c| c.energy_j).collect();
    let between: Vec<f64> = (0..n * n)
        .map(|k| {
            let (a, b) = (&candidates[k / n], &candidates[k % n]);
            let straight = f64::from(a.goal.distance(b.goal));
            let around = f64::from((a.path_length_m - b.path_length_m).abs());
            per_metre * straight.max(around)
        })
        .collect();
    let order = least_cost_open_tour(TourCosts {
        from_start: &from_start,
        between: &between,
    });
    order.first().map(|&k| candidates[k].entity)
}

/// Choose step of the tour strategy.
pub fn choose_by_tour(
    mut commands: Commands,
    uavs: Query<(Entity, &TourStrategy, &Candidates), With<NeedsDecision>>,
    candidates: CandidateQuery,
) {
    for (uav, strategy, list) in &uavs {
        let views = choosable(list, &candidates);
        if let Some(pick) = first_of_tour_among_largest_gain(&views, strategy.shortlist) {
            commands.entity(uav).insert(Chosen(pick));
        }
    }
}
