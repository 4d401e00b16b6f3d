//! `uavex calibrate AIRFRAME`: the paper's measurement flights (coverage.md, "Fitting the model
//! from measurements"; Di Franco and Buttazzo 2015, section on the energy model) flown on the
//! simulated quadrotor instead of a real one, and the speed-based model fitted from their log.
//!
//! The experiments, each its own flight from hover on an empty rapier world ([`fly_profile`]):
//! - speeding up at the maximum acceleration to the top speed and braking at the maximum
//!   deceleration;
//! - straight legs at constant speeds over the airframe's range (their ramps add acceleration
//!   and deceleration rows at lower speeds);
//! - hovering, climbing and descending at constant vertical speeds, and a full turn in place.
//!
//! Every physics step is a row (time, speed, power, phase), the phase being the one of the
//! reference flown at that instant; [`fit_model`](uavex_systems::coverage::fit_model) then fits
//! the curves by least squares, and the model is refused if the model loader would refuse it.

use super::CoverageIoError;
use super::flight::fly_profile;
use super::measurements::fit_usable_model;
use super::profile::{Piece, Profile};
use glam::DVec3;
use rayon::prelude::*;
use std::path::PathBuf;
use uavex_components::airframe::Airframe;
use uavex_systems::coverage::{FitDegrees, FittedModel, Measurement, SpeedEnergyModel};

/// What to fly for a calibration.
#[derive(Debug, Clone, PartialEq)]
pub struct CalibrationPlan {
    /// The "maximum" acceleration and deceleration flown (m/s^2).
    pub acceleration: f64,
    /// Constant speeds of the level legs (m/s), ascending; the last is the top speed.
    pub cruise_speeds: Vec<f64>,
    /// Time at constant speed on each level leg (s).
    pub cruise_time_s: f64,
    pub hover_time_s: f64,
    /// Vertical speeds (m/s) and the height climbed then descended (m).
    pub climb_speed: f64,
    pub descent_speed: f64,
    pub vertical_height_m: f64,
    /// Yaw rate of the turn in place (rad/s), turned through a full circle.
    pub turn_rate: f64,
    pub degrees: FitDegrees,
}

impl CalibrationPlan {
    /// Half the airframe's acceleration limit (the controller then tracks the steps of the
    /// profile closely), ten speeds up to its speed limit, 1 m/s vertically, 0.5 rad/s turns.
    pub fn for_airframe(airframe: &Airframe) -> Self {
        let top = airframe.max_velocity;
        Self {
            acceleration: 0.5 * airframe.max_acceleration,
            cruise_speeds: (1..=10).map(|i| top * i as f64 / 10.0).collect(),
            cruise_time_s: 8.0,
            hover_time_s: 10.0,
            climb_speed: 1.0,
            descent_speed: 1.0,
            vertical_height_m: 10.0,
            turn_rate: 0.5,
            degrees: FitDegrees::default(),
        }
    }

    /// The experiments as named profiles, each flown from hover at 20 m.
    pub fn experiments(&self) -> Vec<(String, Profile)> {
        let origin = DVec3::new(0.0, 0.0, 20.0);
        let a = self.acceleration;
        let level = |speed: f64, cruise_time: f64| Piece::Line {
            from: origin,
            to: origin + DVec3::X * (speed * speed / a + speed * cruise_time),
            speed,
            acceleration: a,
            deceleration: a,
            yaw: 0.0,
        };
        let vertical = |height: f64, speed: f64| Piece::Line {
            from: origin,
            to: origin + DVec3::Z * height,
            speed,
            acceleration: a,
            deceleration: a,
            yaw: 0.0,
        };
        let top = self.cruise_speeds.last().copied().unwrap_or(1.0);
        let mut experiments = vec![(
            format!("accelerate to {top:.2} m/s and brake at {a:.2} m/s^2"),
            Profile::new(vec![level(top, 1.0)]),
        )];
        for &speed in &self.cruise_speeds {
            experiments.push((
                format!("level leg at {speed:.2} m/s"),
                Profile::new(vec![level(speed, self.cruise_time_s)]),
            ));
        }
        experiments.extend([
            (
                format!("hover {:.0} s", self.hover_time_s),
                Profile::new(vec![Piece::Hover {
                    at: origin,
                    yaw: 0.0,
                    duration: self.hover_time_s,
                }]),
            ),
            (
                format!("climb at {:.2} m/s", self.climb_speed),
                Profile::new(vec![vertical(self.vertical_height_m, self.climb_speed)]),
            ),
            (
                format!("descend at {:.2} m/s", self.descent_speed),
                Profile::new(vec![vertical(-self.vertical_height_m, self.descent_speed)]),
            ),
            (
                format!("turn in place at {:.2} rad/s", self.turn_rate),
                Profile::new(vec![Piece::Turn {
                    at: origin,
                    from_yaw: 0.0,
                    angle: std::f64::consts::TAU,
                    rate: self.turn_rate,
                }]),
            ),
        ]);
        experiments
    }
}

/// A calibration's log and fitted model.
#[derive(Debug, Clone, PartialEq)]
pub struct Calibration {
    /// Every experiment's rows, one after the other (times offset so they never overlap).
    pub log: Vec<Measurement>,
    pub fitted: FittedModel,
}

/// Flies `plan`'s experiments on `airframe` (in parallel) and fits a model named `name`.
pub fn calibrate(
    name: &str,
    airframe: &Airframe,
    plan: &CalibrationPlan,
) -> Result<Calibration, CoverageIoError> {
    let experiments = plan.experiments();
    let flown = experiments
        .par_iter()
        .map(|(what, profile)| {
            fly_profile(airframe, profile)
                .map_err(|e| CoverageIoError::Flight(format!("calibration `{what}`: {e}")))
        })
        .collect::<Result<Vec<_>, _>>()?;
    let mut log = Vec::new();
    let mut offset = 0.0;
    for run in flown {
        let end = run.log.last().map_or(0.0, |m| m.time_s);
        log.extend(run.log.into_iter().map(|m| Measurement {
            time_s: m.time_s + offset,
            ..m
        }));
        offset += end + 1.0;
    }
    let data = PathBuf::from(format!("calibration flights of {name}"));
    let fitted = fit_usable_model(name, &log, plan.degrees, &data)?;
    Ok(Calibration { log, fitted })
}

/// One fresh straight leg: the model's `E(d, v)` against the flight's energy.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LegCheck {
    pub distance_m: f64,
    pub speed: f64,
    pub predicted_j: f64,
    pub flown_j: f64,
    /// `flown / predicted - 1`.
    pub error: f64,
}

/// Flies straight legs from rest to rest at the given (distance, cruise speed) with the model's
/// acceleration and deceleration, and compares each with `E(d, v)`.
pub fn check_legs(
    airframe: &Airframe,
    model: &SpeedEnergyModel,
    legs: &[(f64, f64)],
) -> Result<Vec<LegCheck>, CoverageIoError> {
    legs.par_iter()
        .map(|&(distance, speed)| {
            let speed = speed.min(model.reachable_speed(distance));
            let predicted = model.straight_energy(distance, speed).map_err(|e| {
                CoverageIoError::Flight(format!("leg of {distance} m at {speed} m/s: {e}"))
            })?;
            let origin = DVec3::new(0.0, 0.0, 20.0);
            let profile = Profile::new(vec![Piece::Line {
                from: origin,
                to: origin + DVec3::new(0.6, 0.8, 0.0) * distance,
                speed,
                acceleration: model.acceleration,
                deceleration: model.deceleration,
                yaw: 0.3,
            }]);
            let flown = fly_profile(airframe, &profile)?;
            Ok(LegCheck {
                distance_m: distance,
                speed,
                predicted_j: predicted,
                flown_j: flown.energy_j,
                error: flown.energy_j / predicted - 1.0,
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The check: calibrated on the simulated kingfisher, the model predicts what the
    /// simulator draws along fresh legs (lengths and speeds the calibration did not fly) to
    /// within 3 %.
    #[test]
    fn kingfisher_calibration_predicts_fresh_legs_within_3_percent() {
        for drag in [0.0, 0.4] {
            let mut airframe = Airframe::kingfisher();
            airframe.drag.body = drag;
            let plan = CalibrationPlan::for_airframe(&airframe);
            // Half the 4 m/s^2 limit, ten speeds up to 5 m/s.
            assert_eq!(plan.acceleration, 2.0);
            assert_eq!(plan.cruise_speeds[0], 0.5);
            let calibration = calibrate("kf", &airframe, &plan).unwrap();
            let model = &calibration.fitted.model;
            // Hover: 123 W at 1086 rad/s (physics tests); the fit sees the same.
            assert!((model.hover_power() / 123.0 - 1.0).abs() < 0.01);
            assert!((model.acceleration / 2.0 - 1.0).abs() < 0.05, "{model:?}");
            assert!((model.deceleration / 2.0 - 1.0).abs() < 0.05, "{model:?}");
            assert!((model.turn.rate / 0.5 - 1.0).abs() < 0.01, "{model:?}");
            let legs = [(23.0, 1.3), (61.0, 3.7), (140.0, 4.6), (9.0, 2.5)];
            for check in check_legs(&airframe, model, &legs).unwrap() {
                assert!(check.error.abs() < 0.03, "drag {drag}: {check:?}");
            }
            if drag > 0.0 {
                // Body drag makes level flight cost more with speed: 0.4 N s/m x (4.5 m/s)^2 =
                // 8.1 W of drag power alone at 4.5 m/s.
                let rise = model.level.power(4.5) - model.level.power(0.0);
                assert!(rise > 4.0, "{rise}");
            }
        }
    }

    #[test]
    fn the_experiments_cover_every_phase() {
        let plan = CalibrationPlan::for_airframe(&Airframe::kingfisher());
        let experiments = plan.experiments();
        // Accelerate-brake, ten level legs, hover, climb, descent, turn.
        assert_eq!(experiments.len(), 15);
        let turn = &experiments[14].1;
        // A full turn at 0.5 rad/s: 4 pi s.
        assert!((turn.pieces()[0].duration() - 4.0 * std::f64::consts::PI).abs() < 1e-12);
    }
}
