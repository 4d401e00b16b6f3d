//! Files a run writes: `summary.json`, `series.csv` (map metrics over time), `uavs.csv` (tracks).
//! Every file is written to a temporary name and renamed, so a reader never sees half a file.

use crate::metrics::{MapRow, UavRow};
use serde::{Deserialize, Serialize};
use std::fmt::Write as _;
use std::io;
use std::path::Path;
use uavex_components::sim::Outcome;

/// Per-UAV part of the summary.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct UavSummary {
    pub name: String,
    pub path_length_m: f64,
    /// How this UAV ended: "finished", "crashed", or "flying" when the run ended first.
    pub status: String,
}

/// `summary.json`: one run, as a flat record (a row of a sweep's table).
///
/// Every field is a pure function of scenario and seed except `wall_time_s`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RunSummary {
    pub scenario: String,
    pub seed: u64,
    pub outcome: Outcome,
    /// Why the run ended, in words.
    pub reason: String,
    pub mission_time_s: f64,
    pub ticks: u64,
    pub explored_fraction: f64,
    pub known_voxels: u64,
    pub occupied_voxels: u64,
    pub box_voxels: u64,
    /// Mean entropy over known voxels (bit).
    pub entropy_known_bits: Option<f64>,
    /// Mean entropy over the bounding box, unknown counting 1 bit.
    pub entropy_box_bits: f64,
    pub uncertainty_total: f64,
    pub uncertainty_mean: f64,
    pub uncertainty_free_mean: Option<f64>,
    pub uncertainty_occupied_mean: Option<f64>,
    /// Fraction of known voxels whose state (free/occupied) agrees with the ground truth.
    pub map_accuracy: Option<f64>,
    pub time_to_explored_50_s: Option<f64>,
    pub time_to_explored_90_s: Option<f64>,
    pub time_to_explored_95_s: Option<f64>,
    pub time_to_explored_99_s: Option<f64>,
    /// Total distance flown by all UAVs.
    pub path_length_m: f64,
    pub uavs: Vec<UavSummary>,
    /// Host time the run took (s); the one field that is not deterministic.
    pub wall_time_s: f64,
}

/// Writes `contents` to `path` through a temporary file and a rename.
pub fn write_atomically(path: &Path, contents: &[u8]) -> io::Result<()> {
    let mut tmp = path.as_os_str().to_owned();
    tmp.push(".partial");
    std::fs::write(&tmp, contents)?;
    std::fs::rename(&tmp, path)
}

fn cell(value: Option<f64>) -> String {
    value.map(|v| v.to_string()).unwrap_or_default()
}

/// The map time series as CSV, one row per sample.
pub fn map_series_csv(rows: &[MapRow]) -> String {
    let mut out = String::from(
        "time_s,explored_fraction,known_voxels,free_voxels,occupied_voxels,entropy_known_bits,\
         entropy_box_bits,uncertainty_total,uncertainty_mean,uncertainty_free_mean,\
         uncertainty_occupied_mean\n",
    );
    for row in rows {
        let m = &row.metrics;
        let _ = writeln!(
            out,
            "{},{},{},{},{},{},{},{},{},{},{}",
            row.time_s,
            m.explored_fraction,
            m.known_voxels,
            m.free_voxels,
            m.occupied_voxels,
            cell(m.mean_entropy_known),
            m.mean_entropy_box,
            m.uncertainty_total,
            m.uncertainty_mean,
            cell(m.mean_uncertainty_free),
            cell(m.mean_uncertainty_occupied),
        );
    }
    out
}

/// The UAV tracks as CSV, one row per UAV per sample.
pub fn uav_series_csv(rows: &[UavRow]) -> String {
    let mut out = String::from("time_s,uav,x,y,z,yaw,speed,path_length_m\n");
    for r in rows {
        let _ = writeln!(
            out,
            "{},{},{},{},{},{},{},{}",
            r.time_s, r.uav, r.x, r.y, r.z, r.yaw, r.speed, r.path_length_m
        );
    }
    out
}
