//! Analytic reference trajectories for controller studies and benchmarks: a circle and a
//! figure-eight (lemniscate of Gerono) in a horizontal plane, flown at a constant angular rate
//! reached and left through smooth ramps, so that the reference starts and ends at rest with
//! continuous derivatives up to snap.

use glam::DVec3;
use std::f64::consts::TAU;
use uavex_components::trajectory::{Trajectory, TrajectoryPoint};

/// A closed planar curve parametrised by an angle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PlanarCurve {
    /// `r (cos phi - 1, sin phi)`: starts at the origin, centre at (-r, 0).
    Circle { radius: f64 },
    /// `(a sin phi, a sin phi cos phi)`: a figure-eight through the origin, 2a wide, a tall.
    FigureEight { half_width: f64 },
}

impl PlanarCurve {
    /// Derivatives of order 0..=4 of the curve with respect to its angle.
    fn derivatives(&self, phi: f64) -> [DVec3; 5] {
        let (s, c) = phi.sin_cos();
        match *self {
            PlanarCurve::Circle { radius: r } => [
                DVec3::new(r * (c - 1.0), r * s, 0.0),
                DVec3::new(-r * s, r * c, 0.0),
                DVec3::new(-r * c, -r * s, 0.0),
                DVec3::new(r * s, -r * c, 0.0),
                DVec3::new(r * c, r * s, 0.0),
            ],
            PlanarCurve::FigureEight { half_width: a } => {
                // y = (a / 2) sin 2 phi.
                let (s2, c2) = (2.0 * phi).sin_cos();
                [
                    DVec3::new(a * s, 0.5 * a * s2, 0.0),
                    DVec3::new(a * c, a * c2, 0.0),
                    DVec3::new(-a * s, -2.0 * a * s2, 0.0),
                    DVec3::new(-a * c, -4.0 * a * c2, 0.0),
                    DVec3::new(a * s, 8.0 * a * s2, 0.0),
                ]
            }
        }
    }

    /// Largest |d curve / d phi|: the speed per unit angular rate.
    fn max_tangent(&self) -> f64 {
        match *self {
            PlanarCurve::Circle { radius } => radius,
            // |(a cos phi, a cos 2 phi)| is largest at phi = 0: a sqrt(2).
            PlanarCurve::FigureEight { half_width } => half_width * 2f64.sqrt(),
        }
    }
}

/// A planar curve flown from `start`: angular rate ramped up over `ramp` seconds, held for
/// `laps` turns, ramped down over `ramp` seconds.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CurveReference {
    pub start: DVec3,
    pub curve: PlanarCurve,
    /// Cruise angular rate (rad/s).
    pub angular_rate: f64,
    pub ramp: f64,
    pub cruise: f64,
    pub yaw: f64,
}

impl CurveReference {
    /// A circle of `radius` flown at `speed` for `laps` turns (plus the ramps).
    pub fn circle(start: DVec3, radius: f64, speed: f64, laps: f64, ramp: f64) -> Self {
        Self::new(start, PlanarCurve::Circle { radius }, speed, laps, ramp)
    }

    /// A figure-eight of half-width `half_width` whose fastest point moves at `peak_speed`.
    pub fn figure_eight(
        start: DVec3,
        half_width: f64,
        peak_speed: f64,
        laps: f64,
        ramp: f64,
    ) -> Self {
        Self::new(
            start,
            PlanarCurve::FigureEight { half_width },
            peak_speed,
            laps,
            ramp,
        )
    }

    fn new(start: DVec3, curve: PlanarCurve, peak_speed: f64, laps: f64, ramp: f64) -> Self {
        let angular_rate = peak_speed / curve.max_tangent();
        Self {
            start,
            curve,
            angular_rate,
            ramp,
            cruise: laps * TAU / angular_rate,
            yaw: 0.0,
        }
    }

    /// Angle and its time derivatives of order 1..=4 at time t.
    fn phase(&self, t: f64) -> [f64; 5] {
        let (w, tr) = (self.angular_rate, self.ramp);
        let t = t.clamp(0.0, self.duration());
        // Quintic smoothstep S(x) = 6x^5 - 15x^4 + 10x^3, its derivatives and its integral.
        let s = |x: f64| {
            [
                x * x * x * (10.0 + x * (-15.0 + 6.0 * x)),
                30.0 * x * x * (1.0 - x) * (1.0 - x),
                60.0 * x * (1.0 - x) * (1.0 - 2.0 * x),
                60.0 - 360.0 * x + 360.0 * x * x,
            ]
        };
        let integral = |x: f64| x.powi(4) * (2.5 + x * (-3.0 + x));
        let ramp_up_angle = w * tr * integral(1.0);
        if t < tr {
            let x = t / tr;
            let [s0, s1, s2, s3] = s(x);
            [
                w * tr * integral(x),
                w * s0,
                w * s1 / tr,
                w * s2 / (tr * tr),
                w * s3 / tr.powi(3),
            ]
        } else if t < tr + self.cruise {
            [ramp_up_angle + w * (t - tr), w, 0.0, 0.0, 0.0]
        } else {
            // Mirror of the ramp up: S(1 - y), whose integral from 0 to y is I(1) - I(1 - y).
            let y = (t - tr - self.cruise) / tr;
            let [s0, s1, s2, s3] = s(1.0 - y);
            [
                ramp_up_angle + w * self.cruise + w * tr * (integral(1.0) - integral(1.0 - y)),
                w * s0,
                -w * s1 / tr,
                w * s2 / (tr * tr),
                -w * s3 / tr.powi(3),
            ]
        }
    }
}

impl Trajectory for CurveReference {
    fn duration(&self) -> f64 {
        2.0 * self.ramp + self.cruise
    }

    fn sample(&self, t: f64) -> TrajectoryPoint {
        let [phi, p1, p2, p3, p4] = self.phase(t);
        let [c0, c1, c2, c3, c4] = self.curve.derivatives(phi);
        // Chain rule (Faa di Bruno) up to the fourth derivative.
        TrajectoryPoint {
            position: self.start + c0,
            velocity: c1 * p1,
            acceleration: c2 * (p1 * p1) + c1 * p2,
            jerk: c3 * p1.powi(3) + c2 * (3.0 * p1 * p2) + c1 * p3,
            snap: c4 * p1.powi(4)
                + c3 * (6.0 * p1 * p1 * p2)
                + c2 * (3.0 * p2 * p2 + 4.0 * p1 * p3)
                + c1 * p4,
            yaw: self.yaw,
            yaw_rate: 0.0,
            yaw_acceleration: 0.0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Central differences of the sampled reference against its analytic derivatives.
    fn check_derivatives(reference: &CurveReference) {
        let h = 1e-5;
        let n = 200;
        for i in 1..n {
            let t = reference.duration() * i as f64 / n as f64;
            let (a, b) = (reference.sample(t - h), reference.sample(t + h));
            let p = reference.sample(t);
            let tol = 1e-4;
            assert!(((b.position - a.position) / (2.0 * h) - p.velocity).length() < tol);
            assert!(((b.velocity - a.velocity) / (2.0 * h) - p.acceleration).length() < tol);
            assert!(((b.acceleration - a.acceleration) / (2.0 * h) - p.jerk).length() < tol);
            assert!(
                ((b.jerk - a.jerk) / (2.0 * h) - p.snap).length() < 1e-3,
                "t = {t}"
            );
        }
    }

    #[test]
    fn circle_derivatives_are_consistent_and_speed_is_reached() {
        let circle = CurveReference::circle(DVec3::new(1.0, 2.0, 1.0), 3.0, 3.0, 1.0, 2.0);
        check_derivatives(&circle);
        // Cruise: speed 3 m/s, centripetal acceleration v^2 / r = 3 m/s^2.
        let mid = circle.sample(circle.duration() / 2.0);
        assert!((mid.velocity.length() - 3.0).abs() < 1e-9);
        assert!((mid.acceleration.length() - 3.0).abs() < 1e-9);
        // Starts at the start point and at rest; ends at rest.
        let start = circle.sample(0.0);
        assert_eq!(start.position, DVec3::new(1.0, 2.0, 1.0));
        assert_eq!(start.velocity, DVec3::ZERO);
        assert!(circle.sample(circle.duration()).velocity.length() < 1e-12);
    }

    #[test]
    fn figure_eight_peak_speed() {
        let eight = CurveReference::figure_eight(DVec3::ZERO, 3.0, 3.0, 1.0, 2.0);
        check_derivatives(&eight);
        let peak = (0..2000)
            .map(|i| {
                eight
                    .sample(eight.duration() * i as f64 / 2000.0)
                    .velocity
                    .length()
            })
            .fold(0.0, f64::max);
        assert!((peak - 3.0).abs() < 1e-3, "{peak}");
    }
}
