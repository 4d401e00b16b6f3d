//! Cholesky factorisation and solve of a symmetric positive definite *band* matrix, with the
//! floating-point operations of nalgebra's dense `Cholesky` (0.35: `new`, then `solve`) in the
//! same order, so that every result is bit for bit the dense one.
//!
//! Why: the minimum-snap system (`super::min_snap`) couples only the joints of one segment, so
//! its free block is a band of half-width <= 7 around the diagonal. The dense factorisation
//! costs n^3 / 6 multiply-adds (n = 3 per inner waypoint: 250 000 for 40 waypoints, for each
//! of the four outputs and every re-timing round), the band one n w^2 / 2; the trajectories
//! must not change (decision logs are pure functions of scenario and seed, and a speed-up is
//! checked by digests of the planned trajectories).
//!
//! Why the same bits: outside the band the dense code only ever adds products with a factor
//! that is exactly zero. Those entries start as `+0` (the assembled form adds its terms to
//! `+0` and scales by positive numbers) and stay `+0` (IEEE: `+0 + -0 = +0`, and a sum that
//! cancels exactly is `+0`), so adding such a product changes nothing except a `-0`
//! accumulator, which the forward solve is the only one to meet (a right-hand side of `-0`);
//! [`BandCholesky::solve`] replays that case. The back substitution's dot products use
//! nalgebra's eight-accumulator unrolling, which [`dense_dot`] reproduces for the band part.

/// A symmetric matrix given by its lower band: row `i` holds columns `first[i]..=i`, with
/// `first` non-decreasing (entries left of `first[i]` are zero).
#[derive(Debug, Clone, PartialEq)]
pub struct BandMatrix {
    first: Vec<usize>,
    width: usize,
    values: Vec<f64>,
}

impl BandMatrix {
    /// A zero matrix with the given row starts (`first[i] <= i`, non-decreasing).
    pub fn zeros(first: Vec<usize>) -> Self {
        debug_assert!(first.iter().enumerate().all(|(i, &f)| f <= i));
        debug_assert!(first.windows(2).all(|w| w[0] <= w[1]));
        let width = first
            .iter()
            .enumerate()
            .map(|(i, &f)| i - f)
            .max()
            .unwrap_or(0);
        Self {
            values: vec![0.0; first.len() * (width + 1)],
            first,
            width,
        }
    }

    fn len(&self) -> usize {
        self.first.len()
    }

    /// First stored column of row `i`.
    pub fn first(&self, i: usize) -> usize {
        self.first[i]
    }

    #[inline]
    fn slot(&self, i: usize, j: usize) -> usize {
        debug_assert!(self.first[i] <= j && j <= i);
        i * (self.width + 1) + (j + self.width - i)
    }

    /// Entry (i, j) for `first[i] <= j <= i`.
    #[inline]
    pub fn get(&self, i: usize, j: usize) -> f64 {
        self.values[self.slot(i, j)]
    }

    #[inline]
    pub fn set(&mut self, i: usize, j: usize, value: f64) {
        let slot = self.slot(i, j);
        self.values[slot] = value;
    }
}

/// The lower factor `L` of a [`BandMatrix`] (same band).
#[derive(Debug, Clone, PartialEq)]
pub struct BandCholesky {
    l: BandMatrix,
    /// Last row of each column's band: `last[j] = max { i : first[i] <= j }`.
    last: Vec<usize>,
}

impl BandCholesky {
    /// `L L^T = a`, or `None` where nalgebra's `cholesky()` gives `None` (a pivot that is not
    /// positive). Per entry, the dense left-looking algorithm: `y = a_ij`, then
    /// `y += -l_jk l_ik` for k ascending, then `l_jj = sqrt(y)` or `l_ij = y / l_jj`.
    pub fn new(mut a: BandMatrix) -> Option<Self> {
        let n = a.len();
        for i in 0..n {
            let row_first = a.first[i];
            for j in row_first..=i {
                let mut y = a.get(i, j);
                // l_ik = 0 for k < first[i], and first[j] <= first[i].
                for k in row_first..j {
                    y += -a.get(j, k) * a.get(i, k);
                }
                let value = if j == i {
                    if y.is_nan() || y <= 0.0 {
                        return None;
                    }
                    y.sqrt()
                } else {
                    y / a.get(j, j)
                };
                a.set(i, j, value);
            }
        }
        let mut last = vec![0; n];
        for (i, &f) in a.first.iter().enumerate() {
            for slot in &mut last[f..=i] {
                *slot = i;
            }
        }
        Some(Self { l: a, last })
    }

    /// Solves `L L^T x = b` in place.
    pub fn solve(&self, b: &mut [f64]) {
        let n = self.l.len();
        debug_assert_eq!(b.len(), n);
        // Forward: nalgebra subtracts column by column, so row r receives the (zero) products
        // of the columns left of its band first; `-0 + +0 = +0` is their only effect, and a
        // product (-z_i) * (+0) is +0 exactly when z_i has its sign bit set.
        let mut signed_before = vec![false; n + 1];
        for r in 0..n {
            let f = self.l.first(r);
            let mut y = b[r];
            if y == 0.0 && y.is_sign_negative() && signed_before[f] {
                y = 0.0;
            }
            for (i, z) in b.iter().enumerate().take(r).skip(f) {
                y += -z * self.l.get(r, i);
            }
            b[r] = y / self.l.get(r, r);
            signed_before[r + 1] = signed_before[r] || b[r].is_sign_negative();
        }
        // Backward: x_i = (z_i - dot(L[i+1.., i], x[i+1..])) / l_ii, the dot over the whole
        // column as nalgebra forms it; its band part sits at the start.
        let mut products = Vec::with_capacity(self.l.width);
        for i in (0..n).rev() {
            products.clear();
            products.extend((i + 1..=self.last[i]).map(|row| self.l.get(row, i) * b[row]));
            let dot = dense_dot(&products, n - i - 1);
            b[i] = (b[i] - dot) / self.l.get(i, i);
        }
    }
}

/// nalgebra's dot product of two dynamic vectors of length `len` whose element-wise products
/// are `products` followed by zeros: eight accumulators over the full blocks of eight, combined
/// as (0 + 4) (1 + 5) (2 + 6) (3 + 7), then the rest in order. Zero products added to a sum
/// that is never `-0` change nothing, so they are skipped.
fn dense_dot(products: &[f64], len: usize) -> f64 {
    debug_assert!(products.len() <= len);
    let blocks = len / 8 * 8;
    let mut acc = [0.0; 8];
    for (k, &p) in products.iter().enumerate().take(blocks) {
        acc[k % 8] += p;
    }
    let mut res = 0.0;
    res += acc[0] + acc[4];
    res += acc[1] + acc[5];
    res += acc[2] + acc[6];
    res += acc[3] + acc[7];
    for &p in products.iter().skip(blocks) {
        res += p;
    }
    res
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{DMatrix, DVector};

    /// xorshift in [-1, 1).
    fn sequence(mut seed: u64) -> impl FnMut() -> f64 {
        move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        }
    }

    /// Random band matrices (unit-ish diagonal, exact zeros inside the band, band widths that
    /// vary by row) and right-hand sides with zeros of both signs: the band code must give the
    /// dense factor's bits, and solutions whose every bit (signs of zeros included) matches.
    #[test]
    fn band_cholesky_matches_nalgebra_dense_bit_for_bit() {
        let mut next = sequence(0x9e37_79b9_7f4a_7c15);
        for n in [1, 2, 5, 8, 9, 16, 17, 40, 61] {
            for width in [1, 3, 5, 7, 11] {
                let mut first = Vec::with_capacity(n);
                for i in 0..n {
                    let previous = first.last().copied().unwrap_or(0);
                    let wide = i.saturating_sub(width);
                    let narrow = i.saturating_sub(width / 2);
                    let pick = if next() > 0.0 { wide } else { narrow };
                    first.push(pick.max(previous));
                }
                let mut dense = DMatrix::<f64>::zeros(n, n);
                let mut band = BandMatrix::zeros(first.clone());
                for i in 0..n {
                    for j in first[i]..=i {
                        let value = if i == j {
                            1.0 + 2.0 * width as f64 + next().abs()
                        } else if next() > 0.6 {
                            0.0
                        } else {
                            next()
                        };
                        dense[(i, j)] = value;
                        band.set(i, j, value);
                    }
                }
                let rhs: Vec<f64> = (0..n)
                    .map(|_| match next() {
                        x if x > 0.5 => 0.0,
                        x if x > 0.0 => -0.0,
                        _ => next() * 100.0,
                    })
                    .collect();
                let factor = dense.clone().cholesky().expect("diagonally dominant");
                let band = BandCholesky::new(band).expect("diagonally dominant");
                let l = factor.l();
                for i in 0..n {
                    for j in first[i]..=i {
                        assert_eq!(
                            band.l.get(i, j).to_bits(),
                            l[(i, j)].to_bits(),
                            "{n} {i} {j}"
                        );
                    }
                }
                let want = factor.solve(&DVector::from_column_slice(&rhs));
                let mut got = rhs.clone();
                band.solve(&mut got);
                for (g, w) in got.iter().zip(want.iter()) {
                    assert_eq!(
                        g.to_bits(),
                        w.to_bits(),
                        "n {n} width {width}: {got:?} {want:?}"
                    );
                }
            }
        }
    }

    #[test]
    fn a_matrix_that_is_not_positive_definite_is_refused() {
        let mut band = BandMatrix::zeros(vec![0, 0]);
        band.set(0, 0, 1.0);
        band.set(1, 0, 2.0);
        band.set(1, 1, 1.0);
        assert!(BandCholesky::new(band).is_none());
    }
}
