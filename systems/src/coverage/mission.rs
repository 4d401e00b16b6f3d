//! The mission: the path at one altitude with the speed, energy and time of every leg and turn,
//! the mission energy of paper eq. 18, feasibility against a battery and the altitude search that
//! spends spare energy on resolution (coverage.md, "Feasibility and resolution trade").

use super::camera::{Camera, CameraError, Overlaps, SurveyGeometry};
use super::energy_model::{EnergyModelError, SpeedEnergyModel};
use super::path::{CoveragePath, PathError, ScanDirection, plan_path};
use super::polygon::Polygon;
use glam::DVec2;
use serde::{Deserialize, Serialize};
use thiserror::Error;

#[derive(Debug, Clone, PartialEq, Error)]
pub enum MissionError {
    #[error(transparent)]
    Camera(#[from] CameraError),
    #[error(transparent)]
    Path(#[from] PathError),
    #[error(transparent)]
    EnergyModel(#[from] EnergyModelError),
    #[error("available energy must be positive and finite (J), got {0}")]
    AvailableEnergy(f64),
    #[error(
        "altitude search: need 0 < step ({step_m} m), 0 <= tolerance ({tolerance_j} J) and \
         0 < min altitude ({min_altitude_m} m) <= max altitude ({max_altitude_m} m)"
    )]
    Search {
        step_m: f64,
        tolerance_j: f64,
        min_altitude_m: f64,
        max_altitude_m: f64,
    },
    #[error(
        "altitude search: step {step_m:?} m is below {min_step_m} m, finer than any altitude is \
         flown"
    )]
    StepTooSmall { step_m: f64, min_step_m: f64 },
    #[error(
        "altitude search: {steps:.0} steps of {step_m} m between {min_altitude_m} m and \
         {max_altitude_m} m, more than the {limit} re-plans allowed"
    )]
    TooManySteps {
        steps: f64,
        step_m: f64,
        min_altitude_m: f64,
        max_altitude_m: f64,
        limit: usize,
    },
    #[error(
        "the plan needs {energy_j:.4e} J, more than {limit} times the {available_j} J available \
         (its slowest leg is flown at {slowest_mps:.3e} m/s): no count of flights is meaningful"
    )]
    FarBeyondBattery {
        energy_j: f64,
        available_j: f64,
        slowest_mps: f64,
        limit: u32,
    },
    #[error(
        "leg {leg} of the plan prices at {energy_j} J: the energy model gives no positive energy"
    )]
    LegEnergy { leg: usize, energy_j: f64 },
    #[error(
        "the required resolution needs flying at {required_m:.2} m or lower, below the minimum \
         altitude {min_altitude_m} m"
    )]
    ResolutionUnreachable {
        required_m: f64,
        min_altitude_m: f64,
    },
}

/// What to survey and how: the inputs of the planner that do not depend on the airframe.
#[derive(Debug, Clone, PartialEq)]
pub struct CoverageProblem {
    pub polygon: Polygon,
    /// Index into [`Polygon::vertices`] where the UAV takes off and lands.
    pub start_vertex: usize,
    pub camera: Camera,
    pub overlaps: Overlaps,
    /// Required ground resolution `R_d` (px/m).
    pub required_resolution_px_per_m: f64,
    pub direction: ScanDirection,
}

/// One straight leg, flown from rest to rest at its own optimal speed.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct LegPlan {
    pub start: DVec2,
    pub end: DVec2,
    /// Indices of its first and last waypoint in the path.
    pub waypoints: [usize; 2],
    /// Photos taken along it, ends included.
    pub shots: usize,
    pub length_m: f64,
    /// The speed cap: `v_max`, or lower where the leg's shots are closer than `d_y`.
    pub speed_limit: f64,
    /// `v*(d)` under the cap (m/s).
    pub speed: f64,
    pub energy_j: f64,
    pub time_s: f64,
}

/// A turn in place between two legs.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct TurnPlan {
    pub at: DVec2,
    pub angle_rad: f64,
    pub energy_j: f64,
    pub time_s: f64,
}

/// The path at one altitude with its energy and time.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MissionPlan {
    pub survey: SurveyGeometry,
    pub path: CoveragePath,
    pub legs: Vec<LegPlan>,
    pub turns: Vec<TurnPlan>,
    pub climb_energy_j: f64,
    pub climb_time_s: f64,
    pub descent_energy_j: f64,
    pub descent_time_s: f64,
    /// `E_tot = E_climb(0, h) + E_desc(h, 0) + sum E_turn + sum_i E(d_i, v*_i)` (eq. 18), J.
    pub energy_j: f64,
    pub time_s: f64,
}

impl MissionPlan {
    pub fn length_m(&self) -> f64 {
        self.legs.iter().map(|l| l.length_m).sum()
    }

    pub fn legs_energy_j(&self) -> f64 {
        self.legs.iter().map(|l| l.energy_j).sum()
    }

    pub fn turns_energy_j(&self) -> f64 {
        self.turns.iter().map(|t| t.energy_j).sum()
    }

    /// Feasible when `E_tot < E_available`.
    pub fn is_feasible(&self, available_j: f64) -> bool {
        self.energy_j < available_j
    }
}

/// Plans the path at `altitude_m` and prices it with `model`.
pub fn plan_mission(
    problem: &CoverageProblem,
    altitude_m: f64,
    model: &SpeedEnergyModel,
) -> Result<MissionPlan, MissionError> {
    model.validate()?;
    let survey = problem.camera.survey(altitude_m, problem.overlaps)?;
    let path = plan_path(
        &problem.polygon,
        problem.start_vertex,
        &survey,
        problem.direction,
    )?;
    price(survey, path, model)
}

/// Speeds, energies and times of a planned path.
pub fn price(
    survey: SurveyGeometry,
    path: CoveragePath,
    model: &SpeedEnergyModel,
) -> Result<MissionPlan, MissionError> {
    let legs = path
        .legs()
        .iter()
        .map(|leg| {
            // v_max = L_y (1 - ov_y) / T_s assumes shots d_y apart; shots closer together
            // (Delta_y <= d_y) must come no faster than one per shot period either.
            let speed_limit = leg
                .min_shot_spacing
                .map_or(survey.v_max, |s| survey.v_max.min(s / survey.shot_period_s));
            let flight = model.straight(leg.length(), speed_limit)?;
            Ok(LegPlan {
                start: leg.start,
                end: leg.end,
                waypoints: leg.waypoints,
                shots: leg.shots,
                length_m: leg.length(),
                speed_limit,
                speed: flight.speed,
                energy_j: flight.energy_j,
                time_s: flight.time_s,
            })
        })
        .collect::<Result<Vec<_>, EnergyModelError>>()?;
    // The model's curves are checked positive where they are used; this catches anything they
    // still let through (a dip between the checked speeds) before it becomes a "feasible" plan.
    if let Some((leg, l)) = legs
        .iter()
        .enumerate()
        .find(|(_, l)| !(l.energy_j >= 0.0 && l.energy_j.is_finite()))
    {
        return Err(MissionError::LegEnergy {
            leg,
            energy_j: l.energy_j,
        });
    }
    let turns: Vec<TurnPlan> = legs
        .windows(2)
        .map(|w| {
            let angle_rad = (w[0].end - w[0].start)
                .angle_to(w[1].end - w[1].start)
                .abs();
            TurnPlan {
                at: w[0].end,
                angle_rad,
                energy_j: model.turn_energy(angle_rad),
                time_s: model.turn_time(angle_rad),
            }
        })
        .collect();
    let h = survey.altitude_m;
    let climb_energy_j = model.climb_energy(h);
    let descent_energy_j = model.descent_energy(h);
    let energy_j = climb_energy_j
        + descent_energy_j
        + turns.iter().map(|t| t.energy_j).sum::<f64>()
        + legs.iter().map(|l| l.energy_j).sum::<f64>();
    let time_s = model.climb_time(h)
        + model.descent_time(h)
        + turns.iter().map(|t| t.time_s).sum::<f64>()
        + legs.iter().map(|l| l.time_s).sum::<f64>();
    Ok(MissionPlan {
        survey,
        path,
        legs,
        turns,
        climb_energy_j,
        climb_time_s: model.climb_time(h),
        descent_energy_j,
        descent_time_s: model.descent_time(h),
        energy_j,
        time_s,
    })
}

/// How the altitude search steps.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct AltitudeSearch {
    /// Altitude change between two re-plans (m).
    pub step_m: f64,
    /// Lowering stops once `E_tot` is within this much below `E_available` (J).
    pub tolerance_j: f64,
    /// Lowest altitude allowed (m).
    pub min_altitude_m: f64,
    /// Highest altitude allowed (m), e.g. the legal ceiling.
    pub max_altitude_m: f64,
    /// When the required resolution is infeasible, raise the altitude (accepting less
    /// resolution) instead of reporting that more flights are needed.
    pub accept_lower_resolution: bool,
}

impl Default for AltitudeSearch {
    /// 1 m steps, 1 kJ tolerance, between 5 m and 120 m (a common legal ceiling).
    fn default() -> Self {
        Self {
            step_m: 1.0,
            tolerance_j: 1000.0,
            min_altitude_m: 5.0,
            max_altitude_m: 120.0,
            accept_lower_resolution: false,
        }
    }
}

/// One re-plan of the search.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct AltitudeTrial {
    pub altitude_m: f64,
    pub energy_j: f64,
    pub feasible: bool,
}

#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", tag = "kind")]
pub enum Verdict {
    /// The required resolution is feasible; the plan flies at or below `h_max`.
    Feasible,
    /// Only feasible above `h_max`, with less resolution than required.
    LowerResolution,
    /// Not feasible within the altitude limits: at least `flights` battery loads are needed
    /// (a lower bound: each extra flight adds its own climb, descent and transit).
    Infeasible { flights: u32 },
}

/// The search's result: the chosen plan (at `h_max` when infeasible) and every re-plan tried.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AltitudeOutcome {
    pub verdict: Verdict,
    pub plan: MissionPlan,
    /// `h_max` for the required resolution (capped by the ceiling).
    pub required_altitude_m: f64,
    pub available_energy_j: f64,
    pub trials: Vec<AltitudeTrial>,
    /// The altitude at which lowering stopped because the survey there would take more than
    /// [`MAX_SHOTS`](super::path::MAX_SHOTS) photos (none when it did not stop there).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub photo_limit_at_m: Option<f64>,
}

/// Most re-plans of one altitude search (each a whole path).
pub const MAX_ALTITUDE_STEPS: usize = 100_000;

/// Finest altitude step (m): altitudes are not flown to better than a millimetre, and a finer
/// step would re-plan the same path over and over.
pub const MIN_ALTITUDE_STEP_M: f64 = 1e-3;

/// Most battery loads an infeasible verdict counts; a plan needing more is nonsense (e.g. a shot
/// period that crawls the UAV along) and is refused rather than given a saturated count.
pub const MAX_FLIGHTS: u32 = 1_000_000;

/// Plans at `h_max`; if feasible, lowers the altitude step by step (more resolution), re-planning
/// and re-testing, until `E_tot` is within the tolerance below `E_available`, the minimum
/// altitude is reached or the survey would take more photos than the planner allows, and keeps
/// the lowest feasible plan (energy against altitude is not monotonic, so an infeasible step does
/// not end the search). If infeasible, raises the altitude when less resolution is acceptable,
/// else reports the flights needed.
pub fn search_altitude(
    problem: &CoverageProblem,
    model: &SpeedEnergyModel,
    available_j: f64,
    search: &AltitudeSearch,
) -> Result<AltitudeOutcome, MissionError> {
    if !(available_j > 0.0 && available_j.is_finite()) {
        return Err(MissionError::AvailableEnergy(available_j));
    }
    let valid = search.step_m > 0.0
        && search.step_m.is_finite()
        && search.tolerance_j >= 0.0
        && search.min_altitude_m > 0.0
        && search.min_altitude_m <= search.max_altitude_m
        && search.max_altitude_m.is_finite()
        && search.tolerance_j.is_finite();
    if !valid {
        return Err(MissionError::Search {
            step_m: search.step_m,
            tolerance_j: search.tolerance_j,
            min_altitude_m: search.min_altitude_m,
            max_altitude_m: search.max_altitude_m,
        });
    }
    // Bounded work: a step below what altitude resolves would try one altitude again and again
    // (h - k step rounds back to h), so both the step and the number of steps are limited.
    if search.step_m < MIN_ALTITUDE_STEP_M {
        return Err(MissionError::StepTooSmall {
            step_m: search.step_m,
            min_step_m: MIN_ALTITUDE_STEP_M,
        });
    }
    let steps = (search.max_altitude_m - search.min_altitude_m) / search.step_m;
    if steps > MAX_ALTITUDE_STEPS as f64 {
        return Err(MissionError::TooManySteps {
            steps,
            step_m: search.step_m,
            min_altitude_m: search.min_altitude_m,
            max_altitude_m: search.max_altitude_m,
            limit: MAX_ALTITUDE_STEPS,
        });
    }
    let h_max = problem
        .camera
        .max_altitude(problem.required_resolution_px_per_m)?
        .min(search.max_altitude_m);
    if h_max < search.min_altitude_m {
        return Err(MissionError::ResolutionUnreachable {
            required_m: h_max,
            min_altitude_m: search.min_altitude_m,
        });
    }
    let mut trials = Vec::new();
    let mut try_at = |h: f64| -> Result<MissionPlan, MissionError> {
        let plan = plan_mission(problem, h, model)?;
        trials.push(AltitudeTrial {
            altitude_m: h,
            energy_j: plan.energy_j,
            feasible: plan.is_feasible(available_j),
        });
        Ok(plan)
    };
    let at_h_max = try_at(h_max)?;
    let mut photo_limit_at_m = None;
    let (verdict, plan) = if at_h_max.is_feasible(available_j) {
        let mut best = at_h_max;
        // The loops run over step counts fixed up front, never over a float compared with a
        // bound it may never cross.
        for h in altitude_steps(h_max, search.min_altitude_m, -search.step_m) {
            if available_j - best.energy_j <= search.tolerance_j {
                break;
            }
            let plan = match try_at(h) {
                Ok(plan) => plan,
                // A lower altitude has a smaller footprint, hence needs more photos still: no
                // altitude below is plannable either. The lowest feasible plan above stands.
                Err(MissionError::Path(PathError::TooManyShots { .. })) => {
                    photo_limit_at_m = Some(h);
                    break;
                }
                Err(e) => return Err(e),
            };
            if plan.is_feasible(available_j) {
                best = plan;
            }
        }
        (Verdict::Feasible, best)
    } else {
        let mut raised = None;
        if search.accept_lower_resolution {
            for h in altitude_steps(h_max, search.max_altitude_m, search.step_m) {
                let plan = try_at(h)?;
                if plan.is_feasible(available_j) {
                    raised = Some(plan);
                    break;
                }
            }
        }
        match raised {
            Some(plan) => (Verdict::LowerResolution, plan),
            None => (
                Verdict::Infeasible {
                    flights: flights_needed(&at_h_max, available_j)?,
                },
                at_h_max,
            ),
        }
    };
    Ok(AltitudeOutcome {
        verdict,
        plan,
        required_altitude_m: h_max,
        available_energy_j: available_j,
        trials,
        photo_limit_at_m,
    })
}

/// Altitudes `from + k step` for `k = 1, 2, ...` up to and including `limit` (`step` signed
/// towards it): `floor(|limit - from| / |step|)` of them, a count fixed before the first re-plan.
/// The caller bounds that count ([`MAX_ALTITUDE_STEPS`]).
fn altitude_steps(from: f64, limit: f64, step: f64) -> impl Iterator<Item = f64> {
    let count = ((limit - from) / step).floor();
    let count = if count >= 1.0 {
        (count as usize).min(MAX_ALTITUDE_STEPS)
    } else {
        0
    };
    (1..=count).map(move |k| from + k as f64 * step)
}

/// The battery loads an infeasible plan needs at least: `ceil(E_tot / E_available)`, at least 2.
/// Refused above [`MAX_FLIGHTS`], where the count says nothing and would saturate.
fn flights_needed(plan: &MissionPlan, available_j: f64) -> Result<u32, MissionError> {
    let flights = (plan.energy_j / available_j).ceil().max(2.0);
    if flights <= f64::from(MAX_FLIGHTS) {
        return Ok(flights as u32);
    }
    Err(MissionError::FarBeyondBattery {
        energy_j: plan.energy_j,
        available_j,
        slowest_mps: plan
            .legs
            .iter()
            .map(|l| l.speed)
            .filter(|&v| v > 0.0)
            .fold(f64::INFINITY, f64::min),
        limit: MAX_FLIGHTS,
    })
}

#[cfg(test)]
#[path = "mission_tests.rs"]
mod tests;
