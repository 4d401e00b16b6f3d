//! The candidate trajectories of a decision (eaae.md steps 6-8) in the recording: one line strip
//! per candidate, sampled from its trajectory and coloured by its predicted energy (cheapest of
//! the decision green, costliest red), with the numbers the strategies weighed; the chosen one
//! again on its own entity, thick and white.

use super::colour::{Palette, Span};
use super::entity_path;
use re_chunk::EntityPath;
use re_sdk_types::AnyValues;
use re_sdk_types::archetypes::LineStrips3D;
use re_sdk_types::components::{Color, Radius};
use re_sdk_types::external::arrow::array::{BooleanArray, Float64Array, UInt32Array};
use std::sync::Arc;
use uavex_components::exploration::CandidateTrajectory;
use uavex_components::trajectory::Trajectory;

/// Sampling step along a candidate's trajectory (s): 0.1 s at the kingfisher's 5 m/s is 0.5 m,
/// finer than the curvature of a minimum-snap leg.
pub const SAMPLE_STEP_S: f64 = 0.1;

/// Field names of the numbers logged beside the strips (one value per candidate).
pub const PREDICTED_ENERGY: &str = "predicted_energy_j";
pub const PREDICTED_DURATION: &str = "predicted_duration_s";
pub const INFORMATION_GAIN: &str = "information_gain";
pub const AFFORDABLE: &str = "affordable";

/// What the recording keeps of one candidate: its sampled trajectory and the numbers of its
/// evaluation, taken in the Decide stage before the candidates are despawned.
#[derive(Debug, Clone, PartialEq)]
pub struct CandidateSketch {
    pub points: Vec<[f32; 3]>,
    pub energy_j: f64,
    pub duration_s: f64,
    pub information_gain: u32,
    /// The return home fits the energy budget (always, without a budget).
    pub affordable: bool,
    pub chosen: bool,
}

impl CandidateSketch {
    pub fn of(
        candidate: &CandidateTrajectory,
        energy_j: f64,
        duration_s: f64,
        affordable: bool,
        chosen: bool,
    ) -> Self {
        Self {
            points: sample(candidate.trajectory.as_ref()),
            energy_j,
            duration_s,
            information_gain: candidate.information_gain,
            affordable,
            chosen,
        }
    }
}

/// Positions every [`SAMPLE_STEP_S`] from start to end, both included.
pub fn sample(trajectory: &dyn Trajectory) -> Vec<[f32; 3]> {
    let duration = trajectory.duration().max(0.0);
    let steps = (duration / SAMPLE_STEP_S).ceil() as usize;
    (0..=steps)
        .map(|i| {
            let t = (i as f64 * SAMPLE_STEP_S).min(duration);
            trajectory.position(t).as_vec3().to_array()
        })
        .collect()
}

/// `world/uavs/NAME/candidates`.
pub fn candidates_entity(uav: &str) -> EntityPath {
    entity_path(&["world", "uavs", uav, "candidates"])
}

/// `world/uavs/NAME/chosen`.
pub fn chosen_entity(uav: &str) -> EntityPath {
    entity_path(&["world", "uavs", uav, "chosen"])
}

/// The colour of each candidate on the energy scale spanned by the decision's candidates.
pub fn energy_colours(candidates: &[CandidateSketch]) -> Vec<Color> {
    let span = Span::of(candidates.iter().map(|c| c.energy_j));
    candidates
        .iter()
        .map(|c| {
            let fraction = span.map_or(0.0, |s| s.fraction(c.energy_j));
            Color::from(Palette::ENERGY.at(fraction))
        })
        .collect()
}

/// Every candidate of a decision as a strip coloured by predicted energy, labelled with it.
pub fn candidate_strips(candidates: &[CandidateSketch]) -> LineStrips3D {
    LineStrips3D::new(candidates.iter().map(|c| c.points.clone()))
        .with_colors(energy_colours(candidates))
        .with_radii(
            candidates
                .iter()
                .map(|c| Radius::new_scene_units(if c.chosen { 0.05 } else { 0.025 })),
        )
        .with_labels(
            candidates
                .iter()
                .map(|c| format!("{:.0} J, IG {}", c.energy_j, c.information_gain)),
        )
}

/// The numbers behind the strips, in the same order, for the viewer's selection panel.
pub fn candidate_values(candidates: &[CandidateSketch]) -> AnyValues {
    let floats = |f: fn(&CandidateSketch) -> f64| {
        Arc::new(Float64Array::from_iter_values(candidates.iter().map(f)))
    };
    AnyValues::default()
        .with_component_from_data(PREDICTED_ENERGY, floats(|c| c.energy_j))
        .with_component_from_data(PREDICTED_DURATION, floats(|c| c.duration_s))
        .with_component_from_data(
            INFORMATION_GAIN,
            Arc::new(UInt32Array::from_iter_values(
                candidates.iter().map(|c| c.information_gain),
            )),
        )
        .with_component_from_data(
            AFFORDABLE,
            Arc::new(BooleanArray::from_iter(
                candidates.iter().map(|c| Some(c.affordable)),
            )),
        )
}

/// The chosen candidate alone (no strip when the decision chose none).
pub fn chosen_strip(candidates: &[CandidateSketch]) -> LineStrips3D {
    let chosen: Vec<&CandidateSketch> = candidates.iter().filter(|c| c.chosen).collect();
    LineStrips3D::new(chosen.iter().map(|c| c.points.clone()))
        .with_colors(chosen.iter().map(|_| Color::WHITE))
        .with_radii(chosen.iter().map(|_| Radius::new_scene_units(0.06)))
        .with_labels(
            chosen
                .iter()
                .map(|c| format!("chosen: {:.0} J, IG {}", c.energy_j, c.information_gain)),
        )
}
