//! common.md §2: "a ray grid whose angular step matches resolution / max_range sees the same
//! voxels [as one ray per pixel] at a fraction of the cost". Checked in the EAAE Pillars scene:
//! the same camera poses, once with the auto grid and once per pixel, each integrated into a
//! fresh map; the two maps must mark (almost) the same voxels with the same states.

use super::build_world;
use crate::scenario::WorldSpec;
use glam::{DVec3, IVec3, Quat, Vec3};
use std::collections::{HashMap, HashSet};
use std::path::Path;
use uavex_components::map::{MapConfig, MapSettings, ScanId, VoxelState};
use uavex_components::sensor::{Scan, SensorQuality};
use uavex_components::sim::RunSeed;
use uavex_components::world::WorldGeometry;
use uavex_systems::mapping::{ChunkStore, OccupancyMap, ScanRays, integrate_scan};
use uavex_systems::sensing::{
    PinholeCamera, RayGrid, RayPattern, SensorPose, SweepScratch, camera_pattern, sweep,
};

/// The Pillars scene of /work/shared/worlds/eaae.md (walls and pillars as yawed boxes).
pub(super) const PILLARS_WORLD: &str = r#"
bounds = { min = [-10.8609, -10.9254, 0.0], max = [10.5891, 11.2747, 2.5] }
[[obstacle]]
kind = "box"
name = "wall east"
center = [10.6641, 0.1746, 1.25]
size = [22.5, 0.15, 2.5]
yaw = -1.5708
[[obstacle]]
kind = "box"
name = "wall south"
center = [-0.1359, -11.0004, 1.25]
size = [21.75, 0.15, 2.5]
yaw = 3.14159
[[obstacle]]
kind = "box"
name = "wall west"
center = [-10.9359, 0.1746, 1.25]
size = [22.5, 0.15, 2.5]
yaw = 1.5708
[[obstacle]]
kind = "box"
name = "wall north"
center = [-0.1359, 11.3497, 1.25]
size = [21.75, 0.15, 2.5]
yaw = 0.0
[[obstacle]]
kind = "box"
name = "pillar 1"
center = [-0.3643, -6.3997, 1.25]
size = [2.0, 2.0, 2.5]
[[obstacle]]
kind = "box"
name = "pillar 2"
center = [5.2752, 4.8380, 1.25]
size = [2.0, 2.0, 2.5]
yaw = -1.5708
[[obstacle]]
kind = "box"
name = "pillar 3"
center = [-5.1558, 4.5622, 1.25]
size = [2.0, 2.0, 2.5]
yaw = -1.5708
"#;

pub(super) fn pillars_world() -> (WorldSpec, WorldGeometry) {
    let spec: WorldSpec = toml::from_str(PILLARS_WORLD).unwrap();
    let world = build_world(
        &spec,
        RunSeed(0),
        &[Vec3::new(0.0, 0.0, 1.0)],
        &[],
        Path::new("."),
    )
    .unwrap();
    (spec, world)
}

/// Camera poses: in front of each pillar, along a wall, looking into a corner (position, yaw).
const POSES: [([f32; 3], f32); 6] = [
    ([0.0, 0.0, 1.0], 0.0),
    ([0.0, -2.5, 1.2], -std::f32::consts::FRAC_PI_2),
    ([2.0, 2.0, 1.0], 0.785),
    ([-2.0, 1.5, 1.5], 2.2),
    ([7.0, -7.0, 1.0], -0.785),
    ([-7.0, -2.0, 0.8], 3.0),
];

/// One frame of `pattern` from every pose, each integrated into one fresh map; the known voxels
/// of that map with their states.
fn map_of_frames(
    world: &WorldGeometry,
    spec: &WorldSpec,
    pattern: &RayPattern,
) -> HashMap<IVec3, VoxelState> {
    let config = MapConfig::new(&MapSettings {
        resolution: 0.1,
        bounds_min: DVec3::from_array(spec.bounds.min),
        bounds_max: DVec3::from_array(spec.bounds.max),
        p_min: 0.12,
        p_max: 0.97,
    })
    .unwrap();
    let increments = config
        .increments(&SensorQuality::from_probabilities(0.7, 0.4, 0.0))
        .unwrap();
    let mut store = ChunkStore::new(&config);
    let mut totals = Default::default();
    let (mut scan, mut scratch, mut id) = (Scan::default(), SweepScratch::default(), None);
    for (position, yaw) in POSES {
        let pose = SensorPose {
            origin: Vec3::from_array(position),
            rotation: Quat::from_rotation_z(yaw),
        };
        sweep(pattern, pose, world, None, &mut scratch, &mut scan, 0.0);
        let scan_id = ScanId::after(id);
        id = Some(scan_id);
        integrate_scan(
            &config,
            scan_id,
            ScanRays::of(&scan),
            increments,
            &mut store,
            &mut totals,
        )
        .unwrap();
    }
    store
        .known_voxels()
        .map(|(key, _)| (key, store.state(key)))
        .collect()
}

/// How well a coarse map reproduces a fine one.
#[derive(Debug)]
struct Agreement {
    /// Voxels known in both / known in the fine map.
    known: f64,
    /// Voxels known in both with the same state / known in the fine map.
    same_state: f64,
    /// Occupied in both / occupied in the fine map.
    occupied: f64,
    /// Voxels known in the coarse map only / known in the coarse map.
    extra: f64,
}

fn agreement(fine: &HashMap<IVec3, VoxelState>, coarse: &HashMap<IVec3, VoxelState>) -> Agreement {
    let both = fine.keys().filter(|k| coarse.contains_key(k)).count();
    let same = fine
        .iter()
        .filter(|(k, s)| coarse.get(k) == Some(s))
        .count();
    let occupied = |m: &HashMap<IVec3, VoxelState>| {
        m.iter()
            .filter(|(_, s)| **s == VoxelState::Occupied)
            .map(|(k, _)| *k)
            .collect::<HashSet<_>>()
    };
    let (occ_fine, occ_coarse) = (occupied(fine), occupied(coarse));
    let occ_both = occ_fine.intersection(&occ_coarse).count();
    Agreement {
        known: both as f64 / fine.len() as f64,
        same_state: same as f64 / fine.len() as f64,
        occupied: occ_both as f64 / occ_fine.len() as f64,
        extra: (coarse.len() - both) as f64 / coarse.len() as f64,
    }
}

/// Measured (6 poses, 0.1 m map): per pixel 307,200 rays mark 122,611 voxels (4,682 occupied);
/// the auto grid's 2,255 rays mark 118,282 of them plus 1 other: 96.5 % of the voxels, 96.1 %
/// with the same state, 89.0 % of the occupied ones (the misses are surfaces seen at grazing
/// angles, where rays one voxel apart across the view land further apart along the surface).
/// A grid at twice the auto step (28 x 21 rays) falls to 75.9 % of the voxels and 38.3 % of the
/// occupied ones, so the thresholds separate "matched to the voxel size" from merely "coarse".
#[test]
fn auto_grid_marks_the_voxels_one_ray_per_pixel_marks() {
    let (spec, world) = pillars_world();
    let camera = PinholeCamera {
        width: 640,
        height: 480,
        hfov: 1.0,
    };
    let pattern = |grid| camera_pattern(camera, grid, 0.5, 5.0).unwrap();
    let auto = pattern(RayGrid::Auto { resolution: 0.1 });
    let per_pixel = pattern(RayGrid::Explicit {
        columns: 640,
        rows: 480,
    });
    let half = pattern(RayGrid::Explicit {
        columns: 28,
        rows: 21,
    });
    let fine = map_of_frames(&world, &spec, &per_pixel);
    let matched = agreement(&fine, &map_of_frames(&world, &spec, &auto));
    let coarser = agreement(&fine, &map_of_frames(&world, &spec, &half));
    println!(
        "per pixel: {} voxels known; auto {matched:?}; half {coarser:?}",
        fine.len()
    );
    assert!(fine.len() > 100_000, "the frames must see a real scene");
    assert!(
        matched.known > 0.95 && matched.same_state > 0.95,
        "{matched:?}"
    );
    assert!(
        matched.occupied > 0.85 && matched.extra < 0.01,
        "{matched:?}"
    );
    assert!(
        coarser.known < 0.85 && coarser.occupied < 0.5,
        "{coarser:?}"
    );
}
