//! Files a run writes: `summary.json`, `series.csv` (map metrics over time), `uavs.csv` (tracks,
//! with power and rotor speeds of dynamic UAVs; empty cells for kinematic ones),
//! `stage_timings.csv` (the host's wall-clock time per stage of the tick).
//! Every file is written to a temporary name and renamed, so a reader never sees half a file.

use crate::metrics::{MapRow, UavRow};
use serde::{Deserialize, Serialize};
use std::fmt::Write as _;
use std::io;
use std::path::Path;
use uavex_components::sim::Outcome;
use uavex_components::uav::PredictedMission;
use uavex_systems::flight::EnergySummary;
use uavex_systems::stage_clock::StageClock;
use uavex_systems::stages::Stage;

/// Per-UAV part of the summary.
///
/// The energy fields (common.md §4-5) are those of the true flight, integrated every physics
/// step; they are `null` for a kinematic (`scripted`) UAV, which has no dynamics to draw power.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct UavSummary {
    pub name: String,
    pub path_length_m: f64,
    /// How this UAV ended: "finished", "crashed", "battery_empty", or "flying" when the run
    /// ended first.
    pub status: String,
    /// When a crashed UAV touched geometry, or a UAV's battery ran out (s); `null` otherwise.
    pub ended_time_s: Option<f64>,
    /// Where that happened (m, world frame); `null` otherwise.
    pub ended_position: Option<[f32; 3]>,
    /// Energy drawn by the rotors (J).
    pub energy_j: Option<f64>,
    /// Mean power over the UAV's flight (W).
    pub avg_power_w: Option<f64>,
    pub peak_power_w: Option<f64>,
    /// Standard deviation of power over time (W).
    pub power_std_w: Option<f64>,
    /// Fraction of the battery's full capacity left at the end.
    pub battery_soc_end: Option<f64>,
    /// The behaviour's prediction of its mission energy (J) and time (s), made before flight;
    /// `null` for behaviours that make none.
    pub predicted_energy_j: Option<f64>,
    pub predicted_time_s: Option<f64>,
}

impl UavSummary {
    /// A UAV's summary; `ended` is the time and place of a crash or an empty battery,
    /// `energy` is `None` for a kinematic UAV.
    pub fn new(
        name: String,
        path_length_m: f64,
        status: String,
        ended: Option<(f64, [f32; 3])>,
        energy: Option<&EnergySummary>,
        predicted: Option<PredictedMission>,
    ) -> Self {
        Self {
            name,
            path_length_m,
            status,
            ended_time_s: ended.map(|(t, _)| t),
            ended_position: ended.map(|(_, p)| p),
            energy_j: energy.map(|e| e.energy_j),
            avg_power_w: energy.map(|e| e.avg_power_w),
            peak_power_w: energy.map(|e| e.peak_power_w),
            power_std_w: energy.map(|e| e.power_std_w),
            battery_soc_end: energy.map(|e| e.battery_soc_end),
            predicted_energy_j: predicted.map(|p| p.energy_j),
            predicted_time_s: predicted.map(|p| p.time_s),
        }
    }
}

/// The `summary.json` fields that measure the host rather than the run (wall-clock times);
/// every other field is a pure function of scenario and seed.
pub const HOST_FIELDS: [&str; 3] = ["wall_time_s", "decision_ms_p50", "decision_ms_p95"];

/// `summary.json`: one run, as a flat record (a row of a sweep's table).
///
/// Every field is a pure function of scenario and seed except the [`HOST_FIELDS`].
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
    /// Energy drawn by all dynamic UAVs (J); `null` when no UAV flies dynamically (as for
    /// every energy field below).
    pub energy_j: Option<f64>,
    /// Mean of the fleet's total power over the mission (W).
    pub avg_power_w: Option<f64>,
    /// Peak of the fleet's total power (W).
    pub peak_power_w: Option<f64>,
    /// Standard deviation of the fleet's total power over time (W).
    pub power_std_w: Option<f64>,
    /// The lowest state of charge among the UAVs' batteries at the end.
    pub battery_soc_end: Option<f64>,
    /// The exploration keys, for runs in which some UAV explores (flattened into the record).
    #[serde(flatten, default, skip_serializing_if = "Option::is_none")]
    pub exploration: Option<ExplorationKeys>,
    pub uavs: Vec<UavSummary>,
    /// Host time the run took (s), one of the [`HOST_FIELDS`].
    pub wall_time_s: f64,
}

/// The summary keys of an exploration run (eaae.md; the list).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ExplorationKeys {
    /// Decisions that chose a goal.
    pub decisions: u64,
    /// Mission time when the run ended `complete` (no reachable frontier left), else `null`.
    pub completion_time_s: Option<f64>,
    /// Mean |flown - predicted| / predicted energy over the goals reached.
    pub mean_prediction_error: Option<f64>,
    /// Median and 95th percentile of the wall-clock time of a decision (ms), [`HOST_FIELDS`].
    pub decision_ms_p50: Option<f64>,
    pub decision_ms_p95: Option<f64>,
    /// Known share of the free space connected to the start (%), from the ground truth.
    pub explored_reachable_pct: Option<f64>,
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

/// `text` as one CSV field (RFC 4180): quoted, with its quotes doubled, when it holds a comma,
/// a quote or a line break (a UAV named "left,right" once split its rows into 14 fields).
fn text_cell(text: &str) -> std::borrow::Cow<'_, str> {
    if text.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", text.replace('"', "\"\"")).into()
    } else {
        text.into()
    }
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
    let mut out = String::from(
        "time_s,uav,x,y,z,yaw,speed,path_length_m,power_w,\
         rotor_speed_0,rotor_speed_1,rotor_speed_2,rotor_speed_3\n",
    );
    for r in rows {
        let [w0, w1, w2, w3] = r.rotor_speeds.map_or([None; 4], |w| w.map(Some));
        let w = |speed: Option<f32>| speed.map(|s| s.to_string()).unwrap_or_default();
        let _ = writeln!(
            out,
            "{},{},{},{},{},{},{},{},{},{},{},{},{}",
            r.time_s,
            text_cell(&r.uav),
            r.x,
            r.y,
            r.z,
            r.yaw,
            r.speed,
            r.path_length_m,
            cell(r.power_w),
            w(w0),
            w(w1),
            w(w2),
            w(w3),
        );
    }
    out
}

/// The wall-clock time of each stage of the tick as CSV, one row per stage in tick order: the
/// time (s), its share of all stages (%) and its mean per tick (us). Host measurements, like
/// the decision timings: they differ from machine to machine.
pub fn stage_timings_csv(clock: &StageClock) -> String {
    let mut out = String::from("stage,wall_s,share_pct,mean_us_per_tick\n");
    let total = clock.total().as_secs_f64();
    for stage in Stage::ORDER {
        let spent = clock.spent(stage).as_secs_f64();
        let share = if total > 0.0 {
            100.0 * spent / total
        } else {
            0.0
        };
        let per_tick = 1e6 * spent / clock.ticks().max(1) as f64;
        let name = format!("{stage:?}").to_lowercase();
        let _ = writeln!(out, "{name},{spent:.6},{share:.2},{per_tick:.3}");
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(uav: &str, power_w: Option<f64>, rotor_speeds: Option<[f32; 4]>) -> UavRow {
        UavRow {
            time_s: 0.5,
            uav: uav.to_owned(),
            x: 1.0,
            y: 2.0,
            z: 3.0,
            yaw: 0.25,
            speed: 1.5,
            path_length_m: 4.0,
            power_w,
            rotor_speeds,
        }
    }

    #[test]
    fn uav_series_has_power_and_rotor_speeds_or_empty_cells() {
        let csv = uav_series_csv(&[
            row(
                "dynamic",
                Some(123.5),
                Some([1000.0, 1001.0, 1002.0, 1003.5]),
            ),
            row("kinematic", None, None),
        ]);
        let lines: Vec<&str> = csv.lines().collect();
        assert_eq!(
            lines,
            [
                "time_s,uav,x,y,z,yaw,speed,path_length_m,power_w,\
                 rotor_speed_0,rotor_speed_1,rotor_speed_2,rotor_speed_3",
                "0.5,dynamic,1,2,3,0.25,1.5,4,123.5,1000,1001,1002,1003.5",
                "0.5,kinematic,1,2,3,0.25,1.5,4,,,,,",
            ]
        );
    }

    #[test]
    fn uav_names_with_commas_or_quotes_stay_one_field() {
        let names = ["left,right", "say \"hi\"", "two\nlines", "plain"];
        let rows: Vec<UavRow> = names.iter().map(|&n| row(n, None, None)).collect();
        let text = uav_series_csv(&rows);
        let mut reader = csv::Reader::from_reader(text.as_bytes());
        let width = reader.headers().unwrap().len();
        let read: Vec<String> = reader
            .records()
            .map(|record| {
                let record = record.unwrap();
                assert_eq!(record.len(), width, "{record:?}");
                record[1].to_owned()
            })
            .collect();
        assert_eq!(read, names);
    }

    #[test]
    fn kinematic_uavs_have_null_energy() {
        let summary = UavSummary::new("k".into(), 2.0, "finished".into(), None, None, None);
        let json = serde_json::to_value(&summary).unwrap();
        assert!(json["energy_j"].is_null() && json["battery_soc_end"].is_null());
        assert!(json["ended_position"].is_null());
    }
}
