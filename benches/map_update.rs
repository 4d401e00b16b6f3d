//! Map update cost (common.md §1): one depth-camera frame integrated into a 0.1 m map.
//!
//! The camera (640 x 480 px, horizontal FoV 1.0 rad, common.md §2) stands in a 20 m box room
//! and looks at a wall 3 to 5 m away. Two ray sets:
//! - "auto": the angular grid matched to the map (step 0.02 rad = resolution / max range),
//!   1,938 rays;
//! - "per_pixel": one ray per pixel, 307,200 rays.
//!
//! Each iteration integrates the same frame as a new scan into a warmed-up map (all chunks
//! exist), which is the steady state of a run. Throughput is reported in DDA voxel visits.
//! A third case runs the ECS system `integrate_scans` on the auto frame, to show what lending
//! the chunk entities adds to the plain function.

use bevy_ecs::prelude::*;
use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use glam::{DVec3, Vec3};
use std::hint::black_box;
use uavex_components::map::{
    LogOddsIncrements, MapConfig, MapSettings, MapTotals, ScanCounter, StatSums,
};
use uavex_components::sensor::{Scan, SensorId, SensorQuality};
use uavex_components::sim::RunEnd;
use uavex_systems::mapping::{
    ChunkStore, ScanRays, insert_map_resources, integrate_scan, integrate_scan_tallied,
    integrate_scans,
};

const OCTOMAP: LogOddsIncrements = LogOddsIncrements {
    hit: 847,
    miss: -405,
};
const ORIGIN: Vec3 = Vec3::new(16.0, 10.0, 5.0);

fn room() -> MapConfig {
    MapConfig::new(&MapSettings {
        resolution: 0.1,
        bounds_min: DVec3::ZERO,
        bounds_max: DVec3::splat(20.0),
        ..MapSettings::default()
    })
    .expect("valid map settings")
}

/// Where a ray from [`ORIGIN`] along `dir` meets the wall: the plane through (19.5, 10, 5)
/// turned 15 degrees about z, so ranges spread over about 3.5 to 4.9 m across the image.
fn wall_hit(dir: Vec3) -> Vec3 {
    let normal = Vec3::new(0.9659, -0.2588, 0.0);
    let on_wall = Vec3::new(19.5, 10.0, 5.0);
    let t = (on_wall - ORIGIN).dot(normal) / dir.dot(normal);
    ORIGIN + dir * t
}

/// Rays of a pinhole camera looking along +x: `columns x rows` rays spread evenly over the
/// image (the camera's own grid when 640 x 480).
fn pinhole_frame(columns: usize, rows: usize) -> Scan {
    let focal = 320.0 / (0.5_f32).tan(); // px, from the 1.0 rad horizontal FoV
    let mut endpoints = Vec::with_capacity(columns * rows);
    for r in 0..rows {
        for c in 0..columns {
            let u = (c as f32 + 0.5) / columns as f32 * 640.0 - 320.0;
            let v = (r as f32 + 0.5) / rows as f32 * 480.0 - 240.0;
            endpoints.push(wall_hit(Vec3::new(focal, -u, -v).normalize()));
        }
    }
    Scan {
        origin: ORIGIN,
        hit: vec![true; endpoints.len()],
        endpoints,
        sequence: 1,
        time_s: 0.0,
    }
}

/// The matched grid: angular step 0.02 rad over 1.0 x 0.75 rad.
fn auto_frame() -> Scan {
    pinhole_frame(51, 38)
}

/// CPU time of this thread (ns) from Linux's `/proc/thread-self/schedstat`; `None` elsewhere.
fn thread_cpu_ns() -> Option<u64> {
    let stat = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    stat.split_whitespace().next()?.parse().ok()
}

/// Median CPU time per call (ns) over 7 batches of about 0.3 s of CPU each. On a shared
/// machine wall-clock times (criterion's) include time waiting for a core; CPU time does not.
fn cpu_time_per_call(mut f: impl FnMut()) -> Option<f64> {
    let start = thread_cpu_ns()?;
    f();
    let once = (thread_cpu_ns()? - start).max(1);
    let calls = (300_000_000 / once).clamp(1, 10_000);
    let mut batches: Vec<f64> = (0..7)
        .map(|_| {
            let t0 = thread_cpu_ns().unwrap_or(0);
            for _ in 0..calls {
                f();
            }
            (thread_cpu_ns().unwrap_or(0) - t0) as f64 / calls as f64
        })
        .collect();
    batches.sort_by(f64::total_cmp);
    Some(batches[3])
}

fn bench_plain(c: &mut Criterion) {
    let config = room();
    let mut group = c.benchmark_group("map_update");
    for (name, scan, samples) in [
        ("auto", auto_frame(), 50),
        ("per_pixel", pinhole_frame(640, 480), 10),
    ] {
        let mut store = ChunkStore::new(&config);
        let mut totals = StatSums::default();
        let mut counter = ScanCounter::default();
        // With `tallied`, the report counts how the walks skipped; the timed runs do not, as
        // the map update does not.
        let mut integrate = |store: &mut ChunkStore, totals: &mut StatSums, tallied: bool| {
            let integrate_scan = if tallied {
                integrate_scan_tallied
            } else {
                integrate_scan
            };
            integrate_scan(
                &config,
                counter.next_id(),
                ScanRays::of(&scan),
                OCTOMAP,
                store,
                totals,
            )
            .expect("valid scan")
        };
        // Steady state: the frame again until its free space is saturated (the last time
        // with the tallies, for the line below).
        for _ in 0..10 {
            integrate(&mut store, &mut totals, false);
        }
        let report = integrate(&mut store, &mut totals, true);
        let ranges = scan.endpoints.iter().map(|p| p.distance(ORIGIN));
        let (near, far) = ranges.fold((f32::MAX, 0.0_f32), |(a, b), r| (a.min(r), b.max(r)));
        println!(
            "{name}: {} rays, ranges {near:.2}..{far:.2} m, {} voxel visits per frame \
             ({} passed over in saturated cubes), {} voxels known, {} chunks",
            report.rays,
            report.voxel_visits,
            report.skipped_voxels,
            totals.known(),
            store.chunk_count()
        );
        if let Some(ns) = cpu_time_per_call(|| {
            black_box(integrate(&mut store, &mut totals, false));
        }) {
            println!(
                "{name}: CPU time {:.3} ms per frame, {:.1} M voxel visits per CPU second",
                ns / 1e6,
                report.voxel_visits as f64 / ns * 1e3
            );
        }
        group.sample_size(samples);
        group.throughput(Throughput::Elements(report.voxel_visits));
        group.bench_function(BenchmarkId::new("plain", name), |b| {
            b.iter(|| black_box(integrate(&mut store, &mut totals, false)))
        });
    }
    group.finish();
}

fn bench_ecs(c: &mut Criterion) {
    let mut world = World::new();
    insert_map_resources(&mut world, room());
    world.insert_resource(RunEnd::default());
    let quality = SensorQuality::from_probabilities(0.7, 0.4, 0.0);
    let sensor = world.spawn((SensorId(0), auto_frame(), quality)).id();
    let mut schedule = Schedule::default();
    schedule.add_systems(integrate_scans);
    schedule.run(&mut world);
    let chunks = world.resource::<uavex_components::map::ChunkIndex>().len();
    let known = world.resource::<MapTotals>().0.known();
    println!("ecs auto: {chunks} chunk entities, {known} voxels known");
    let mut next_frame = |world: &mut World| {
        world
            .get_mut::<Scan>(sensor)
            .expect("sensor has a scan")
            .sequence += 1;
        schedule.run(world);
    };
    if let Some(ns) = cpu_time_per_call(|| next_frame(&mut world)) {
        println!("ecs auto: CPU time {:.3} ms per frame", ns / 1e6);
    }
    let mut group = c.benchmark_group("map_update");
    group.sample_size(50);
    group.bench_function(BenchmarkId::new("ecs_system", "auto"), |b| {
        b.iter(|| next_frame(&mut world))
    });
    group.finish();
}

criterion_group!(benches, bench_plain, bench_ecs);
criterion_main!(benches);
