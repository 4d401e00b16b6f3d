//! Fitting a speed-based energy model from measurements (coverage.md, "Deriving a model from
//! measurements"): the paper's experiments, maximum-acceleration and maximum-deceleration runs,
//! constant-speed straight flights, climb, descent, hover and rotation, logged as rows of (time,
//! speed, power, phase), give the model by polynomial least squares, with the residuals reported
//! so that a poor fit shows.

use super::energy_model::{SpeedEnergyModel, Turning, VerticalFlight};
use super::power_curve::{PowerCurve, polyval};
use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};
use std::fmt;
use std::str::FromStr;
use thiserror::Error;

/// What the vehicle was doing when a row was logged.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Phase {
    /// Speeding up at the maximum acceleration; speed is the horizontal speed.
    Accelerate,
    /// Slowing down at the maximum deceleration.
    Decelerate,
    /// Straight level flight at constant horizontal speed.
    Cruise,
    /// Climbing straight up; speed is the vertical speed.
    Climb,
    /// Descending straight down; speed is the vertical speed (either sign).
    Descend,
    /// Hovering; fitted into the level-flight curve as speed 0.
    Hover,
    /// Turning in place; speed is the yaw rate (rad/s).
    Turn,
}

impl Phase {
    pub const ALL: [Phase; 7] = [
        Phase::Accelerate,
        Phase::Decelerate,
        Phase::Cruise,
        Phase::Climb,
        Phase::Descend,
        Phase::Hover,
        Phase::Turn,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Phase::Accelerate => "accelerate",
            Phase::Decelerate => "decelerate",
            Phase::Cruise => "cruise",
            Phase::Climb => "climb",
            Phase::Descend => "descend",
            Phase::Hover => "hover",
            Phase::Turn => "turn",
        }
    }
}

impl fmt::Display for Phase {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Phase {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let s = s.trim();
        Phase::ALL
            .into_iter()
            .find(|p| p.name().eq_ignore_ascii_case(s))
            .ok_or_else(|| {
                let names: Vec<&str> = Phase::ALL.iter().map(|p| p.name()).collect();
                format!("unknown phase `{s}`, expected one of {}", names.join(", "))
            })
    }
}

/// One logged sample.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Measurement {
    pub time_s: f64,
    /// Horizontal speed (m/s), vertical speed for climb and descent, yaw rate (rad/s) for turns.
    pub speed: f64,
    pub power_w: f64,
    pub phase: Phase,
}

/// Degrees of the fitted polynomials (the published IRIS model uses 4, 5 and 4).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FitDegrees {
    pub level: usize,
    pub accelerating: usize,
    pub decelerating: usize,
}

impl Default for FitDegrees {
    fn default() -> Self {
        Self {
            level: 4,
            accelerating: 5,
            decelerating: 4,
        }
    }
}

#[derive(Debug, Clone, PartialEq, Error)]
pub enum FitError {
    #[error("measurement {row} has a non-finite value")]
    NonFinite { row: usize },
    #[error("no `{phase}` measurements: the model needs every experiment")]
    Missing { phase: &'static str },
    #[error(
        "a degree-{degree} polynomial for `{phase}` needs at least {needed} measurements at \
         distinct speeds, got {got}"
    )]
    TooFew {
        phase: &'static str,
        degree: usize,
        needed: usize,
        got: usize,
    },
    #[error("the `{phase}` runs give no usable rate: speed does not change with time")]
    NoRate { phase: &'static str },
    #[error("the fitted {what} of `{phase}` is not positive ({value})")]
    NotPositive {
        what: &'static str,
        phase: &'static str,
        value: f64,
    },
}

/// A polynomial fit and how well it matches its data.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CurveFit {
    pub degree: usize,
    pub samples: usize,
    pub rms_residual_w: f64,
    pub max_abs_residual_w: f64,
    pub r_squared: f64,
}

/// A constant (mean) power and speed.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct MeanFit {
    pub samples: usize,
    pub power_w: f64,
    pub speed: f64,
    /// Standard deviation of the power about its mean (W).
    pub rms_residual_w: f64,
}

/// An acceleration or deceleration from the slope of speed against time.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct RateFit {
    pub samples: usize,
    /// m/s^2, positive.
    pub value: f64,
    /// RMS of the speed about the fitted lines (m/s).
    pub rms_residual: f64,
}

/// Every fit behind a fitted model.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FitReport {
    pub level: CurveFit,
    pub accelerating: CurveFit,
    pub decelerating: CurveFit,
    pub acceleration: RateFit,
    pub deceleration: RateFit,
    pub climb: MeanFit,
    pub descent: MeanFit,
    pub turn: MeanFit,
    /// The hover rows (fitted into the level curve at speed 0), if any.
    pub hover: Option<MeanFit>,
}

/// A fitted model with its report; serialisable to a file that `SpeedEnergyModel` users load.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FittedModel {
    pub model: SpeedEnergyModel,
    pub report: FitReport,
}

/// Fits every part of a speed-based model from `rows`.
pub fn fit_model(
    name: &str,
    rows: &[Measurement],
    degrees: FitDegrees,
) -> Result<FittedModel, FitError> {
    for (row, m) in rows.iter().enumerate() {
        if !(m.time_s.is_finite() && m.speed.is_finite() && m.power_w.is_finite()) {
            return Err(FitError::NonFinite { row });
        }
    }
    let of = |phase: Phase| -> Vec<Measurement> {
        rows.iter().copied().filter(|m| m.phase == phase).collect()
    };
    let samples = |ms: &[Measurement]| -> Vec<(f64, f64)> {
        ms.iter().map(|m| (m.speed.abs(), m.power_w)).collect()
    };
    let mut level_rows = of(Phase::Cruise);
    let hover_rows = of(Phase::Hover);
    let hover = (!hover_rows.is_empty()).then(|| mean_fit(&hover_rows));
    level_rows.extend(hover_rows.iter().map(|m| Measurement { speed: 0.0, ..*m }));
    let (level, level_fit) = fit_curve("cruise", &samples(&level_rows), degrees.level)?;
    let accelerate = of(Phase::Accelerate);
    let (accelerating, accelerating_fit) =
        fit_curve("accelerate", &samples(&accelerate), degrees.accelerating)?;
    let decelerate = of(Phase::Decelerate);
    let (decelerating, decelerating_fit) =
        fit_curve("decelerate", &samples(&decelerate), degrees.decelerating)?;
    let acceleration = fit_rate(rows, Phase::Accelerate)?;
    let deceleration = fit_rate(rows, Phase::Decelerate)?;
    let constant = |phase: Phase| -> Result<MeanFit, FitError> {
        let ms = of(phase);
        if ms.is_empty() {
            return Err(FitError::Missing {
                phase: phase.name(),
            });
        }
        let fit = mean_fit(&ms);
        for (what, value) in [("mean power", fit.power_w), ("mean speed", fit.speed)] {
            if value.is_nan() || value <= 0.0 {
                return Err(FitError::NotPositive {
                    what,
                    phase: phase.name(),
                    value,
                });
            }
        }
        Ok(fit)
    };
    let climb = constant(Phase::Climb)?;
    let descent = constant(Phase::Descend)?;
    let turn = constant(Phase::Turn)?;
    // Curves are trusted only where all three were measured.
    let top = |ms: &[Measurement]| ms.iter().map(|m| m.speed.abs()).fold(0.0, f64::max);
    let max_speed = top(&level_rows).min(top(&accelerate)).min(top(&decelerate));
    if max_speed.is_nan() || max_speed <= 0.0 {
        return Err(FitError::NotPositive {
            what: "highest speed",
            phase: "cruise, accelerate and decelerate",
            value: max_speed,
        });
    }
    let model = SpeedEnergyModel {
        name: name.to_owned(),
        level: PowerCurve::polynomial(level),
        accelerating: PowerCurve::polynomial(accelerating),
        decelerating: PowerCurve::polynomial(decelerating),
        acceleration: acceleration.value,
        deceleration: deceleration.value,
        climb: VerticalFlight {
            power_w: climb.power_w,
            speed: climb.speed,
        },
        descent: VerticalFlight {
            power_w: descent.power_w,
            speed: descent.speed,
        },
        turn: Turning {
            power_w: turn.power_w,
            rate: turn.speed,
        },
        max_speed,
    };
    Ok(FittedModel {
        model,
        report: FitReport {
            level: level_fit,
            accelerating: accelerating_fit,
            decelerating: decelerating_fit,
            acceleration,
            deceleration,
            climb,
            descent,
            turn,
            hover,
        },
    })
}

/// Least-squares polynomial of `degree` through (speed, power) samples, by SVD on speeds scaled
/// to [0, 1] (a raw Vandermonde matrix of speeds up to 15 m/s is badly conditioned), returned in
/// descending order for the unscaled speed.
pub fn fit_curve(
    phase: &'static str,
    samples: &[(f64, f64)],
    degree: usize,
) -> Result<(Vec<f64>, CurveFit), FitError> {
    let too_few = |got| FitError::TooFew {
        phase,
        degree,
        needed: degree + 1,
        got,
    };
    if samples.is_empty() {
        return Err(FitError::Missing { phase });
    }
    let mut speeds: Vec<f64> = samples.iter().map(|s| s.0).collect();
    speeds.sort_by(f64::total_cmp);
    speeds.dedup();
    if speeds.len() < degree + 1 {
        return Err(too_few(speeds.len()));
    }
    let scale = speeds.last().copied().unwrap_or(1.0).max(f64::MIN_POSITIVE);
    let n = degree + 1;
    let a = DMatrix::from_fn(samples.len(), n, |i, j| {
        (samples[i].0 / scale).powi((degree - j) as i32)
    });
    let b = DVector::from_iterator(samples.len(), samples.iter().map(|s| s.1));
    let svd = a.svd(true, true);
    let largest = svd.singular_values.max();
    let full_rank = svd.singular_values.min() > 1e-12 * largest;
    if !full_rank {
        return Err(too_few(speeds.len()));
    }
    let scaled = svd.solve(&b, 0.0).map_err(|_| too_few(speeds.len()))?;
    let coefficients: Vec<f64> = (0..n)
        .map(|j| scaled[j] / scale.powi((degree - j) as i32))
        .collect();
    let residuals: Vec<f64> = samples
        .iter()
        .map(|&(v, p)| p - polyval(&coefficients, v))
        .collect();
    let count = samples.len() as f64;
    let mean = samples.iter().map(|s| s.1).sum::<f64>() / count;
    let ss_res: f64 = residuals.iter().map(|r| r * r).sum();
    let ss_tot: f64 = samples.iter().map(|s| (s.1 - mean).powi(2)).sum();
    let fit = CurveFit {
        degree,
        samples: samples.len(),
        rms_residual_w: (ss_res / count).sqrt(),
        max_abs_residual_w: residuals.iter().map(|r| r.abs()).fold(0.0, f64::max),
        r_squared: if ss_tot > 0.0 {
            1.0 - ss_res / ss_tot
        } else {
            1.0
        },
    };
    Ok((coefficients, fit))
}

/// The common slope of speed against time over every run of `phase` (a run: consecutive rows of
/// that phase with increasing time), each run with its own intercept: pooled within-run least
/// squares, so runs logged one after another in one file need no separating.
fn fit_rate(rows: &[Measurement], phase: Phase) -> Result<RateFit, FitError> {
    let mut runs: Vec<Vec<(f64, f64)>> = Vec::new();
    let mut previous: Option<&Measurement> = None;
    for m in rows {
        if m.phase == phase {
            let continues = previous.is_some_and(|p| p.phase == phase && m.time_s > p.time_s);
            if !continues {
                runs.push(Vec::new());
            }
            if let Some(run) = runs.last_mut() {
                run.push((m.time_s, m.speed.abs()));
            }
        }
        previous = Some(m);
    }
    let (mut sxy, mut sxx, mut samples) = (0.0, 0.0, 0);
    for run in &runs {
        let n = run.len() as f64;
        let (tm, vm) = run
            .iter()
            .fold((0.0, 0.0), |(a, b), &(t, v)| (a + t / n, b + v / n));
        for &(t, v) in run {
            sxy += (t - tm) * (v - vm);
            sxx += (t - tm) * (t - tm);
        }
        samples += run.len();
    }
    if samples == 0 {
        return Err(FitError::Missing {
            phase: phase.name(),
        });
    }
    if sxx.is_nan() || sxx <= 0.0 || sxy == 0.0 {
        return Err(FitError::NoRate {
            phase: phase.name(),
        });
    }
    let slope = sxy / sxx;
    let mut ss = 0.0;
    for run in &runs {
        let n = run.len() as f64;
        let (tm, vm) = run
            .iter()
            .fold((0.0, 0.0), |(a, b), &(t, v)| (a + t / n, b + v / n));
        ss += run
            .iter()
            .map(|&(t, v)| (v - vm - slope * (t - tm)).powi(2))
            .sum::<f64>();
    }
    // Speeding up gives a positive slope, slowing down a negative one; both rates are positive.
    let value = if phase == Phase::Decelerate {
        -slope
    } else {
        slope
    };
    if value.is_nan() || value <= 0.0 {
        return Err(FitError::NotPositive {
            what: "rate",
            phase: phase.name(),
            value,
        });
    }
    Ok(RateFit {
        samples,
        value,
        rms_residual: (ss / samples as f64).sqrt(),
    })
}

fn mean_fit(rows: &[Measurement]) -> MeanFit {
    let n = rows.len() as f64;
    let power_w = rows.iter().map(|m| m.power_w).sum::<f64>() / n;
    let speed = rows.iter().map(|m| m.speed.abs()).sum::<f64>() / n;
    let var = rows
        .iter()
        .map(|m| (m.power_w - power_w).powi(2))
        .sum::<f64>()
        / n;
    MeanFit {
        samples: rows.len(),
        power_w,
        speed,
        rms_residual_w: var.sqrt(),
    }
}

#[cfg(test)]
#[path = "fit_tests.rs"]
mod tests;
