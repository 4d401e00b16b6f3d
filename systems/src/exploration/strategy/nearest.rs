//! Nearest frontier baseline (eaae.md "Baselines"): `c* = argmin ||p_c - p_uav||` over all
//! feasible clusters (straight-line distance to the centroid, as published).

use super::{CandidateQuery, CandidateView, Deciding, choosable, first_min_by};
use bevy_ecs::prelude::*;
use uavex_components::exploration::{CandidateScope, Chosen, Ranking};

/// Marker of a UAV that goes to the nearest frontier cluster.
#[derive(Component, Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct NearestStrategy;

impl NearestStrategy {
    /// What the choice needs evaluated: the nearest choosable cluster.
    pub fn scope(&self) -> CandidateScope {
        CandidateScope::Ranked {
            by: Ranking::Distance,
            needed: 1,
        }
    }
}

/// The nearest centroid (plain function).
pub fn nearest(candidates: &[CandidateView]) -> Option<Entity> {
    first_min_by(candidates, |c| f64::from(c.centroid_distance_m)).map(|c| c.entity)
}

/// Choose step of the Nearest baseline.
pub fn choose_nearest(
    mut commands: Commands,
    uavs: Deciding<NearestStrategy>,
    candidates: CandidateQuery,
) {
    for (uav, list) in &uavs {
        if let Some(pick) = nearest(&choosable(list, &candidates)) {
            commands.entity(uav).insert(Chosen(pick));
        }
    }
}
