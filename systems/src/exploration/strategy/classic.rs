//! Classic frontier baseline (eaae.md "Baselines"): `c* = argmax IG(c)` over all feasible
//! clusters.

use super::{CandidateQuery, CandidateView, Deciding, choosable, first_min_by};
use bevy_ecs::prelude::*;
use uavex_components::exploration::{CandidateScope, Chosen, Ranking};

/// Marker of a UAV that goes to the largest frontier cluster.
#[derive(Component, Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct ClassicStrategy;

impl ClassicStrategy {
    /// What the choice needs evaluated: the choosable cluster of largest IG.
    pub fn scope(&self) -> CandidateScope {
        CandidateScope::Ranked {
            by: Ranking::InformationGain,
            needed: 1,
        }
    }
}

/// The largest information gain (plain function).
pub fn largest_gain(candidates: &[CandidateView]) -> Option<Entity> {
    first_min_by(candidates, |c| -f64::from(c.information_gain)).map(|c| c.entity)
}

/// Choose step of the Classic baseline.
pub fn choose_largest_gain(
    mut commands: Commands,
    uavs: Deciding<ClassicStrategy>,
    candidates: CandidateQuery,
) {
    for (uav, list) in &uavs {
        if let Some(pick) = largest_gain(&choosable(list, &candidates)) {
            commands.entity(uav).insert(Chosen(pick));
        }
    }
}
