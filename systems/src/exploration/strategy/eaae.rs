//! EAAE (eaae.md steps 5 and 8): among the N clusters of largest information gain, the one
//! whose candidate trajectory the rollout predicts to need the least energy,
//! `pi* = argmin E(pi_i)`. The thesis used N = 3; `None` weighs every candidate.

use super::{CandidateQuery, CandidateView, choosable, first_min_by};
use bevy_ecs::prelude::*;
use uavex_components::exploration::{CandidateScope, Candidates, Chosen, NeedsDecision, Ranking};

/// Marker of a UAV that explores with EAAE's choice.
#[derive(Component, Debug, Clone, Copy, PartialEq, Eq)]
pub struct EaaeStrategy {
    /// How many candidates of largest IG are weighed by energy (`None`: all).
    pub shortlist: Option<usize>,
}

impl EaaeStrategy {
    /// What the choice needs evaluated: the `shortlist` choosable clusters of largest IG, or
    /// every cluster when all are weighed.
    pub fn scope(&self) -> CandidateScope {
        match self.shortlist {
            Some(n) => CandidateScope::Ranked {
                by: Ranking::InformationGain,
                needed: n,
            },
            None => CandidateScope::All,
        }
    }
}

/// The EAAE choice among `candidates` (plain function).
pub fn least_energy_among_largest_gain(
    candidates: &[CandidateView],
    shortlist: Option<usize>,
) -> Option<Entity> {
    first_min_by(&largest_gains(candidates, shortlist), |c| c.energy_j).map(|c| c.entity)
}

/// The `shortlist` candidates of largest information gain (`None`: all), largest first; equal
/// gains keep their order.
pub fn largest_gains(candidates: &[CandidateView], shortlist: Option<usize>) -> Vec<CandidateView> {
    let mut by_gain = candidates.to_vec();
    by_gain.sort_by_key(|c| std::cmp::Reverse(c.information_gain));
    by_gain.truncate(shortlist.unwrap_or(usize::MAX));
    by_gain
}

/// Choose step of EAAE.
pub fn choose_least_energy(
    mut commands: Commands,
    uavs: Query<(Entity, &EaaeStrategy, &Candidates), With<NeedsDecision>>,
    candidates: CandidateQuery,
) {
    for (uav, strategy, list) in &uavs {
        let views = choosable(list, &candidates);
        if let Some(pick) = least_energy_among_largest_gain(&views, strategy.shortlist) {
            commands.entity(uav).insert(Chosen(pick));
        }
    }
}
