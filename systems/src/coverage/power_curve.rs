//! Power as a polynomial of speed, in the published form (coverage.md, "Measured energy model"):
//! coefficients in descending powers (numpy `polyval` order), optionally of a reflected argument
//! (the paper's deceleration power `q(15 - v)`), with its integral over speed in closed form.

use serde::{Deserialize, Serialize};

/// `P(v) = c_0 x^n + c_1 x^(n-1) + ... + c_n` with `x = v`, or `x = reflect_at - v`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PowerCurve {
    /// Coefficients, highest power first (W / (m/s)^k).
    pub coefficients: Vec<f64>,
    /// When set, the polynomial's argument is `reflect_at - v` (m/s).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reflect_at: Option<f64>,
}

impl PowerCurve {
    pub fn polynomial(coefficients: Vec<f64>) -> Self {
        Self {
            coefficients,
            reflect_at: None,
        }
    }

    pub fn reflected(coefficients: Vec<f64>, at: f64) -> Self {
        Self {
            coefficients,
            reflect_at: Some(at),
        }
    }

    /// Power at speed `v` (W).
    pub fn power(&self, v: f64) -> f64 {
        polyval(&self.coefficients, self.argument(v))
    }

    /// `int_0^v P(u) du` (W m/s), from the antiderivative of the polynomial; with a reflected
    /// argument `int_0^v q(r - u) du = Q(r) - Q(r - v)`.
    pub fn integral(&self, v: f64) -> f64 {
        match self.reflect_at {
            None => antiderivative(&self.coefficients, v),
            Some(r) => {
                antiderivative(&self.coefficients, r) - antiderivative(&self.coefficients, r - v)
            }
        }
    }

    fn argument(&self, v: f64) -> f64 {
        self.reflect_at.map_or(v, |r| r - v)
    }

    pub fn is_finite(&self) -> bool {
        !self.coefficients.is_empty()
            && self.coefficients.iter().all(|c| c.is_finite())
            && self.reflect_at.is_none_or(f64::is_finite)
    }
}

/// Horner evaluation of descending-order coefficients.
pub fn polyval(coefficients: &[f64], x: f64) -> f64 {
    coefficients.iter().fold(0.0, |acc, &c| acc * x + c)
}

/// `Q(x)` with `Q' = p` and `Q(0) = 0`: the coefficient of `x^k` becomes that of `x^(k+1) / (k+1)`.
fn antiderivative(coefficients: &[f64], x: f64) -> f64 {
    let n = coefficients.len();
    let value = coefficients
        .iter()
        .enumerate()
        .fold(0.0, |acc, (i, &c)| acc * x + c / (n - i) as f64);
    value * x
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn polyval_is_descending_order() {
        // 2 x^2 + 3 x + 4 at x = 2: 8 + 6 + 4 = 18.
        assert_eq!(polyval(&[2.0, 3.0, 4.0], 2.0), 18.0);
        assert_eq!(PowerCurve::polynomial(vec![2.0, 3.0, 4.0]).power(2.0), 18.0);
    }

    #[test]
    fn integral_by_hand() {
        // int_0^3 (2u^2 + 3u + 4) du = 2*9 + 3*9/2 + 12 = 18 + 13.5 + 12 = 43.5.
        let p = PowerCurve::polynomial(vec![2.0, 3.0, 4.0]);
        assert!((p.integral(3.0) - 43.5).abs() < 1e-12);
        // Reflected: q(x) = x, r = 10: int_0^4 (10 - u) du = 40 - 8 = 32.
        let q = PowerCurve::reflected(vec![1.0, 0.0], 10.0);
        assert_eq!(q.power(4.0), 6.0);
        assert!((q.integral(4.0) - 32.0).abs() < 1e-12);
    }
}
