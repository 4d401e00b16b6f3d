//! The shipped waypoint tour of the Pillars scene flies on the true quadrotor with a plausible
//! energy, which the offline rollout of the same plan predicts (issue 3, "Must show").

mod common;

use std::sync::Arc;
use uavex::components::airframe::Airframe;
use uavex::components::sim::Outcome;
use uavex::engine::run::{RunOptions, run};
use uavex::engine::scenario;
use uavex::engine::sim::Sim;
use uavex::systems::flight::{
    FlightState, ReferenceTrajectory, RolloutConfig, power::total_power, rollout,
};

/// Kingfisher hover power (W): 4 rotors at sqrt(m g / (4 k_f)) = 1086.43 rad/s drawing
/// 6.088e-3 w + 1.875e-8 w^3 + 7.7e-20 w^6 = 30.785 W each (common.md §3-4).
const HOVER_POWER_W: f64 = 123.14;

#[test]
fn the_pillars_tour_completes_with_plausible_energy_and_series() {
    let loaded = scenario::load("scenarios/pillars_waypoints.toml").unwrap();
    let dir = tempfile::tempdir().unwrap();
    let options = RunOptions {
        out_dir: Some(dir.path().to_owned()),
        seed: None,
        ..RunOptions::default()
    };
    let summary = run(&loaded, &options).unwrap().summary;
    assert_eq!(summary.outcome, Outcome::Complete, "{}", summary.reason);
    let uav = &summary.uavs[0];
    assert_eq!(uav.status, "finished");
    assert_eq!((uav.ended_time_s, uav.ended_position), (None, None));

    // The legs are 66 m of straight lines: at the 5 m/s limit no less than 13 s; the
    // min-snap path is longer than its chords and slows for corners.
    let time = summary.mission_time_s;
    assert!((15.0..60.0).contains(&time), "{time}");
    assert!(uav.path_length_m > 66.0 && uav.path_length_m < 80.0);
    // Without drag, energy beyond hover only goes into accelerating: at least hover power
    // times the flight time, and well under 1.5 times that.
    let energy = uav.energy_j.unwrap();
    let hover = HOVER_POWER_W * time;
    assert!(
        energy > hover && energy < 1.5 * hover,
        "{energy} J over {time} s (hover {hover} J)"
    );
    let average = uav.avg_power_w.unwrap();
    assert!((average - energy / time).abs() < 1e-6 * average);
    let peak = uav.peak_power_w.unwrap();
    assert!(peak > average && peak < 2.0 * HOVER_POWER_W, "{peak}");
    assert!(uav.power_std_w.unwrap() > 0.0);
    // The 26.64 Wh pack: state of charge 1 - E / 95 904 J.
    let soc = uav.battery_soc_end.unwrap();
    assert!((soc - (1.0 - energy / 95_904.0)).abs() < 1e-9, "{soc}");
    // One UAV: the run's totals are its own.
    assert_eq!(summary.energy_j, Some(energy));
    assert!((summary.avg_power_w.unwrap() - average).abs() < 1e-6 * average);
    assert_eq!(summary.battery_soc_end, Some(soc));

    // summary.json carries the keys; uavs.csv the power and the four rotor speeds.
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.path().join("summary.json")).unwrap()).unwrap();
    for key in [
        "energy_j",
        "avg_power_w",
        "peak_power_w",
        "power_std_w",
        "path_length_m",
        "battery_soc_end",
    ] {
        assert!(json[key].is_f64(), "{key}: {}", json[key]);
        assert!(json["uavs"][0][key].is_f64(), "uavs.0.{key}");
    }
    let series = std::fs::read_to_string(dir.path().join("uavs.csv")).unwrap();
    let mut lines = series.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let column = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let (power, w0, w3) = (
        column("power_w"),
        column("rotor_speed_0"),
        column("rotor_speed_3"),
    );
    let first: Vec<&str> = lines.next().unwrap().split(',').collect();
    // At t = 0 the UAV hovers: 1086.43 rad/s on every rotor, 123.14 W.
    let hover_speed: f64 = first[w0].parse().unwrap();
    assert!((hover_speed - 1086.43).abs() < 0.01, "{hover_speed}");
    let hover_power: f64 = first[power].parse().unwrap();
    assert!((hover_power - HOVER_POWER_W).abs() < 0.01, "{hover_power}");
    // Power in the series follows from the rotor speeds of the same row, to within the
    // half-step motor lag between the speeds recorded and the midpoint speeds powered.
    let airframe = Airframe::kingfisher();
    for line in lines {
        let row: Vec<&str> = line.split(',').collect();
        let speeds: Vec<f64> = row[w0..=w3].iter().map(|s| s.parse().unwrap()).collect();
        let from_speeds = total_power(
            &airframe.power,
            &[speeds[0], speeds[1], speeds[2], speeds[3]],
        );
        let recorded: f64 = row[power].parse().unwrap();
        assert!(
            (recorded - from_speeds).abs() < 0.05 * recorded,
            "{recorded} vs {from_speeds} at {line}"
        );
    }
}

#[test]
fn the_rollout_of_the_planned_tour_predicts_the_flown_energy() {
    let loaded = scenario::load("scenarios/pillars_waypoints.toml").unwrap();
    let flown = common::run_quietly(&loaded);
    let energy = flown.uavs[0].energy_j.unwrap();
    // The plan the run flew, from a fresh build of the same scenario.
    let mut sim = Sim::build(&loaded, loaded.scenario.seed).unwrap();
    let reference: Arc<_> = sim
        .world
        .query::<&ReferenceTrajectory>()
        .single(&sim.world)
        .unwrap()
        .trajectory
        .clone();
    let airframe = Airframe::kingfisher();
    let start = FlightState::hovering(&airframe, glam::DVec3::new(0.0, 0.0, 1.0), 0.0);
    let predicted = rollout(
        &airframe,
        &start,
        reference.as_ref(),
        &RolloutConfig::default(),
    )
    .unwrap();
    // EAAE's estimator (0.02 s, midpoint energy) against the 300 Hz rapier flight: within 2 %
    // (the bound of the flight core's 20 random trajectories), and the same duration to a few
    // ticks (the run ends on the tick the UAV arrives, the rollout on its 0.02 s grid).
    let error = predicted.energy_j / energy - 1.0;
    eprintln!(
        "rollout {:.1} J in {:.3} s, flown {energy:.1} J in {:.3} s: {:+.3} %",
        predicted.energy_j,
        predicted.duration_s,
        flown.mission_time_s,
        100.0 * error
    );
    assert!(
        error.abs() < 0.02,
        "rollout {predicted:?} vs flown {energy} J"
    );
    assert!(
        (predicted.duration_s - flown.mission_time_s).abs() < 0.05,
        "{} vs {}",
        predicted.duration_s,
        flown.mission_time_s
    );
}
