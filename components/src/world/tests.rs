//! Ray casts and ground truth against shapes whose answers follow from elementary geometry.

use super::*;
use glam::{IVec3, Quat, Vec3};
use parry3d::shape::TriMesh;
use std::f32::consts::FRAC_PI_2;

const EPS: f32 = 1e-5;

fn box_obstacle(name: &str, center: Vec3, size: Vec3, yaw: f32) -> Obstacle {
    let pose = Pose::from_parts(center, Quat::from_rotation_z(yaw));
    let half = size * 0.5;
    Obstacle::new(
        name,
        "test",
        pose,
        SharedShape::cuboid(half.x, half.y, half.z),
    )
}

/// Upright cylinder standing on `base` (parry's cylinder axis is +y: turn it onto +z).
fn cylinder_obstacle(base: Vec3, radius: f32, height: f32) -> Obstacle {
    let pose = Pose::from_parts(
        base + Vec3::Z * (0.5 * height),
        Quat::from_rotation_x(FRAC_PI_2),
    );
    Obstacle::new(
        "cylinder",
        "test",
        pose,
        SharedShape::cylinder(0.5 * height, radius),
    )
}

fn world(obstacles: Vec<Obstacle>) -> WorldGeometry {
    WorldGeometry::new(obstacles).unwrap()
}

/// Closed unit cube [0,1]^3 as 12 outward-oriented triangles.
fn unit_cube_mesh(flags: TriMeshFlags) -> TriMesh {
    let v = |x: f32, y: f32, z: f32| Vec3::new(x, y, z);
    let vertices = vec![
        v(0., 0., 0.),
        v(1., 0., 0.),
        v(1., 1., 0.),
        v(0., 1., 0.),
        v(0., 0., 1.),
        v(1., 0., 1.),
        v(1., 1., 1.),
        v(0., 1., 1.),
    ];
    let triangles = vec![
        [0, 2, 1],
        [0, 3, 2], // bottom (-z)
        [4, 5, 6],
        [4, 6, 7], // top (+z)
        [0, 1, 5],
        [0, 5, 4], // -y
        [2, 3, 7],
        [2, 7, 6], // +y
        [1, 2, 6],
        [1, 6, 5], // +x
        [0, 4, 7],
        [0, 7, 3], // -x
    ];
    TriMesh::with_flags(vertices, triangles, flags).unwrap()
}

#[test]
fn ray_hits_yawed_box_at_the_rotated_face() {
    // A 2 x 1 x 1 box at (5, 0, 0) turned by 90 deg: its long side now runs along y, so the face
    // towards the origin is at x = 5 - 0.5 (half the short side), not 5 - 1.
    let w = world(vec![box_obstacle(
        "b",
        Vec3::new(5.0, 0.0, 0.0),
        Vec3::new(2.0, 1.0, 1.0),
        FRAC_PI_2,
    )]);
    let d = w.cast_ray(Vec3::ZERO, Vec3::X, 100.0).unwrap();
    assert!((d - 4.5).abs() < EPS, "{d}");
    // Along y at x = 5 the ray meets the (rotated) long side's end at y = -1.
    let d = w
        .cast_ray(Vec3::new(5.0, -10.0, 0.0), Vec3::Y, 100.0)
        .unwrap();
    assert!((d - 9.0).abs() < EPS, "{d}");
    // A 45 deg yaw: the corner of a 2 x 2 x 2 cube points at the origin, sqrt(2) from its centre.
    let w = world(vec![box_obstacle(
        "b",
        Vec3::new(5.0, 0.0, 0.0),
        Vec3::splat(2.0),
        std::f32::consts::FRAC_PI_4,
    )]);
    let d = w.cast_ray(Vec3::ZERO, Vec3::X, 100.0).unwrap();
    assert!((d - (5.0 - 2f32.sqrt())).abs() < EPS, "{d}");
}

#[test]
fn ray_misses_beyond_max_distance_and_reports_the_nearest_obstacle() {
    let w = world(vec![
        box_obstacle("far", Vec3::new(8.0, 0.0, 0.0), Vec3::ONE, 0.0),
        box_obstacle("near", Vec3::new(3.0, 0.0, 0.0), Vec3::ONE, 0.0),
    ]);
    assert_eq!(w.cast_ray(Vec3::ZERO, Vec3::X, 2.4), None);
    let (i, d) = w
        .cast_ray_and_get_obstacle(Vec3::ZERO, Vec3::X, 20.0)
        .unwrap();
    assert_eq!(w.obstacles()[i].name, "near");
    assert!((d - 2.5).abs() < EPS);
    assert_eq!(w.cast_ray(Vec3::ZERO, -Vec3::X, 20.0), None);
    assert_eq!(
        w.cast_ray(Vec3::new(3.0, 0.2, 0.0), Vec3::Y, 20.0),
        Some(0.0)
    );
    assert_eq!(
        WorldGeometry::empty().cast_ray(Vec3::ZERO, Vec3::X, 20.0),
        None
    );
}

#[test]
fn ray_hits_upright_cylinder_side_and_top() {
    // Radius 0.5, height 2, standing on (4, 0, 0).
    let w = world(vec![cylinder_obstacle(Vec3::new(4.0, 0.0, 0.0), 0.5, 2.0)]);
    let d = w
        .cast_ray(Vec3::new(0.0, 0.0, 1.0), Vec3::X, 100.0)
        .unwrap();
    assert!((d - 3.5).abs() < EPS, "{d}");
    // Off-axis by 0.3: the side is at x = 4 - sqrt(0.5^2 - 0.3^2) = 3.6.
    let d = w
        .cast_ray(Vec3::new(0.0, 0.3, 1.0), Vec3::X, 100.0)
        .unwrap();
    assert!((d - 3.6).abs() < EPS, "{d}");
    // From above: the top disc at z = 2 (an x-axis cylinder would answer 0.5 below the top).
    let d = w
        .cast_ray(Vec3::new(4.0, 0.0, 5.0), -Vec3::Z, 100.0)
        .unwrap();
    assert!((d - 3.0).abs() < EPS, "{d}");
    // Above the top it misses.
    assert_eq!(w.cast_ray(Vec3::new(0.0, 0.0, 2.1), Vec3::X, 100.0), None);
}

#[test]
fn ray_hits_sphere_at_the_chord() {
    let sphere = Obstacle::new(
        "s",
        "test",
        Pose::from_translation(Vec3::new(0.0, 6.0, 1.0)),
        SharedShape::ball(1.0),
    );
    let w = world(vec![sphere]);
    let d = w
        .cast_ray(Vec3::new(0.0, 0.0, 1.0), Vec3::Y, 100.0)
        .unwrap();
    assert!((d - 5.0).abs() < EPS, "{d}");
    // Offset 0.6 sideways: hit at 6 - sqrt(1 - 0.36) = 5.2.
    let d = w
        .cast_ray(Vec3::new(0.6, 0.0, 1.0), Vec3::Y, 100.0)
        .unwrap();
    assert!((d - 5.2).abs() < EPS, "{d}");
}

#[test]
fn ray_hits_mesh_and_cloud() {
    let cube = Obstacle::new(
        "mesh",
        "test",
        Pose::from_translation(Vec3::new(3.0, -0.5, -0.5)),
        SharedShape::new(unit_cube_mesh(TriMeshFlags::ORIENTED)),
    );
    let balls: Vec<(Pose, SharedShape)> = [Vec3::new(0.0, 0.0, 0.0), Vec3::new(0.0, 0.0, 1.0)]
        .into_iter()
        .map(|p| (Pose::from_translation(p), SharedShape::ball(0.25)))
        .collect();
    let cloud = Obstacle::new(
        "cloud",
        "test",
        Pose::from_translation(Vec3::new(-4.0, 0.0, 0.0)),
        SharedShape::compound(balls),
    );
    let w = world(vec![cube, cloud]);
    let d = w.cast_ray(Vec3::ZERO, Vec3::X, 100.0).unwrap();
    assert!((d - 3.0).abs() < EPS, "{d}");
    // The cloud's point at (-4, 0, 1) is a ball of 0.25: hit at x = -3.75.
    let d = w
        .cast_ray(Vec3::new(0.0, 0.0, 1.0), -Vec3::X, 100.0)
        .unwrap();
    assert!((d - 3.75).abs() < EPS, "{d}");
    // Between the two balls (z = 0.5) the ray passes.
    assert_eq!(w.cast_ray(Vec3::new(0.0, 0.0, 0.5), -Vec3::X, 100.0), None);
}

#[test]
fn batch_cast_equals_single_casts_serial_and_parallel() {
    let w = world(vec![
        box_obstacle("a", Vec3::new(3.0, 0.0, 0.0), Vec3::ONE, 0.3),
        cylinder_obstacle(Vec3::new(-2.0, 1.0, -1.0), 0.4, 3.0),
    ]);
    for n in [100, PARALLEL_RAY_THRESHOLD + 123] {
        let dirs: Vec<Vec3> = (0..n)
            .map(|i| {
                let a = i as f32 * 0.001 * std::f32::consts::TAU;
                Vec3::new(a.cos(), a.sin(), 0.1 * (i as f32 * 0.37).sin()).normalize()
            })
            .collect();
        let mut out = vec![Some(-1.0); 3];
        w.cast_rays(Vec3::new(0.0, 0.0, 0.2), &dirs, 10.0, &mut out);
        assert_eq!(out.len(), n);
        let hits = out.iter().filter(|d| d.is_some()).count();
        assert!(hits > n / 20, "some rays must hit ({hits})");
        for (dir, got) in dirs.iter().zip(&out) {
            assert_eq!(*got, w.cast_ray(Vec3::new(0.0, 0.0, 0.2), *dir, 10.0));
        }
    }
}

#[test]
fn points_and_balls_against_box_cylinder_and_closed_mesh() {
    let w = world(vec![
        box_obstacle("box", Vec3::new(0.0, 0.0, 0.5), Vec3::ONE, 0.0),
        cylinder_obstacle(Vec3::new(5.0, 0.0, 0.0), 0.5, 2.0),
        Obstacle::new(
            "mesh",
            "test",
            Pose::from_translation(Vec3::new(10.0, 0.0, 0.0)),
            SharedShape::new(unit_cube_mesh(TriMeshFlags::ORIENTED)),
        ),
    ]);
    assert_eq!(w.obstacle_containing(Vec3::new(0.2, 0.2, 0.5)), Some(0));
    assert_eq!(w.obstacle_containing(Vec3::new(5.3, 0.0, 1.9)), Some(1));
    assert_eq!(w.obstacle_containing(Vec3::new(10.5, 0.5, 0.5)), Some(2));
    assert!(!w.contains_point(Vec3::new(0.6, 0.0, 0.5)));
    assert!(!w.contains_point(Vec3::new(5.0, 0.0, 2.1)));
    assert!(!w.contains_point(Vec3::new(11.1, 0.5, 0.5)));
    // A ball of 0.3 at 0.25 from the box face touches it; at 0.35 it does not.
    assert!(w.intersects_ball(Vec3::new(0.75, 0.0, 0.5), 0.3));
    assert!(!w.intersects_ball(Vec3::new(0.85, 0.0, 0.5), 0.3));
    // A small ball wholly inside the closed mesh intersects it (the inside is solid).
    assert_eq!(
        w.obstacle_intersecting_ball(Vec3::new(10.5, 0.5, 0.5), 0.1),
        Some(2)
    );
    assert_eq!(
        w.obstacle_intersecting_ball(Vec3::new(5.0, 0.7, 1.0), 0.25),
        Some(1)
    );
}

/// A ball counts an obstacle only if the obstacle reaches into the region: the slab under a
/// region whose floor is z = 0 touches its face and does not, a box standing in it does.
#[test]
fn balls_against_the_obstacles_that_reach_into_a_region() {
    let w = world(vec![
        box_obstacle(
            "slab",
            Vec3::new(0.0, 0.0, -0.5),
            Vec3::new(20.0, 20.0, 1.0),
            0.0,
        ),
        box_obstacle(
            "box",
            Vec3::new(3.0, 0.0, 1.0),
            Vec3::new(1.0, 1.0, 2.0),
            0.0,
        ),
    ]);
    let region = Aabb::new(Vec3::new(-5.0, -5.0, 1e-4), Vec3::new(5.0, 5.0, 2.5));
    let within = |c: Vec3, r: f32| w.obstacle_intersecting_ball_within(c, r, &region);
    // A ball reaching 0.2 m below the floor: the slab alone, outside the region.
    assert_eq!(
        w.obstacle_intersecting_ball(Vec3::new(0.0, 0.0, 1.0), 1.2),
        Some(0)
    );
    assert_eq!(within(Vec3::new(0.0, 0.0, 1.0), 1.2), None);
    // Reaching the box's face as well (at x = 2.5, 0.3 m off): the box.
    assert_eq!(within(Vec3::new(1.3, 0.0, 1.0), 1.5), Some(1));
    assert_eq!(within(Vec3::new(1.0, 0.0, 1.0), 1.4), None);
    // With the region's floor below the slab's top, the slab reaches into it.
    let lower = Aabb::new(Vec3::new(-5.0, -5.0, -0.5), Vec3::new(5.0, 5.0, 2.5));
    assert_eq!(
        w.obstacle_intersecting_ball_within(Vec3::new(0.0, 0.0, 1.0), 1.2, &lower),
        Some(0)
    );
}

#[test]
fn open_mesh_is_a_shell_only() {
    // Without ORIENTED the cube is 12 thin triangles: its inside is free space.
    let w = world(vec![Obstacle::new(
        "shell",
        "test",
        Pose::IDENTITY,
        SharedShape::new(unit_cube_mesh(TriMeshFlags::empty())),
    )]);
    assert!(!w.obstacles()[0].is_solid_mesh());
    assert!(!w.voxel_occupied(Vec3::splat(0.5), 0.1));
    assert!(w.voxel_occupied(Vec3::new(0.5, 0.5, 0.98), 0.1));
}

#[test]
fn voxel_ground_truth_inside_outside_and_at_faces_of_a_box() {
    // Box [0, 1] x [0, 2] x [0, 0.5], faces on voxel boundaries of a 0.1 m grid.
    let w = world(vec![box_obstacle(
        "box",
        Vec3::new(0.5, 1.0, 0.25),
        Vec3::new(1.0, 2.0, 0.5),
        0.0,
    )]);
    let res = 0.1;
    // Inside, including the voxels whose faces lie on the box faces.
    for key in [
        IVec3::new(5, 10, 2),
        IVec3::new(0, 0, 0),
        IVec3::new(9, 19, 4),
        IVec3::new(0, 19, 4),
    ] {
        assert!(w.voxel_key_occupied(key, res), "{key} must be occupied");
    }
    // Outside neighbours touching a face, an edge, a corner: not occupied.
    for key in [
        IVec3::new(-1, 5, 2),
        IVec3::new(10, 5, 2),
        IVec3::new(5, 20, 2),
        IVec3::new(5, 10, 5),
        IVec3::new(5, 10, -1),
        IVec3::new(10, 20, 2),
        IVec3::new(-1, -1, -1),
        IVec3::new(10, 20, 5),
    ] {
        assert!(!w.voxel_key_occupied(key, res), "{key} must be free");
    }
    // A face crossing the middle of a voxel (box shifted by half a voxel): both sides' voxels
    // overlap it; the voxel beyond does not.
    let w = world(vec![box_obstacle(
        "box",
        Vec3::new(0.55, 1.0, 0.25),
        Vec3::new(1.0, 2.0, 0.5),
        0.0,
    )]);
    assert!(w.voxel_key_occupied(IVec3::new(10, 5, 2), res));
    assert!(w.voxel_key_occupied(IVec3::new(0, 5, 2), res));
    assert!(!w.voxel_key_occupied(IVec3::new(11, 5, 2), res));
    assert!(!w.voxel_key_occupied(IVec3::new(-1, 5, 2), res));
}

#[test]
fn voxel_ground_truth_against_cylinder_and_cloud() {
    let w = world(vec![
        cylinder_obstacle(Vec3::ZERO, 0.5, 1.0),
        Obstacle::new(
            "cloud",
            "test",
            Pose::IDENTITY,
            SharedShape::compound(vec![(
                Pose::from_translation(Vec3::new(3.05, 0.05, 0.05)),
                SharedShape::ball(0.02),
            )]),
        ),
    ]);
    // Voxel [0.4, 0.5] x [0, 0.1]: its inner corner is inside the disc of radius 0.5.
    assert!(w.voxel_key_occupied(IVec3::new(4, 0, 3), 0.1));
    // Voxel [0.4, 0.5] x [0.3, 0.4]: nearest point (0.4, 0.3) lies 0.5 from the axis: touching
    // only, shrunk away.
    assert!(!w.voxel_key_occupied(IVec3::new(4, 3, 3), 0.1));
    // Voxel [0.3, 0.4] x [0.3, 0.4]: nearest point at 0.424 < 0.5.
    assert!(w.voxel_key_occupied(IVec3::new(3, 3, 3), 0.1));
    // Above the top (z = 1) nothing.
    assert!(!w.voxel_key_occupied(IVec3::new(0, 0, 10), 0.1));
    // The cloud's ball lies in voxel (30, 0, 0) only.
    assert!(w.voxel_key_occupied(IVec3::new(30, 0, 0), 0.1));
    assert!(!w.voxel_key_occupied(IVec3::new(31, 0, 0), 0.1));
}

#[test]
fn non_finite_obstacles_are_refused() {
    let bad = box_obstacle("bad", Vec3::new(f32::NAN, 0.0, 0.0), Vec3::ONE, 0.0);
    let err = WorldGeometry::new(vec![bad]).unwrap_err();
    assert!(err.to_string().contains("'bad'"), "{err}");
    assert!(WorldGeometry::new(Vec::new()).unwrap().aabb().is_none());
}

/// A block of voxels said to be free holds no occupied voxel, and the blocks beside a box's
/// faces, which only touch it, are said free: checked block by block around a yawed box and a
/// cylinder, against the voxel test.
#[test]
fn voxel_blocks_said_free_hold_no_occupied_voxel() {
    let w = world(vec![
        box_obstacle(
            "box",
            Vec3::new(0.5, 1.0, 0.25),
            Vec3::new(1.0, 2.0, 0.5),
            0.0,
        ),
        box_obstacle(
            "yawed",
            Vec3::new(-1.0, -1.0, 0.5),
            Vec3::new(0.6, 0.3, 1.0),
            0.4,
        ),
        cylinder_obstacle(Vec3::new(1.5, -1.5, 0.0), 0.3, 1.0),
    ]);
    let res = 0.1;
    // The block of keys 10..=13 on x beside the box's face at x = 1: free.
    let beside = IVec3::new(10, 4, 0);
    assert!(!w.voxel_keys_may_be_occupied(beside, beside + IVec3::splat(3), res));
    assert!(w.voxel_keys_may_be_occupied(beside - IVec3::X, beside + IVec3::splat(3), res));
    let (mut free_blocks, mut checked) = (0, 0);
    for bz in -2..4 {
        for by in -6..7 {
            for bx in -6..6 {
                let lo = IVec3::new(bx, by, bz) * 4;
                let hi = lo + IVec3::splat(3);
                if w.voxel_keys_may_be_occupied(lo, hi, res) {
                    continue;
                }
                free_blocks += 1;
                for z in lo.z..=hi.z {
                    for y in lo.y..=hi.y {
                        for x in lo.x..=hi.x {
                            let key = IVec3::new(x, y, z);
                            assert!(!w.voxel_key_occupied(key, res), "{key} in {lo}");
                            checked += 1;
                        }
                    }
                }
            }
        }
    }
    assert!(free_blocks > 100 && checked == 64 * free_blocks);
    assert!(!world(Vec::new()).voxel_keys_may_be_occupied(IVec3::ZERO, IVec3::ONE, res));
}
