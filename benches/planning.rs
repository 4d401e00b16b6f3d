//! Planning cost (EAAE steps 6 and 9) on a Pillars-like map (22 x 22 x 2.5 m at 0.1 m, the
//! bounds of `scenarios/eaae_pillars.toml`), everything known: free inside, the floor and the
//! outermost voxel layer along the walls occupied, the three 2 x 2 m pillars occupied.
//! Inflation: the kingfisher's bounding radius plus the 0.1 m margin.
//!
//! - `refresh/one_changed_chunk`: one map chunk changed, so it and its 26 neighbours are
//!   recomputed (the cost per chunk is this / 27); `refresh/whole_map`: every chunk.
//! - `find_paths/40_goals`: one Dijkstra from the centre to 40 goals spread over the map.
//! - `find_path/across`: A* from one corner region to the opposite one.
//! - `plan_along/*`: the minimum-snap fit along a ~10 m path, straight and around a pillar.
//! - `plan_local/horizon_7.5m`: the local planner toward a goal 15 m away.

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use glam::{DVec3, IVec3};
use std::hint::black_box;
use uavex_components::airframe::Airframe;
use uavex_components::map::{ChunkCoord, MapConfig, MapSettings, local_index};
use uavex_components::trajectory::TrajectoryPoint;
use uavex_systems::behaviour::waypoints::CLEARANCE_MARGIN_M;
use uavex_systems::mapping::{ChunkAccess, ChunkStore};
use uavex_systems::planning::{
    TraversableGrid, find_path, find_paths, path_length, plan_along, plan_local,
};
use uavex_systems::trajectory::DynamicLimits;

const FREE: i16 = -1992;
const OCCUPIED: i16 = 3476;

fn pillars() -> (MapConfig, ChunkStore) {
    let config = MapConfig::new(&MapSettings {
        resolution: 0.1,
        bounds_min: DVec3::new(-10.8609, -10.9254, 0.0),
        bounds_max: DVec3::new(10.5891, 11.2747, 2.5),
        ..MapSettings::default()
    })
    .expect("valid map settings");
    let mut store = ChunkStore::new(&config);
    let pillars = [
        DVec3::new(-0.3643, -6.3997, 0.0),
        DVec3::new(5.2752, 4.8380, 0.0),
        DVec3::new(-5.1558, 4.5622, 0.0),
    ];
    let (lo, hi) = (config.key_min(), config.key_max());
    for z in lo.z..=hi.z {
        for y in lo.y..=hi.y {
            for x in lo.x..=hi.x {
                let key = IVec3::new(x, y, z);
                let centre = config.center_of(key).as_dvec3();
                let wall = x == lo.x || x == hi.x || y == lo.y || y == hi.y || z == lo.z;
                let pillar = pillars
                    .iter()
                    .any(|p| (centre.x - p.x).abs() <= 1.0 && (centre.y - p.y).abs() <= 1.0);
                let coord = ChunkCoord::of_key(key);
                let flat = config.chunk_grid().flat(coord).expect("key in the map");
                let (chunk, _) = store.chunk_mut(flat, coord);
                chunk.voxels_mut()[local_index(key)].log_odds =
                    if wall || pillar { OCCUPIED } else { FREE };
            }
        }
    }
    (config, store)
}

fn inflation() -> f64 {
    Airframe::kingfisher().bounding_radius() + CLEARANCE_MARGIN_M
}

fn built_grid(config: &MapConfig, store: &ChunkStore) -> TraversableGrid {
    let mut grid = TraversableGrid::new(config, inflation());
    grid.mark_all();
    grid.refresh(store);
    grid
}

/// 40 goals on a jittered 8 x 5 grid over the room, at 1.0 to 1.8 m.
fn goals() -> Vec<DVec3> {
    (0..40)
        .map(|i| {
            let (gx, gy) = (i % 8, i / 8);
            DVec3::new(
                -9.5 + 2.6 * gx as f64 + 0.3 * (i % 3) as f64,
                -9.5 + 4.6 * gy as f64 + 0.2 * (i % 4) as f64,
                1.0 + 0.2 * (i % 5) as f64,
            )
        })
        .collect()
}

fn bench_refresh(c: &mut Criterion) {
    let (config, store) = pillars();
    let mut grid = built_grid(&config, &store);
    let mut group = c.benchmark_group("refresh");
    let chunk = ChunkCoord::of_key(IVec3::new(0, 0, 10));
    group.bench_function("one_changed_chunk", |b| {
        b.iter(|| {
            grid.mark_changed(chunk);
            grid.refresh(black_box(&store));
        })
    });
    group.sample_size(20);
    group.bench_function("whole_map", |b| {
        b.iter(|| {
            grid.mark_all();
            grid.refresh(black_box(&store));
        })
    });
    group.finish();
}

fn bench_search(c: &mut Criterion) {
    let (config, store) = pillars();
    let grid = built_grid(&config, &store);
    let goals = goals();
    let centre = DVec3::new(0.0, 0.0, 1.0);
    let found = find_paths(&grid, centre, &goals, usize::MAX);
    let reached = found.iter().flatten().count();
    let lattice = grid.lattice();
    let open = (0..lattice.len()).filter(|&i| lattice.is_open(i)).count();
    eprintln!(
        "find_paths: {reached} of {} goals reached; lattice {} cells, {open} open",
        goals.len(),
        lattice.len()
    );
    let mut group = c.benchmark_group("find_paths");
    group.sample_size(20);
    group.bench_function("40_goals", |b| {
        b.iter(|| find_paths(black_box(&grid), centre, black_box(&goals), usize::MAX))
    });
    group.finish();
    let (from, to) = (DVec3::new(-9.0, -9.0, 1.0), DVec3::new(9.0, 9.5, 1.5));
    let path = find_path(&grid, from, to, usize::MAX).expect("a path across the room");
    eprintln!("find_path across: {:.2} m", path_length(&path));
    c.bench_function("find_path/across", |b| {
        b.iter(|| find_path(black_box(&grid), from, to, usize::MAX))
    });
}

fn bench_trajectories(c: &mut Criterion) {
    let (config, store) = pillars();
    let grid = built_grid(&config, &store);
    let limits = DynamicLimits::of(&Airframe::kingfisher());
    let start = TrajectoryPoint::at_rest(DVec3::new(0.0, 0.0, 1.0), 0.0);
    let mut group = c.benchmark_group("plan_along");
    for (name, goal) in [
        ("straight_10m", DVec3::new(8.0, -6.0, 1.5)),
        ("around_pillar_10m", DVec3::new(0.0, -9.5, 1.0)),
    ] {
        let path = find_path(&grid, start.position, goal, usize::MAX).expect("a path");
        let plan = plan_along(&grid, &start, &path, None, &limits).expect("a plan");
        eprintln!(
            "plan_along {name}: lattice path {:.2} m ({} points), shortened {:.2} m ({} points), {} segments",
            path_length(&path),
            path.len(),
            plan.path_length_m,
            plan.path.len(),
            plan.trajectory.segments().len()
        );
        group.bench_function(BenchmarkId::from_parameter(name), |b| {
            b.iter(|| plan_along(black_box(&grid), &start, black_box(&path), None, &limits))
        });
    }
    group.finish();
    let goal = DVec3::new(-8.0, 9.0, 1.2);
    c.bench_function("plan_local/horizon_7.5m", |b| {
        b.iter(|| plan_local(black_box(&grid), &start, goal, None, 7.5, &limits))
    });
}

criterion_group!(benches, bench_refresh, bench_search, bench_trajectories);
criterion_main!(benches);
