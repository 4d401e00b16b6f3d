//! How dynamic flights end, and what is refused before they start: a UAV flown into a wall
//! crashes there, a small battery runs out, a bad airframe override or a tour through a wall is
//! refused at its line; kinematic and dynamic UAVs share a run (issue 3, "Must show").

mod common;

use uavex::components::sim::Outcome;
use uavex::engine::run::{RunOptions, run};
use uavex::engine::scenario::{Diagnostic, LoadedScenario};

/// A scenario in `common::ROOM` (walls with faces at x = -4 and x = +4) with one kingfisher
/// starting at the origin, 1.5 m up, and the given behaviour and overrides.
fn room_scenario(behaviour: &str, overrides: &str) -> String {
    format!(
        r#"name = "room"
time_limit_s = 30.0
{room}
[[uav]]
name = "k"
start = {{ position = [0.0, 0.0, 1.5] }}
airframe_overrides = {{ {overrides} }}
behaviour = {behaviour}
"#,
        room = common::ROOM
    )
}

/// The errors `run` refuses a scenario with (the world-building ones included).
fn refusal(loaded: &LoadedScenario) -> Vec<Diagnostic> {
    run(loaded, &RunOptions::default())
        .expect_err("the scenario was accepted")
        .diagnostics
}

fn line_of(text: &str, needle: &str) -> usize {
    text.lines().position(|l| l.contains(needle)).unwrap() + 1
}

#[test]
fn a_uav_flown_into_a_wall_crashes_there_and_summary_json_says_so() {
    // Beyond the east wall's face (x = 4.0) and planned without the collision check.
    let text = room_scenario(
        r#"{ kind = "waypoints", waypoints = [[4.7, 0.0, 1.5]], collision_check = false }"#,
        "",
    );
    let loaded = common::scenario(&text);
    let dir = tempfile::tempdir().unwrap();
    let options = RunOptions {
        out_dir: Some(dir.path().to_owned()),
        seed: None,
        ..RunOptions::default()
    };
    let summary = run(&loaded, &options).unwrap().summary;
    assert_eq!(summary.outcome, Outcome::Crashed, "{}", summary.reason);
    assert!(
        summary.reason.contains("obstacle 'east'"),
        "{}",
        summary.reason
    );
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.path().join("summary.json")).unwrap()).unwrap();
    assert_eq!(json["outcome"], "crashed");
    let uav = &json["uavs"][0];
    assert_eq!(uav["status"], "crashed");
    // The collision box reaches 0.14 m ahead of the centre when level (0.28 m long); pitched
    // by up to 20 degrees its corner reaches 0.14 cos + 0.04 sin = 0.145 m. So the centre
    // stops between 4.0 - 0.145 = 3.855 and 3.86 m, one step (at most 5 m/s / 300 = 1.7 cm)
    // early at worst.
    let x = uav["ended_position"][0].as_f64().unwrap();
    assert!(x > 3.855 - 0.017 && x <= 3.861, "{x}");
    let y = uav["ended_position"][1].as_f64().unwrap();
    assert!(y.abs() < 0.05, "{y}");
    let time = uav["ended_time_s"].as_f64().unwrap();
    assert!(time > 0.5 && time <= summary.mission_time_s, "{time}");
    // It drew energy until the crash, and none after.
    let energy = uav["energy_j"].as_f64().unwrap();
    assert!(
        energy > 123.0 * time * 0.99 && energy < 1.5 * 123.14 * time,
        "{energy}"
    );
}

#[test]
fn a_small_battery_runs_out() {
    // 0.05 Wh = 180 J, 80 % usable: 144 J, i.e. 144 / 123.14 = 1.169 s of hover; a tour
    // draws a little more than hover, so it runs out a little earlier.
    let text = room_scenario(
        r#"{ kind = "waypoints", waypoints = [[2.0, 2.0, 1.5], [-2.0, 2.0, 1.5]] }"#,
        "battery_capacity_wh = 0.05",
    );
    let summary = common::run_quietly(&common::scenario(&text));
    assert_eq!(summary.outcome, Outcome::BatteryEmpty, "{}", summary.reason);
    let uav = &summary.uavs[0];
    assert_eq!(uav.status, "battery_empty");
    let time = uav.ended_time_s.unwrap();
    assert!(time > 1.0 && time <= 1.17, "{time}");
    assert!((summary.mission_time_s - time).abs() < 1e-9);
    // At least 144 J drawn (within one step of 1/300 s at < 200 W), so 20 % of 180 J left.
    let energy = uav.energy_j.unwrap();
    assert!((144.0..144.7).contains(&energy), "{energy}");
    assert!((uav.battery_soc_end.unwrap() - 0.2).abs() < 0.004);
}

#[test]
fn bad_airframe_overrides_are_refused_at_their_line() {
    // Too heavy to lift (8.5 N per rotor carry at most 3.47 kg).
    let text = room_scenario(
        r#"{ kind = "waypoints", waypoints = [[2.0, 0.0, 1.5]] }"#,
        "mass = 4.0",
    );
    let errors = refusal(&common::scenario(&text));
    assert_eq!(errors.len(), 1, "{errors:?}");
    assert_eq!(errors[0].path, "uav[0].airframe_overrides.mass");
    assert_eq!(errors[0].line, line_of(&text, "mass = 4.0"));
    assert!(
        errors[0].message.contains("less than the weight"),
        "{}",
        errors[0]
    );

    // An unknown name, with the valid ones listed.
    let text = room_scenario(
        r#"{ kind = "scripted", speed = 1.0, waypoints = [[2.0, 0.0, 1.5]] }"#,
        "weight = 1.0",
    );
    let errors = refusal(&common::scenario(&text));
    assert_eq!(errors[0].path, "uav[0].airframe_overrides.weight");
    assert_eq!(errors[0].line, line_of(&text, "weight = 1.0"));
    assert!(
        errors[0].message.contains("thrust_coefficient"),
        "{}",
        errors[0]
    );
}

#[test]
fn planning_limits_beyond_a_multirotor_are_refused_at_their_line() {
    // 1e30 m/s once made the planner's collision sampling (a step of spacing / max_velocity
    // over a trajectory whose length the acceleration sets) run forever.
    let text = room_scenario(
        r#"{ kind = "waypoints", waypoints = [[2.0, 0.0, 1.5]] }"#,
        "max_velocity = 1e30",
    );
    let errors = refusal(&common::scenario(&text));
    assert_eq!(errors.len(), 1, "{errors:?}");
    assert_eq!(errors[0].path, "uav[0].airframe_overrides.max_velocity");
    assert_eq!(errors[0].line, line_of(&text, "max_velocity = 1e30"));
    assert!(
        errors[0]
            .message
            .contains("max_velocity must be in [0.1, 100]"),
        "{}",
        errors[0]
    );
}

#[test]
fn a_flight_that_diverges_ends_failed_with_the_reason() {
    // A roll inertia of 1e-30 kg m^2 passes every check on its own, but the attitude dynamics
    // blow up within steps: the run must say so, not fail later on a sensor origin that is
    // not finite, nor run on with NaN metrics.
    let text = room_scenario(
        r#"{ kind = "waypoints", waypoints = [[2.0, 0.0, 1.5]] }"#,
        "inertia_xx = 1e-30",
    );
    let summary = common::run_quietly(&common::scenario(&text));
    assert_eq!(summary.outcome, Outcome::Failed, "{}", summary.reason);
    assert!(
        summary
            .reason
            .starts_with("UAV 'k' became numerically unstable at t = "),
        "{}",
        summary.reason
    );
    assert!(summary.mission_time_s < 1.0, "{}", summary.mission_time_s);
}

#[test]
fn a_tour_into_a_wall_or_too_close_to_it_is_refused_at_its_waypoint() {
    let text = room_scenario(
        r#"{ kind = "waypoints", waypoints = [
    [2.0, 0.0, 1.5],
    [3.8, 0.0, 1.5],
] }"#,
        "",
    );
    // 3.8 m is 0.2 m from the face: inside the 0.32 m clearance of the kingfisher
    // (bounding radius 0.22 m and the 0.1 m margin).
    let errors = refusal(&common::scenario(&text));
    assert_eq!(errors.len(), 1, "{errors:?}");
    assert_eq!(errors[0].path, "uav[0].behaviour.waypoints[1]");
    assert_eq!(errors[0].line, line_of(&text, "[3.8, 0.0, 1.5]"));
    assert!(errors[0].message.contains("0.32 m"), "{}", errors[0]);
}

#[test]
fn kinematic_and_dynamic_uavs_fly_together_and_deterministically() {
    let text = format!(
        r#"name = "mixed"
time_limit_s = 30.0
{room}
[[uav]]
name = "walker"
start = {{ position = [0.0, -2.0, 1.0] }}
behaviour = {{ kind = "scripted", speed = 1.0, waypoints = [[1.0, -2.0, 1.0]] }}

[[uav]]
name = "flyer"
airframe = "iris"
start = {{ position = [0.0, 2.0, 1.0] }}
behaviour = {{ kind = "waypoints", waypoints = [[2.0, 2.0, 1.5]], yaw = [0.5] }}
"#,
        room = common::ROOM
    );
    let loaded = common::scenario(&text);
    let summary = common::run_quietly(&loaded);
    assert_eq!(summary.outcome, Outcome::Complete, "{}", summary.reason);
    let (walker, flyer) = (&summary.uavs[0], &summary.uavs[1]);
    assert_eq!(
        (walker.status.as_str(), flyer.status.as_str()),
        ("finished", "finished")
    );
    // The kinematic UAV has no energy account: null, not zero.
    assert_eq!(walker.energy_j, None);
    assert_eq!(walker.battery_soc_end, None);
    // The IRIS hovers at its measured 221.3 W (coverage.md); the run's totals are the flyer's.
    let energy = flyer.energy_j.unwrap();
    let time = summary.mission_time_s;
    assert!(
        energy > 221.2 * time * 0.99 && energy < 1.5 * 221.3 * time,
        "{energy}"
    );
    assert_eq!(summary.energy_j, Some(energy));
    assert_eq!(summary.battery_soc_end, flyer.battery_soc_end);
    // The same scenario and seed give the same run, bit for bit.
    let again = common::run_quietly(&loaded);
    let strip = |mut s: uavex::engine::output::RunSummary| {
        s.wall_time_s = 0.0;
        s
    };
    assert_eq!(strip(summary), strip(again));
}

#[test]
fn a_heading_list_of_the_wrong_length_is_refused_on_loading() {
    let text = room_scenario(
        r#"{ kind = "waypoints", waypoints = [[2.0, 0.0, 1.5], [2.0, 2.0, 1.5]], yaw = [0.0] }"#,
        "",
    );
    let errors = uavex::engine::scenario::parse_str(&text, "test.toml")
        .expect_err("accepted")
        .diagnostics;
    assert_eq!(errors.len(), 1, "{errors:?}");
    assert_eq!(errors[0].path, "uav[0].behaviour.yaw");
    assert!(
        errors[0].message.contains("one heading per waypoint (2)"),
        "{}",
        errors[0]
    );
}
