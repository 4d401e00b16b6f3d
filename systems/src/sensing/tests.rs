//! Ray patterns, sweeps and the Sense system, against hand-derived values.

use super::*;
use bevy_ecs::system::RunSystemOnce;
use glam::{Quat, Vec3};
use parry3d::math::Pose;
use parry3d::shape::SharedShape;
use rand_chacha::ChaCha8Rng;
use rand_chacha::rand_core::SeedableRng;
use std::f32::consts::FRAC_PI_2;
use uavex_components::sensor::{Mount, Scan, SensorOf, SensorQuality};
use uavex_components::sim::SimClock;
use uavex_components::uav::QuadState;
use uavex_components::world::{Obstacle, WorldGeometry};

/// EAAE Table 5.1 camera: 640 x 480, hfov 1.0 rad.
const THESIS: PinholeCamera = PinholeCamera {
    width: 640,
    height: 480,
    hfov: 1.0,
};

fn angle(a: Vec3, b: Vec3) -> f64 {
    a.as_dvec3().angle_between(b.as_dvec3())
}

/// Largest angle between 4-neighbours of a grid pattern (brute force over all pairs).
fn max_neighbour_angle(p: &RayPattern) -> f64 {
    let at = |r: u32, c: u32| p.directions[(r * p.columns + c) as usize];
    let mut worst = 0.0f64;
    for r in 0..p.rows {
        for c in 0..p.columns {
            if c + 1 < p.columns {
                worst = worst.max(angle(at(r, c), at(r, c + 1)));
            }
            if r + 1 < p.rows {
                worst = worst.max(angle(at(r, c), at(r + 1, c)));
            }
        }
    }
    worst
}

fn wall(center: Vec3, size: Vec3) -> Obstacle {
    let h = size * 0.5;
    Obstacle::new(
        "wall",
        "test",
        Pose::from_translation(center),
        SharedShape::cuboid(h.x, h.y, h.z),
    )
}

#[test]
fn per_pixel_grid_has_one_ray_per_pixel_through_pixel_centres() {
    let explicit = RayGrid::Explicit {
        columns: 640,
        rows: 480,
    };
    let p = camera_pattern(THESIS, explicit, 0.5, 5.0).unwrap();
    assert_eq!(p.directions.len(), 307_200);
    assert_eq!((p.columns, p.rows), (640, 480));
    // Focal length 320 / tan(0.5) = 585.756 px; vertical FoV 2 atan(0.75 tan 0.5) = 0.777727 rad.
    assert!((THESIS.focal_px() - 585.756_07).abs() < 1e-4);
    assert!((THESIS.vfov() - 0.777_726_76).abs() < 1e-7);
    // Top-left pixel centre: 319.5 px left of and 239.5 px above the axis.
    let corner = p.directions[0];
    let az = f64::from(corner.y).atan2(f64::from(corner.x));
    let el = f64::from(corner.z).atan2(f64::from(corner.x));
    assert!(
        (az - (319.5f64 / 585.756_070_9).atan()).abs() < 1e-6,
        "{az}"
    );
    assert!(
        (el - (239.5f64 / 585.756_070_9).atan()).abs() < 1e-6,
        "{el}"
    );
    // The outer edge of the corner pixel (half a pixel further out) lies on the FoV:
    // tan(az) * 320 / 319.5 = tan(hfov / 2), tan(el) * 240 / 239.5 = tan(vfov / 2).
    assert!(((az.tan() * 320.0 / 319.5).atan() - 0.5).abs() < 1e-6);
    assert!(((el.tan() * 240.0 / 239.5).atan() - 0.388_863_38).abs() < 1e-6);
    // Bottom-right mirrors top-left; rows go down, columns go right (towards -y).
    let last = p.directions[307_199];
    assert!((last - Vec3::new(corner.x, -corner.y, -corner.z)).length() < 1e-6);
    assert!(p.directions[1].y < corner.y && p.directions[640].z < corner.z);
    assert!(
        p.directions
            .iter()
            .all(|d| (d.length() - 1.0).abs() < 1e-6 && d.x > 0.0)
    );
}

#[test]
fn auto_grid_is_the_coarsest_meeting_the_step_bound() {
    // Step bound 0.1 m / 5 m = 0.02 rad. Image plane 2 tan(0.5) = 1.0926 wide, 0.8195 high.
    // 55 columns: central pair at 0 and s = 1.0926 / 55, atan(s) = 0.019863 <= 0.02;
    // 54 columns: central pair at +-s/2, 2 atan(s/2) = 0.020233 > 0.02. Rows: 41 give 0.019984,
    // 40 give 0.020486.
    let grid = auto_grid(THESIS, 0.1, 5.0).unwrap();
    assert_eq!(grid, (55, 41));
    let p = camera_pattern(THESIS, RayGrid::Auto { resolution: 0.1 }, 0.5, 5.0).unwrap();
    assert_eq!(p.directions.len(), 55 * 41);
    let worst = max_neighbour_angle(&p);
    assert!(worst <= 0.02 && worst > 0.0199, "{worst}");
    for (columns, rows) in [(54, 41), (55, 40)] {
        let coarser = camera_pattern(THESIS, RayGrid::Explicit { columns, rows }, 0.5, 5.0);
        assert!(
            max_neighbour_angle(&coarser.unwrap()) > 0.02,
            "{columns} x {rows}"
        );
    }
    // The bound holds for other cameras too, and one column fewer breaks it.
    for (camera, res, range) in [
        (
            PinholeCamera {
                width: 848,
                height: 480,
                hfov: 1.5,
            },
            0.05,
            8.0,
        ),
        (
            PinholeCamera {
                width: 100,
                height: 100,
                hfov: 0.3,
            },
            0.2,
            2.0,
        ),
    ] {
        let step = res / range;
        let (c, r) = auto_grid(camera, res, range).unwrap();
        let grid = RayGrid::Explicit {
            columns: c,
            rows: r,
        };
        assert!(max_neighbour_angle(&camera_pattern(camera, grid, 0.1, range).unwrap()) <= step);
        let fewer = RayGrid::Explicit {
            columns: c - 1,
            rows: r,
        };
        let p = camera_pattern(camera, fewer, 0.1, range).unwrap();
        assert!(max_neighbour_angle(&p) > step);
    }
}

#[test]
fn bad_camera_and_lidar_parameters_are_refused() {
    let auto = RayGrid::Auto { resolution: 0.1 };
    let wide = PinholeCamera {
        hfov: 3.2,
        ..THESIS
    };
    assert_eq!(
        camera_pattern(wide, auto, 0.5, 5.0).unwrap_err().field,
        "hfov"
    );
    assert_eq!(
        camera_pattern(THESIS, auto, 6.0, 5.0).unwrap_err().field,
        "range_max"
    );
    let tiny = RayGrid::Auto { resolution: 1e-7 };
    assert_eq!(
        camera_pattern(THESIS, tiny, 0.5, 5.0).unwrap_err().field,
        "ray_grid"
    );
    let empty = RayGrid::Explicit {
        columns: 0,
        rows: 4,
    };
    assert_eq!(
        camera_pattern(THESIS, empty, 0.5, 5.0).unwrap_err().field,
        "ray_grid"
    );
    let flat = LidarBeams {
        hfov: 1.0,
        beams_h: 10,
        vfov: 0.0,
        beams_v: 4,
    };
    assert_eq!(lidar_pattern(flat, 0.1, 20.0).unwrap_err().field, "vfov");
}

#[test]
fn planar_lidar_sweeps_270_degrees_in_the_horizontal_plane() {
    let beams = LidarBeams {
        hfov: 270f64.to_radians(),
        beams_h: 1080,
        vfov: 0.0,
        beams_v: 1,
    };
    let p = lidar_pattern(beams, 0.1, 20.0).unwrap();
    assert_eq!((p.directions.len(), p.columns, p.rows), (1080, 1080, 1));
    let azimuth = |d: Vec3| f64::from(d.y).atan2(f64::from(d.x)).to_degrees();
    // First beam on the right edge (-135 deg), last on the left (+135 deg), 270/1079 deg apart.
    assert!((azimuth(p.directions[0]) + 135.0).abs() < 1e-4);
    assert!((azimuth(p.directions[1079]) - 135.0).abs() < 1e-4);
    let step = 270.0 / 1079.0;
    for pair in p.directions.windows(2) {
        assert!((angle(pair[0], pair[1]).to_degrees() - step).abs() < 1e-4);
    }
    assert!(p.directions.iter().all(|d| d.z == 0.0));
    // Nothing behind: the 90 deg sector around -x is empty.
    assert!(
        p.directions
            .iter()
            .all(|d| azimuth(*d).abs() <= 135.0 + 1e-4)
    );
}

#[test]
fn full_circle_and_multi_beam_lidar() {
    let ring = LidarBeams {
        hfov: std::f64::consts::TAU,
        beams_h: 4,
        vfov: 0.0,
        beams_v: 1,
    };
    let p = lidar_pattern(ring, 0.1, 20.0).unwrap();
    let expected = [-Vec3::X, -Vec3::Y, Vec3::X, Vec3::Y];
    for (got, want) in p.directions.iter().zip(expected) {
        assert!((*got - want).length() < 1e-6, "{got} vs {want}");
    }
    // 16 beams over 30 deg (a VLP-16): top row at +15 deg, bottom at -15 deg, 2 deg apart.
    let vlp = LidarBeams {
        hfov: std::f64::consts::TAU,
        beams_h: 360,
        vfov: 30f64.to_radians(),
        beams_v: 16,
    };
    let p = lidar_pattern(vlp, 0.1, 100.0).unwrap();
    assert_eq!(p.directions.len(), 360 * 16);
    let elevation = |i: usize| f64::from(p.directions[i].z).asin().to_degrees();
    assert!((elevation(0) - 15.0).abs() < 1e-4);
    assert!((elevation(360) - 13.0).abs() < 1e-4);
    assert!((elevation(15 * 360 + 7) + 15.0).abs() < 1e-4);
}

#[test]
fn mounted_sensor_pose_follows_uav_and_mount() {
    // UAV at (1, 2, 1) heading +y (yaw 90 deg); camera 0.1 m ahead, 0.05 m up, turned a further
    // 90 deg left: it looks along -x of the world from (1, 2.1, 1.05).
    let body = QuadState::at_rest(Vec3::new(1.0, 2.0, 1.0), FRAC_PI_2);
    let mount = Mount {
        translation: Vec3::new(0.1, 0.0, 0.05),
        rotation: Quat::from_rotation_z(FRAC_PI_2),
    };
    let pose = SensorPose::of(&body, &mount);
    assert!((pose.origin - Vec3::new(1.0, 2.1, 1.05)).length() < 1e-6);
    assert!((pose.rotation * Vec3::X - -Vec3::X).length() < 1e-6);
    // A wall whose near face is at x = -3 is 4 m in front of it.
    let world = WorldGeometry::new(vec![wall(
        Vec3::new(-3.5, 2.0, 1.0),
        Vec3::new(1.0, 10.0, 4.0),
    )])
    .unwrap();
    let pattern = lidar_pattern(
        LidarBeams {
            hfov: 1.0,
            beams_h: 1,
            vfov: 0.0,
            beams_v: 1,
        },
        0.1,
        10.0,
    )
    .unwrap();
    let mut scan = Scan::default();
    sweep(
        &pattern,
        pose,
        &world,
        None,
        &mut SweepScratch::default(),
        &mut scan,
        0.5,
    );
    assert_eq!(scan.hit, vec![true]);
    assert!((scan.endpoints[0] - Vec3::new(-3.0, 2.1, 1.05)).length() < 1e-5);
    assert_eq!((scan.sequence, scan.time_s), (1, 0.5));
}

/// Three beams straight ahead, 30 deg left and 30 deg right, against walls at 0.3 m (left),
/// 4 m (ahead) and nothing (right).
fn three_beam_setup() -> (RayPattern, WorldGeometry) {
    let pattern = lidar_pattern(
        LidarBeams {
            hfov: 60f64.to_radians(),
            beams_h: 3,
            vfov: 0.0,
            beams_v: 1,
        },
        0.5,
        10.0,
    )
    .unwrap();
    let world = WorldGeometry::new(vec![
        wall(Vec3::new(4.5, 0.0, 0.0), Vec3::new(1.0, 1.0, 1.0)),
        // Plane y = 0.3 to the left, close: the 30 deg left beam meets it at 0.3 / sin 30 = 0.6.
        wall(Vec3::new(0.5, 0.8, 0.0), Vec3::new(1.0, 1.0, 1.0)),
    ])
    .unwrap();
    (pattern, world)
}

#[test]
fn sweep_drops_close_rays_cuts_far_rays_and_reuses_buffers() {
    let (mut pattern, world) = three_beam_setup();
    let pose = SensorPose {
        origin: Vec3::ZERO,
        rotation: Quat::IDENTITY,
    };
    let mut scratch = SweepScratch::default();
    let mut scan = Scan::default();
    sweep(&pattern, pose, &world, None, &mut scratch, &mut scan, 0.0);
    // Beam 0 (right): no surface, cut at 10 m. Beam 1 (ahead): 4 m. Beam 2 (left): 0.6 m.
    assert_eq!(scan.hit, vec![false, true, true]);
    let right = Vec3::new(30f32.to_radians().cos(), -0.5, 0.0);
    assert!((scan.endpoints[0] - right * 10.0).length() < 1e-5);
    assert!((scan.endpoints[1] - Vec3::new(4.0, 0.0, 0.0)).length() < 1e-5);
    assert!((scan.endpoints[2].y - 0.3).abs() < 1e-5);

    // Min range 0.7 drops the left beam (0.6 m: no depth); max range 3 cuts the 4 m hit.
    pattern.range_min = 0.7;
    pattern.range_max = 3.0;
    let capacity = scan.endpoints.capacity();
    let buffer = scan.endpoints.as_ptr();
    sweep(&pattern, pose, &world, None, &mut scratch, &mut scan, 0.1);
    assert_eq!(scan.hit, vec![false, false]);
    assert!((scan.endpoints[1] - Vec3::new(3.0, 0.0, 0.0)).length() < 1e-5);
    assert_eq!(scan.sequence, 2);
    assert_eq!(scan.endpoints.capacity(), capacity);
    assert_eq!(scan.endpoints.as_ptr(), buffer);
}

#[test]
fn range_noise_is_gaussian_and_reproducible_per_stream() {
    // 20,000 rays at a wall 4 m ahead, noise std 0.05 m.
    let pattern = RayPattern {
        directions: vec![Vec3::X; 20_000],
        columns: 20_000,
        rows: 1,
        range_min: 0.5,
        range_max: 10.0,
        frustum: None,
        tiles: Vec::new(),
    };
    let world = WorldGeometry::new(vec![wall(Vec3::new(4.5, 0.0, 0.0), Vec3::ONE)]).unwrap();
    let pose = SensorPose {
        origin: Vec3::ZERO,
        rotation: Quat::IDENTITY,
    };
    let run = |seed: u64| {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let noise = RangeNoise {
            std_m: 0.05,
            rng: &mut rng,
        };
        let mut scan = Scan::default();
        let mut scratch = SweepScratch::default();
        sweep(
            &pattern,
            pose,
            &world,
            Some(noise),
            &mut scratch,
            &mut scan,
            0.0,
        );
        scan.endpoints
            .iter()
            .map(|e| e.x - 4.0)
            .collect::<Vec<f32>>()
    };
    let errors = run(7);
    assert_eq!(errors, run(7));
    assert_ne!(errors, run(8));
    let n = errors.len() as f64;
    let mean = errors.iter().map(|&e| f64::from(e)).sum::<f64>() / n;
    let var = errors
        .iter()
        .map(|&e| (f64::from(e) - mean).powi(2))
        .sum::<f64>()
        / n;
    // Standard error of the mean: 0.05 / sqrt(20000) = 3.5e-4; of the std: ~2.5e-4.
    assert!(mean.abs() < 1.5e-3, "{mean}");
    assert!((var.sqrt() - 0.05).abs() < 1.5e-3, "{}", var.sqrt());
}

#[test]
fn schedule_sweeps_a_30_hz_camera_every_tenth_tick_of_300_hz() {
    let mut schedule = SweepSchedule::from_rate(30.0);
    let mut clock = SimClock::new(300.0);
    let mut ticks = Vec::new();
    for _ in 0..300 {
        if schedule.is_due(clock.time_s()) {
            schedule.advance(clock.time_s());
            ticks.push(clock.tick);
        }
        clock.tick += 1;
    }
    assert_eq!(ticks, (0..30).map(|k| k * 10).collect::<Vec<u64>>());
    // A rate that does not divide the clock: 7 Hz on 300 Hz sweeps at the first tick at or after
    // k / 7 s, i.e. tick ceil(300 k / 7).
    let mut schedule = SweepSchedule::from_rate(7.0);
    let mut clock = SimClock::new(300.0);
    let mut ticks = Vec::new();
    for _ in 0..301 {
        if schedule.is_due(clock.time_s()) {
            schedule.advance(clock.time_s());
            ticks.push(clock.tick);
        }
        clock.tick += 1;
    }
    assert_eq!(ticks, vec![0, 43, 86, 129, 172, 215, 258, 300]);
}

#[test]
fn sense_system_sweeps_due_sensors_only() {
    let (pattern, world) = three_beam_setup();
    let mut ecs = World::new();
    ecs.insert_resource(SimClock::new(300.0));
    ecs.insert_resource(world);
    let uav = ecs.spawn(QuadState::at_rest(Vec3::ZERO, 0.0)).id();
    let sensor = ecs
        .spawn((
            SensorOf(uav),
            Mount::default(),
            SensorQuality::from_probabilities(0.7, 0.4, 0.0),
            pattern,
            SweepSchedule::from_rate(30.0),
            NoiseRng(ChaCha8Rng::seed_from_u64(1)),
            SweepScratch::default(),
            Scan::default(),
        ))
        .id();
    // A registered system keeps its last-run tick, so `Changed` means "since I last looked".
    let count_changed = ecs.register_system(|q: Query<(), Changed<Scan>>| q.iter().count());
    let changed = |ecs: &mut World| ecs.run_system(count_changed).unwrap();
    ecs.run_system_once(sense).unwrap();
    assert_eq!(ecs.get::<Scan>(sensor).unwrap().sequence, 1);
    assert_eq!(
        ecs.get::<Scan>(sensor).unwrap().hit,
        vec![false, true, true]
    );
    assert_eq!(changed(&mut ecs), 1);
    assert_eq!(changed(&mut ecs), 0);
    // Tick 1 (not due): nothing happens, the scan is not marked changed.
    ecs.resource_mut::<SimClock>().tick = 1;
    ecs.run_system_once(sense).unwrap();
    assert_eq!(ecs.get::<Scan>(sensor).unwrap().sequence, 1);
    assert_eq!(changed(&mut ecs), 0);
    // Tick 10: due again; the UAV moved 2 m forward, the wall is now 2 m ahead.
    ecs.resource_mut::<SimClock>().tick = 10;
    ecs.get_mut::<QuadState>(uav).unwrap().position = Vec3::new(2.0, 0.0, 0.0);
    ecs.run_system_once(sense).unwrap();
    let scan = ecs.get::<Scan>(sensor).unwrap();
    assert_eq!(scan.sequence, 2);
    assert!((scan.endpoints[1] - Vec3::new(4.0, 0.0, 0.0)).length() < 1e-5);
    assert!((scan.time_s - 10.0 / 300.0).abs() < 1e-12);
}
