//! Minimum-snap polynomial trajectories in closed form (Richter, Bry & Roy, ISRR 2013, §III).
//!
//! Each output (x, y, z, yaw) is a piecewise polynomial of degree 7 through the waypoints.
//! Every segment's polynomial is fixed by its boundary derivatives (orders 0..3 at both ends,
//! shared at the joints), and its snap cost `int (d^4 p / dt^4)^2 dt` is a quadratic form in
//! them. Summing the segments gives one quadratic form `d^T R d` over the joint derivatives;
//! with the fixed ones `d_F` (waypoints, start and end state) given, the free ones (velocity,
//! acceleration, jerk at the inner waypoints) minimise it at `d_P = -R_PP^-1 R_PF d_F`
//! (Richter et al. eq. 6-7): an unconstrained QP, solved exactly. The optimum is continuous up
//! to the sixth derivative at inner waypoints (its optimality conditions join snap and its
//! next two derivatives), which the tests check for snap.
//!
//! Numbers: polynomials live in normalised time (see
//! `uavex_components::trajectory::PolynomialSegment`), so the constant matrices are small
//! integers; `R_PP` is scaled to unit diagonal before its Cholesky factorisation, which keeps
//! segments of very different durations well conditioned.

use super::PlanError;
use super::banded::{BandCholesky, BandMatrix};
use nalgebra::SMatrix;
use std::sync::OnceLock;
use uavex_components::trajectory::{POLYNOMIAL_COEFFICIENTS, PolynomialSegment};

/// Derivative orders shared at a joint: position, velocity, acceleration, jerk.
const ORDERS: usize = 4;
const N: usize = POLYNOMIAL_COEFFICIENTS;
type Matrix8 = SMatrix<f64, N, N>;

/// The boundary conditions of one output (x, y, z or yaw) at every joint.
#[derive(Debug, Clone, PartialEq)]
pub struct JointConstraints {
    /// `values[joint][order]`: the prescribed derivative, or `None` when it is free.
    pub values: Vec<[Option<f64>; ORDERS]>,
}

/// k! / (k - n)!.
fn falling(k: usize, n: usize) -> f64 {
    if n > k {
        return 0.0;
    }
    ((k + 1 - n)..=k).map(|i| i as f64).product()
}

/// `A^-1`, where `A` maps the 8 coefficients of a polynomial in tau to its derivatives of
/// order 0..3 at tau = 0 then at tau = 1; and `H = A^-T Q A^-1`, the snap cost over tau in
/// [0, 1] as a form in those 8 boundary derivatives (Richter et al. eq. 3-5).
fn constant_matrices() -> &'static (Matrix8, Matrix8) {
    static MATRICES: OnceLock<(Matrix8, Matrix8)> = OnceLock::new();
    MATRICES.get_or_init(|| {
        let mut a = Matrix8::zeros();
        for r in 0..ORDERS {
            a[(r, r)] = falling(r, r);
            for k in r..N {
                a[(ORDERS + r, k)] = falling(k, r);
            }
        }
        let a_inv = a
            .try_inverse()
            .expect("the boundary map of degree-7 polynomials is invertible");
        let mut q = Matrix8::zeros();
        for j in 4..N {
            for k in 4..N {
                q[(j, k)] = falling(j, 4) * falling(k, 4) / (j + k - 7) as f64;
            }
        }
        let h = a_inv.transpose() * q * a_inv;
        (a_inv, h)
    })
}

/// Scale of real-time derivatives into tau-derivatives: `d_tau^(r) = T^r d^(r)`.
fn tau_scale(duration: f64) -> [f64; N] {
    let t = duration;
    [1.0, t, t * t, t * t * t, 1.0, t, t * t, t * t * t]
}

/// Solves the minimum-snap problem of one output for the given segment durations and returns,
/// for each joint, its four derivatives (the free ones filled in).
pub fn solve_joint_derivatives(
    durations: &[f64],
    constraints: &JointConstraints,
) -> Result<Vec<[f64; ORDERS]>, PlanError> {
    let mut solved = solve_outputs(durations, std::slice::from_ref(constraints))?;
    Ok(solved.pop().expect("one output"))
}

/// [`solve_joint_derivatives`] for several outputs over the same durations, in order (the
/// first error returned). The snap form depends on the durations only, and its free block on
/// which derivatives are free: outputs with the same free set (x, y and z always; yaw when
/// every heading is given) share one factorisation.
pub fn solve_outputs(
    durations: &[f64],
    outputs: &[JointConstraints],
) -> Result<Vec<Vec<[f64; ORDERS]>>, PlanError> {
    let joints = durations.len() + 1;
    if let Some(c) = outputs.iter().find(|c| c.values.len() != joints) {
        return Err(PlanError::Internal(format!(
            "{} joint constraints for {} segments",
            c.values.len(),
            durations.len()
        )));
    }
    let form = SnapForm::new(durations);
    let mut factor: Option<FreeBlock> = None;
    let mut solved = Vec::with_capacity(outputs.len());
    for constraints in outputs {
        let mut free = Vec::with_capacity(ORDERS * joints);
        let mut fixed = Vec::with_capacity(ORDERS * joints);
        let mut values = vec![0.0; ORDERS * joints];
        for (joint, orders) in constraints.values.iter().enumerate() {
            for (order, value) in orders.iter().enumerate() {
                let index = ORDERS * joint + order;
                match value {
                    Some(v) => {
                        if !v.is_finite() {
                            return Err(PlanError::NonFinite(format!(
                                "derivative {order} at waypoint {joint}"
                            )));
                        }
                        values[index] = *v;
                        fixed.push(index);
                    }
                    None => free.push(index),
                }
            }
        }
        if !free.is_empty() {
            if factor.as_ref().is_none_or(|f| f.free != free) {
                factor = Some(FreeBlock::new(&form, free)?);
            }
            let block = factor.as_ref().expect("factorised above");
            // R_PP x = -R_PF d_F, with R_PP scaled to unit diagonal: D R_PP D y = -D R_PF d_F.
            // Only the fixed variables within the band of a free one meet it in `R` (`fixed`
            // is ascending); the others' terms are zeros.
            let mut y: Vec<f64> = block
                .free
                .iter()
                .zip(&block.scale)
                .map(|(&q, &scale)| {
                    let first = fixed.partition_point(|&f| f + BAND < q);
                    -scale
                        * fixed[first..]
                            .iter()
                            .take_while(|&&f| f <= q + BAND)
                            .map(|&f| form.get(q, f) * values[f])
                            .sum::<f64>()
                })
                .collect();
            block.cholesky.solve(&mut y);
            for (a, &index) in block.free.iter().enumerate() {
                values[index] = block.scale[a] * y[a];
            }
        }
        if values.iter().any(|v| !v.is_finite()) {
            return Err(PlanError::Singular);
        }
        solved.push(
            (0..joints)
                .map(|j| std::array::from_fn(|o| values[ORDERS * j + o]))
                .collect(),
        );
    }
    Ok(solved)
}

/// Half-width of the snap form's band: a segment couples the 8 derivatives of its two joints.
const BAND: usize = 2 * ORDERS - 1;

/// The snap form `R` (the sum over segments of `T^-7 S H S` on each segment's 8 joint
/// variables), stored by its band: `band[p][q + BAND - p]` for |p - q| <= BAND, zero elsewhere.
/// Both triangles are kept: `H` is symmetric only up to rounding, and the dense code this
/// replaces read `R[p][q]` for the right-hand side and the lower triangle for the factor.
struct SnapForm {
    band: Vec<[f64; 2 * BAND + 1]>,
}

impl SnapForm {
    fn new(durations: &[f64]) -> Self {
        let (_, h) = constant_matrices();
        let mut band = vec![[0.0; 2 * BAND + 1]; ORDERS * (durations.len() + 1)];
        for (i, &duration) in durations.iter().enumerate() {
            let s = tau_scale(duration);
            let weight = duration.powi(-7);
            for a in 0..N {
                for b in 0..N {
                    band[ORDERS * i + a][b + BAND - a] += weight * s[a] * h[(a, b)] * s[b];
                }
            }
        }
        Self { band }
    }

    #[inline]
    fn get(&self, p: usize, q: usize) -> f64 {
        if p.abs_diff(q) > BAND {
            return 0.0;
        }
        self.band[p][q + BAND - p]
    }
}

/// The free block `R_PP` of one free set, scaled to unit diagonal and factorised.
struct FreeBlock {
    free: Vec<usize>,
    scale: Vec<f64>,
    cholesky: BandCholesky,
}

impl FreeBlock {
    fn new(form: &SnapForm, free: Vec<usize>) -> Result<Self, PlanError> {
        let scale: Vec<f64> = free.iter().map(|&i| 1.0 / form.get(i, i).sqrt()).collect();
        // Free variables further apart than the band never share a segment.
        let first: Vec<usize> = (0..free.len())
            .map(|a| free.partition_point(|&q| q + BAND < free[a]))
            .collect();
        let mut block = BandMatrix::zeros(first);
        for a in 0..free.len() {
            for b in block.first(a)..=a {
                block.set(a, b, scale[a] * form.get(free[a], free[b]) * scale[b]);
            }
        }
        let cholesky = BandCholesky::new(block).ok_or(PlanError::Singular)?;
        Ok(Self {
            free,
            scale,
            cholesky,
        })
    }
}

/// The tau-polynomial coefficients of one segment from its boundary derivatives (real time).
pub fn segment_coefficients(duration: f64, start: &[f64; ORDERS], end: &[f64; ORDERS]) -> [f64; N] {
    let (a_inv, _) = constant_matrices();
    let s = tau_scale(duration);
    let boundary = nalgebra::SVector::<f64, N>::from_fn(|i, _| {
        let value = if i < ORDERS {
            start[i]
        } else {
            end[i - ORDERS]
        };
        value * s[i]
    });
    let c = a_inv * boundary;
    std::array::from_fn(|k| c[k])
}

/// Builds the segments of all four outputs from their joint derivatives.
pub fn build_segments(
    durations: &[f64],
    outputs: &[Vec<[f64; ORDERS]>; 4],
) -> Vec<PolynomialSegment> {
    durations
        .iter()
        .enumerate()
        .map(|(i, &duration)| PolynomialSegment {
            duration,
            coefficients: std::array::from_fn(|o| {
                segment_coefficients(duration, &outputs[o][i], &outputs[o][i + 1])
            }),
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn boundary_map_reproduces_boundary_derivatives() {
        // x from 0 (v 1, a 0, j 0) to 5 (v 0, a 2, j -1) in 2 s.
        let start = [0.0, 1.0, 0.0, 0.0];
        let end = [5.0, 0.0, 2.0, -1.0];
        let coefficients = segment_coefficients(2.0, &start, &end);
        let segment = PolynomialSegment {
            duration: 2.0,
            coefficients: [coefficients, [0.0; N], [0.0; N], [0.0; N]],
        };
        let d0 = segment.derivatives(0, 0.0);
        let d1 = segment.derivatives(0, 1.0);
        for o in 0..ORDERS {
            assert!((d0[o] - start[o]).abs() < 1e-12, "{d0:?}");
            assert!((d1[o] - end[o]).abs() < 1e-12, "{d1:?}");
        }
    }

    #[test]
    fn one_rest_to_rest_segment_is_the_known_septic() {
        // With all eight boundary values fixed there is nothing to optimise: from 0 to 1 at
        // rest in 1 s the polynomial is 35 t^4 - 84 t^5 + 70 t^6 - 20 t^7.
        let constraints = JointConstraints {
            values: vec![
                [Some(0.0), Some(0.0), Some(0.0), Some(0.0)],
                [Some(1.0), Some(0.0), Some(0.0), Some(0.0)],
            ],
        };
        let joints = solve_joint_derivatives(&[1.0], &constraints).unwrap();
        let c = segment_coefficients(1.0, &joints[0], &joints[1]);
        let expected = [0.0, 0.0, 0.0, 0.0, 35.0, -84.0, 70.0, -20.0];
        for (got, want) in c.iter().zip(expected) {
            assert!((got - want).abs() < 1e-9, "{c:?}");
        }
    }

    #[test]
    fn a_waypoint_on_the_single_segment_optimum_changes_nothing() {
        // Rest to rest from 0 to 2 in 2 s, the optimum is x(t) = 2 s(t / 2) with
        // s(u) = 35u^4 - 84u^5 + 70u^6 - 20u^7, which passes x = 1 at t = 1. Adding that
        // waypoint leaves the optimum unchanged, so the free middle derivatives must be those
        // of the septic at t = 1: v = s'(1/2) = 2.1875, a = s''(1/2) / 2 = 0,
        // j = s'''(1/2) / 4 = -13.125.
        let rest = |x: f64| [Some(x), Some(0.0), Some(0.0), Some(0.0)];
        let constraints = JointConstraints {
            values: vec![rest(0.0), [Some(1.0), None, None, None], rest(2.0)],
        };
        let joints = solve_joint_derivatives(&[1.0, 1.0], &constraints).unwrap();
        let expected = [1.0, 2.1875, 0.0, -13.125];
        for (got, want) in joints[1].iter().zip(expected) {
            assert!((got - want).abs() < 1e-9, "{:?}", joints[1]);
        }
    }
}
