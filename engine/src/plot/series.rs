//! Time series of several runs brought onto one time grid: mean and spread band per group.
//!
//! Runs end at different times. A run's value is held after its last sample (a finished
//! mission keeps the map it has), so the mean over a group does not jump when its shortest
//! run ends; the band is the envelope (min to max) over the group's runs, the honest spread
//! for the handful of seeds a sweep usually has.

use std::path::Path;

/// One run's samples of one column, in time order.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Curve {
    pub times: Vec<f64>,
    pub values: Vec<f64>,
}

impl Curve {
    /// The value at `t`: the last sample at or before `t`, the first sample before it starts.
    pub fn value_at(&self, t: f64) -> Option<f64> {
        let after = self.times.partition_point(|&s| s <= t);
        let at = after.saturating_sub(1);
        self.values.get(at).copied()
    }

    /// The median gap between samples (`None` with fewer than two samples).
    fn median_step(&self) -> Option<f64> {
        let mut gaps: Vec<f64> = self
            .times
            .windows(2)
            .map(|w| w[1] - w[0])
            .filter(|g| *g > 0.0)
            .collect();
        gaps.sort_by(f64::total_cmp);
        gaps.get(gaps.len() / 2).copied()
    }
}

/// A group's mean and envelope on a common time grid.
#[derive(Debug, Clone, PartialEq)]
pub struct Band {
    pub times: Vec<f64>,
    pub mean: Vec<f64>,
    pub low: Vec<f64>,
    pub high: Vec<f64>,
}

/// At most this many grid points per band (enough for any figure width).
const MAX_POINTS: usize = 2000;

/// The band of `curves` on a grid from 0 to the last sample of any of them, with the finest
/// median sampling step among them (coarsened to at most `MAX_POINTS` points).
pub fn band(curves: &[Curve]) -> Option<Band> {
    let curves: Vec<&Curve> = curves.iter().filter(|c| !c.times.is_empty()).collect();
    let end = curves
        .iter()
        .filter_map(|c| c.times.last().copied())
        .fold(f64::NEG_INFINITY, f64::max);
    if curves.is_empty() || !end.is_finite() {
        return None;
    }
    let start = curves
        .iter()
        .map(|c| c.times[0])
        .fold(f64::INFINITY, f64::min)
        .min(0.0);
    let span = end - start;
    let finest = curves
        .iter()
        .filter_map(|c| c.median_step())
        .fold(f64::INFINITY, f64::min);
    let step = if finest.is_finite() {
        finest.max(span / MAX_POINTS as f64)
    } else {
        span.max(1.0)
    };
    let mut times = Vec::new();
    let mut k = 0usize;
    loop {
        let t = start + k as f64 * step;
        if t >= end - step * 1e-9 {
            break;
        }
        times.push(t);
        k += 1;
    }
    times.push(end);
    let (mut mean, mut low, mut high) = (Vec::new(), Vec::new(), Vec::new());
    for &t in &times {
        let values: Vec<f64> = curves.iter().filter_map(|c| c.value_at(t)).collect();
        mean.push(values.iter().sum::<f64>() / values.len() as f64);
        low.push(values.iter().copied().fold(f64::INFINITY, f64::min));
        high.push(values.iter().copied().fold(f64::NEG_INFINITY, f64::max));
    }
    Some(Band {
        times,
        mean,
        low,
        high,
    })
}

/// Reads `column` against `time_s` from a run's CSV file, multiplied by `scale`. Rows sharing
/// a time (one per UAV, as in `uavs.csv`) are summed: the total over the UAVs. Empty cells
/// are skipped. `Ok(None)` when the file has no such column.
pub fn read_curve(path: &Path, column: &str, scale: f64) -> Result<Option<Curve>, String> {
    let mut reader =
        csv::Reader::from_path(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let headers = reader
        .headers()
        .map_err(|e| format!("{}: {e}", path.display()))?
        .clone();
    let find = |name: &str| headers.iter().position(|h| h == name);
    let (Some(time_at), Some(value_at)) = (find("time_s"), find(column)) else {
        return Ok(None);
    };
    let mut curve = Curve::default();
    for record in reader.records() {
        let record = record.map_err(|e| format!("{}: {e}", path.display()))?;
        let number = |at: usize| record.get(at).and_then(|s| s.trim().parse::<f64>().ok());
        let (Some(t), Some(v)) = (number(time_at), number(value_at)) else {
            continue;
        };
        if curve.times.last() == Some(&t) {
            if let Some(last) = curve.values.last_mut() {
                *last += v * scale;
            }
        } else {
            curve.times.push(t);
            curve.values.push(v * scale);
        }
    }
    Ok(Some(curve))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn curve(samples: &[(f64, f64)]) -> Curve {
        Curve {
            times: samples.iter().map(|s| s.0).collect(),
            values: samples.iter().map(|s| s.1).collect(),
        }
    }

    #[test]
    fn values_hold_between_and_after_samples() {
        let c = curve(&[(0.0, 1.0), (0.5, 2.0), (1.0, 4.0)]);
        assert_eq!(c.value_at(-1.0), Some(1.0));
        assert_eq!(c.value_at(0.0), Some(1.0));
        assert_eq!(c.value_at(0.7), Some(2.0));
        assert_eq!(c.value_at(1.0), Some(4.0));
        assert_eq!(c.value_at(9.0), Some(4.0));
        assert_eq!(Curve::default().value_at(0.0), None);
    }

    #[test]
    fn band_holds_finished_runs_and_spans_the_longest() {
        // Run a ends at 1 s with 10, run b goes on to 2 s.
        let a = curve(&[(0.0, 0.0), (0.5, 4.0), (1.0, 10.0)]);
        let b = curve(&[(0.0, 2.0), (0.5, 6.0), (1.0, 8.0), (1.5, 12.0), (2.0, 14.0)]);
        let band = band(&[a, b]).unwrap();
        assert_eq!(band.times, [0.0, 0.5, 1.0, 1.5, 2.0]);
        assert_eq!(band.mean, [1.0, 5.0, 9.0, 11.0, 12.0]);
        assert_eq!(band.low, [0.0, 4.0, 8.0, 10.0, 10.0]);
        assert_eq!(band.high, [2.0, 6.0, 10.0, 12.0, 14.0]);
    }

    #[test]
    fn grid_ends_exactly_at_the_last_sample() {
        let a = curve(&[(0.0, 1.0), (0.5, 1.0), (1.0, 1.0), (1.2, 3.0)]);
        let band = band(&[a]).unwrap();
        assert_eq!(band.times, [0.0, 0.5, 1.0, 1.2]);
        assert_eq!(band.mean.last(), Some(&3.0));
        assert!(super::band(&[]).is_none());
        assert!(super::band(&[Curve::default()]).is_none());
    }

    #[test]
    fn a_single_sample_gives_a_one_point_band() {
        let band = band(&[curve(&[(0.0, 5.0)])]).unwrap();
        assert_eq!(band.times, [0.0]);
        assert_eq!(band.mean, [5.0]);
    }

    #[test]
    fn reads_a_column_and_sums_rows_of_the_same_time() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("uavs.csv");
        std::fs::write(
            &path,
            "time_s,uav,power_w\n0,a,100\n0,b,120\n0.5,a,110\n0.5,b,\n1,a,90\n1,b,95\n",
        )
        .unwrap();
        let c = read_curve(&path, "power_w", 1.0).unwrap().unwrap();
        assert_eq!(c.times, [0.0, 0.5, 1.0]);
        assert_eq!(c.values, [220.0, 110.0, 185.0]);
        let pct = read_curve(&path, "power_w", 0.5).unwrap().unwrap();
        assert_eq!(pct.values[0], 110.0);
        assert_eq!(read_curve(&path, "missing", 1.0).unwrap(), None);
        assert!(read_curve(&dir.path().join("none.csv"), "x", 1.0).is_err());
    }
}
