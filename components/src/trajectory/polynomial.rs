//! Piecewise-polynomial trajectories (the form minimum-snap planning produces).
//!
//! Each segment stores its polynomials in normalised time `tau = (t - t_start) / duration`,
//! in [0, 1]: coefficients then stay of the size of the positions whatever the segment's
//! duration, which keeps both the solver that writes them and the evaluation well conditioned.
//! The derivative of order n in real time is the tau-derivative divided by `duration^n`.

use super::{Trajectory, TrajectoryPoint};
use glam::DVec3;
use serde::{Deserialize, Serialize};

/// Coefficients per polynomial: degree 7, the degree of minimum-snap segments
/// (Richter, Bry & Roy 2013: 2 x 4 boundary conditions per segment).
pub const POLYNOMIAL_COEFFICIENTS: usize = 8;

/// Indices of the flat outputs in [`PolynomialSegment::coefficients`].
const X: usize = 0;
const Y: usize = 1;
const Z: usize = 2;
const YAW: usize = 3;

/// One segment: x, y, z and yaw as polynomials in normalised time.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PolynomialSegment {
    /// Length of the segment (s), > 0.
    pub duration: f64,
    /// `coefficients[output][k]` multiplies `tau^k`; outputs are x, y, z (m) and yaw (rad).
    pub coefficients: [[f64; POLYNOMIAL_COEFFICIENTS]; 4],
}

impl PolynomialSegment {
    /// Derivatives of order 0..=4 of one output with respect to real time, at normalised time
    /// `tau`.
    pub fn derivatives(&self, output: usize, tau: f64) -> [f64; 5] {
        self.first_derivatives(output, tau)
    }

    /// Derivatives of order `0..N` (N <= 5) of one output with respect to real time, at
    /// normalised time `tau`: each order the same operations whatever `N`, so the orders a
    /// caller does not read (the position alone, the yaw's jerk and snap) cost nothing and the
    /// others are those of [`Self::derivatives`] bit for bit.
    #[inline]
    pub fn first_derivatives<const N: usize>(&self, output: usize, tau: f64) -> [f64; N] {
        let c = &self.coefficients[output];
        let inv_duration = 1.0 / self.duration;
        let mut result = [0.0; N];
        let mut scale = 1.0;
        for (order, value) in result.iter_mut().enumerate() {
            // Horner on the order-th derivative: sum_k k!/(k-order)! c_k tau^(k-order).
            let factors = &FALLING_FACTORIALS[order];
            let mut acc = 0.0;
            for k in (order..POLYNOMIAL_COEFFICIENTS).rev() {
                acc = acc * tau + factors[k] * c[k];
            }
            *value = acc * scale;
            scale *= inv_duration;
        }
        result
    }

    /// The reference at normalised time `tau` of this segment.
    pub fn point(&self, tau: f64) -> TrajectoryPoint {
        let x = self.derivatives(X, tau);
        let y = self.derivatives(Y, tau);
        let z = self.derivatives(Z, tau);
        // A reference carries the yaw up to its acceleration.
        let yaw: [f64; 3] = self.first_derivatives(YAW, tau);
        reference(|n| DVec3::new(x[n], y[n], z[n]), yaw)
    }

    /// The position at normalised time `tau`: [`Self::point`]'s, bit for bit.
    #[inline]
    pub fn position(&self, tau: f64) -> DVec3 {
        let [x] = self.first_derivatives(X, tau);
        let [y] = self.first_derivatives(Y, tau);
        let [z] = self.first_derivatives(Z, tau);
        DVec3::new(x, y, z)
    }
}

/// A reference from the position's derivatives of orders 0 to 4 (`derivative(n)`) and the
/// yaw's of orders 0 to 2.
#[inline(always)]
fn reference(derivative: impl Fn(usize) -> DVec3, yaw: [f64; 3]) -> TrajectoryPoint {
    TrajectoryPoint {
        position: derivative(0),
        velocity: derivative(1),
        acceleration: derivative(2),
        jerk: derivative(3),
        snap: derivative(4),
        yaw: yaw[0],
        yaw_rate: yaw[1],
        yaw_acceleration: yaw[2],
    }
}

/// `FALLING_FACTORIALS[n][k] = k! / (k - n)!` (0 for k < n): the factor of `c_k` in the n-th
/// derivative of `sum c_k tau^k`.
const FALLING_FACTORIALS: [[f64; POLYNOMIAL_COEFFICIENTS]; 5] = {
    let mut table = [[0.0; POLYNOMIAL_COEFFICIENTS]; 5];
    let mut n = 0;
    while n < 5 {
        let mut k = n;
        while k < POLYNOMIAL_COEFFICIENTS {
            let mut product = 1.0;
            let mut i = k + 1 - n;
            while i <= k {
                product *= i as f64;
                i += 1;
            }
            table[n][k] = product;
            k += 1;
        }
        n += 1;
    }
    table
};

/// Segments flown one after the other.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PiecewisePolynomial {
    segments: Vec<PolynomialSegment>,
    /// Start time of each segment, then the total duration (len = segments + 1).
    knots: Vec<f64>,
}

impl PiecewisePolynomial {
    /// Joins segments; refuses an empty list, non-positive or non-finite durations and
    /// non-finite coefficients.
    pub fn new(segments: Vec<PolynomialSegment>) -> Result<Self, String> {
        if segments.is_empty() {
            return Err("a piecewise polynomial needs at least one segment".into());
        }
        let mut knots = Vec::with_capacity(segments.len() + 1);
        let mut t = 0.0;
        knots.push(t);
        for (i, segment) in segments.iter().enumerate() {
            if !(segment.duration.is_finite() && segment.duration > 0.0) {
                return Err(format!(
                    "segment {i} has duration {}, expected a finite value > 0",
                    segment.duration
                ));
            }
            if segment
                .coefficients
                .iter()
                .flatten()
                .any(|c| !c.is_finite())
            {
                return Err(format!("segment {i} has non-finite coefficients"));
            }
            t += segment.duration;
            knots.push(t);
        }
        Ok(Self { segments, knots })
    }

    pub fn segments(&self) -> &[PolynomialSegment] {
        &self.segments
    }

    /// Times at which the segments meet, from 0 to the duration (the waypoint times).
    pub fn knots(&self) -> &[f64] {
        &self.knots
    }

    /// The segment that holds time `t` (clamped to the trajectory) and the normalised time in it.
    pub fn locate(&self, t: f64) -> (usize, f64) {
        let last = self.segments.len() - 1;
        let index = self.knots[1..=last]
            .partition_point(|&knot| knot <= t)
            .min(last);
        let tau = (t - self.knots[index]) / self.segments[index].duration;
        (index, tau.clamp(0.0, 1.0))
    }
}

impl PiecewisePolynomial {
    /// Where time `t` falls ([`Self::locate`]); `None` at or past the end, where the trajectory
    /// holds its end point at rest.
    fn within(&self, t: f64) -> Option<(usize, f64)> {
        if t >= self.duration() {
            None
        } else {
            Some(self.locate(t))
        }
    }
}

/// The reference held after a trajectory's end: its end point, at rest.
fn held_end(end: TrajectoryPoint) -> TrajectoryPoint {
    TrajectoryPoint::at_rest(end.position, end.yaw)
}

impl Trajectory for PiecewisePolynomial {
    fn duration(&self) -> f64 {
        self.knots[self.segments.len()]
    }

    fn prepared(&self) -> Option<Box<dyn Trajectory + '_>> {
        Some(Box::new(PreparedPolynomial::new(self)))
    }

    fn sample(&self, t: f64) -> TrajectoryPoint {
        match self.within(t) {
            Some((index, tau)) => self.segments[index].point(tau),
            None => held_end(self.segments[self.segments.len() - 1].point(1.0)),
        }
    }

    /// The position only: a fifth of the work of a sample (collision checks every 5 cm).
    fn position(&self, t: f64) -> DVec3 {
        let (index, tau) = self.within(t).unwrap_or((self.segments.len() - 1, 1.0));
        self.segments[index].position(tau)
    }

    /// [`Self::position`], the segment found from the last one onward (`segment`) instead of
    /// by a binary search: the same segment, since the knots increase.
    fn position_onward(&self, t: f64, segment: &mut usize) -> DVec3 {
        let last = self.segments.len() - 1;
        let mut index = (*segment).min(last);
        if t >= self.duration() || t.is_nan() || self.knots[index] > t {
            // Past the end, before the hint (or not a number): as `position` does.
            return self.position(t);
        }
        while index < last && self.knots[index + 1] <= t {
            index += 1;
        }
        *segment = index;
        let tau = (t - self.knots[index]) / self.segments[index].duration;
        self.segments[index].position(tau.clamp(0.0, 1.0))
    }
}

/// A [`PiecewisePolynomial`] made ready for many samples (a rollout takes 100 a second, a
/// collision check one every 5 cm): each segment's Horner coefficients `k!/(k-n)! c_k` and
/// real-time factors `duration^-n` computed once, instead of at every sample, and laid out by
/// power then output (x, y, z, yaw side by side), so that the four outputs step together.
/// Every sample is [`PiecewisePolynomial`]'s to the bit: the products and the Horner steps are
/// the same operations in the same order (`PolynomialSegment::first_derivatives`).
#[derive(Debug)]
pub struct PreparedPolynomial<'a> {
    polynomial: &'a PiecewisePolynomial,
    segments: Vec<PreparedSegment>,
}

/// One segment's Horner coefficients, `[order][power][output]`, and real-time factors.
#[derive(Debug, Clone, Copy)]
struct PreparedSegment {
    coefficients: [[[f64; 4]; POLYNOMIAL_COEFFICIENTS]; ORDERS],
    scales: [f64; ORDERS],
}

/// Derivative orders of a sample: position to snap.
const ORDERS: usize = 5;

impl PreparedSegment {
    fn new(segment: &PolynomialSegment) -> Self {
        let mut coefficients = [[[0.0; 4]; POLYNOMIAL_COEFFICIENTS]; ORDERS];
        for (order, powers) in coefficients.iter_mut().enumerate() {
            for (k, lanes) in powers.iter_mut().enumerate().skip(order) {
                for (lane, output) in lanes.iter_mut().zip(&segment.coefficients) {
                    *lane = FALLING_FACTORIALS[order][k] * output[k];
                }
            }
        }
        // As `first_derivatives` forms them: 1, then times 1 / duration once per order.
        let inv_duration = 1.0 / segment.duration;
        let mut scales = [1.0; ORDERS];
        for order in 1..ORDERS {
            scales[order] = scales[order - 1] * inv_duration;
        }
        Self {
            coefficients,
            scales,
        }
    }

    /// Derivatives of order `0..N` of the four outputs at normalised time `tau`, in real time.
    #[inline(always)]
    fn derivatives<const N: usize>(&self, tau: f64) -> [[f64; 4]; N] {
        let mut result = [[0.0; 4]; N];
        for (order, value) in result.iter_mut().enumerate() {
            let mut acc = [0.0; 4];
            for c in self.coefficients[order][order..].iter().rev() {
                for lane in 0..4 {
                    acc[lane] = acc[lane] * tau + c[lane];
                }
            }
            let scale = self.scales[order];
            *value = acc.map(|a| a * scale);
        }
        result
    }

    fn point(&self, tau: f64) -> TrajectoryPoint {
        let d: [[f64; 4]; ORDERS] = self.derivatives(tau);
        let yaw = [d[0][YAW], d[1][YAW], d[2][YAW]];
        reference(|n| DVec3::new(d[n][X], d[n][Y], d[n][Z]), yaw)
    }

    fn position(&self, tau: f64) -> DVec3 {
        let [p] = self.derivatives::<1>(tau);
        DVec3::new(p[X], p[Y], p[Z])
    }
}

impl<'a> PreparedPolynomial<'a> {
    pub fn new(polynomial: &'a PiecewisePolynomial) -> Self {
        Self {
            polynomial,
            segments: polynomial
                .segments
                .iter()
                .map(PreparedSegment::new)
                .collect(),
        }
    }
}

impl Trajectory for PreparedPolynomial<'_> {
    fn duration(&self) -> f64 {
        self.polynomial.duration()
    }

    fn sample(&self, t: f64) -> TrajectoryPoint {
        match self.polynomial.within(t) {
            Some((index, tau)) => self.segments[index].point(tau),
            None => held_end(self.segments[self.segments.len() - 1].point(1.0)),
        }
    }

    fn position(&self, t: f64) -> DVec3 {
        let end = (self.segments.len() - 1, 1.0);
        let (index, tau) = self.polynomial.within(t).unwrap_or(end);
        self.segments[index].position(tau)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// x(t) = t^3 on a 2 s segment: in tau, x = 8 tau^3.
    fn cubic_segment() -> PolynomialSegment {
        let mut coefficients = [[0.0; POLYNOMIAL_COEFFICIENTS]; 4];
        coefficients[X][3] = 8.0;
        coefficients[YAW][1] = 1.0; // yaw(t) = t / 2
        PolynomialSegment {
            duration: 2.0,
            coefficients,
        }
    }

    #[test]
    fn derivatives_are_in_real_time() {
        let segment = cubic_segment();
        // At t = 1 s (tau = 0.5): x = 1, x' = 3 t^2 = 3, x'' = 6 t = 6, x''' = 6, x'''' = 0.
        let d = segment.derivatives(X, 0.5);
        let expected = [1.0, 3.0, 6.0, 6.0, 0.0];
        for (got, want) in d.iter().zip(expected) {
            assert!((got - want).abs() < 1e-12, "{d:?}");
        }
        let point = segment.point(0.5);
        assert!((point.yaw - 0.5).abs() < 1e-12);
        assert!((point.yaw_rate - 0.5).abs() < 1e-12);
    }

    #[test]
    fn sampling_finds_the_segment_and_holds_the_end() {
        let mut second = cubic_segment();
        // x continues from 8 m at rest: constant 8 over 1 s.
        second.coefficients[X] = [8.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0];
        second.duration = 1.0;
        let trajectory = PiecewisePolynomial::new(vec![cubic_segment(), second]).unwrap();
        assert_eq!(trajectory.duration(), 3.0);
        assert_eq!(trajectory.knots(), &[0.0, 2.0, 3.0]);
        assert!((trajectory.sample(1.0).position.x - 1.0).abs() < 1e-12);
        assert_eq!(trajectory.locate(2.5), (1, 0.5));
        assert!((trajectory.sample(2.5).position.x - 8.0).abs() < 1e-12);
        let after = trajectory.sample(7.0);
        assert!((after.position.x - 8.0).abs() < 1e-12);
        assert_eq!(after.velocity, DVec3::ZERO);
        // Before the start: the start itself.
        assert_eq!(trajectory.sample(-1.0).position, DVec3::ZERO);
    }

    /// Positions alone (also sampled onward), the yaw up to its acceleration alone, and the
    /// prepared form's samples are the full sample's to the bit: in every segment, at the
    /// knots, before the start and past the end.
    #[test]
    fn positions_yaw_and_prepared_samples_equal_the_full_computation_to_the_bit() {
        // Awkward coefficients and durations (no exact binary fractions), three segments.
        let segment = |seed: f64, duration: f64| {
            let mut coefficients = [[0.0; POLYNOMIAL_COEFFICIENTS]; 4];
            for (output, row) in coefficients.iter_mut().enumerate() {
                for (k, c) in row.iter_mut().enumerate() {
                    *c = (seed * (output * 8 + k + 1) as f64).sin() * 3.7;
                }
            }
            PolynomialSegment {
                duration,
                coefficients,
            }
        };
        let trajectory = PiecewisePolynomial::new(vec![
            segment(0.37, 0.93),
            segment(1.91, 2.17),
            segment(2.63, 0.41),
        ])
        .unwrap();
        let bits = |v: DVec3| v.to_array().map(f64::to_bits);
        let end = trajectory.duration();
        let knots = trajectory.knots().to_vec();
        let times = (0..=997).map(|i| -0.1 + (end + 0.3) * f64::from(i) / 997.0);
        for t in times.chain(knots) {
            let point = trajectory.sample(t);
            assert_eq!(
                bits(trajectory.position(t)),
                bits(point.position),
                "t = {t}"
            );
        }
        // The prepared form samples the same, every field, to the bit.
        let prepared = PreparedPolynomial::new(&trajectory);
        let fields = |p: TrajectoryPoint| {
            let v = [p.position, p.velocity, p.acceleration, p.jerk, p.snap];
            let mut bits: Vec<u64> = v.iter().flat_map(|&v| bits(v)).collect();
            bits.extend([p.yaw, p.yaw_rate, p.yaw_acceleration].map(f64::to_bits));
            bits
        };
        let times = (0..=997).map(|i| -0.1 + (end + 0.3) * f64::from(i) / 997.0);
        for t in times.chain(trajectory.knots().iter().copied()) {
            assert_eq!(
                fields(prepared.sample(t)),
                fields(trajectory.sample(t)),
                "t = {t}"
            );
            assert_eq!(
                bits(prepared.position(t)),
                bits(trajectory.position(t)),
                "t = {t}"
            );
        }
        assert_eq!(prepared.duration(), end);
        // Positions sampled onward, the segment kept between calls, and at times that go back
        // or are not numbers.
        let times = (0..=997).map(|i| -0.1 + (end + 0.3) * f64::from(i) / 997.0);
        let knots = trajectory.knots().to_vec();
        for times in [times.collect(), knots, vec![2.0, 0.5, f64::NAN, 1.0]] {
            let mut segment = 0;
            for t in times {
                assert_eq!(
                    bits(trajectory.position_onward(t, &mut segment)),
                    bits(trajectory.position(t)),
                    "t = {t}"
                );
            }
        }
        assert!(trajectory.prepared().is_some());
        for tau in (0..=100).map(|i| f64::from(i) / 100.0) {
            let segment = &trajectory.segments()[1];
            let (point, yaw) = (segment.point(tau), segment.derivatives(YAW, tau));
            assert_eq!(
                [point.yaw, point.yaw_rate, point.yaw_acceleration].map(f64::to_bits),
                [yaw[0], yaw[1], yaw[2]].map(f64::to_bits)
            );
        }
    }

    #[test]
    fn bad_segments_are_refused() {
        assert!(PiecewisePolynomial::new(vec![]).is_err());
        let mut zero = cubic_segment();
        zero.duration = 0.0;
        assert!(PiecewisePolynomial::new(vec![zero]).is_err());
        let mut nan = cubic_segment();
        nan.coefficients[Y][2] = f64::NAN;
        assert!(PiecewisePolynomial::new(vec![nan]).is_err());
    }
}
