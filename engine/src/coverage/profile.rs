//! The motions the speed-based energy model describes (coverage.md, "Measured energy model"),
//! as a reference trajectory the geometric controller flies: straight segments from rest to rest
//! with a trapezoidal speed profile (accelerate at `a_acc`, cruise, decelerate at `a_dec`),
//! turns in place at a constant yaw rate, and hovering. Each instant carries the [`Phase`] the
//! model prices it with, so the same profile serves calibration (label the log) and flying a
//! plan (compare with the prediction).
//!
//! Accelerations switch in steps, as the model assumes (the paper flew PX4's maximum
//! acceleration); jerk and snap are zero inside each piece, and the controller absorbs the steps.

use glam::DVec3;
use uavex_components::trajectory::{Trajectory, TrajectoryPoint};
use uavex_systems::coverage::Phase;

/// Below this, a segment counts as vertical (climb or descent) rather than level.
const VERTICAL: f64 = 0.99;

/// One piece of a [`Profile`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Piece {
    /// From `from` to `to` at rest at both ends, at `yaw` throughout.
    Line {
        from: DVec3,
        to: DVec3,
        /// Cruise speed; lowered to the most the length allows (m/s).
        speed: f64,
        acceleration: f64,
        deceleration: f64,
        yaw: f64,
    },
    /// In place at `at`, from heading `from_yaw` by `angle` (signed, rad) at `rate` (rad/s).
    Turn {
        at: DVec3,
        from_yaw: f64,
        angle: f64,
        rate: f64,
    },
    /// At rest at `at`.
    Hover { at: DVec3, yaw: f64, duration: f64 },
}

/// The speed profile of a [`Piece::Line`].
#[derive(Debug, Clone, Copy, PartialEq)]
struct Ramp {
    length: f64,
    speed: f64,
    acceleration: f64,
    deceleration: f64,
}

impl Ramp {
    fn new(length: f64, speed: f64, acceleration: f64, deceleration: f64) -> Self {
        // v^2 / (2 a) + v^2 / (2 b) <= d (energy_model.rs, `reachable_speed`).
        let reachable =
            (2.0 * length * acceleration * deceleration / (acceleration + deceleration)).sqrt();
        Self {
            length,
            speed: speed.min(reachable),
            acceleration,
            deceleration,
        }
    }

    fn accelerating_time(&self) -> f64 {
        self.speed / self.acceleration
    }

    fn cruise_time(&self) -> f64 {
        let ramps = self.speed * self.speed * (0.5 / self.acceleration + 0.5 / self.deceleration);
        ((self.length - ramps) / self.speed).max(0.0)
    }

    fn duration(&self) -> f64 {
        if self.length <= 0.0 || self.speed <= 0.0 {
            return 0.0;
        }
        self.accelerating_time() + self.cruise_time() + self.speed / self.deceleration
    }

    /// Distance, speed and acceleration along the segment at `t`, and the phase.
    fn at(&self, t: f64) -> (f64, f64, f64, Phase) {
        let t1 = self.accelerating_time();
        let t2 = t1 + self.cruise_time();
        let end = self.duration();
        if t <= 0.0 || end == 0.0 {
            (0.0, 0.0, 0.0, Phase::Accelerate)
        } else if t < t1 {
            let a = self.acceleration;
            (0.5 * a * t * t, a * t, a, Phase::Accelerate)
        } else if t < t2 {
            let s1 = 0.5 * self.speed * t1;
            (s1 + self.speed * (t - t1), self.speed, 0.0, Phase::Cruise)
        } else if t < end {
            let s2 = 0.5 * self.speed * t1 + self.speed * (t2 - t1);
            let u = t - t2;
            let b = self.deceleration;
            (
                s2 + self.speed * u - 0.5 * b * u * u,
                self.speed - b * u,
                -b,
                Phase::Decelerate,
            )
        } else {
            (self.length, 0.0, 0.0, Phase::Decelerate)
        }
    }
}

impl Piece {
    fn ramp(&self) -> Option<(Ramp, DVec3)> {
        match *self {
            Piece::Line {
                from,
                to,
                speed,
                acceleration,
                deceleration,
                ..
            } => {
                let length = from.distance(to);
                let direction = if length > 0.0 {
                    (to - from) / length
                } else {
                    DVec3::X
                };
                Some((
                    Ramp::new(length, speed, acceleration, deceleration),
                    direction,
                ))
            }
            _ => None,
        }
    }

    /// Time the piece lasts (s).
    pub fn duration(&self) -> f64 {
        match *self {
            Piece::Line { .. } => self.ramp().map_or(0.0, |(r, _)| r.duration()),
            Piece::Turn { angle, rate, .. } => angle.abs() / rate,
            Piece::Hover { duration, .. } => duration,
        }
    }

    /// The reference and the model's phase `t` seconds into the piece.
    pub fn sample(&self, t: f64) -> (TrajectoryPoint, Phase) {
        match *self {
            Piece::Line { from, yaw, .. } => {
                let (ramp, direction) = self.ramp().expect("a line has a ramp");
                let (s, v, a, phase) = ramp.at(t);
                let phase = if direction.z > VERTICAL {
                    Phase::Climb
                } else if direction.z < -VERTICAL {
                    Phase::Descend
                } else {
                    phase
                };
                let point = TrajectoryPoint {
                    position: from + direction * s,
                    velocity: direction * v,
                    acceleration: direction * a,
                    yaw,
                    ..TrajectoryPoint::default()
                };
                (point, phase)
            }
            Piece::Turn {
                at,
                from_yaw,
                angle,
                rate,
            } => {
                let duration = self.duration();
                let t = t.clamp(0.0, duration);
                let turning = t < duration;
                let point = TrajectoryPoint {
                    yaw: from_yaw + angle.signum() * rate * t,
                    yaw_rate: if turning { angle.signum() * rate } else { 0.0 },
                    ..TrajectoryPoint::at_rest(at, 0.0)
                };
                (point, Phase::Turn)
            }
            Piece::Hover { at, yaw, .. } => (TrajectoryPoint::at_rest(at, yaw), Phase::Hover),
        }
    }
}

/// Pieces flown one after the other.
#[derive(Debug, Clone, PartialEq)]
pub struct Profile {
    pieces: Vec<Piece>,
    /// Start time of each piece, then the total duration.
    starts: Vec<f64>,
}

impl Profile {
    pub fn new(pieces: Vec<Piece>) -> Self {
        let mut starts = Vec::with_capacity(pieces.len() + 1);
        let mut t = 0.0;
        starts.push(t);
        for piece in &pieces {
            t += piece.duration();
            starts.push(t);
        }
        Self { pieces, starts }
    }

    pub fn pieces(&self) -> &[Piece] {
        &self.pieces
    }

    /// The piece flown at `t` and the time into it.
    fn locate(&self, t: f64) -> Option<(usize, f64)> {
        if self.pieces.is_empty() {
            return None;
        }
        let i = self.starts[1..]
            .partition_point(|&end| end <= t)
            .min(self.pieces.len() - 1);
        Some((i, t - self.starts[i]))
    }

    /// The reference and the model's phase at `t` (the last piece's end after the end).
    pub fn sample_phase(&self, t: f64) -> (TrajectoryPoint, Phase) {
        match self.locate(t) {
            Some((i, u)) => {
                let (mut point, phase) = self.pieces[i].sample(u);
                if t >= self.duration() {
                    point = TrajectoryPoint::at_rest(point.position, point.yaw);
                }
                (point, phase)
            }
            None => (TrajectoryPoint::default(), Phase::Hover),
        }
    }
}

impl Trajectory for Profile {
    fn duration(&self) -> f64 {
        *self.starts.last().unwrap_or(&0.0)
    }

    fn sample(&self, t: f64) -> TrajectoryPoint {
        self.sample_phase(t).0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn line(to: DVec3, speed: f64) -> Piece {
        Piece::Line {
            from: DVec3::ZERO,
            to,
            speed,
            acceleration: 1.0,
            deceleration: 2.0,
            yaw: 0.0,
        }
    }

    #[test]
    fn trapezoid_by_hand() {
        // 20 m at 4 m/s, a = 1, b = 2: ramps 8 m + 4 m, cruise 8 m (2 s); 4 + 2 + 2 = 8 s.
        let piece = line(DVec3::new(20.0, 0.0, 0.0), 4.0);
        assert!((piece.duration() - 8.0).abs() < 1e-12);
        let (p, phase) = piece.sample(2.0);
        assert_eq!(phase, Phase::Accelerate);
        assert!((p.position.x - 2.0).abs() < 1e-12 && (p.velocity.x - 2.0).abs() < 1e-12);
        let (p, phase) = piece.sample(5.0);
        assert_eq!(phase, Phase::Cruise);
        assert!((p.position.x - 12.0).abs() < 1e-12 && p.acceleration.x == 0.0);
        let (p, phase) = piece.sample(7.0);
        assert_eq!(phase, Phase::Decelerate);
        // 16 + 4 - 1 = 19 m, 2 m/s.
        assert!((p.position.x - 19.0).abs() < 1e-12 && (p.velocity.x - 2.0).abs() < 1e-12);
        assert!((piece.sample(8.0).0.position.x - 20.0).abs() < 1e-12);
    }

    #[test]
    fn short_lines_never_reach_cruise_and_vertical_lines_climb() {
        // 3 m with a = 1, b = 2: v^2 (1/2 + 1/4) = 3 gives 2 m/s, not 4.
        let piece = line(DVec3::new(0.0, 3.0, 0.0), 4.0);
        assert!((piece.duration() - 3.0).abs() < 1e-12);
        assert_eq!(piece.sample(1.0).1, Phase::Accelerate);
        assert_eq!(
            line(DVec3::new(0.0, 0.0, 5.0), 1.0).sample(1.0).1,
            Phase::Climb
        );
        assert_eq!(
            line(DVec3::new(0.0, 0.0, -5.0), 1.0).sample(1.0).1,
            Phase::Descend
        );
    }

    #[test]
    fn profile_chains_pieces_in_time() {
        let turn = Piece::Turn {
            at: DVec3::ZERO,
            from_yaw: 0.5,
            angle: -1.0,
            rate: 0.5,
        };
        let profile = Profile::new(vec![
            Piece::Hover {
                at: DVec3::ZERO,
                yaw: 0.5,
                duration: 1.0,
            },
            turn,
            line(DVec3::new(20.0, 0.0, 0.0), 4.0),
        ]);
        assert!((profile.duration() - 11.0).abs() < 1e-12);
        assert_eq!(profile.sample_phase(0.5).1, Phase::Hover);
        let (p, phase) = profile.sample_phase(2.0);
        assert_eq!(phase, Phase::Turn);
        assert!((p.yaw - 0.0).abs() < 1e-12 && (p.yaw_rate + 0.5).abs() < 1e-12);
        assert_eq!(profile.sample_phase(8.0).1, Phase::Cruise);
        let end = profile.sample(20.0);
        assert_eq!(end.velocity, DVec3::ZERO);
        assert!((end.position.x - 20.0).abs() < 1e-12);
    }
}
