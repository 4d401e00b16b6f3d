//! Peak speed and acceleration of polynomial trajectories, found exactly enough to enforce
//! `|v| <= vmax` and `|a| <= amax` "everywhere" rather than at samples: the maxima of
//! `|d|^2` over a segment lie at its ends or where `d . d' = 0`, which is bracketed on a grid
//! and refined by bisection.

use uavex_components::trajectory::{PiecewisePolynomial, PolynomialSegment};

/// Grid intervals per segment when bracketing maxima. A degree-7 position gives a degree-11
/// `v . a`: at most 11 roots, so 48 intervals separate all but nearly coincident ones (whose
/// maximum the grid then samples closely anyway).
const GRID: usize = 48;
const BISECTIONS: usize = 50;

/// Derivative of order `order` of the position (x, y, z), and the next one, at `tau`.
fn derivative_pair(segment: &PolynomialSegment, order: usize, tau: f64) -> ([f64; 3], [f64; 3]) {
    let mut d = [0.0; 3];
    let mut next = [0.0; 3];
    for axis in 0..3 {
        let all = segment.derivatives(axis, tau);
        d[axis] = all[order];
        next[axis] = all[order + 1];
    }
    (d, next)
}

fn dot(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Largest norm over the segment of the position's derivative of `order` (1: speed,
/// 2: acceleration, 3: jerk; other orders are brought into that range).
pub fn segment_peak(segment: &PolynomialSegment, order: usize) -> f64 {
    let order = order.clamp(1, 3);
    let slope = |tau: f64| {
        let (d, next) = derivative_pair(segment, order, tau);
        (dot(&d, &d), dot(&d, &next))
    };
    let mut best: f64 = 0.0;
    let mut previous = slope(0.0);
    best = best.max(previous.0);
    for i in 1..=GRID {
        let tau = i as f64 / GRID as f64;
        let current = slope(tau);
        best = best.max(current.0);
        // |d|^2 rising then falling: a maximum inside.
        if previous.1 > 0.0 && current.1 < 0.0 {
            let (mut lo, mut hi) = ((i - 1) as f64 / GRID as f64, tau);
            for _ in 0..BISECTIONS {
                let mid = 0.5 * (lo + hi);
                if slope(mid).1 > 0.0 {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            best = best.max(slope(0.5 * (lo + hi)).0);
        }
        previous = current;
    }
    best.sqrt()
}

/// Peak speed and peak acceleration of each segment.
pub fn segment_peaks(trajectory: &PiecewisePolynomial) -> Vec<(f64, f64)> {
    trajectory
        .segments()
        .iter()
        .map(|s| (segment_peak(s, 1), segment_peak(s, 2)))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use uavex_components::trajectory::POLYNOMIAL_COEFFICIENTS;

    #[test]
    fn peak_of_the_rest_to_rest_septic() {
        // x(t) = 35t^4 - 84t^5 + 70t^6 - 20t^7 on 1 s: peak speed x'(1/2) = 2.1875 m/s;
        // peak acceleration at t = (1 -+ 1/sqrt(5)) / 2 where x''' = 0:
        // x'' = 420 t^2 (1 - t)^2 (1 - 2t) -> 7.5132 m/s^2.
        let mut coefficients = [[0.0; POLYNOMIAL_COEFFICIENTS]; 4];
        coefficients[0] = [0.0, 0.0, 0.0, 0.0, 35.0, -84.0, 70.0, -20.0];
        let segment = PolynomialSegment {
            duration: 1.0,
            coefficients,
        };
        assert!((segment_peak(&segment, 1) - 2.1875).abs() < 1e-12);
        let t = (1.0 - 1.0 / 5f64.sqrt()) / 2.0;
        let expected = 420.0 * t * t * (1.0 - t) * (1.0 - t) * (1.0 - 2.0 * t);
        assert!((expected - 7.5132).abs() < 1e-4);
        assert!((segment_peak(&segment, 2) - expected).abs() < 1e-9);
    }
}
