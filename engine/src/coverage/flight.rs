//! Flying coverage motions on the true quadrotor: a [`Profile`] flown by the geometric
//! controller on a rapier [`FlightWorld`] (the same flight as `fly_trajectory` everywhere else:
//! 300 Hz sample and hold, motor lag, rotor power model of common.md §4), logging every step as
//! a measurement row (time, speed, power, phase) like the paper's flight logs; and a planned
//! coverage mission turned into such a profile (climb, legs at their planned speeds with the
//! model's acceleration and deceleration, turns in place, descent) and flown, to compare the
//! model's predicted energy and time (eq. 18) with what the flight drew.

use super::CoverageIoError;
use super::profile::{Piece, Profile};
use glam::DVec3;
use serde::Serialize;
use uavex_components::airframe::Airframe;
use uavex_components::trajectory::Trajectory;
use uavex_systems::coverage::{Measurement, MissionPlan, Phase, SpeedEnergyModel};
use uavex_systems::flight::{Completion, ControllerGains, FlightState, GeometricController};

use crate::physics::{FlightWorld, FlightWorldConfig, UavStatus, fly_trajectory};

/// What flying a profile measured.
#[derive(Debug, Clone, PartialEq)]
pub struct FlownProfile {
    /// One row per physics step, phase from the reference being flown.
    pub log: Vec<Measurement>,
    /// Energy drawn over the profile's own duration (J): what the model prices.
    pub energy_j: f64,
    /// Energy until the UAV counted as arrived, settling included (J).
    pub energy_to_arrival_j: f64,
    /// The profile's duration (s).
    pub duration_s: f64,
    /// Until arrival (s).
    pub time_to_arrival_s: f64,
    pub rms_tracking_error_m: f64,
}

/// Flies `profile` from hover at its start on an empty world.
pub fn fly_profile(
    airframe: &Airframe,
    profile: &Profile,
) -> Result<FlownProfile, CoverageIoError> {
    let flight = |message: String| CoverageIoError::Flight(message);
    let start = profile.sample(0.0);
    let mut world = FlightWorld::from_shapes(Vec::new(), FlightWorldConfig::default())
        .map_err(|e| flight(e.to_string()))?;
    let state = FlightState::hovering(airframe, start.position, start.yaw);
    let uav = world
        .add_uav(airframe, &state)
        .map_err(|e| flight(e.to_string()))?;
    let controller = GeometricController::new(airframe, ControllerGains::default())
        .ok_or_else(|| flight("the airframe's rotors cannot be mixed".to_owned()))?;
    let dt = world.config().dt;
    let duration = profile.duration();
    let mut log = Vec::with_capacity((duration / dt) as usize + 1);
    let mut energy = 0.0;
    let record = fly_trajectory(
        &mut world,
        uav,
        &controller,
        profile,
        &Completion::default(),
        &mut |t, state, power| {
            // The step's power is held over the step that ends at `t`.
            let phase = profile.sample_phase(t - 0.5 * dt).1;
            if t <= duration + 0.5 * dt {
                energy += power * dt;
            }
            let speed = match phase {
                Phase::Climb | Phase::Descend => state.velocity.z.abs(),
                Phase::Turn => (state.attitude * state.body_rates).z.abs(),
                _ => state.velocity.truncate().length(),
            };
            log.push(Measurement {
                time_s: t,
                speed,
                power_w: power,
                phase,
            });
        },
    );
    if record.status != UavStatus::Flying {
        return Err(flight(format!(
            "the flight ended early: {:?}",
            record.status
        )));
    }
    Ok(FlownProfile {
        log,
        energy_j: energy,
        energy_to_arrival_j: record.energy_j,
        duration_s: duration,
        time_to_arrival_s: record.duration_s,
        rms_tracking_error_m: record.rms_tracking_error_m,
    })
}

/// The profile of a planned mission: take off from the start (at `ground_z`) straight up to the
/// plan's altitude at the model's climb speed, fly each leg at its planned speed accelerating and
/// decelerating at the model's rates, turn in place between legs at the model's yaw rate, and
/// descend at the model's descent speed: exactly the motions eq. 18 prices.
pub fn plan_profile(plan: &MissionPlan, model: &SpeedEnergyModel, ground_z: f64) -> Profile {
    let altitude = ground_z + plan.survey.altitude_m;
    let heading = |leg: &uavex_systems::coverage::LegPlan| {
        let d = leg.end - leg.start;
        d.y.atan2(d.x)
    };
    let Some(first) = plan.legs.first() else {
        return Profile::new(Vec::new());
    };
    let start = plan
        .path
        .waypoints
        .first()
        .map_or(first.start, |w| w.position);
    let mut yaw = heading(first);
    let vertical = |from: DVec3, to: DVec3, speed: f64, yaw: f64| Piece::Line {
        from,
        to,
        speed,
        // Vertical speeds are reached quickly: the model prices climb and descent at
        // constant speed.
        acceleration: model.acceleration.max(model.deceleration),
        deceleration: model.acceleration.max(model.deceleration),
        yaw,
    };
    let mut pieces = vec![vertical(
        start.extend(ground_z),
        start.extend(altitude),
        model.climb.speed,
        yaw,
    )];
    let mut position = start.extend(altitude);
    for (i, leg) in plan.legs.iter().enumerate() {
        if i > 0 {
            let next = heading(leg);
            let mut angle = next - yaw;
            angle = (angle + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU)
                - std::f64::consts::PI;
            if angle.abs() > 1e-9 {
                pieces.push(Piece::Turn {
                    at: position,
                    from_yaw: yaw,
                    angle,
                    rate: model.turn.rate,
                });
            }
            yaw = next;
        }
        let to = leg.end.extend(altitude);
        if leg.length_m > 0.0 && leg.speed > 0.0 {
            pieces.push(Piece::Line {
                from: leg.start.extend(altitude),
                to,
                speed: leg.speed,
                acceleration: model.acceleration,
                deceleration: model.deceleration,
                yaw,
            });
        }
        position = to;
    }
    pieces.push(vertical(
        position,
        position.truncate().extend(ground_z),
        model.descent.speed,
        yaw,
    ));
    Profile::new(pieces)
}

/// Predicted (eq. 18) against flown energy and time of a coverage mission.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PlanComparison {
    pub predicted_energy_j: f64,
    pub flown_energy_j: f64,
    pub predicted_time_s: f64,
    pub flown_time_s: f64,
    /// `flown / predicted - 1`.
    pub energy_error: f64,
    pub time_error: f64,
    pub rms_tracking_error_m: f64,
}

/// Flies `plan` (priced with `model`) on `airframe` and compares.
pub fn fly_plan(
    airframe: &Airframe,
    plan: &MissionPlan,
    model: &SpeedEnergyModel,
) -> Result<PlanComparison, CoverageIoError> {
    let profile = plan_profile(plan, model, 0.0);
    let flown = fly_profile(airframe, &profile)?;
    // Flown: until the UAV has landed and settled (Completion), as a real flight is timed.
    Ok(PlanComparison {
        predicted_energy_j: plan.energy_j,
        flown_energy_j: flown.energy_to_arrival_j,
        predicted_time_s: plan.time_s,
        flown_time_s: flown.time_to_arrival_s,
        energy_error: flown.energy_to_arrival_j / plan.energy_j - 1.0,
        time_error: flown.time_to_arrival_s / plan.time_s - 1.0,
        rms_tracking_error_m: flown.rms_tracking_error_m,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use uavex_systems::coverage::{
        Camera, CoverageProblem, Overlaps, Polygon, ScanDirection, plan_mission,
    };

    fn rectangle_plan(model: &SpeedEnergyModel) -> MissionPlan {
        let problem = CoverageProblem {
            polygon: Polygon::new(vec![
                glam::DVec2::new(0.0, 0.0),
                glam::DVec2::new(60.0, 0.0),
                glam::DVec2::new(60.0, 30.0),
                glam::DVec2::new(0.0, 30.0),
            ])
            .unwrap(),
            start_vertex: 0,
            camera: Camera {
                angle_of_view: 1.2,
                width_px: 4000,
                height_px: 3000,
                shot_period_s: 1.0,
            },
            overlaps: Overlaps { x: 0.2, y: 0.3 },
            required_resolution_px_per_m: 150.0,
            direction: ScanDirection::LongestEdge,
        };
        plan_mission(&problem, 10.0, model).unwrap()
    }

    #[test]
    fn the_profile_flies_what_eq_18_prices() {
        let model = SpeedEnergyModel::iris();
        let plan = rectangle_plan(&model);
        let profile = plan_profile(&plan, &model, 0.0);
        let pieces = profile.pieces();
        let lines = pieces
            .iter()
            .filter(|p| matches!(p, Piece::Line { .. }))
            .count();
        let turns = pieces
            .iter()
            .filter(|p| matches!(p, Piece::Turn { .. }))
            .count();
        // Climb + every leg + descent; one turn between consecutive legs of different heading.
        assert_eq!(lines, plan.legs.len() + 2);
        assert_eq!(
            turns,
            plan.turns.iter().filter(|t| t.angle_rad > 1e-9).count()
        );
        // Legs and turns take exactly the model's times; the climb and descent add their
        // speed-up and slow-down, v / a each (IRIS: 2.0912 and 1.2794 m/s at a = 1 m/s^2).
        let ramps = model.climb.speed / 1.0 + model.descent.speed / 1.0;
        assert!((profile.duration() - plan.time_s - ramps).abs() < 1e-6);
        let end = profile.sample(profile.duration());
        let start = plan.path.waypoints[0].position;
        assert!(end.position.z.abs() < 1e-12);
        assert_eq!(profile.sample(0.0).position, start.extend(0.0));
        let after_climb = model.climb_time(10.0) + model.climb.speed + 0.5;
        assert!((profile.sample(after_climb).position.z - 10.0).abs() < 1e-9);
    }
}
