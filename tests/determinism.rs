//! A run is a pure function of scenario and seed, whatever the thread count (DESIGN.md).

mod common;

use uavex::engine::output::RunSummary;
use uavex::engine::run::{RunOptions, run};

/// Two UAVs, range noise (seeded per sensor) and a seeded pillar field: every source of
/// randomness a run has today.
const SCENARIO: &str = r#"
name = "determinism"
seed = 11
time_limit_s = 6.0
physics_rate_hz = 100.0

[world.bounds]
min = [-8.0, -8.0, 0.0]
max = [8.0, 8.0, 3.0]

[[world.obstacle]]
kind = "pillars"
region_min = [-7.0, -7.0]
region_max = [7.0, 7.0]
density = 0.08
radius_min = 0.15
radius_max = 0.4
height = 3.0

[[uav]]
name = "a"
start = { position = [0.0, 0.0, 1.0] }
behaviour = { kind = "scripted", speed = 1.0, waypoints = [[3.0, 0.0, 1.0], [3.0, 3.0, 1.5]] }
[[uav.sensor]]
kind = "depth_camera"
quality = { range_noise_std = 0.03 }

[[uav]]
name = "b"
start = { position = [-1.0, -1.0, 1.2], yaw = 2.0 }
behaviour = { kind = "scripted", speed = 0.8, waypoints = [[-3.0, -1.0, 1.2]] }
[[uav.sensor]]
kind = "lidar"
beams_v = 8
vfov = 0.5
quality = { p_hit = 0.65, p_miss = 0.45, range_noise_std = 0.05 }
"#;

fn run_in_pool(threads: usize, dir: &std::path::Path) -> (RunSummary, String, String) {
    let loaded = common::scenario(SCENARIO);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    let options = RunOptions {
        out_dir: Some(dir.to_owned()),
        seed: None,
        ..RunOptions::default()
    };
    let mut summary = pool.install(|| run(&loaded, &options)).unwrap().summary;
    summary.wall_time_s = 0.0; // the one field that measures the host, not the run
    let read = |name: &str| std::fs::read_to_string(dir.join(name)).unwrap();
    (summary, read("series.csv"), read("uavs.csv"))
}

#[test]
fn same_seed_gives_identical_results_on_one_and_two_threads() {
    let tmp = tempfile::tempdir().unwrap();
    let one = run_in_pool(1, &tmp.path().join("one"));
    let two = run_in_pool(2, &tmp.path().join("two"));
    assert!(one.0.known_voxels > 10_000, "the run mapped something");
    assert_eq!(one.0, two.0);
    assert_eq!(one.1, two.1);
    assert_eq!(one.2, two.2);
    let bt = |d: &str| std::fs::read(tmp.path().join(d).join("map.bt")).unwrap();
    assert_eq!(bt("one"), bt("two"));
}

#[test]
fn another_seed_gives_another_run() {
    let loaded = common::scenario(SCENARIO);
    let a = run(&loaded, &RunOptions::default()).unwrap().summary;
    let b = run(
        &loaded,
        &RunOptions {
            out_dir: None,
            seed: Some(12),
            ..RunOptions::default()
        },
    )
    .unwrap()
    .summary;
    assert_ne!(
        a.known_voxels, b.known_voxels,
        "seed 12 should draw other pillars and noise"
    );
}
