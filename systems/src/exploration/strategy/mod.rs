//! Strategies (eaae.md step 8 and "Baselines"): each is one system in [`DecideStep::Choose`]
//! that looks at the candidates of the UAVs carrying its marker component and marks its pick
//! with [`Chosen`](uavex_components::exploration::Chosen). Detection, clustering, filtering, planning and rollouts are shared; only the
//! choice differs. A new strategy is a new marker and a new system, added with
//! `schedule.add_systems(my_choice.in_set(DecideStep::Choose))`: nothing here changes.
//!
//! Candidates are visited in their spawn order (clusters ordered by centroid), and ties keep
//! the first, so a choice is a pure function of the candidates.
//!
//! [`DecideStep::Choose`]: super::DecideStep::Choose

pub mod classic;
pub mod eaae;
pub mod nearest;
pub mod tour;

pub use classic::{ClassicStrategy, choose_largest_gain};
pub use eaae::{EaaeStrategy, choose_least_energy};
pub use nearest::{NearestStrategy, choose_nearest};
pub use tour::{TourStrategy, choose_by_tour};

use bevy_ecs::prelude::*;
use glam::Vec3;
use uavex_components::exploration::{
    CandidateTrajectory, Candidates, NeedsDecision, PredictedDuration, PredictedEnergy,
    Unaffordable,
};

/// What a strategy sees of one candidate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CandidateView {
    pub entity: Entity,
    /// Where its trajectory ends (`CandidateTrajectory::goal`).
    pub goal: Vec3,
    pub information_gain: u32,
    pub centroid_distance_m: f32,
    pub path_length_m: f32,
    pub energy_j: f64,
    pub duration_s: f64,
}

/// The query strategies read candidates through.
pub type CandidateQuery<'w, 's> = Query<
    'w,
    's,
    (
        &'static CandidateTrajectory,
        &'static PredictedEnergy,
        &'static PredictedDuration,
        Has<Unaffordable>,
    ),
>;

/// The UAVs carrying strategy marker `S` that need a decision, with their candidates.
pub type Deciding<'w, 's, S> =
    Query<'w, 's, (Entity, &'static Candidates), (With<NeedsDecision>, With<S>)>;

/// A UAV's candidates a strategy may choose from (affordable ones), in spawn order.
pub fn choosable(candidates: &Candidates, query: &CandidateQuery) -> Vec<CandidateView> {
    candidates
        .entities()
        .iter()
        .filter_map(|&entity| {
            let (candidate, energy, duration, unaffordable) = query.get(entity).ok()?;
            (!unaffordable).then_some(CandidateView {
                entity,
                goal: candidate.goal,
                information_gain: candidate.information_gain,
                centroid_distance_m: candidate.centroid_distance_m,
                path_length_m: candidate.path_length_m,
                energy_j: energy.0,
                duration_s: duration.0,
            })
        })
        .collect()
}

/// The first candidate minimising `key` (ties keep the earliest).
pub fn first_min_by(
    candidates: &[CandidateView],
    key: impl Fn(&CandidateView) -> f64,
) -> Option<&CandidateView> {
    candidates
        .iter()
        .fold(None, |best: Option<(&CandidateView, f64)>, c| {
            let k = key(c);
            match best {
                Some((_, b)) if b <= k => best,
                _ => Some((c, k)),
            }
        })
        .map(|(c, _)| c)
}

#[cfg(test)]
mod tests;
