//! Energy accounting (common.md §4-5): power integrated over time, its statistics, the path
//! length and the battery's state of charge.
//!
//! The true flight records every physics step; the offline rollout integrates energy inside its
//! own integrator. Both report the same [`EnergySummary`] keys.

use glam::DVec3;
use serde::{Deserialize, Serialize};
use uavex_components::airframe::BatterySpec;

/// Joules per watt-hour.
pub const JOULES_PER_WH: f64 = 3600.0;

/// Running integrals of power over time for one UAV.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct EnergyMeter {
    /// Integral of power over time (J).
    pub energy_j: f64,
    /// Time recorded so far (s).
    pub time_s: f64,
    /// Highest power recorded (W).
    pub peak_power_w: f64,
    /// Integral of the squared power over time (W^2 s), for the spread of power.
    power_squared_integral: f64,
    /// Length of the flown path (m), from the recorded positions.
    pub path_length_m: f64,
    last_position: Option<DVec3>,
}

impl EnergyMeter {
    /// Adds `dt` seconds at `power_w` watts (the step's mean power: the midpoint value for the
    /// midpoint rule), ending at `position`.
    pub fn record(&mut self, dt: f64, power_w: f64, position: DVec3) {
        self.energy_j += power_w * dt;
        self.power_squared_integral += power_w * power_w * dt;
        self.time_s += dt;
        self.peak_power_w = self.peak_power_w.max(power_w);
        if let Some(last) = self.last_position {
            self.path_length_m += position.distance(last);
        }
        self.last_position = Some(position);
    }

    /// Sets where the path starts without adding energy (the first `record` measures from it).
    pub fn start_at(&mut self, position: DVec3) {
        self.last_position = Some(position);
    }

    /// Mean power over the recorded time (W): energy / time.
    pub fn average_power_w(&self) -> f64 {
        if self.time_s > 0.0 {
            self.energy_j / self.time_s
        } else {
            0.0
        }
    }

    /// Standard deviation of power over time (W): sqrt(mean(P^2) - mean(P)^2).
    pub fn power_std_w(&self) -> f64 {
        if self.time_s <= 0.0 {
            return 0.0;
        }
        let mean = self.average_power_w();
        (self.power_squared_integral / self.time_s - mean * mean)
            .max(0.0)
            .sqrt()
    }
}

/// A battery being drained.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Battery {
    /// Full nominal capacity (J).
    pub capacity_j: f64,
    /// What a mission may draw (J): capacity x usable fraction.
    pub usable_j: f64,
    /// Drawn so far (J).
    pub used_j: f64,
}

impl Battery {
    /// A full battery.
    pub fn new(spec: &BatterySpec) -> Self {
        let capacity_j = spec.capacity_wh * JOULES_PER_WH;
        Self {
            capacity_j,
            usable_j: capacity_j * spec.usable_fraction,
            used_j: 0.0,
        }
    }

    pub fn draw(&mut self, energy_j: f64) {
        self.used_j += energy_j;
    }

    /// State of charge: the fraction of the full capacity left (1 when full). A spent battery
    /// still holds `1 - usable_fraction`.
    pub fn state_of_charge(&self) -> f64 {
        (1.0 - self.used_j / self.capacity_j).max(0.0)
    }

    /// Whether the usable energy is drawn: the run ends as `battery_empty`.
    pub fn is_spent(&self) -> bool {
        self.used_j >= self.usable_j
    }
}

/// The energy part of a run summary (keys of `summary.json`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct EnergySummary {
    pub energy_j: f64,
    pub avg_power_w: f64,
    pub peak_power_w: f64,
    pub power_std_w: f64,
    pub path_length_m: f64,
    pub battery_soc_end: f64,
    pub flight_time_s: f64,
}

impl EnergySummary {
    pub fn new(meter: &EnergyMeter, battery: &Battery) -> Self {
        Self {
            energy_j: meter.energy_j,
            avg_power_w: meter.average_power_w(),
            peak_power_w: meter.peak_power_w,
            power_std_w: meter.power_std_w(),
            path_length_m: meter.path_length_m,
            battery_soc_end: battery.state_of_charge(),
            flight_time_s: meter.time_s,
        }
    }

    /// The summary as (key, value) pairs, in a fixed order.
    pub fn entries(&self) -> [(&'static str, f64); 7] {
        [
            ("energy_j", self.energy_j),
            ("avg_power_w", self.avg_power_w),
            ("peak_power_w", self.peak_power_w),
            ("power_std_w", self.power_std_w),
            ("path_length_m", self.path_length_m),
            ("battery_soc_end", self.battery_soc_end),
            ("flight_time_s", self.flight_time_s),
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn meter_integrates_power_and_its_spread() {
        let mut meter = EnergyMeter::default();
        meter.start_at(DVec3::ZERO);
        // 1 s at 100 W then 1 s at 140 W: 240 J, mean 120 W, std 20 W, peak 140 W.
        meter.record(1.0, 100.0, DVec3::new(3.0, 4.0, 0.0));
        meter.record(1.0, 140.0, DVec3::new(3.0, 4.0, 2.0));
        assert_eq!(meter.energy_j, 240.0);
        assert_eq!(meter.average_power_w(), 120.0);
        assert!((meter.power_std_w() - 20.0).abs() < 1e-9);
        assert_eq!(meter.peak_power_w, 140.0);
        assert_eq!(meter.path_length_m, 7.0);
    }

    #[test]
    fn battery_soc_and_exhaustion() {
        let mut battery = Battery::new(&BatterySpec {
            capacity_wh: 10.0,
            usable_fraction: 0.8,
        });
        assert_eq!(battery.capacity_j, 36_000.0);
        battery.draw(18_000.0);
        assert!((battery.state_of_charge() - 0.5).abs() < 1e-12);
        assert!(!battery.is_spent());
        battery.draw(10_800.0);
        assert!(battery.is_spent());
        assert!((battery.state_of_charge() - 0.2).abs() < 1e-12);
        let summary = EnergySummary::new(&EnergyMeter::default(), &battery);
        assert_eq!(
            summary.entries()[5],
            ("battery_soc_end", battery.state_of_charge())
        );
    }
}
