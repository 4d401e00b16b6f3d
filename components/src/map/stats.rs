//! Incremental map statistics (common.md §5): voxel counts, entropy and uncertainty sums per
//! chunk ([`ChunkStats`]) and over the whole map ([`MapTotals`]), so that exploration rate, map
//! entropy and map uncertainty cost O(1) at any tick.
//!
//! Sums are fixed-point integers in units of 1 / [`STAT_ONE`] (2^-24 bit of entropy). Each
//! voxel update subtracts the old value's table entry and adds the new one's; integer sums
//! never drift, so after any number of updates they equal a from-scratch recount exactly.
//! Why 2^-24 and not 2^-32: a map of up to 2^36 voxels (the [`super::MAX_BOX_VOXELS`] limit)
//! at 1 bit each sums to 2^60, inside i64; the table rounding (< 3e-8 bit per voxel) is far
//! below any reported digit.

use super::chunk::{CHUNK_VOXELS, UNKNOWN_LOG_ODDS, VoxelChunk};
use super::config::MapConfig;
use bevy_ecs::prelude::*;

/// Fixed-point one: a table value of `STAT_ONE` is 1 bit of entropy (or an uncertainty of 1).
pub const STAT_ONE: i64 = 1 << 24;

/// Entropy and uncertainty of one quantised log-odds value, in units of 1 / [`STAT_ONE`].
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct StatEntry {
    /// H = -p log2 p - (1-p) log2 (1-p) (EAAE eq. 5.5).
    pub entropy: i32,
    /// u = (0.5 - |0.5 - p|)^2 (heterogeneous seed).
    pub uncertainty: i32,
}

/// [`StatEntry`] for every log-odds value between the clamping bounds (milli units), with
/// p = 1 - 1 / (1 + exp(l)) (common.md §1).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct StatTables {
    min: i16,
    entries: Vec<StatEntry>,
}

impl StatTables {
    pub fn new(clamp_min: i16, clamp_max: i16) -> Self {
        let entries = (clamp_min..=clamp_max)
            .map(|milli| {
                let p = probability(f64::from(milli) / 1000.0);
                let fixed = |x: f64| (x * STAT_ONE as f64).round() as i32;
                StatEntry {
                    entropy: fixed(entropy_bits(p)),
                    uncertainty: fixed(uncertainty(p)),
                }
            })
            .collect();
        Self {
            min: clamp_min,
            entries,
        }
    }

    /// Entry of a stored log-odds value (values outside the table's range, which the mapping
    /// stage never stores, read as the nearest bound).
    #[inline]
    pub fn entry(&self, log_odds: i16) -> StatEntry {
        let last = self.entries.len().saturating_sub(1) as i32;
        let i = (i32::from(log_odds) - i32::from(self.min)).clamp(0, last) as usize;
        self.entries.get(i).copied().unwrap_or_default()
    }
}

/// p = 1 - 1 / (1 + exp(l)) (common.md §1).
pub fn probability(log_odds: f64) -> f64 {
    1.0 - 1.0 / (1.0 + log_odds.exp())
}

fn entropy_bits(p: f64) -> f64 {
    let h = |x: f64| if x > 0.0 { -x * x.log2() } else { 0.0 };
    h(p) + h(1.0 - p)
}

fn uncertainty(p: f64) -> f64 {
    (0.5 - (0.5 - p).abs()).powi(2)
}

/// Counts and fixed-point sums over a set of known voxels, split by class (index 0 free,
/// 1 occupied), so that means over free and over occupied voxels are available too.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct StatSums {
    pub counts: [i64; 2],
    pub entropy: [i64; 2],
    pub uncertainty: [i64; 2],
}

impl StatSums {
    /// Adds a known voxel with stored log-odds `log_odds`.
    #[inline]
    pub fn add_voxel(&mut self, log_odds: i16, tables: &StatTables) {
        let class = usize::from(log_odds >= 0);
        let e = tables.entry(log_odds);
        self.counts[class] += 1;
        self.entropy[class] += i64::from(e.entropy);
        self.uncertainty[class] += i64::from(e.uncertainty);
    }

    /// Removes a known voxel with stored log-odds `log_odds` (its value before an update).
    #[inline]
    pub fn remove_voxel(&mut self, log_odds: i16, tables: &StatTables) {
        let class = usize::from(log_odds >= 0);
        let e = tables.entry(log_odds);
        self.counts[class] -= 1;
        self.entropy[class] -= i64::from(e.entropy);
        self.uncertainty[class] -= i64::from(e.uncertainty);
    }

    /// Adds `after - before` (the change of one chunk's sums) to these sums.
    #[inline]
    pub fn add_change(&mut self, before: &StatSums, after: &StatSums) {
        for c in 0..2 {
            self.counts[c] += after.counts[c] - before.counts[c];
            self.entropy[c] += after.entropy[c] - before.entropy[c];
            self.uncertainty[c] += after.uncertainty[c] - before.uncertainty[c];
        }
    }

    pub fn add(&mut self, other: &StatSums) {
        self.add_change(&StatSums::default(), other);
    }

    pub fn free(&self) -> i64 {
        self.counts[0]
    }

    pub fn occupied(&self) -> i64 {
        self.counts[1]
    }

    pub fn known(&self) -> i64 {
        self.counts[0] + self.counts[1]
    }

    /// The sums of a chunk counted from scratch (the reference the incremental sums must equal).
    pub fn of_chunk(chunk: &VoxelChunk, tables: &StatTables) -> Self {
        let mut sums = Self::default();
        for voxel in chunk.voxels().iter().take(CHUNK_VOXELS) {
            if voxel.log_odds != UNKNOWN_LOG_ODDS {
                sums.add_voxel(voxel.log_odds, tables);
            }
        }
        sums
    }
}

/// Statistics of the known voxels of one chunk, kept in step with its [`VoxelChunk`].
#[derive(Component, Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct ChunkStats(pub StatSums);

/// The sum of all [`ChunkStats`], maintained by the same updates.
#[derive(Resource, Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct MapTotals(pub StatSums);

/// Map metrics of common.md §5 at one instant. Means over an empty set are `None`.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct MapMetrics {
    pub box_voxels: u64,
    pub known_voxels: u64,
    pub free_voxels: u64,
    pub occupied_voxels: u64,
    /// (free + occupied) / box voxels, in [0, 1] (x 100 for the exploration rate in %).
    pub explored_fraction: f64,
    /// Mean entropy over known voxels (bit).
    pub mean_entropy_known: Option<f64>,
    /// Mean entropy over the box, unknown voxels counting 1 bit.
    pub mean_entropy_box: f64,
    pub mean_entropy_free: Option<f64>,
    pub mean_entropy_occupied: Option<f64>,
    /// Sum of u over the box, unknown voxels counting 0.25.
    pub uncertainty_total: f64,
    /// Mean of u over the box.
    pub uncertainty_mean: f64,
    pub mean_uncertainty_free: Option<f64>,
    pub mean_uncertainty_occupied: Option<f64>,
}

impl MapTotals {
    pub fn metrics(&self, config: &MapConfig) -> MapMetrics {
        let s = &self.0;
        let box_voxels = config.box_voxels();
        let known = s.known().max(0) as u64;
        let unknown = box_voxels.saturating_sub(known) as f64;
        let n = box_voxels.max(1) as f64;
        let one = STAT_ONE as f64;
        let mean = |sum: i64, count: i64| (count > 0).then(|| sum as f64 / one / count as f64);
        let entropy_known = (s.entropy[0] + s.entropy[1]) as f64 / one;
        let uncertainty_known = (s.uncertainty[0] + s.uncertainty[1]) as f64 / one;
        let uncertainty_total = uncertainty_known + 0.25 * unknown;
        MapMetrics {
            box_voxels,
            known_voxels: known,
            free_voxels: s.free().max(0) as u64,
            occupied_voxels: s.occupied().max(0) as u64,
            explored_fraction: known as f64 / n,
            mean_entropy_known: mean(s.entropy[0] + s.entropy[1], s.known()),
            mean_entropy_box: (entropy_known + unknown) / n,
            mean_entropy_free: mean(s.entropy[0], s.counts[0]),
            mean_entropy_occupied: mean(s.entropy[1], s.counts[1]),
            uncertainty_total,
            uncertainty_mean: uncertainty_total / n,
            mean_uncertainty_free: mean(s.uncertainty[0], s.counts[0]),
            mean_uncertainty_occupied: mean(s.uncertainty[1], s.counts[1]),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::config::MapSettings;
    use super::*;
    use glam::DVec3;

    #[test]
    fn table_values_match_the_formulas() {
        let t = StatTables::new(-1992, 3476);
        let one = STAT_ONE as f64;
        // l = 0: p = 0.5, H = 1 bit, u = 0.25.
        assert_eq!(t.entry(0).entropy as i64, STAT_ONE);
        assert_eq!(t.entry(0).uncertainty as i64, STAT_ONE / 4);
        // l = 0.847: p = 0.7 (to 4 digits: 0.69995), H(0.7) = 0.881291 bit, u = 0.3^2 = 0.09.
        let e = t.entry(847);
        assert!((e.entropy as f64 / one - 0.881291).abs() < 2e-4);
        assert!((e.uncertainty as f64 / one - 0.09).abs() < 1e-4);
        // l = -0.405: p = 0.4, H = 0.970951 bit, u = 0.16; symmetric in l.
        let e = t.entry(-405);
        assert!((e.entropy as f64 / one - 0.970951).abs() < 2e-4);
        assert!((e.uncertainty as f64 / one - 0.16).abs() < 1e-4);
        assert_eq!(t.entry(405), e);
        // Out-of-table values read as the nearest bound instead of panicking.
        assert_eq!(t.entry(i16::MAX), t.entry(3476));
        assert_eq!(t.entry(i16::MIN + 1), t.entry(-1992));
    }

    #[test]
    fn metrics_of_a_small_map() {
        // A 1 m cube at 0.5 m: 8 voxels; one occupied at l = 0 (H 1, u 0.25), one free at
        // l = -0.405 (H 0.970951, u 0.16), six unknown.
        let config = MapConfig::new(&MapSettings {
            resolution: 0.5,
            bounds_min: DVec3::ZERO,
            bounds_max: DVec3::ONE,
            ..MapSettings::default()
        })
        .unwrap();
        let mut totals = MapTotals::default();
        totals.0.add_voxel(0, config.tables());
        totals.0.add_voxel(-405, config.tables());
        let m = totals.metrics(&config);
        assert_eq!((m.box_voxels, m.known_voxels), (8, 2));
        assert_eq!((m.free_voxels, m.occupied_voxels), (1, 1));
        assert_eq!(m.explored_fraction, 0.25);
        let close = |a: f64, b: f64| (a - b).abs() < 2e-4;
        assert!(close(m.mean_entropy_known.unwrap(), (1.0 + 0.970951) / 2.0));
        assert!(close(m.mean_entropy_box, (1.0 + 0.970951 + 6.0) / 8.0));
        assert!(close(m.mean_entropy_occupied.unwrap(), 1.0));
        assert!(close(m.uncertainty_total, 0.25 + 0.16 + 6.0 * 0.25));
        assert!(close(m.uncertainty_mean, (0.25 + 0.16 + 1.5) / 8.0));
        assert!(close(m.mean_uncertainty_free.unwrap(), 0.16));
        // Removing the free voxel leaves no free voxels: its means are undefined.
        totals.0.remove_voxel(-405, config.tables());
        let m = totals.metrics(&config);
        assert_eq!(m.mean_uncertainty_free, None);
        assert_eq!(totals.0.entropy[0], 0);
    }
}
