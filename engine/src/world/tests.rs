//! World building from scenario tables: every obstacle kind at its analytic distance, files
//! relative to the scenario, errors with field paths, pillars, colliders, sensors.

use super::*;
use crate::scenario::{MapSpec, SensorSpec, WorldSpec};
use bevy_ecs::prelude::*;
use glam::{IVec3, Quat};
use std::path::PathBuf;
use uavex_components::sensor::{SensorId, SensorOf};

fn world_spec(toml_text: &str) -> WorldSpec {
    toml::from_str(toml_text).unwrap()
}

fn build(spec: &WorldSpec, dir: &Path) -> Result<WorldGeometry, Vec<BuildError>> {
    build_world(spec, RunSeed(1), &[Vec3::new(0.0, 0.0, 1.0)], &[], dir)
}

/// Unit cube [0, 1]^3 as six quads (OBJ, counter-clockwise seen from outside).
const CUBE_OBJ: &str = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n\
f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 3 4 8 7\nf 2 3 7 6\nf 1 5 8 4\n";

/// The same cube wound inside out (every face reversed).
const CUBE_OBJ_INSIDE_OUT: &str = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\n\
v 1 1 1\nv 0 1 1\nf 2 3 4 1\nf 8 7 6 5\nf 5 6 2 1\nf 7 8 4 3\nf 6 7 3 2\nf 4 8 5 1\n";

/// The cube without its top: an open box.
const OPEN_BOX_OBJ: &str = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\n\
v 0 1 1\nf 1 4 3 2\nf 1 2 6 5\nf 3 4 8 7\nf 2 3 7 6\nf 1 5 8 4\n";

const TWO_POINTS_PLY: &str = "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\n\
property float y\nproperty float z\nend_header\n0 0 0\n1 0 0\n";

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let path = dir.join(name);
    std::fs::create_dir_all(path.parent().unwrap()).unwrap();
    std::fs::write(&path, text).unwrap();
    path
}

fn every_kind(dir: &Path) -> WorldSpec {
    write(dir, "models/cube.obj", CUBE_OBJ);
    write(dir, "models/two.ply", TWO_POINTS_PLY);
    world_spec(
        r#"
        bounds = { min = [-12, -12, 0], max = [12, 12, 3] }
        [[obstacle]]
        kind = "box"
        name = "long box"
        center = [7, -8, 1]
        size = [2, 1, 2]
        yaw = 1.5707963267948966
        [[obstacle]]
        kind = "cylinder"
        base = [-5, 0, 0]
        radius = 0.5
        height = 2
        [[obstacle]]
        kind = "sphere"
        center = [0, 6, 1]
        radius = 1
        [[obstacle]]
        kind = "mesh"
        file = "models/cube.obj"
        translation = [5, 0, 0]
        yaw = 1.5707963267948966
        scale = 2
        [[obstacle]]
        kind = "cloud"
        file = "models/two.ply"
        point_radius = 0.1
        translation = [0, -5, 1]
        yaw = 1.5707963267948966
        "#,
    )
}

fn distance(world: &WorldGeometry, origin: [f32; 3], dir: Vec3) -> f32 {
    world
        .cast_ray(Vec3::from_array(origin), dir, 100.0)
        .unwrap()
}

#[test]
fn every_obstacle_kind_is_hit_at_its_analytic_distance() {
    let dir = tempfile::tempdir().unwrap();
    let world = build(&every_kind(dir.path()), dir.path()).unwrap();
    let names: Vec<&str> = world.obstacles().iter().map(|o| o.name.as_str()).collect();
    assert_eq!(
        names,
        [
            "ground",
            "long box",
            "cylinder 1",
            "sphere 2",
            "mesh 3",
            "cloud 4"
        ]
    );
    // Box 2 x 1 turned 90 deg: its 1 m side faces -x, near face at x = 7 - 0.5.
    assert!((distance(&world, [0., -8., 1.], Vec3::X) - 6.5).abs() < 1e-5);
    // Cylinder radius 0.5 standing on (-5, 0, 0): side at x = -4.5; top at z = 2.
    assert!((distance(&world, [0., 0., 1.], -Vec3::X) - 4.5).abs() < 1e-5);
    assert!((distance(&world, [-5., 0., 3.], -Vec3::Z) - 1.0).abs() < 1e-5);
    assert!((distance(&world, [0., 0., 1.], Vec3::Y) - 5.0).abs() < 1e-5);
    // Cube [0,1]^3 scaled by 2, turned 90 deg (x' = -y, y' = x), moved by (5, 0, 0):
    // x in [3, 5], y in [0, 2], z in [0, 2].
    assert!((distance(&world, [0., 1., 1.], Vec3::X) - 3.0).abs() < 1e-5);
    assert!((distance(&world, [4., 5., 1.], -Vec3::Y) - 3.0).abs() < 1e-5);
    assert!((distance(&world, [4., 1., 5.], -Vec3::Z) - 3.0).abs() < 1e-5);
    // Cloud points (0,0,0) and (1,0,0) turned 90 deg and moved by (0,-5,1): (0,-5,1), (0,-4,1),
    // balls of 0.1: the nearer is met at 4 - 0.1.
    assert!((distance(&world, [0., 0., 1.], -Vec3::Y) - 3.9).abs() < 1e-5);
    // The ground: straight down from 1 m, and far outside the bounds (inside its margin).
    assert!((distance(&world, [0., 0., 1.], -Vec3::Z) - 1.0).abs() < 1e-5);
    assert!((distance(&world, [500., -300., 2.], -Vec3::Z) - 2.0).abs() < 1e-5);
}

#[test]
fn ground_truth_of_built_world() {
    let dir = tempfile::tempdir().unwrap();
    let world = build(&every_kind(dir.path()), dir.path()).unwrap();
    let res = 0.1;
    // Ground: the voxel just below the floor is solid, the one just above is free.
    assert!(world.voxel_key_occupied(IVec3::new(0, 0, -1), res));
    assert!(!world.voxel_key_occupied(IVec3::new(0, 0, 0), res));
    // The closed mesh is solid: a voxel deep inside it is occupied.
    assert!(world.voxel_key_occupied(IVec3::new(40, 10, 10), res));
    assert!(world.obstacles()[4].is_solid_mesh());
    // Inside the cloud's ball at (0, -4, 1): voxel [0, 0.1] x [-4, -3.9] x [1, 1.1] touches it
    // at its corner (0, -4, 1) -- the centre itself -- so it overlaps.
    assert!(world.voxel_key_occupied(IVec3::new(0, -40, 10), res));
    assert!(!world.voxel_key_occupied(IVec3::new(2, -40, 10), res));
}

#[test]
fn closed_meshes_are_solid_whatever_their_winding_and_open_ones_are_shells() {
    let dir = tempfile::tempdir().unwrap();
    write(dir.path(), "in.obj", CUBE_OBJ_INSIDE_OUT);
    write(dir.path(), "open.obj", OPEN_BOX_OBJ);
    let spec = world_spec(
        r#"
        bounds = { min = [-5, -5, 0], max = [5, 5, 3] }
        ground = false
        [[obstacle]]
        kind = "mesh"
        file = "in.obj"
        [[obstacle]]
        kind = "mesh"
        file = "open.obj"
        translation = [3, 0, 0]
        "#,
    );
    let world = build(&spec, dir.path()).unwrap();
    assert!(world.obstacles()[0].is_solid_mesh());
    assert!(world.contains_point(Vec3::splat(0.5)));
    assert!(world.voxel_occupied(Vec3::splat(0.5), 0.1));
    assert!(!world.obstacles()[1].is_solid_mesh());
    assert!(!world.voxel_occupied(Vec3::new(3.5, 0.5, 0.5), 0.1));
    // A ray from above enters the open box through its missing top and meets the bottom.
    assert!((distance(&world, [3.5, 0.5, 2.], -Vec3::Z) - 2.0).abs() < 1e-5);
}

#[test]
fn problems_are_reported_with_their_field_paths_all_at_once() {
    let dir = tempfile::tempdir().unwrap();
    // Two of its three corners coincide: welded, the only triangle is degenerate.
    write(
        dir.path(),
        "flat.obj",
        "v 0 0 0\nv 1 0 0\nv 0 0 0\nf 1 2 3\n",
    );
    let spec = world_spec(
        r#"
        bounds = { min = [-5, -5, 0], max = [5, 5, 3] }
        [[obstacle]]
        kind = "box"
        center = [0, 0, 1]
        size = [1, -2, 1]
        [[obstacle]]
        kind = "mesh"
        file = "missing.obj"
        [[obstacle]]
        kind = "cloud"
        file = "none.pcd"
        point_radius = 0.0
        [[obstacle]]
        kind = "mesh"
        file = "flat.obj"
        [[obstacle]]
        kind = "pillars"
        region_min = [0, 0]
        region_max = [0, 5]
        density = 0.1
        radius_min = 0.3
        radius_max = 0.2
        height = 2
        "#,
    );
    let errors = build(&spec, dir.path()).unwrap_err();
    let paths: Vec<&str> = errors.iter().map(|e| e.path.as_str()).collect();
    assert_eq!(
        paths,
        [
            "world.obstacle[0].size.y",
            "world.obstacle[1].file",
            "world.obstacle[2].point_radius",
            "world.obstacle[3].file",
            "world.obstacle[4].region_max",
            "world.obstacle[4].radius_max",
        ]
    );
    assert!(errors[1].message.contains("missing.obj"), "{}", errors[1]);
    assert!(errors[3].message.contains("degenerate"), "{}", errors[3]);
    assert_eq!(
        errors[0].to_string(),
        "world.obstacle[0].size.y: must be finite and positive, got -2"
    );
}

#[test]
fn starts_inside_or_touching_obstacles_are_refused() {
    let spec = world_spec(
        r#"
        bounds = { min = [-5, -5, 0], max = [5, 5, 3] }
        [[obstacle]]
        kind = "box"
        name = "crate"
        center = [2, 0, 1]
        size = [1, 1, 2]
        "#,
    );
    let world = build(&spec, Path::new(".")).unwrap();
    let starts = [
        Vec3::new(0.0, 0.0, 1.0),
        Vec3::new(2.0, 0.3, 1.0),
        Vec3::new(1.4, 0.0, 1.0),
        Vec3::new(-3.0, 0.0, 0.1),
    ];
    let errors = check_starts(&world, &starts, 0.2);
    let paths: Vec<&str> = errors.iter().map(|e| e.path.as_str()).collect();
    // (2, 0.3) is inside the crate; (1.4, 0) is 0.1 from its face (< 0.2); (-3, 0, 0.1) is 0.1
    // above the ground.
    assert_eq!(
        paths,
        [
            "uav[1].start.position",
            "uav[2].start.position",
            "uav[3].start.position"
        ]
    );
    assert!(errors[0].message.contains("'crate' (world.obstacle[0])"));
    assert!(errors[2].message.contains("'ground'"));
}

#[test]
fn rapier_colliders_see_the_same_obstacles() {
    use rapier3d::prelude::*;
    let dir = tempfile::tempdir().unwrap();
    let world = build(&every_kind(dir.path()), dir.path()).unwrap();
    let colliders = colliders(&world);
    assert_eq!(colliders.len(), world.obstacles().len());
    let params = IntegrationParameters::default();
    let mut broad_phase = BroadPhaseBvh::new();
    for (handle, collider) in colliders.iter() {
        broad_phase.set_aabb(&params, handle, collider.compute_aabb());
    }
    let narrow_phase = NarrowPhase::new();
    let bodies = RigidBodySet::new();
    let query = broad_phase.as_query_pipeline(
        narrow_phase.query_dispatcher(),
        &bodies,
        &colliders,
        QueryFilter::default(),
    );
    // 2,000 rays in all directions from two points: same obstacle, same distance.
    let mut hits = 0;
    for origin in [Vec3::new(0.0, 0.0, 1.0), Vec3::new(2.0, -3.0, 1.5)] {
        for i in 0..1000 {
            let z = 1.0 - 2.0 * (i as f32 + 0.5) / 1000.0;
            let phi = i as f32 * 2.399_963;
            let r = (1.0 - z * z).sqrt();
            let dir = Vec3::new(r * phi.cos(), r * phi.sin(), z);
            let ours = world.cast_ray_and_get_obstacle(origin, dir, 30.0);
            let theirs = query.cast_ray(&Ray::new(origin, dir), 30.0, true);
            match (ours, theirs) {
                (None, None) => {}
                (Some((index, d)), Some((handle, toi))) => {
                    hits += 1;
                    assert_eq!(colliders[handle].user_data, index as u128);
                    // Cylinders are cast in closed form here and by GJK in rapier, which
                    // stops within a few millimetres of the surface (components'
                    // `cylinder_ray` tests); every other shape by the same parry code.
                    let cylinder = world.obstacles()[index].shape.as_cylinder().is_some();
                    let tolerance = if cylinder { 5e-3 } else { 1e-5 };
                    assert!((d - toi).abs() < tolerance, "{dir}: {d} {toi}");
                }
                other => panic!("disagreement for {dir}: {other:?}"),
            }
        }
    }
    assert!(hits > 1000, "{hits}");
    // A ball touching the sphere obstacle is reported by rapier's shape query as that collider.
    let ball = Ball::new(0.3);
    let touching: Vec<u128> = query
        .intersect_shape(Pose::from_translation(Vec3::new(0.0, 4.8, 1.0)), &ball)
        .map(|(_, c)| c.user_data)
        .collect();
    assert_eq!(touching, vec![3]);
    assert_eq!(
        world.obstacle_intersecting_ball(Vec3::new(0.0, 4.8, 1.0), 0.3),
        Some(3)
    );
}

fn thesis_camera(extra: &str) -> SensorSpec {
    let text = format!("kind = \"depth_camera\"\n{extra}");
    toml::from_str(&text).unwrap()
}

#[test]
fn sensor_bundle_from_a_camera_table() {
    let map = MapSpec::default();
    let mut ecs = World::new();
    let uav = ecs.spawn_empty().id();
    let spec =
        thesis_camera("mount = { translation = [0.1, 0, 0], rpy = [0, 0.2, 1.5707963267948966] }");
    let bundle = sensor_bundle(
        &spec,
        &map,
        uav,
        SensorId(3),
        RunSeed(9),
        "uav[0].sensor[0]",
    )
    .unwrap();
    // Default grid "auto" at the map's 0.1 m: 55 x 41 (see sensing::auto_grid).
    assert_eq!((bundle.pattern.columns, bundle.pattern.rows), (55, 41));
    assert_eq!(
        (bundle.pattern.range_min, bundle.pattern.range_max),
        (0.5, 5.0)
    );
    assert!((bundle.schedule.period_s - 1.0 / 30.0).abs() < 1e-15);
    // Yaw first: the camera's +x turns to +y, then pitches 0.2 rad down about its own y.
    let forward = bundle.mount.rotation * Vec3::X;
    let expected =
        Quat::from_rotation_z(std::f32::consts::FRAC_PI_2) * Quat::from_rotation_y(0.2) * Vec3::X;
    assert!((forward - expected).length() < 1e-6);
    assert!((forward - Vec3::new(0.0, 0.2f32.cos(), -(0.2f32.sin()))).length() < 1e-6);
    // OctoMap defaults from the map: ln(0.7 / 0.3) = 0.8473, ln(0.4 / 0.6) = -0.4055.
    assert!((bundle.quality.log_odds_hit - 0.847_298).abs() < 1e-5);
    assert!((bundle.quality.log_odds_miss + 0.405_465).abs() < 1e-5);
    let per_pixel = thesis_camera("ray_grid = [640, 480]");
    let bundle = sensor_bundle(&per_pixel, &map, uav, SensorId(0), RunSeed(9), "s").unwrap();
    assert_eq!(bundle.pattern.directions.len(), 307_200);
    let entity = ecs.spawn(bundle).id();
    assert_eq!(ecs.get::<SensorOf>(entity), Some(&SensorOf(uav)));
}

#[test]
fn sensor_problems_name_their_fields() {
    let map = MapSpec::default();
    let uav = Entity::PLACEHOLDER;
    let path_of = |extra: &str| {
        let spec = thesis_camera(extra);
        sensor_bundle(
            &spec,
            &map,
            uav,
            SensorId(0),
            RunSeed(0),
            "uav[1].sensor[2]",
        )
        .err()
        .unwrap()
        .path
    };
    assert_eq!(path_of("hfov = 3.5"), "uav[1].sensor[2].hfov");
    assert_eq!(path_of("range_min = 6.0"), "uav[1].sensor[2].range_max");
    assert_eq!(path_of("rate_hz = 0.0"), "uav[1].sensor[2].rate_hz");
    assert_eq!(
        path_of("quality = { p_hit = 0.4 }"),
        "uav[1].sensor[2].quality.p_hit"
    );
    let tiny_map = MapSpec {
        resolution: 1e-9,
        ..MapSpec::default()
    };
    let spec = thesis_camera("");
    let err = sensor_bundle(&spec, &tiny_map, uav, SensorId(0), RunSeed(0), "s")
        .err()
        .unwrap();
    assert_eq!(err.path, "s.ray_grid");
}
