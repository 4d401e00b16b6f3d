//! The command line refuses bad scenarios with located messages and exit code 2, and runs good
//! ones into an output folder.

use std::process::Command;

fn uavex(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_uavex"))
        .args(args)
        .output()
        .unwrap()
}

const BAD: &str = r#"name = "bad"
time_limit_s = 10.0

[world.bounds]
min = [0.0, 0.0, 0.0]
max = [10.0, 10.0, 3.0]

[[uav]]
name = "u"
start = { position = [20.0, 5.0, 1.0] }
behaviour = { kind = "scripted", speed = 1.0, waypoints = [[5.0, 5.0, 1.0]] }
[[uav.sensor]]
kind = "depth_camera"
range_min = 6.0
rnage_max = 5.0
"#;

#[test]
fn validate_and_run_refuse_a_bad_scenario_with_every_problem_located() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("bad.toml");
    std::fs::write(&file, BAD).unwrap();
    let file = file.to_str().unwrap();
    for args in [vec!["validate", file], vec!["run", file]] {
        let out = uavex(&args);
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        let err = String::from_utf8(out.stderr).unwrap();
        // The misspelt field, with its line and a suggestion.
        assert!(err.contains(&format!("{file}:15:")), "{err}");
        assert!(
            err.contains("rnage_max") && err.contains("range_max"),
            "{err}"
        );
        // The start outside the bounds, at its line.
        assert!(err.contains(&format!("{file}:10:")), "{err}");
        assert!(err.contains("uav[0].start.position"), "{err}");
    }
}

#[test]
fn run_writes_summary_series_and_map_files() {
    let dir = tempfile::tempdir().unwrap();
    let scenario = dir.path().join("ok.toml");
    std::fs::write(
        &scenario,
        r#"name = "ok"
time_limit_s = 5.0
physics_rate_hz = 60.0
[world.bounds]
min = [-3.0, -3.0, 0.0]
max = [3.0, 3.0, 2.0]
[[world.obstacle]]
kind = "sphere"
center = [2.0, 0.0, 1.0]
radius = 0.5
[[uav]]
name = "u"
start = { position = [0.0, 0.0, 1.0] }
behaviour = { kind = "scripted", speed = 1.0, waypoints = [[0.0, 1.0, 1.0]] }
[[uav.sensor]]
kind = "depth_camera"
"#,
    )
    .unwrap();
    let out_dir = dir.path().join("out");
    let out = uavex(&[
        "run",
        scenario.to_str().unwrap(),
        "--out",
        out_dir.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let summary: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out_dir.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["outcome"], "complete");
    for key in [
        "mission_time_s",
        "explored_fraction",
        "entropy_known_bits",
        "entropy_box_bits",
    ] {
        assert!(summary[key].is_number(), "{key} in {summary}");
    }
    assert!(summary["map_accuracy"].as_f64().unwrap() > 0.95);
    for file in ["series.csv", "uavs.csv", "map.bt", "map_occupied.ply"] {
        assert!(out_dir.join(file).metadata().unwrap().len() > 0, "{file}");
    }
    // The host's time per stage: every stage once, in tick order, with shares summing to
    // 100 %; this run senses and maps, so those stages took time.
    let timings = std::fs::read_to_string(out_dir.join("stage_timings.csv")).unwrap();
    let rows: Vec<Vec<&str>> = timings.lines().map(|l| l.split(',').collect()).collect();
    assert_eq!(
        rows[0],
        ["stage", "wall_s", "share_pct", "mean_us_per_tick"]
    );
    let stages: Vec<&str> = rows[1..].iter().map(|r| r[0]).collect();
    let order = [
        "sense", "map", "frontier", "decide", "adapt", "plan", "control", "physics", "account",
    ];
    assert_eq!(stages, order, "{timings}");
    let number = |r: &Vec<&str>, i: usize| r[i].parse::<f64>().unwrap();
    let shares: f64 = rows[1..].iter().map(|r| number(r, 2)).sum();
    assert!((shares - 100.0).abs() < 0.1, "{timings}");
    assert!(
        number(&rows[1], 1) > 0.0 && number(&rows[2], 1) > 0.0,
        "{timings}"
    );
}

/// A build without the `record` feature refuses `--record` (exit code 2, naming the feature)
/// before running anything, rather than running without the recording asked for.
#[cfg(not(feature = "record"))]
#[test]
fn run_refuses_to_record_without_the_record_feature() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("run.rrd");
    let out = uavex(&[
        "run",
        "scenarios/eaae_pillars.toml",
        "--record",
        file.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8(out.stderr).unwrap();
    assert!(
        err.contains("--record") && err.contains("`record` feature"),
        "{err}"
    );
    assert!(!file.exists());
}
