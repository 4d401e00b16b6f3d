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
const fn falling(k: usize, n: usize) -> f64 {
    let (mut p, mut i) = (1.0, k + 1 - n);
    while i <= k {
        p *= i as f64;
        i += 1;
    }
    p
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

/// [`segment_peak`] for one order: the grid's values and every bracketed maximum refined.
fn peak<const ORDER: usize>(segment: &PolynomialSegment) -> f64 {
    let prepared = Prepared::new(segment, ORDER);
    let (mut best, brackets) = prepared.scan::<ORDER>();
    for bracket in &brackets {
        best = best.max(prepared.refine::<ORDER>(bracket));
    }
    best.sqrt()
}

/// One derivative order of a segment ready for the peak search: its Horner coefficients, those
/// of the next order, and what bounds it between two grid points.
struct Prepared {
    derivative: Derivative,
    next: Derivative,
    duration: f64,
    /// Per axis, a bound on the second tau-derivative of this derivative over tau in [0, 1]
    /// (sum of |coefficients|, in real-time units).
    curvature: [f64; 3],
    /// Per axis, a bound on the rounding of one evaluation (a generous multiple of the sum of
    /// the |terms|).
    rounding: [f64; 3],
}

/// A grid interval where `|d|^2` rises then falls, and a bound on `|d|^2` inside it.
struct Bracket {
    lo: f64,
    hi: f64,
    bound: f64,
}

impl Prepared {
    fn new(segment: &PolynomialSegment, order: usize) -> Self {
        let derivative = Derivative::new(segment, order);
        let abs_sum = |order: usize, axis: usize| {
            segment.coefficients[axis]
                .iter()
                .enumerate()
                .skip(order)
                .map(|(k, c)| falling(k, order) * c.abs())
                .sum::<f64>()
                * derivative.scale
        };
        Self {
            next: Derivative::new(segment, order + 1),
            duration: segment.duration,
            curvature: std::array::from_fn(|axis| abs_sum(order + 2, axis)),
            rounding: std::array::from_fn(|axis| 1e-9 * abs_sum(order, axis)),
            derivative,
        }
    }

    /// The derivative and the next order at `tau`.
    #[inline(always)]
    fn at<const ORDER: usize>(&self, tau: f64) -> ([f64; 3], [f64; 3]) {
        self.derivative.pair_at::<ORDER>(&self.next, tau)
    }

    /// `|d|^2` and `d . d'` at `tau`.
    #[inline(always)]
    fn slope<const ORDER: usize>(&self, tau: f64) -> (f64, f64) {
        let (d, next) = self.at::<ORDER>(tau);
        (dot(&d, &d), dot(&d, &next))
    }

    /// The largest `|d|^2` on the grid (ends included) and the brackets of inner maxima.
    fn scan<const ORDER: usize>(&self) -> (f64, Vec<Bracket>) {
        let mut brackets = Vec::new();
        let mut best: f64 = 0.0;
        let mut previous_tau = 0.0;
        let mut previous_values = self.at::<ORDER>(previous_tau);
        let mut previous = (
            dot(&previous_values.0, &previous_values.0),
            dot(&previous_values.0, &previous_values.1),
        );
        best = best.max(previous.0);
        for i in 1..=GRID {
            let tau = i as f64 / GRID as f64;
            let values = self.at::<ORDER>(tau);
            let current = (dot(&values.0, &values.0), dot(&values.0, &values.1));
            best = best.max(current.0);
            // |d|^2 rising then falling: a maximum inside.
            if previous.1 > 0.0 && current.1 < 0.0 {
                brackets.push(Bracket {
                    lo: previous_tau,
                    hi: tau,
                    bound: self.bound(previous_values, tau - previous_tau),
                });
            }
            (previous_tau, previous_values, previous) = (tau, values, current);
        }
        (best, brackets)
    }

    /// A bound on `|d|^2` over `[tau, tau + width]`, from the values at `tau` (`d`, and `next`
    /// = d' in real time): per axis |d| + w T |next| + w^2 / 2 max|d''|, plus rounding.
    fn bound(&self, (d, next): ([f64; 3], [f64; 3]), width: f64) -> f64 {
        let w = width * (1.0 + 1e-9);
        let mut sum = 0.0;
        for axis in 0..3 {
            let reach = d[axis].abs()
                + w * self.duration * next[axis].abs()
                + 0.5 * w * w * self.curvature[axis]
                + self.rounding[axis];
            sum += reach * reach;
        }
        sum * (1.0 + 1e-9)
    }

    /// The bisected maximum of a bracket, as [`segment_peak`] has always found it.
    fn refine<const ORDER: usize>(&self, bracket: &Bracket) -> f64 {
        let (mut lo, mut hi) = (bracket.lo, bracket.hi);
        for _ in 0..BISECTIONS {
            let mid = 0.5 * (lo + hi);
            if self.slope::<ORDER>(mid).1 > 0.0 {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        self.slope::<ORDER>(0.5 * (lo + hi)).0
    }
}

/// The largest excess ratio `max(v / vmax, sqrt(a / amax))` over the trajectory, the same
/// number, bit for bit, as the largest over [`segment_peaks`], when it is above `floor`;
/// otherwise a number <= `floor`.
///
/// Why not the peaks of every segment: only the largest value decides (the ratio is monotonic
/// in `|d|^2`), and most segments of a plan are far from binding. Each (segment, order) gets a
/// cheap bound on its whole range first (`segment_bound`); they are grid-scanned largest
/// bound first, until the bound cannot beat the ratio found so far (or `floor`). The bisection
/// of each grid bracket costs as much as the grid, so a bracket too is refined only if the
/// bound on its inside could beat the ratio found so far, largest bound first. A part skipped
/// holds no value above the result, so the maximum is the same as over every part.
pub fn worst_ratio(
    trajectory: &PiecewisePolynomial,
    max_velocity: f64,
    max_acceleration: f64,
    floor: f64,
) -> f64 {
    let ratio = |order: usize, d2: f64| {
        if order == 1 {
            d2.sqrt() / max_velocity
        } else {
            (d2.sqrt() / max_acceleration).sqrt()
        }
    };
    let segments = trajectory.segments();
    let mut parts: Vec<(f64, usize, usize)> = segments
        .iter()
        .enumerate()
        .flat_map(|(index, segment)| {
            [1, 2].map(|order| (ratio(order, segment_bound(segment, order)), index, order))
        })
        .collect();
    parts.sort_by(|a, b| b.0.total_cmp(&a.0));
    let mut worst: f64 = 0.0;
    let mut prepared = Vec::with_capacity(parts.len());
    let mut pending = Vec::with_capacity(parts.len());
    for &(bound, index, order) in &parts {
        if bound <= worst.max(floor) {
            break;
        }
        let part = Prepared::new(&segments[index], order);
        let (best, brackets) = if order == 1 {
            part.scan::<1>()
        } else {
            part.scan::<2>()
        };
        worst = worst.max(ratio(order, best));
        pending.extend(
            brackets
                .into_iter()
                .map(|b| (ratio(order, b.bound), prepared.len(), order, b)),
        );
        prepared.push(part);
    }
    pending.sort_by(|a, b| b.0.total_cmp(&a.0));
    for (bound, part, order, bracket) in &pending {
        if *bound <= worst.max(floor) {
            break;
        }
        let d2 = if *order == 1 {
            prepared[*part].refine::<1>(bracket)
        } else {
            prepared[*part].refine::<2>(bracket)
        };
        worst = worst.max(ratio(*order, d2));
    }
    worst
}

/// A bound on `|d|^2` over a whole segment, `d` the position's derivative of `order` (1 or 2),
/// above every value the grid scan and the bisection of [`Prepared`] compute.
///
/// In the Bernstein basis of degree `m` on `tau` in [0, 1], `d(tau)` is a convex combination
/// of its control points `b_i = sum_{j <= i} C(i, j) / C(m, j) a_j` (`a_j` its power
/// coefficients), so `|d| <= max_i |b_i|` (the norm is convex). Each evaluation of `d` is off
/// by at most the `rounding` of [`Prepared`] per axis (as is each computed `b_i`, far more
/// closely), hence twice that is added to the reach.
fn segment_bound(segment: &PolynomialSegment, order: usize) -> f64 {
    let to_bernstein = &TO_BERNSTEIN[order - 1];
    let scale = segment.duration.powi(-(order as i32));
    let mut reach: f64 = 0.0;
    for row in to_bernstein.iter().take(N - order) {
        let mut point = [0.0; 3];
        for (axis, p) in point.iter_mut().enumerate() {
            let c = &segment.coefficients[axis][order..];
            *p = row.iter().zip(c).map(|(m, c)| m * c).sum::<f64>() * scale;
        }
        reach = reach.max(dot(&point, &point).sqrt());
    }
    let abs_sum: [f64; 3] = std::array::from_fn(|axis| {
        (order..N)
            .map(|k| falling(k, order) * segment.coefficients[axis][k].abs())
            .sum::<f64>()
            * scale
    });
    let rounding = 2e-9 * dot(&abs_sum, &abs_sum).sqrt();
    (reach + rounding).powi(2) * (1.0 + 1e-9)
}

/// For derivative orders 1 and 2 (degree `m = N - 1 - order`), the map from the position's
/// coefficients `c_{order..}` to the derivative's Bernstein control points (tau units):
/// `b_i = sum_j C(i, j) / C(m, j) (j + order)! / j! c_{j + order}`.
const TO_BERNSTEIN: [[[f64; N]; N]; 2] = [to_bernstein(1), to_bernstein(2)];

const fn to_bernstein(order: usize) -> [[f64; N]; N] {
    const fn binomial(n: usize, k: usize) -> f64 {
        falling(n, k) / falling(k, k)
    }
    let degree = N - 1 - order;
    let mut matrix = [[0.0; N]; N];
    let mut i = 0;
    while i <= degree {
        let mut j = 0;
        while j <= i {
            matrix[i][j] = binomial(i, j) / binomial(degree, j) * falling(j + order, order);
            j += 1;
        }
        i += 1;
    }
    matrix
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

    /// A xorshift stream of numbers in [0, 1): reproducible inputs without a generator crate.
    fn unit_stream(mut seed: u64) -> impl FnMut() -> f64 {
        move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    /// A segment of `duration` whose coefficients are drawn from `next` (in [-1, 1)) with
    /// magnitudes spread over `decades` decades either side of 1.
    fn random_segment(
        next: &mut impl FnMut() -> f64,
        duration: f64,
        decades: f64,
    ) -> PolynomialSegment {
        let mut coefficients = [[0.0; N]; 4];
        for output in &mut coefficients {
            for c in output.iter_mut() {
                *c = next() * 10f64.powf(decades * next());
            }
        }
        PolynomialSegment {
            duration,
            coefficients,
        }
    }

    #[test]
    fn prepared_derivatives_match_the_segment_bit_for_bit() {
        // Odd durations and coefficients of mixed sizes and signs: any change in the order of
        // operations would show in the last bits.
        let mut unit = unit_stream(0x2545_f491_4f6c_dd1d);
        let mut next = || unit() * 2.0 - 1.0;
        for duration in [0.05, 0.37, 1.0, 2.9, 13.7] {
            let segment = random_segment(&mut next, duration, 3.0);
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

    #[test]
    fn segment_bound_holds_every_peak_and_is_tight_on_a_straight_line() {
        // A constant velocity (3, -4, 0) m/s over 2 s: |v| = 5 everywhere, a = 0.
        let mut coefficients = [[0.0; N]; 4];
        coefficients[0][1] = 6.0;
        coefficients[1][1] = -8.0;
        let line = PolynomialSegment {
            duration: 2.0,
            coefficients,
        };
        let bound = segment_bound(&line, 1);
        assert!((25.0..25.0 + 1e-6).contains(&bound), "{bound}");
        assert!(segment_bound(&line, 2) < 1e-12);
        // Random segments: the bound is above the peak the search finds, and within the
        // looseness expected of a control polygon (a few times the peak, not orders more).
        let mut unit = unit_stream(0x9e37_79b9_7f4a_7c15);
        let mut next = || unit() * 2.0 - 1.0;
        let mut ratios = Vec::new();
        for duration in [0.05, 0.37, 1.0, 2.9, 13.7] {
            for _ in 0..20 {
                let segment = random_segment(&mut next, duration, 2.0);
                for order in [1, 2] {
                    let peak = segment_peak(&segment, order);
                    let bound = segment_bound(&segment, order);
                    assert!(bound >= peak * peak, "{order}: {bound} < {}", peak * peak);
                    ratios.push(bound.sqrt() / peak);
                }
            }
        }
        ratios.sort_by(f64::total_cmp);
        assert!(
            ratios[ratios.len() / 2] < 3.0,
            "median looseness {}",
            ratios[ratios.len() / 2]
        );
    }

    #[test]
    fn worst_ratio_is_the_largest_segment_ratio_bit_for_bit() {
        // Minimum-snap tours through random points (so that segments have several brackets
        // of very different heights), at random limits: the pruned search must return the
        // plain maximum over every segment's peaks, and with a floor, a value on the same
        // side of it.
        use crate::trajectory::{Waypoint, min_snap_with_durations};
        use glam::DVec3;
        use uavex_components::trajectory::TrajectoryPoint;
        let mut next = unit_stream(0x853c_49e6_748f_ea9b);
        for _ in 0..40 {
            let count = 1 + (next() * 12.0) as usize;
            let waypoints: Vec<Waypoint> = (0..count)
                .map(|_| Waypoint::new(DVec3::new(next() * 8.0, next() * 8.0, next() * 2.0)))
                .collect();
            let durations: Vec<f64> = (0..count).map(|_| 0.2 + 3.0 * next()).collect();
            let start = TrajectoryPoint::at_rest(DVec3::ZERO, 0.0);
            let trajectory = min_snap_with_durations(&start, &waypoints, &durations).unwrap();
            let (vmax, amax) = (0.5 + 4.0 * next(), 0.5 + 6.0 * next());
            let plain = segment_peaks(&trajectory)
                .into_iter()
                .map(|(v, a)| (v / vmax).max((a / amax).sqrt()))
                .fold(0.0, f64::max);
            let pruned = worst_ratio(&trajectory, vmax, amax, 0.0);
            assert_eq!(pruned.to_bits(), plain.to_bits(), "{pruned} {plain}");
            for floor in [0.5 * plain, plain, 2.0 * plain] {
                let above = worst_ratio(&trajectory, vmax, amax, floor);
                if plain > floor {
                    assert_eq!(above.to_bits(), plain.to_bits());
                } else {
                    assert!(above <= floor, "{above} {floor}");
                }
            }
        }
    }
}
