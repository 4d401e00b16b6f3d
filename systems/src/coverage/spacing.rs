//! How many shots a stretch takes and how many stripes a cell, and where they go (coverage.md,
//! "Path"; Di Franco and Buttazzo 2015): `m = ceil(d / d_y)` shots `Delta_y = (d - L_y)/(m - 1)`
//! apart, an even `n_s = ceil(d_max / d_x)` stripes `Delta_x = (d_max - L_x)/(n_s - 1)` apart.
//! The counts come from the inputs, so they are checked as floats before any cast.

use super::sweep::Cell;

/// How many shots a stretch of `length` takes: `m = ceil(length / d_y)`, at least 2, or 1 when a
/// single footprint spans it; `None` when the count is not a finite number a `usize` holds (the
/// float is checked before the cast, which would saturate or wrap).
pub(super) fn shot_count(length: f64, l_y: f64, d_y: f64) -> Option<usize> {
    if length <= l_y {
        return Some(1);
    }
    finite_count((length / d_y).ceil().max(2.0))
}

/// Offsets of the `count` shots ([`shot_count`]) along a stretch of `length`: the first `L_y/2`
/// in, the last `L_y/2` before its end, `Delta_y = (length - L_y)/(m - 1)` apart; one in the
/// middle when a single footprint spans the stretch.
pub(super) fn shot_offsets(length: f64, l_y: f64, count: usize) -> Vec<f64> {
    if count <= 1 || length <= l_y {
        return vec![length / 2.0];
    }
    let delta = (length - l_y) / (count - 1) as f64;
    (0..count).map(|i| l_y / 2.0 + delta * i as f64).collect()
}

/// How many stripes a cell of height `d_max` takes: `n_s = ceil(d_max / d_x)`, at least 2, made
/// even; `None` when that is no finite `usize`.
pub(super) fn stripe_count(d_max: f64, l_x: f64, d_x: f64) -> Option<usize> {
    if d_max <= l_x {
        return Some(2);
    }
    let n_s = (d_max / d_x).ceil().max(2.0);
    finite_count(n_s + n_s % 2.0)
}

/// Levels of the `n_s` stripes ([`stripe_count`]) over `cell`, of height `d_max`: the first
/// `L_x/2` above the base, the last `L_x/2` below the top, `Delta_x = (d_max - L_x)/(n_s - 1)`
/// apart. When one footprint spans the cell (`d_max <= L_x`, where that spacing would turn
/// negative) the two stripes of the smallest even count both run through its middle, out and
/// back.
pub(super) fn stripe_levels(cell: &Cell, l_x: f64, n_s: usize) -> Vec<f64> {
    let (bottom, top) = (cell.bottom(), cell.top());
    let d_max = top - bottom;
    if d_max <= l_x || n_s < 2 {
        return vec![bottom + d_max / 2.0; 2];
    }
    let delta = (d_max - l_x) / (n_s - 1) as f64;
    (0..n_s)
        .map(|k| bottom + l_x / 2.0 + delta * k as f64)
        .collect()
}

/// `x` as a count when it is finite and below `usize::MAX` (NaN and infinity are not).
fn finite_count(x: f64) -> Option<usize> {
    // 2^53 is far above any budget and exactly representable, so the cast below is exact.
    (0.0..=9_007_199_254_740_992.0)
        .contains(&x)
        .then_some(x as usize)
}
