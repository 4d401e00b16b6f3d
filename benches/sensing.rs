//! Sensing cost (common.md §2) in the EAAE Pillars scene (`scenarios/eaae_pillars.toml`).
//!
//! - `raycast`: rays per second against the scene's parry BVH (ground, four walls, three
//!   pillars): the thesis camera's 307,200 per-pixel rays from in front of pillar 1, cast one by
//!   one and as one batch (parallel above `PARALLEL_RAY_THRESHOLD`), and a 270 deg planar lidar
//!   (1,080 beams, 20 m).
//! - `sense_and_map`: one thesis-camera frame swept and integrated into a warmed-up 0.1 m map
//!   (all chunks exist, the steady state of a run), with the auto grid (55 x 41 = 2,255 rays)
//!   and with one ray per pixel (307,200 rays); `sweep_only` is the sensing part alone. The same
//!   frame again and again: its free space is saturated after a few frames, so this is the
//!   cost of a camera at rest.
//! - `flight`: the camera flown around the three pillars at 3 m/s (the heading snapping at each
//!   corner), 30 frames per second, each swept and integrated in turn into a map that starts
//!   empty: the cost of frames in flight, where each sees new space next to saturated space.
//!   Throughput is in frames.
//! - `forest`: one thesis-camera frame (auto grid) swept in the shipped forest of round trunks
//!   (`scenarios/eaae_forest.toml`), whose rays meet cylinders (cast in closed form, not by
//!   parry's GJK).

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group};
use glam::{DVec3, Quat, Vec3};
use std::hint::black_box;
use uavex_components::map::{LogOddsIncrements, MapConfig, MapSettings, ScanId, StatSums};
use uavex_components::sensor::{Scan, SensorQuality};
use uavex_components::sim::RunSeed;
use uavex_components::world::WorldGeometry;
use uavex_engine::scenario;
use uavex_engine::world::build_world;
use uavex_systems::mapping::{
    ChunkStore, ScanRays, ScanReport, integrate_scan, integrate_scan_tallied,
};
use uavex_systems::sensing::{
    LidarBeams, PinholeCamera, RayGrid, RayPattern, SensorPose, SweepScratch, camera_pattern,
    lidar_pattern, sweep,
};

const THESIS_CAMERA: PinholeCamera = PinholeCamera {
    width: 640,
    height: 480,
    hfov: 1.0,
};

/// 2.5 m in front of pillar 1's north face, looking at it (-y): the pillar fills the middle of
/// the image, the floor its bottom, the south wall (beyond range) its sides.
fn facing_pillar() -> SensorPose {
    SensorPose {
        origin: Vec3::new(0.0, -2.9, 1.2),
        rotation: Quat::from_rotation_z(-std::f32::consts::FRAC_PI_2),
    }
}

fn pillars() -> (WorldGeometry, MapConfig) {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/scenarios/eaae_pillars.toml");
    let loaded = scenario::load(path).expect("the shipped Pillars scenario loads");
    let world_spec = &loaded.scenario.world;
    let start = Vec3::new(0.0, 0.0, 1.0);
    let world = build_world(world_spec, RunSeed(1), &[start], &[], &loaded.base_dir)
        .expect("the Pillars world builds");
    let map = MapConfig::new(&MapSettings {
        resolution: loaded.scenario.map.resolution,
        bounds_min: DVec3::from_array(world_spec.bounds.min),
        bounds_max: DVec3::from_array(world_spec.bounds.max),
        p_min: loaded.scenario.map.p_min,
        p_max: loaded.scenario.map.p_max,
    })
    .expect("valid map");
    (world, map)
}

fn per_pixel() -> RayPattern {
    let grid = RayGrid::Explicit {
        columns: 640,
        rows: 480,
    };
    camera_pattern(THESIS_CAMERA, grid, 0.5, 5.0).unwrap()
}

fn raycast(c: &mut Criterion) {
    let (world, _) = pillars();
    let pose = facing_pillar();
    let camera: Vec<Vec3> = per_pixel()
        .directions
        .iter()
        .map(|d| pose.rotation * *d)
        .collect();
    let lidar = lidar_pattern(
        LidarBeams {
            hfov: 270f64.to_radians(),
            beams_h: 1080,
            vfov: 0.0,
            beams_v: 1,
        },
        0.1,
        20.0,
    )
    .unwrap();

    let mut group = c.benchmark_group("raycast");
    group.throughput(Throughput::Elements(camera.len() as u64));
    group.bench_function("camera_per_pixel_one_by_one", |b| {
        b.iter(|| {
            let mut hits = 0u32;
            for dir in &camera {
                hits += u32::from(world.cast_ray(pose.origin, *dir, 5.0).is_some());
            }
            black_box(hits)
        })
    });
    let mut distances = Vec::new();
    group.bench_function("camera_per_pixel_batch", |b| {
        b.iter(|| {
            world.cast_rays(pose.origin, &camera, 5.0, &mut distances);
            black_box(distances.len())
        })
    });
    group.throughput(Throughput::Elements(lidar.directions.len() as u64));
    group.bench_function("lidar_270deg_1080_beams_20m", |b| {
        b.iter(|| {
            world.cast_rays(
                Vec3::new(0.0, 0.0, 1.0),
                &lidar.directions,
                20.0,
                &mut distances,
            );
            black_box(distances.len())
        })
    });
    group.finish();
}

fn sense_and_map(c: &mut Criterion) {
    let (world, map) = pillars();
    let increments = map
        .increments(&SensorQuality::from_probabilities(0.7, 0.4, 0.0))
        .unwrap();
    let auto = camera_pattern(THESIS_CAMERA, RayGrid::Auto { resolution: 0.1 }, 0.5, 5.0).unwrap();
    let mut group = c.benchmark_group("sense_and_map");
    for (name, pattern) in [("auto", auto), ("per_pixel", per_pixel())] {
        let mut store = ChunkStore::new(&map);
        let mut totals = StatSums::default();
        let mut scan = Scan::default();
        let mut scratch = SweepScratch::default();
        let mut id = ScanId::after(None);
        // One frame of the camera facing a pillar into `scan`.
        let frame = |scratch: &mut SweepScratch, scan: &mut Scan| {
            sweep(&pattern, facing_pillar(), &world, None, scratch, scan, 0.0);
        };
        // Warm-up: the chunks this frame touches exist, buffers have their size.
        frame(&mut scratch, &mut scan);
        let rays = ScanRays::of(&scan);
        integrate_scan(&map, id, rays, increments, &mut store, &mut totals).unwrap();
        group.throughput(Throughput::Elements(pattern.directions.len() as u64));
        group.bench_function(BenchmarkId::new("sweep_only", name), |b| {
            b.iter(|| {
                frame(&mut scratch, &mut scan);
                black_box(scan.endpoints.len())
            })
        });
        group.bench_function(BenchmarkId::new("thesis_camera_frame", name), |b| {
            b.iter(|| {
                frame(&mut scratch, &mut scan);
                id = ScanId::after(Some(id));
                let rays = ScanRays::of(&scan);
                black_box(
                    integrate_scan(&map, id, rays, increments, &mut store, &mut totals).unwrap(),
                )
            })
        });
    }
    group.finish();
}

/// One thesis-camera frame (the auto grid) swept in the shipped forest
/// (`scenarios/eaae_forest.toml`, seed 1: 0.12 round trunks per m^2, a ball, a crate
/// and a column), at its start, turning on the spot: rays against cylinders, cast in closed
/// form (`uavex_components::world::cast_local_cylinder`).
fn forest(c: &mut Criterion) {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/scenarios/eaae_forest.toml");
    let loaded = scenario::load(path).expect("the shipped forest loads");
    let start = Vec3::new(0.0, 0.0, 1.0);
    let world = build_world(
        &loaded.scenario.world,
        RunSeed(1),
        &[start],
        &[],
        &loaded.base_dir,
    )
    .expect("the forest builds");
    let auto = camera_pattern(THESIS_CAMERA, RayGrid::Auto { resolution: 0.1 }, 0.5, 5.0).unwrap();
    let mut scratch = SweepScratch::default();
    let mut scan = Scan::default();
    let mut group = c.benchmark_group("forest");
    // A turn on the spot, one frame every 45 degrees.
    let poses: Vec<SensorPose> = (0..8)
        .map(|k| SensorPose {
            origin: start,
            rotation: Quat::from_rotation_z(k as f32 * std::f32::consts::FRAC_PI_4),
        })
        .collect();
    group.throughput(Throughput::Elements(
        (poses.len() * auto.directions.len()) as u64,
    ));
    group.bench_function("sweep_only_auto_turn_of_8_frames", |b| {
        b.iter(|| {
            for pose in &poses {
                sweep(&auto, *pose, &world, None, &mut scratch, &mut scan, 0.0);
                black_box(scan.endpoints.len());
            }
        })
    });
    group.finish();
}

/// Camera poses every 1/30 s along a loop around the pillars at 3 m/s, 1.25 m high, looking
/// along the direction of travel (698 frames).
fn flight_poses() -> Vec<SensorPose> {
    const CORNERS: [[f32; 2]; 7] = [
        [0.0, 0.0],
        [-7.5, 0.0],
        [-7.5, -8.5],
        [7.5, -8.5],
        [7.5, 7.5],
        [-7.5, 7.5],
        [-7.5, 0.0],
    ];
    let step = 3.0 / 30.0;
    let mut poses = Vec::new();
    for leg in CORNERS.windows(2) {
        let (a, b) = (
            Vec3::new(leg[0][0], leg[0][1], 1.25),
            Vec3::new(leg[1][0], leg[1][1], 1.25),
        );
        let heading = b - a;
        let rotation = Quat::from_rotation_z(heading.y.atan2(heading.x));
        let frames = (heading.length() / step).round() as usize;
        poses.extend((0..frames).map(|i| SensorPose {
            origin: a + heading * (i as f32 / frames as f32),
            rotation,
        }));
    }
    poses
}

/// The flight of [`flight_poses`], swept and integrated frame by frame into a new map; adds
/// each frame's report to `report` and returns the number of chunks made.
struct Flight {
    world: WorldGeometry,
    map: MapConfig,
    increments: LogOddsIncrements,
    auto: RayPattern,
    poses: Vec<SensorPose>,
    scratch: SweepScratch,
    scan: Scan,
}

impl Flight {
    fn new() -> Self {
        let (world, map) = pillars();
        let increments = map
            .increments(&SensorQuality::from_probabilities(0.7, 0.4, 0.0))
            .unwrap();
        let auto =
            camera_pattern(THESIS_CAMERA, RayGrid::Auto { resolution: 0.1 }, 0.5, 5.0).unwrap();
        Self {
            world,
            map,
            increments,
            auto,
            poses: flight_poses(),
            scratch: SweepScratch::default(),
            scan: Scan::default(),
        }
    }

    /// Flies the poses, mapping every frame; with `tallied`, the report counts how the walks
    /// skipped (`integrate_scan_tallied`), else only visits and changes, as the map update runs.
    fn fly(&mut self, report: &mut ScanReport, tallied: bool) -> usize {
        let mut store = ChunkStore::new(&self.map);
        let mut totals = StatSums::default();
        let mut id = None;
        for &pose in &self.poses {
            let (pattern, world) = (&self.auto, &self.world);
            sweep(
                pattern,
                pose,
                world,
                None,
                &mut self.scratch,
                &mut self.scan,
                0.0,
            );
            let scan_id = ScanId::after(id);
            id = Some(scan_id);
            let integrate = if tallied {
                integrate_scan_tallied
            } else {
                integrate_scan
            };
            let r = integrate(
                &self.map,
                scan_id,
                ScanRays::of(&self.scan),
                self.increments,
                &mut store,
                &mut totals,
            )
            .unwrap();
            report.voxel_visits += r.voxel_visits;
            report.skipped_voxels += r.skipped_voxels;
            report.chunk_visits += r.chunk_visits;
            report.free_box_voxels += r.free_box_voxels;
            report.free_box_rays += r.free_box_rays;
            report.free_box_exits += r.free_box_exits;
            for (total, crossed) in report.cubes_crossed.iter_mut().zip(r.cubes_crossed) {
                *total += crossed;
            }
        }
        store.chunk_count()
    }
}

fn flight(c: &mut Criterion) {
    let mut flight = Flight::new();
    let frames = flight.poses.len();
    let mut report = ScanReport::default();
    flight.fly(&mut report, true);
    eprintln!(
        "flight: {} frames, {:.0} voxel visits per frame, {:.1} % passed over in saturated cubes \
         (per frame: a first free box of {:.0} voxels, {:.0} rays ending in a box, {:.0} moves \
         out of one; {:.0} bricks, {:.0} blocks, {:.0} chunks crossed; {:.0} chunk visits)",
        frames,
        report.voxel_visits as f64 / frames as f64,
        100.0 * report.skipped_voxels as f64 / report.voxel_visits as f64,
        report.free_box_voxels as f64 / frames as f64,
        report.free_box_rays as f64 / frames as f64,
        report.free_box_exits as f64 / frames as f64,
        report.cubes_crossed[0] as f64 / frames as f64,
        report.cubes_crossed[1] as f64 / frames as f64,
        report.cubes_crossed[2] as f64 / frames as f64,
        report.chunk_visits as f64 / frames as f64,
    );
    let mut group = c.benchmark_group("flight");
    group.sample_size(10);
    group.throughput(Throughput::Elements(frames as u64));
    group.bench_function("thesis_camera_auto_frames", |b| {
        b.iter(|| black_box(flight.fly(&mut ScanReport::default(), false)))
    });
    group.finish();
}

criterion_group!(benches, raycast, sense_and_map, forest, flight);

/// `SENSING_PROFILE_FLIGHT=n cargo bench --bench sensing`: fly the flight n times and nothing
/// else, for profilers that count instructions (callgrind), where criterion's timing loop
/// would run a varying number of iterations.
fn main() {
    if let Some(n) = std::env::var("SENSING_PROFILE_FLIGHT")
        .ok()
        .and_then(|n| n.parse::<usize>().ok())
    {
        let mut flight = Flight::new();
        let mut report = ScanReport::default();
        for _ in 0..n {
            black_box(flight.fly(&mut report, false));
        }
        eprintln!(
            "{n} flights of {} frames: {} voxel visits",
            flight.poses.len(),
            report.voxel_visits
        );
        return;
    }
    benches();
    Criterion::default().configure_from_args().final_summary();
}
