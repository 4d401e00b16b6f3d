//! Peak heading rate of polynomial trajectories, so that the time allocation keeps
//! `|yaw rate| <= max_yaw_rate` everywhere, as [`super::limits`] keeps the speed and the
//! acceleration.
//!
//! Why the heading needs a limit of its own: the heading's minimum-snap polynomial passes
//! through the waypoints' headings in the durations the position needs. Where a path turns back
//! on itself the headings of neighbouring waypoints differ by up to pi over a short segment, and
//! the polynomial overshoots; a local replan then starts from that fast-turning reference and
//! overshoots further. In one EAAE Simple mission the reference turned at 9 rad/s; the yaw loop
//! (kp_att_z = 3) cannot follow that, the UAV spun up to the same rate, lost its attitude and
//! hit the ground (docs/performance.md, forty-eighth session).
//!
//! The maxima of `|psi'|` over a segment lie at its ends or where `psi'' = 0`: bracketed on a
//! grid where `psi' psi''` turns from positive to negative, and refined by bisection.

use uavex_components::trajectory::{POLYNOMIAL_COEFFICIENTS, PiecewisePolynomial};

/// The heading's output in a segment's coefficients (x, y, z, yaw).
const YAW: usize = 3;
/// Grid intervals per segment: `psi'` of a degree-7 heading has degree 6, so at most 5 inner
/// extrema, which 48 intervals separate.
const GRID: usize = 48;
const BISECTIONS: usize = 50;
const N: usize = POLYNOMIAL_COEFFICIENTS;

/// The largest `|yaw rate| / max_yaw_rate` over the trajectory when it is above `floor`;
/// otherwise a number <= `floor` (segments whose bound cannot beat `floor` are skipped).
pub fn yaw_rate_ratio(trajectory: &PiecewisePolynomial, max_yaw_rate: f64, floor: f64) -> f64 {
    let mut worst: f64 = 0.0;
    for segment in trajectory.segments() {
        let coefficients = &segment.coefficients[YAW];
        let to_ratio = 1.0 / (segment.duration * max_yaw_rate);
        // On tau in [0, 1], |psi'(tau)| <= sum_k k |c_k|.
        let bound = (1..N)
            .map(|k| k as f64 * coefficients[k].abs())
            .sum::<f64>()
            * to_ratio;
        if bound <= worst.max(floor) {
            continue;
        }
        worst = worst.max(peak_rate(coefficients) * to_ratio);
    }
    worst
}

/// The largest `|psi'(tau)|` over tau in [0, 1] (normalised-time units) of the heading with
/// power coefficients `c`.
fn peak_rate(c: &[f64; N]) -> f64 {
    // psi'(tau) and psi''(tau) by Horner's rule.
    let rate = |tau: f64| {
        let (mut first, mut second) = (0.0, 0.0);
        for k in (1..N).rev() {
            first = first * tau + k as f64 * c[k];
            if k >= 2 {
                second = second * tau + (k * (k - 1)) as f64 * c[k];
            }
        }
        (first, first * second)
    };
    let (mut previous_tau, (first, mut previous_slope)) = (0.0, rate(0.0));
    let mut best = first.abs();
    for i in 1..=GRID {
        let tau = i as f64 / GRID as f64;
        let (first, slope) = rate(tau);
        best = best.max(first.abs());
        // |psi'| rising then falling: a maximum inside.
        if previous_slope > 0.0 && slope < 0.0 {
            let (mut lo, mut hi) = (previous_tau, tau);
            for _ in 0..BISECTIONS {
                let mid = 0.5 * (lo + hi);
                if rate(mid).1 > 0.0 {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            best = best.max(rate(0.5 * (lo + hi)).0.abs());
        }
        (previous_tau, previous_slope) = (tau, slope);
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;
    use uavex_components::trajectory::PolynomialSegment;

    fn heading(duration: f64, yaw: [f64; N]) -> PiecewisePolynomial {
        let mut coefficients = [[0.0; N]; 4];
        coefficients[YAW] = yaw;
        PiecewisePolynomial::new(vec![PolynomialSegment {
            duration,
            coefficients,
        }])
        .unwrap()
    }

    /// The rest-to-rest septic turn psi = pi (35 tau^4 - 84 tau^5 + 70 tau^6 - 20 tau^7) over
    /// 2 s peaks at tau = 1/2, where psi' = 35/16 pi per unit tau: 35 pi / 32 = 3.4361 rad/s.
    #[test]
    fn peak_of_a_rest_to_rest_turn() {
        let pi = std::f64::consts::PI;
        let turn = heading(
            2.0,
            [0.0, 0.0, 0.0, 0.0, 35.0, -84.0, 70.0, -20.0].map(|c| c * pi),
        );
        let peak = 35.0 * pi / 32.0;
        assert!((yaw_rate_ratio(&turn, 1.0, 0.0) - peak).abs() < 1e-12);
        assert!((yaw_rate_ratio(&turn, 2.0, 0.0) - peak / 2.0).abs() < 1e-12);
        // Below the floor the answer is only bounded by it.
        assert!(yaw_rate_ratio(&turn, 1.0, 10.0) <= 10.0);
    }

    /// The maximum at an end and one between grid points. `psi' = c - 12 (tau - 0.51)^2` on a
    /// 1 s segment: with c = 1 the largest |psi'| is at tau = 0 (1 - 12 * 0.2601 = -2.1212);
    /// with c = 3 it is the inner maximum at tau = 0.51, off the grid of 48, found by bisection.
    #[test]
    fn inner_and_end_maxima() {
        // psi' = 1 - 12 (tau^2 - 1.02 tau + 0.2601) = -2.1212 + 12.24 tau - 12 tau^2.
        let inner = heading(1.0, [0.0, -2.1212, 6.12, -4.0, 0.0, 0.0, 0.0, 0.0]);
        assert!((yaw_rate_ratio(&inner, 1.0, 0.0) - 2.1212).abs() < 1e-12);
        // Shifted so that the inner maximum dominates: psi' = 3 - 12 (tau - 0.51)^2.
        let shifted = heading(1.0, [0.0, -0.1212, 6.12, -4.0, 0.0, 0.0, 0.0, 0.0]);
        assert!((yaw_rate_ratio(&shifted, 1.0, 0.0) - 3.0).abs() < 1e-12);
    }
}
