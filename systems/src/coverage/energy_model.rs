//! The speed-based energy model of a multirotor, measured rather than derived (coverage.md,
//! "Measured energy model"): power in straight level flight as a polynomial of speed, power while
//! accelerating and decelerating as polynomials of the speed reached, and constant powers for
//! climbing, descending and turning in place. It sits beside the rotor-speed power model of the
//! flight stack: that one integrates what the rotors do, this one predicts a whole mission from a
//! handful of measured curves (Di Franco and Buttazzo 2015).
//!
//! A straight segment of length `d` is flown from rest to rest: accelerate at `a_acc` to the
//! cruise speed `v`, cruise, decelerate at `a_dec` to rest. With `a_acc = a_dec = a` this is the
//! spec's
//! `E(d, v) = (1/a) int_0^v P_acc(u) du + P(v) (d - v^2/a) / v + (1/a) int_0^v P_dec(u) du`,
//! `t(d, v) = 2 v / a + (d - v^2/a) / v`, valid while `v <= sqrt(a d)`.

use super::power_curve::PowerCurve;
use serde::{Deserialize, Serialize};
use thiserror::Error;

#[derive(Debug, Clone, PartialEq, Error)]
pub enum EnergyModelError {
    #[error("energy model `{model}`: {what} must be positive and finite, got {value}")]
    NotPositive {
        model: String,
        what: &'static str,
        value: f64,
    },
    #[error("energy model `{model}`: the {curve} power curve needs finite coefficients")]
    Curve { model: String, curve: &'static str },
    #[error(
        "energy model `{model}`: {curve}.coefficients has {count} coefficients, at most {limit} \
         (a polynomial of degree {limit} - 1) are accepted"
    )]
    TooManyCoefficients {
        model: String,
        curve: &'static str,
        count: usize,
        limit: usize,
    },
    #[error(
        "energy model `{model}`: {curve}.coefficients give {power_w:.4} W at {speed:.4} m/s: power \
         must be positive at every speed it is used at, 0 to max_speed ({max_speed} m/s)"
    )]
    NonPositivePower {
        model: String,
        curve: &'static str,
        speed: f64,
        power_w: f64,
        max_speed: f64,
    },
    #[error("a leg length must be non-negative and finite (m), got {0}")]
    Distance(f64),
    #[error(
        "cruise speed {speed} m/s is outside (0, {limit:.3}] m/s, the most a {distance} m leg \
         flown from rest to rest allows"
    )]
    Speed {
        speed: f64,
        distance: f64,
        limit: f64,
    },
    #[error("a speed limit must be positive (m/s), got {0}")]
    SpeedLimit(f64),
}

/// Climbing or descending straight up or down at a constant speed.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct VerticalFlight {
    pub power_w: f64,
    /// Vertical speed (m/s), positive.
    pub speed: f64,
}

/// Turning in place at a constant yaw rate.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Turning {
    pub power_w: f64,
    /// Yaw rate `omega_turn` (rad/s).
    pub rate: f64,
}

/// A speed-based energy model (serialisable: presets and fitted models share the format).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SpeedEnergyModel {
    pub name: String,
    /// `P(v)`: straight level flight at constant speed `v`; `P(0)` is the hover power.
    pub level: PowerCurve,
    /// `P_acc(v)`: power while accelerating, as a function of the speed reached.
    pub accelerating: PowerCurve,
    /// `P_dec(v)`: power while decelerating, as a function of the current speed.
    pub decelerating: PowerCurve,
    /// `a_acc` (m/s^2).
    pub acceleration: f64,
    /// `a_dec` (m/s^2), positive.
    pub deceleration: f64,
    pub climb: VerticalFlight,
    pub descent: VerticalFlight,
    pub turn: Turning,
    /// Highest speed the curves were measured at (m/s); no leg is planned faster.
    pub max_speed: f64,
}

/// How one straight segment is flown.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct StraightFlight {
    /// Cruise speed (m/s).
    pub speed: f64,
    pub energy_j: f64,
    pub time_s: f64,
}

impl SpeedEnergyModel {
    /// The IRIS 3DR of the paper, with its authors' published coefficients (coverage.md). The
    /// deceleration curve is published as `q(15 - v)`, i.e. measured down from 15 m/s, so 15 m/s
    /// is taken as the top of the measured range.
    pub fn iris() -> Self {
        Self {
            name: "iris".to_owned(),
            level: PowerCurve::polynomial(vec![
                3.68380646e-03,
                2.25408188e-02,
                -6.96241157e-01,
                3.29818812e-01,
                2.21278607e+02,
            ]),
            accelerating: PowerCurve::polynomial(vec![
                2.02785069e-05,
                1.48596119e-02,
                -4.60420747e-01,
                5.15227981e+00,
                -2.11825328e+01,
                2.33597050e+02,
            ]),
            decelerating: PowerCurve::reflected(
                vec![
                    1.07216605e-02,
                    -4.93828311e-01,
                    8.34385707e+00,
                    -5.77374016e+01,
                    3.41872290e+02,
                ],
                15.0,
            ),
            // PX4's default, as the authors' implementation assumes.
            acceleration: 1.0,
            deceleration: 1.0,
            climb: VerticalFlight {
                power_w: 249.01,
                speed: 2.0912,
            },
            descent: VerticalFlight {
                power_w: 212.47,
                speed: 1.2794,
            },
            turn: Turning {
                power_w: 225.0,
                rate: 2.1,
            },
            max_speed: 15.0,
        }
    }

    /// Presets by name.
    pub fn preset(name: &str) -> Option<Self> {
        match name {
            "iris" => Some(Self::iris()),
            _ => None,
        }
    }

    pub const PRESETS: &[&str] = &["iris"];

    /// Most coefficients of a power curve: the published and fitted curves have 5 or 6, and
    /// every evaluation costs one multiply-add per coefficient.
    pub const MAX_COEFFICIENTS: usize = 16;

    /// Speeds at which [`Self::validate`] checks that power is positive: evenly spaced over
    /// `[0, max_speed]`, ends included.
    const POWER_CHECKS: usize = 1024;

    pub fn validate(&self) -> Result<(), EnergyModelError> {
        let positive = [
            ("acceleration", self.acceleration),
            ("deceleration", self.deceleration),
            ("climb power", self.climb.power_w),
            ("climb speed", self.climb.speed),
            ("descent power", self.descent.power_w),
            ("descent speed", self.descent.speed),
            ("turn power", self.turn.power_w),
            ("turn rate", self.turn.rate),
            ("max speed", self.max_speed),
        ];
        for (what, value) in positive {
            if !(value > 0.0 && value.is_finite()) {
                return Err(EnergyModelError::NotPositive {
                    model: self.name.clone(),
                    what,
                    value,
                });
            }
        }
        for (curve, c) in [
            ("level", &self.level),
            ("accelerating", &self.accelerating),
            ("decelerating", &self.decelerating),
        ] {
            if !c.is_finite() {
                return Err(EnergyModelError::Curve {
                    model: self.name.clone(),
                    curve,
                });
            }
            if c.coefficients.len() > Self::MAX_COEFFICIENTS {
                return Err(EnergyModelError::TooManyCoefficients {
                    model: self.name.clone(),
                    curve,
                    count: c.coefficients.len(),
                    limit: Self::MAX_COEFFICIENTS,
                });
            }
            if let Some((speed, power_w)) =
                first_non_positive(c, self.max_speed, Self::POWER_CHECKS)
            {
                return Err(EnergyModelError::NonPositivePower {
                    model: self.name.clone(),
                    curve,
                    speed,
                    power_w,
                    max_speed: self.max_speed,
                });
            }
        }
        Ok(())
    }

    /// `P(0)` (W).
    pub fn hover_power(&self) -> f64 {
        self.level.power(0.0)
    }

    /// The highest cruise speed a leg of length `d` reaches from rest to rest:
    /// `v^2 (1/(2 a_acc) + 1/(2 a_dec)) = d`, i.e. `sqrt(a d)` when both rates are `a`.
    pub fn reachable_speed(&self, distance: f64) -> f64 {
        let a = self.acceleration;
        let b = self.deceleration;
        (2.0 * distance * a * b / (a + b)).sqrt()
    }

    /// Distance covered while speeding up to `v` and slowing down from it.
    fn ramp_distance(&self, v: f64) -> f64 {
        v * v / (2.0 * self.acceleration) + v * v / (2.0 * self.deceleration)
    }

    fn check(&self, distance: f64, speed: f64) -> Result<(), EnergyModelError> {
        if !(distance >= 0.0 && distance.is_finite()) {
            return Err(EnergyModelError::Distance(distance));
        }
        let limit = self.reachable_speed(distance);
        // A relative slack lets the boundary speed sqrt(a d) itself pass despite rounding.
        if !(speed > 0.0 && speed <= limit * (1.0 + 1e-12)) {
            return Err(EnergyModelError::Speed {
                speed,
                distance,
                limit,
            });
        }
        Ok(())
    }

    /// `E(d, v)` (J): a straight segment of `d` flown from rest to rest at cruise speed `v`.
    pub fn straight_energy(&self, distance: f64, speed: f64) -> Result<f64, EnergyModelError> {
        self.check(distance, speed)?;
        Ok(self.energy_unchecked(distance, speed))
    }

    fn energy_unchecked(&self, distance: f64, v: f64) -> f64 {
        let cruise = (distance - self.ramp_distance(v)).max(0.0);
        self.accelerating.integral(v) / self.acceleration
            + self.level.power(v) * cruise / v
            + self.decelerating.integral(v) / self.deceleration
    }

    /// `t(d, v)` (s): `v / a_acc + v / a_dec + (d - ramps) / v`.
    pub fn straight_time(&self, distance: f64, speed: f64) -> Result<f64, EnergyModelError> {
        self.check(distance, speed)?;
        let cruise = (distance - self.ramp_distance(speed)).max(0.0);
        Ok(speed / self.acceleration + speed / self.deceleration + cruise / speed)
    }

    /// `v*(d)`: the cruise speed minimising `E(d, v)` over `0 < v <= min(sqrt(a d), limit,
    /// max_speed)`.
    pub fn optimal_speed(&self, distance: f64, limit: f64) -> Result<f64, EnergyModelError> {
        if !(distance > 0.0 && distance.is_finite()) {
            return Err(EnergyModelError::Distance(distance));
        }
        if limit.is_nan() || limit <= 0.0 {
            return Err(EnergyModelError::SpeedLimit(limit));
        }
        let hi = self
            .reachable_speed(distance)
            .min(limit)
            .min(self.max_speed);
        Ok(minimise(|v| self.energy_unchecked(distance, v), hi))
    }

    /// The constant-speed optimum `argmin P(v) / v` over `(0, max_speed]`: energy per metre is
    /// least there, and `v*(d)` tends to it on long legs.
    pub fn cruise_optimum(&self) -> f64 {
        minimise(|v| self.level.power(v) / v, self.max_speed)
    }

    /// A straight segment of `d` at its optimal speed under `limit` (m/s); zero for `d = 0`.
    pub fn straight(&self, distance: f64, limit: f64) -> Result<StraightFlight, EnergyModelError> {
        if distance == 0.0 {
            return Ok(StraightFlight {
                speed: 0.0,
                energy_j: 0.0,
                time_s: 0.0,
            });
        }
        let speed = self.optimal_speed(distance, limit)?;
        Ok(StraightFlight {
            speed,
            energy_j: self.straight_energy(distance, speed)?,
            time_s: self.straight_time(distance, speed)?,
        })
    }

    /// `E_climb(0, h)` (J).
    pub fn climb_energy(&self, height: f64) -> f64 {
        self.climb.power_w * self.climb_time(height)
    }

    pub fn climb_time(&self, height: f64) -> f64 {
        height / self.climb.speed
    }

    /// `E_desc(h, 0)` (J).
    pub fn descent_energy(&self, height: f64) -> f64 {
        self.descent.power_w * self.descent_time(height)
    }

    pub fn descent_time(&self, height: f64) -> f64 {
        height / self.descent.speed
    }

    /// `E_turn = P_turn dtheta / omega_turn` (J).
    pub fn turn_energy(&self, angle: f64) -> f64 {
        self.turn.power_w * self.turn_time(angle)
    }

    pub fn turn_time(&self, angle: f64) -> f64 {
        angle.abs() / self.turn.rate
    }
}

/// The first of `samples + 1` evenly spaced speeds over `[0, max_speed]` where `curve` gives no
/// positive, finite power, with that power. A power model must draw power at every speed it is
/// flown at (coverage.md, "Measured energy model"); a fit that dips below zero would price legs
/// at negative energy and call any mission feasible.
fn first_non_positive(curve: &PowerCurve, max_speed: f64, samples: usize) -> Option<(f64, f64)> {
    (0..=samples)
        .map(|i| max_speed * i as f64 / samples as f64)
        .map(|v| (v, curve.power(v)))
        .find(|&(_, p)| !(p > 0.0 && p.is_finite()))
}

/// Minimises `f` over `(0, hi]`: a scan of 64 evenly spaced speeds finds the best bracket (the
/// curves are smooth but need not be unimodal), golden-section search narrows it.
fn minimise(f: impl Fn(f64) -> f64, hi: f64) -> f64 {
    const GRID: usize = 64;
    let grid: [f64; GRID] = std::array::from_fn(|i| hi * (i + 1) as f64 / GRID as f64);
    let values = grid.map(&f);
    let best = (0..GRID)
        .min_by(|&i, &j| values[i].total_cmp(&values[j]))
        .unwrap_or(GRID - 1);
    let mut a = if best == 0 { hi * 1e-9 } else { grid[best - 1] };
    let mut b = grid[(best + 1).min(GRID - 1)];
    let ratio = (5f64.sqrt() - 1.0) / 2.0;
    let mut c = b - ratio * (b - a);
    let mut d = a + ratio * (b - a);
    let (mut fc, mut fd) = (f(c), f(d));
    while b - a > 1e-10 * hi {
        if fc < fd {
            b = d;
            d = c;
            fd = fc;
            c = b - ratio * (b - a);
            fc = f(c);
        } else {
            a = c;
            c = d;
            fc = fd;
            d = a + ratio * (b - a);
            fd = f(d);
        }
    }
    let inner = (a + b) / 2.0;
    // The grid's best and the top of the range stand in case the bracket's ends were better.
    [
        (inner, f(inner)),
        (grid[best], values[best]),
        (hi, values[GRID - 1]),
    ]
    .into_iter()
    .min_by(|x, y| x.1.total_cmp(&y.1))
    .map_or(inner, |(v, _)| v)
}

#[cfg(test)]
#[path = "energy_model_tests.rs"]
mod tests;
