//! Frontier cost (eaae.md steps 1-4) on a Pillars-sized map (22 x 22 x 2.5 m at 0.1 m).
//!
//! The frontier comes from depth-camera-like frames integrated into the map: a UAV at (0, 0, 1)
//! turns on the spot, one frame every 0.5 rad of yaw (13 frames for a full turn), each frame a
//! grid of max-range rays (5 m, horizontal FoV 1.0 rad, vertical 0.75 rad) at 0.03 rad steps.
//! The gaps the ray grid leaves at range are frontier too, which gives a frontier of the size a
//! Pillars run has in its first seconds (the count is printed).
//!
//! - `update/one_frame`: [`update_frontier_set`] for the chunks one frame changed (the
//!   per-tick cost of the Frontier stage);
//! - `update/all_chunks`: the same over every chunk of the map (a rebuild, for scale);
//! - `cluster/divisive_two_means`: the clustering alone on the frontier voxel centres;
//! - `cluster/cluster_frontier`: clustering + reachability + viewpoints (one decision's work).

use criterion::{Criterion, criterion_group, criterion_main};
use glam::{DVec3, Vec3};
use std::hint::black_box;
use uavex_components::frontier::{ClusterSettings, FrontierSet};
use uavex_components::map::{
    ChunkCoord, LogOddsIncrements, MapConfig, MapSettings, ScanCounter, StatSums,
};
use uavex_components::sim::{RunSeed, stream};
use uavex_systems::frontier::{cluster_frontier, divisive_two_means, update_frontier_set};
use uavex_systems::mapping::{ChunkStore, ScanRays, integrate_scan};

const OCTOMAP: LogOddsIncrements = LogOddsIncrements {
    hit: 847,
    miss: -405,
};
const ORIGIN: Vec3 = Vec3::new(0.0, 0.0, 1.0);

fn pillars_map() -> MapConfig {
    MapConfig::new(&MapSettings {
        resolution: 0.1,
        bounds_min: DVec3::new(-11.0, -11.0, 0.0),
        bounds_max: DVec3::new(11.0, 11.0, 2.5),
        ..MapSettings::default()
    })
    .expect("valid map settings")
}

/// End points of one frame's max-range rays, camera yawed by `yaw`.
fn frame(yaw: f32) -> Vec<Vec3> {
    let step = 0.03f32;
    let (h, v) = ((1.0 / step) as i32, (0.75 / step) as i32);
    let mut out = Vec::new();
    for j in -v / 2..=v / 2 {
        for i in -h / 2..=h / 2 {
            let (az, el) = (yaw + i as f32 * step, j as f32 * step);
            let dir = Vec3::new(el.cos() * az.cos(), el.cos() * az.sin(), el.sin());
            out.push(ORIGIN + dir * 5.0);
        }
    }
    out
}

/// Integrates a frame; returns the chunks it changed.
fn integrate(
    store: &mut ChunkStore,
    config: &MapConfig,
    counter: &mut ScanCounter,
    endpoints: &[Vec3],
) -> Vec<ChunkCoord> {
    let hit = vec![false; endpoints.len()];
    let rays = ScanRays {
        origin: ORIGIN,
        endpoints,
        hit: &hit,
    };
    let mut totals = StatSums::default();
    integrate_scan(config, counter.next_id(), rays, OCTOMAP, store, &mut totals)
        .expect("finite rays");
    store.take_written()
}

fn bench(c: &mut Criterion) {
    let config = pillars_map();
    let mut store = ChunkStore::new(&config);
    let mut counter = ScanCounter::default();
    let mut set = FrontierSet::default();
    let mut last_changed = Vec::new();
    for k in 0..13 {
        let endpoints = frame(k as f32 * 0.5);
        last_changed = integrate(&mut store, &config, &mut counter, &endpoints);
        update_frontier_set(&mut set, &store, &last_changed);
    }
    let grid = config.chunk_grid();
    let all: Vec<ChunkCoord> = (0..grid.len()).map(|f| grid.coord(f)).collect();
    let settings = ClusterSettings::default();
    let points: Vec<Vec3> = set.iter().map(|k| config.center_of(k)).collect();
    let clusters = cluster_frontier(
        &set,
        &store,
        &settings,
        &mut RunSeed(1).stream(stream::CLUSTERING, 0),
    );
    let all_clusters = divisive_two_means(
        &points,
        settings.r_max_m,
        &mut RunSeed(1).stream(stream::CLUSTERING, 0),
    );
    println!(
        "frontier: {} voxels in {} chunks; last frame changed {} chunks; {} clusters, {} kept \
         (>= {} voxels)",
        set.len(),
        set.chunks().count(),
        last_changed.len(),
        all_clusters.len(),
        clusters.len(),
        settings.min_cluster_voxels
    );

    let mut group = c.benchmark_group("update");
    group.bench_function("one_frame", |b| {
        b.iter(|| update_frontier_set(black_box(&mut set), &store, &last_changed))
    });
    group.bench_function("all_chunks", |b| {
        b.iter(|| update_frontier_set(black_box(&mut set), &store, &all))
    });
    group.finish();

    let mut group = c.benchmark_group("cluster");
    group.sample_size(20);
    let mut k = 0;
    group.bench_function("divisive_two_means", |b| {
        b.iter(|| {
            k += 1;
            let mut rng = RunSeed(1).stream(stream::CLUSTERING, k);
            divisive_two_means(black_box(&points), settings.r_max_m, &mut rng)
        })
    });
    group.bench_function("cluster_frontier", |b| {
        b.iter(|| {
            k += 1;
            let mut rng = RunSeed(1).stream(stream::CLUSTERING, k);
            cluster_frontier(black_box(&set), &store, &settings, &mut rng)
        })
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
