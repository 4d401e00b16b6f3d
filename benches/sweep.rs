//! Sweep throughput (runs per second) with 1 and 2 jobs, the scaling that `--jobs` buys.
//!
//! The plan: 8 runs (4 cruise speeds x 2 seeds) of a 10 x 10 x 2.5 m room with a seeded pillar
//! field, one UAV flying a scripted square at 1.1 m with the thesis depth camera (auto ray
//! grid, 0.1 m map, 300 Hz physics, 8 s simulated). Each sample runs the whole plan into a
//! fresh folder (nothing to resume), with all files written, as `uavex sweep` does.

use criterion::{BatchSize, BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use std::path::Path;
use uavex_engine::sweep::{Plan, SweepOptions, run_sweep};

const ROOM: &str = r#"
name = "bench_room"
time_limit_s = 8.0

[world.bounds]
min = [-5.0, -5.0, 0.0]
max = [5.0, 5.0, 2.5]

[[world.obstacle]]
kind = "pillars"
region_min = [-4.5, -4.5]
region_max = [4.5, 4.5]
density = 0.06
radius_min = 0.15
radius_max = 0.35
height = 2.5

[[uav]]
name = "kingfisher"
start = { position = [0.0, 0.0, 1.1] }
behaviour = { kind = "scripted", speed = 1.0, waypoints = [[3.0, 0.0, 1.1], [3.0, 3.0, 1.1], [-3.0, 3.0, 1.1], [-3.0, -3.0, 1.1]] }
[[uav.sensor]]
kind = "depth_camera"

[outputs]
export_map = false
"#;

const PLAN: &str = r#"
name = "bench"
seeds = 2
[[scenario]]
file = "room.toml"
[grid]
"uav.0.behaviour.speed" = [0.75, 1.0, 1.25, 1.5]
"#;

fn plan(dir: &Path) -> Plan {
    std::fs::write(dir.join("room.toml"), ROOM).expect("write the scenario");
    Plan::parse(PLAN, &dir.join("plan.toml")).expect("the bench plan parses")
}

fn throughput(c: &mut Criterion) {
    let scratch = tempfile::tempdir().expect("a scratch folder");
    let plan = plan(scratch.path());
    let runs = plan.run_count() as u64;
    let mut group = c.benchmark_group("sweep");
    group.sample_size(10);
    group.throughput(Throughput::Elements(runs));
    for jobs in [1, 2] {
        group.bench_function(BenchmarkId::new("jobs", jobs), |b| {
            b.iter_batched(
                || tempfile::tempdir_in(scratch.path()).expect("an output folder"),
                |out| {
                    let mut options = SweepOptions::new(out.path());
                    options.jobs = jobs;
                    let report = run_sweep(&plan, &options).expect("the sweep runs");
                    assert_eq!((report.ran, report.failed.len()), (runs as usize, 0));
                    out
                },
                BatchSize::PerIteration,
            );
        });
    }
    group.finish();
}

criterion_group!(benches, throughput);
criterion_main!(benches);
