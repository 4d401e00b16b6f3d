//! Peak speed and acceleration of polynomial trajectories, found exactly enough to enforce
//! `|v| <= vmax` and `|a| <= amax` "everywhere" rather than at samples: the maxima of
//! `|d|^2` over a segment lie at its ends or where `d . d' = 0`, which is bracketed on a grid
//! and refined by bisection.
//!
//! Speed: this runs for every segment at every rescaling round of every plan (most of a
//! decision's planning time), so the two derivatives it needs are evaluated from coefficients
//! prepared once per segment (`Derivative`) instead of all five orders of all four outputs
//! per point. The arithmetic is that of `PolynomialSegment::derivatives`, operation for
//! operation, so the peaks (and every trajectory planned with them) are bit for bit the same.

use uavex_components::trajectory::{
    POLYNOMIAL_COEFFICIENTS, PiecewisePolynomial, PolynomialSegment,
};

/// Grid intervals per segment when bracketing maxima. A degree-7 position gives a degree-11
/// `v . a`: at most 11 roots, so 48 intervals separate all but nearly coincident ones (whose
/// maximum the grid then samples closely anyway).
const GRID: usize = 48;
const BISECTIONS: usize = 50;
const N: usize = POLYNOMIAL_COEFFICIENTS;

/// One derivative order of the position (x, y, z) of a segment, ready for Horner's rule: the
/// tau-coefficients `k! / (k - order)! c_k` (by power, then axis, the fourth lane unused so
/// that the three axes step together) and the factor `duration^-order` into real time.
#[derive(Debug, Clone, Copy)]
struct Derivative {
    coefficients: [[f64; 4]; N],
    scale: f64,
}

impl Derivative {
    fn new(segment: &PolynomialSegment, order: usize) -> Self {
        let mut coefficients = [[0.0; 4]; N];
        for (k, lanes) in coefficients.iter_mut().enumerate().skip(order) {
            for (lane, output) in lanes.iter_mut().zip(&segment.coefficients[..3]) {
                *lane = falling(k, order) * output[k];
            }
        }
        // As `derivatives` forms it: 1, then times 1 / duration once per order.
        let inv_duration = 1.0 / segment.duration;
        let mut scale = 1.0;
        for _ in 0..order {
            scale *= inv_duration;
        }
        Self {
            coefficients,
            scale,
        }
    }

    /// This derivative and `next` (of order `ORDER + 1`) at normalised time `tau`, in
    /// real-time units: two Horner chains run side by side (independent, so they overlap in
    /// the pipeline), each with the operations of `PolynomialSegment::derivatives`.
    #[inline(always)]
    fn pair_at<const ORDER: usize>(&self, next: &Self, tau: f64) -> ([f64; 3], [f64; 3]) {
        let (mut d, mut n) = ([0.0; 4], [0.0; 4]);
        for k in (ORDER..N).rev() {
            let c = &self.coefficients[k];
            for lane in 0..4 {
                d[lane] = d[lane] * tau + c[lane];
            }
            if k > ORDER {
                let c = &next.coefficients[k];
                for lane in 0..4 {
                    n[lane] = n[lane] * tau + c[lane];
                }
            }
        }
        let (s, t) = (self.scale, next.scale);
        (
            [d[0] * s, d[1] * s, d[2] * s],
            [n[0] * t, n[1] * t, n[2] * t],
        )
    }
}

/// k! / (k - n)!, a small integer (exact in f64, whatever the order of the product).
fn falling(k: usize, n: usize) -> f64 {
    ((k + 1 - n)..=k).map(|i| i as f64).product()
}

fn dot(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Largest norm over the segment of the position's derivative of `order` (1: speed,
/// 2: acceleration, 3: jerk; other orders are brought into that range).
pub fn segment_peak(segment: &PolynomialSegment, order: usize) -> f64 {
    match order.clamp(1, 3) {
        1 => peak::<1>(segment),
        2 => peak::<2>(segment),
        _ => peak::<3>(segment),
    }
}

/// [`segment_peak`] for one order.
fn peak<const ORDER: usize>(segment: &PolynomialSegment) -> f64 {
    let (derivative, next) = (
        Derivative::new(segment, ORDER),
        Derivative::new(segment, ORDER + 1),
    );
    let slope = |tau: f64| {
        let (d, next) = derivative.pair_at::<ORDER>(&next, tau);
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

    #[test]
    fn prepared_derivatives_match_the_segment_bit_for_bit() {
        // Odd durations and coefficients of mixed sizes and signs: any change in the order of
        // operations would show in the last bits.
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        let mut next = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        for duration in [0.05, 0.37, 1.0, 2.9, 13.7] {
            let mut coefficients = [[0.0; N]; 4];
            for output in &mut coefficients {
                for c in output.iter_mut() {
                    *c = next() * 10f64.powf(3.0 * next());
                }
            }
            let segment = PolynomialSegment {
                duration,
                coefficients,
            };
            let pairs = [
                (Derivative::new(&segment, 1), Derivative::new(&segment, 2)),
                (Derivative::new(&segment, 2), Derivative::new(&segment, 3)),
                (Derivative::new(&segment, 3), Derivative::new(&segment, 4)),
            ];
            for i in 0..=97 {
                let tau = i as f64 / 97.0;
                let got = [
                    pairs[0].0.pair_at::<1>(&pairs[0].1, tau),
                    pairs[1].0.pair_at::<2>(&pairs[1].1, tau),
                    pairs[2].0.pair_at::<3>(&pairs[2].1, tau),
                ];
                for (order, (d, next)) in (1..=3).zip(got) {
                    for axis in 0..3 {
                        let want = segment.derivatives(axis, tau);
                        assert_eq!(d[axis].to_bits(), want[order].to_bits(), "{order} {tau}");
                        assert_eq!(next[axis].to_bits(), want[order + 1].to_bits(), "{tau}");
                    }
                }
            }
        }
    }
}
