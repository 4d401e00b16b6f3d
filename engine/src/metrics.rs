//! What a run records while it runs: the map metrics over time, the UAVs' tracks (with power
//! and rotor speeds for dynamic UAVs), the fleet's total power, and the times at which
//! exploration thresholds were crossed (common.md §5).

use bevy_ecs::prelude::*;
use glam::{DVec3, Vec3};
use serde::Serialize;
use uavex_components::map::{MapConfig, MapMetrics, MapTotals};
use uavex_components::sim::SimClock;
use uavex_components::uav::{QuadState, Uav};
use uavex_systems::flight::{EnergyMeter, FlightEnergy};

/// Exploration thresholds whose crossing times the summary reports.
pub const EXPLORED_THRESHOLDS: [f64; 4] = [0.50, 0.90, 0.95, 0.99];

/// One row of the map time series.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MapRow {
    pub time_s: f64,
    #[serde(flatten)]
    pub metrics: MapMetrics,
}

/// One row of the UAV time series (one per UAV per sample).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct UavRow {
    pub time_s: f64,
    pub uav: String,
    pub x: f32,
    pub y: f32,
    pub z: f32,
    pub yaw: f32,
    pub speed: f32,
    pub path_length_m: f64,
    /// Total rotor power (W) of the last physics step; `None` for a kinematic UAV.
    pub power_w: Option<f64>,
    /// Actual rotor speeds (rad/s) in the airframe's rotor order; `None` for a kinematic UAV.
    pub rotor_speeds: Option<[f32; 4]>,
}

/// A fixed rate in simulated time: samples at 0, T, 2T, ... (the series rows, the recording).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cadence {
    /// Seconds between samples.
    pub period_s: f64,
    next_s: f64,
}

impl Cadence {
    pub fn new(rate_hz: f64) -> Self {
        Self {
            period_s: 1.0 / rate_hz,
            next_s: 0.0,
        }
    }

    /// Whether a sample is due at `time_s`.
    pub fn is_due(&self, time_s: f64) -> bool {
        // A small tolerance keeps samples on the intended grid despite rounding of tick times.
        time_s + 1e-9 >= self.next_s
    }

    /// True when a sample is due at `time_s` (then schedules the next one).
    pub fn take(&mut self, time_s: f64) -> bool {
        if !self.is_due(time_s) {
            return false;
        }
        self.next_s += self.period_s;
        true
    }
}

/// The run's record, filled in the Account stage.
#[derive(Resource, Debug, Clone)]
pub struct RunRecord {
    /// When series rows are taken.
    pub series: Cadence,
    pub map_rows: Vec<MapRow>,
    pub uav_rows: Vec<UavRow>,
    /// Simulation time at which each of [`EXPLORED_THRESHOLDS`] was first reached.
    pub threshold_times_s: [Option<f64>; 4],
    /// Distance flown by each UAV (index = `Uav::index`).
    pub path_length_m: Vec<f64>,
    last_position: Vec<Option<Vec3>>,
    /// This tick's power of each UAV (index = `Uav::index`), `None` for kinematic ones: summed
    /// in index order, so the fleet total does not depend on ECS iteration order.
    power_w: Vec<Option<f64>>,
    /// The fleet's total rotor power over time (the sum over dynamic UAVs, every tick), for
    /// the run's average, peak and spread of power; `None` while no UAV flies dynamically.
    /// (Its path length is not used.)
    pub fleet_power: Option<EnergyMeter>,
}

impl RunRecord {
    pub fn new(series_rate_hz: f64, uav_count: usize) -> Self {
        Self {
            series: Cadence::new(series_rate_hz),
            map_rows: Vec::new(),
            uav_rows: Vec::new(),
            threshold_times_s: [None; 4],
            path_length_m: vec![0.0; uav_count],
            last_position: vec![None; uav_count],
            fleet_power: None,
            power_w: vec![None; uav_count],
        }
    }

    /// Adds one physics step of `dt` seconds at the fleet's total power `power_w`.
    pub fn note_fleet_power(&mut self, dt: f64, power_w: f64) {
        self.fleet_power
            .get_or_insert_with(EnergyMeter::default)
            .record(dt, power_w, DVec3::ZERO);
    }

    /// Marks the thresholds that `explored_fraction` has reached at `time_s`.
    pub fn note_exploration(&mut self, time_s: f64, explored_fraction: f64) {
        for (slot, threshold) in self.threshold_times_s.iter_mut().zip(EXPLORED_THRESHOLDS) {
            if slot.is_none() && explored_fraction >= threshold {
                *slot = Some(time_s);
            }
        }
    }

    /// Adds the distance from a UAV's previous position to `position`.
    pub fn note_position(&mut self, uav: usize, position: Vec3) {
        if let Some(last) = self.last_position[uav] {
            self.path_length_m[uav] += f64::from(last.distance(position));
        }
        self.last_position[uav] = Some(position);
    }

    /// Appends the final sample unless one was taken at this very time.
    pub fn close(&mut self, time_s: f64, metrics: MapMetrics) {
        if self.map_rows.last().is_none_or(|row| row.time_s < time_s) {
            self.map_rows.push(MapRow { time_s, metrics });
        }
    }
}

/// Account stage: path lengths and the fleet's power every tick, thresholds every tick (O(1)
/// from the map totals), series rows at the series rate.
pub fn record_metrics(
    clock: Res<SimClock>,
    config: Res<MapConfig>,
    totals: Res<MapTotals>,
    mut record: ResMut<RunRecord>,
    uavs: Query<(&Uav, &QuadState, Option<&FlightEnergy>)>,
) {
    let time_s = clock.time_s();
    // Every tick: no allocation, fixed order through the UAV index.
    for (uav, state, energy) in &uavs {
        record.note_position(uav.index, state.position);
        record.power_w[uav.index] = energy.map(|e| e.power_w);
    }
    let fleet_power = record
        .power_w
        .iter()
        .flatten()
        .copied()
        .reduce(|a, b| a + b);
    if let Some(power_w) = fleet_power {
        record.note_fleet_power(clock.dt, power_w);
    }
    let metrics = totals.metrics(&config);
    record.note_exploration(time_s, metrics.explored_fraction);
    if !record.series.take(time_s) {
        return;
    }
    record.map_rows.push(MapRow { time_s, metrics });
    let mut uavs: Vec<_> = uavs.iter().collect();
    uavs.sort_by_key(|(uav, ..)| uav.index);
    for (uav, state, energy) in uavs {
        let forward = state.attitude * Vec3::X;
        let row = UavRow {
            time_s,
            uav: uav.name.clone(),
            x: state.position.x,
            y: state.position.y,
            z: state.position.z,
            yaw: forward.y.atan2(forward.x),
            speed: state.velocity.length(),
            path_length_m: record.path_length_m[uav.index],
            power_w: energy.map(|e| e.power_w),
            rotor_speeds: energy.map(|_| state.rotor_speeds),
        };
        record.uav_rows.push(row);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn thresholds_are_crossed_once_at_the_first_time() {
        let mut r = RunRecord::new(1.0, 1);
        r.note_exploration(1.0, 0.4);
        r.note_exploration(2.0, 0.91);
        r.note_exploration(3.0, 0.96);
        r.note_exploration(4.0, 0.5);
        assert_eq!(r.threshold_times_s, [Some(2.0), Some(2.0), Some(3.0), None]);
    }

    #[test]
    fn path_length_sums_segments() {
        let mut r = RunRecord::new(1.0, 2);
        r.note_position(1, Vec3::ZERO);
        r.note_position(1, Vec3::new(3.0, 4.0, 0.0));
        r.note_position(1, Vec3::new(3.0, 4.0, 2.0));
        assert_eq!(r.path_length_m, vec![0.0, 7.0]);
    }

    #[test]
    fn fleet_power_is_absent_until_noted() {
        let mut r = RunRecord::new(1.0, 1);
        assert!(r.fleet_power.is_none());
        // 0.5 s at 100 W, 0.5 s at 200 W: 150 J, mean 150 W, peak 200 W, std 50 W.
        r.note_fleet_power(0.5, 100.0);
        r.note_fleet_power(0.5, 200.0);
        let fleet = r.fleet_power.as_ref().unwrap();
        assert_eq!(fleet.energy_j, 150.0);
        assert_eq!(fleet.average_power_w(), 150.0);
        assert_eq!(fleet.peak_power_w, 200.0);
        assert!((fleet.power_std_w() - 50.0).abs() < 1e-9);
    }

    #[test]
    fn samples_follow_the_period() {
        let mut r = RunRecord::new(2.0, 0);
        let due: Vec<f64> = (0..=9)
            .map(|i| f64::from(i) * 0.25)
            .filter(|&t| r.series.take(t))
            .collect();
        assert_eq!(due, vec![0.0, 0.5, 1.0, 1.5, 2.0]);
    }
}
