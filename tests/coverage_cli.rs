//! `uavex energy`, `uavex cover` and `uavex calibrate` run as a user runs them (issue 6).

use std::path::Path;
use std::process::{Command, Output};

fn uavex(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_uavex"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("the uavex binary runs")
}

fn stdout(output: &Output) -> String {
    String::from_utf8_lossy(&output.stdout).into_owned()
}

#[test]
fn energy_prints_the_optimal_speed_of_the_iris_preset() {
    let output = uavex(&["energy", "iris", "--distance", "100"]);
    assert!(output.status.success(), "{output:?}");
    let text = stdout(&output);
    // A 100 m leg at a = 1 m/s^2 reaches at most sqrt(a d) = 10 m/s; t(d, v) = 2 v / a +
    // (d - v^2 / a) / v = 2 x 9.784 + (100 - 95.73) / 9.784 = 20.00 s.
    assert!(
        text.contains("optimal speed v*(d)       9.784 m/s"),
        "{text}"
    );
    assert!(text.contains("time t(d)                 20.00 s"), "{text}");
    assert!(text.contains("hover power P(0)          221.3 W"), "{text}");
}

#[test]
fn energy_refuses_unknown_models_and_bad_distances() {
    let output = uavex(&["energy", "no_such_model", "--distance", "100"]);
    assert_eq!(output.status.code(), Some(2));
    let error = String::from_utf8_lossy(&output.stderr);
    assert!(
        error.contains("not a preset energy model (presets: iris)"),
        "{error}"
    );
    let output = uavex(&["energy", "iris", "--distance", "-3"]);
    assert_eq!(output.status.code(), Some(2));
}

#[test]
fn cover_plans_writes_the_files_and_the_flight_matches_the_prediction() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().to_str().unwrap();
    let output = uavex(&[
        "cover",
        "scenarios/coverage_field.toml",
        "--out",
        out,
        "--fly",
    ]);
    assert!(output.status.success(), "{output:?}");
    let text = stdout(&output);
    assert!(
        text.contains("feasible at the required resolution"),
        "{text}"
    );
    assert!(
        text.contains("areas           3 (1 + 2 cut off at concavities)"),
        "{text}"
    );
    for name in [
        "coverage_field_waypoints.csv",
        "coverage_field_legs.csv",
        "coverage_field.geojson",
        "coverage_field.svg",
        "coverage_field_flown.json",
    ] {
        assert!(dir.path().join(name).is_file(), "{name} missing");
    }
    let png = std::fs::read(dir.path().join("coverage_field.png")).unwrap();
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
    let geojson = std::fs::read_to_string(dir.path().join("coverage_field.geojson")).unwrap();
    assert!(geojson.contains("FeatureCollection"));
    // The check: predicted energy within 5 % of the flown energy (the model was
    // calibrated on the airframe flown; see the scenario's header).
    let flown: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(dir.path().join("coverage_field_flown.json")).unwrap(),
    )
    .unwrap();
    let energy_error = flown["energy_error"].as_f64().unwrap();
    let time_error = flown["time_error"].as_f64().unwrap();
    assert!(energy_error.abs() < 0.05, "{flown}");
    assert!(time_error.abs() < 0.05, "{flown}");
    assert!(
        flown["flown_energy_j"].as_f64().unwrap() > 50_000.0,
        "{flown}"
    );
}

#[test]
fn cover_refuses_a_scenario_without_a_coverage_uav() {
    let output = uavex(&["cover", "scenarios/pillars_waypoints.toml"]);
    assert_eq!(output.status.code(), Some(2));
    let error = String::from_utf8_lossy(&output.stderr);
    assert!(error.contains("no UAV with"), "{error}");
}

#[test]
fn cover_shows_problems_at_their_line_and_field() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bad.toml");
    let text = std::fs::read_to_string("scenarios/coverage_field.toml").unwrap();
    let line = 1 + text
        .lines()
        .position(|l| l.starts_with("overlap = { x = 0.2"))
        .unwrap();
    let typo = text.replacen("overlap = { x = 0.2", "overlap = { x = 1.5, y_was = 0.2", 1);
    std::fs::write(&path, typo).unwrap();
    let output = uavex(&["cover", path.to_str().unwrap()]);
    assert_eq!(output.status.code(), Some(2));
    let error = String::from_utf8_lossy(&output.stderr);
    // The typo is reported by the loader's decoding, at the key.
    assert!(
        error.starts_with(&format!(
            "{}:{line}:22: uav[0].behaviour.overlap.y_was: unknown field",
            path.display()
        )),
        "{error}"
    );
    let out_of_range = text.replacen("overlap = { x = 0.2", "overlap = { x = 1.5", 1);
    std::fs::write(&path, out_of_range).unwrap();
    let output = uavex(&["cover", path.to_str().unwrap()]);
    assert_eq!(output.status.code(), Some(2));
    let error = String::from_utf8_lossy(&output.stderr);
    assert_eq!(
        error.trim_end(),
        format!(
            "{}:{line}:17: uav[0].behaviour.overlap.x: overlap along x must lie in [0, 1), got 1.5",
            path.display()
        )
    );
}

#[test]
fn calibrate_writes_a_model_that_energy_reads() {
    let dir = tempfile::tempdir().unwrap();
    let model = dir.path().join("models").join("kf.json");
    let output = uavex(&["calibrate", "kingfisher", "--out", model.to_str().unwrap()]);
    assert!(output.status.success(), "{output:?}");
    let text = stdout(&output);
    assert!(text.contains("fresh legs"), "{text}");
    for path in [
        model.clone(),
        dir.path().join("models/kf_fit.txt"),
        dir.path().join("models/kf_measurements.csv"),
    ] {
        assert!(Path::new(&path).is_file(), "{} missing", path.display());
    }
    let output = uavex(&["energy", model.to_str().unwrap(), "--distance", "50"]);
    assert!(output.status.success(), "{output:?}");
    // The kingfisher hovers at 123 W (physics tests); the fit's P(0) recovers it.
    assert!(
        stdout(&output).contains("hover power P(0)          123.1 W"),
        "{}",
        stdout(&output)
    );
}

/// `uavex run` flies the coverage behaviour on the true quadrotor in the ECS: its summary's
/// energy is within 5 % of the plan's prediction (eq. 18) with the calibrated model.
#[test]
fn run_flies_the_coverage_scenario_as_predicted() {
    let dir = tempfile::tempdir().unwrap();
    let output = uavex(&[
        "run",
        "scenarios/coverage_field.toml",
        "--out",
        dir.path().to_str().unwrap(),
    ]);
    assert!(output.status.success(), "{output:?}");
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("summary.json")).unwrap())
            .unwrap();
    let scenario = uavex_engine::coverage::read_coverage_scenario(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/coverage_field.toml"),
    )
    .unwrap();
    let setup = scenario
        .spec
        .resolve(scenario.base_dir(), &scenario.path)
        .unwrap();
    let predicted = setup.plan().unwrap().plan;
    let flown_energy = summary["energy_j"].as_f64().unwrap();
    let flown_time = summary["mission_time_s"].as_f64().unwrap();
    assert_eq!(summary["reason"], "every UAV completed its behaviour");
    assert!(
        (flown_energy / predicted.energy_j - 1.0).abs() < 0.05,
        "{summary}"
    );
    assert!(
        (flown_time / predicted.time_s - 1.0).abs() < 0.05,
        "{summary}"
    );
    // The summary itself carries the prediction beside the flown figures.
    let uav = &summary["uavs"][0];
    assert_eq!(uav["predicted_energy_j"].as_f64(), Some(predicted.energy_j));
    assert_eq!(uav["predicted_time_s"].as_f64(), Some(predicted.time_s));
    assert_eq!(uav["energy_j"].as_f64(), Some(flown_energy));
}
