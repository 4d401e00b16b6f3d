//! The sweep's casts against a hand-built room: the direct casts (with or without the
//! frustum's and the tiles' culling) against parry's hierarchy, to the bit.

use super::*;
use crate::sensing::{PinholeCamera, RayGrid, camera_pattern};
use parry3d::math::Pose;
use parry3d::shape::SharedShape;
use uavex_components::world::Obstacle;

fn cuboid(name: &str, center: Vec3, size: Vec3, yaw: f32) -> Obstacle {
    let h = size * 0.5;
    Obstacle::new(
        name,
        "test",
        Pose::from_parts(center, Quat::from_rotation_z(yaw)),
        SharedShape::cuboid(h.x, h.y, h.z),
    )
}

/// A Pillars-like room: a ground slab, yawed walls (yaws as published, not exact quarter
/// turns), pillars standing on the ground, a ball and an upright cylinder.
// The published yaws (1.5708, 3.14159) are data, not pi written badly.
#[allow(clippy::approx_constant)]
fn room() -> WorldGeometry {
    let mut obstacles = vec![
        cuboid(
            "ground",
            Vec3::new(0.0, 0.0, -0.5),
            Vec3::new(2000.0, 2000.0, 1.0),
            0.0,
        ),
        cuboid(
            "east",
            Vec3::new(6.0, 0.17, 1.25),
            Vec3::new(14.0, 0.15, 2.5),
            -1.5708,
        ),
        cuboid(
            "west",
            Vec3::new(-6.0, 0.17, 1.25),
            Vec3::new(14.0, 0.15, 2.5),
            1.5708,
        ),
        cuboid(
            "north",
            Vec3::new(0.0, 6.0, 1.25),
            Vec3::new(12.0, 0.15, 2.5),
            0.0,
        ),
        cuboid(
            "south",
            Vec3::new(0.0, -6.0, 1.25),
            Vec3::new(12.0, 0.15, 2.5),
            3.14159,
        ),
        cuboid(
            "pillar",
            Vec3::new(-0.3643, -3.3997, 1.25),
            Vec3::new(2.0, 2.0, 2.5),
            0.0,
        ),
        cuboid(
            "turned",
            Vec3::new(3.2752, 2.838, 1.25),
            Vec3::splat(2.0),
            -1.5708,
        ),
        Obstacle::new(
            "ball",
            "test",
            Pose::from_translation(Vec3::new(-3.0, 2.0, 1.0)),
            SharedShape::ball(0.6),
        ),
        Obstacle::new(
            "cylinder",
            "test",
            Pose::from_parts(
                Vec3::new(2.5, -2.5, 1.0),
                Quat::from_rotation_x(std::f32::consts::FRAC_PI_2),
            ),
            SharedShape::cylinder(1.0, 0.4),
        ),
    ];
    obstacles.push(cuboid(
        "roof",
        Vec3::new(0.0, 0.0, 2.6),
        Vec3::new(12.0, 12.0, 0.2),
        0.0,
    ));
    WorldGeometry::new(obstacles).unwrap()
}

/// How a test sweep passes over obstacles.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Cull {
    /// Tries every near obstacle.
    Not,
    /// Passes over those outside the camera's frustum.
    Frustum,
    /// And, tile by tile, those outside the tile's pyramid.
    Tiles,
}

/// Casts one camera frame from `origin` looking along `yaw`, pitched by `pitch`, both
/// directly (passing over obstacles as `cull` says) and through the hierarchy, and checks
/// that they agree to the bit; returns how many obstacles were near. The frame is per
/// pixel (320 x 240, cast in parallel), or 64 x 48 for the tiles (a single batch).
fn compare(
    world: &WorldGeometry,
    (origin, yaw, pitch, range): (Vec3, f32, f32, f32),
    cull: Cull,
) -> usize {
    let camera = PinholeCamera {
        width: 320,
        height: 240,
        hfov: 1.2,
    };
    let grid = match cull {
        Cull::Tiles => RayGrid::Explicit {
            columns: 64,
            rows: 48,
        },
        _ => RayGrid::Explicit {
            columns: 320,
            rows: 240,
        },
    };
    let pattern = camera_pattern(camera, grid, 0.1, f64::from(range)).unwrap();
    let rotation = Quat::from_rotation_z(yaw) * Quat::from_rotation_y(pitch);
    let directions: Vec<Vec3> = pattern.directions.iter().map(|d| rotation * *d).collect();
    assert_eq!(
        directions.len() < PARALLEL_RAY_THRESHOLD,
        cull == Cull::Tiles
    );
    let (mut near, mut direct, mut reference) = (NearObstacles::default(), Vec::new(), Vec::new());
    let frustum = pattern.frustum.map(|f| f.rotated(rotation));
    assert!(frustum.is_some() && !pattern.tiles.is_empty());
    let culling = Culling {
        frustum: frustum.filter(|_| cull != Cull::Not),
        tiles: Some(Tiles {
            tiles: &pattern.tiles,
            columns: pattern.columns as usize,
            rotation,
        })
        .filter(|_| cull == Cull::Tiles),
    };
    cast_sweep(
        world,
        origin,
        &directions,
        culling,
        range,
        &mut near,
        &mut direct,
    );
    world.cast_rays(origin, &directions, range, &mut reference);
    assert_eq!(direct.len(), directions.len());
    for (i, (a, b)) in direct.iter().zip(&reference).enumerate() {
        assert_eq!(
            a.map(f32::to_bits),
            b.map(f32::to_bits),
            "ray {i} {:?} from {origin}",
            directions[i]
        );
    }
    near.all.len()
}

/// A ray that already hit the floor far away still tries a box whose bounding box begins
/// before that hit, and hits it nearer.
#[test]
fn a_box_nearer_than_the_hit_so_far_is_still_tried() {
    let world = WorldGeometry::new(vec![
        cuboid(
            "floor",
            Vec3::new(0.0, 0.0, -0.1),
            Vec3::new(40.0, 40.0, 0.2),
            0.0,
        ),
        cuboid(
            "post",
            Vec3::new(3.85, 0.0, 0.5),
            Vec3::new(0.2, 2.0, 1.0),
            0.0,
        ),
    ])
    .unwrap();
    let origin = Vec3::new(0.0, 0.0, 1.0);
    // Down to the floor 4.12 m away; the post's box begins 3.75 m away, the ray meets it
    // at 3.87 m.
    let directions = [Vec3::new(4.0, 0.0, -1.0).normalize()];
    let (mut near, mut direct, mut reference) = (NearObstacles::default(), Vec::new(), Vec::new());
    let culling = Culling::default();
    cast_sweep(
        &world,
        origin,
        &directions,
        culling,
        5.0,
        &mut near,
        &mut direct,
    );
    world.cast_rays(origin, &directions, 5.0, &mut reference);
    assert_eq!(near.all.len(), 2);
    let hit = direct[0].expect("a hit");
    assert!((hit - 3.75 * 4.0f32.hypot(1.0) / 4.0).abs() < 1e-4, "{hit}");
    assert_eq!(direct, reference);
}

/// A surface exactly at the range is no hit (the ray is cut there), for rays cast four at a
/// time as for a ray cast alone, and as for the hierarchy.
#[test]
fn a_surface_at_the_range_is_no_hit_in_packets_too() {
    let world = WorldGeometry::new(vec![cuboid(
        "wall",
        Vec3::new(5.5, 0.0, 1.0),
        Vec3::new(1.0, 10.0, 2.0),
        0.0,
    )])
    .unwrap();
    let origin = Vec3::new(0.0, 0.0, 1.0);
    // Four rays straight at the wall 5 m away (a packet), then one alone; a range of 5 m
    // and one of 6 m.
    let directions = [Vec3::X; 5];
    for (range, expected) in [(5.0, None), (6.0, Some(5.0))] {
        let (mut near, mut direct, mut reference) =
            (NearObstacles::default(), Vec::new(), Vec::new());
        cast_sweep(
            &world,
            origin,
            &directions,
            Culling::default(),
            range,
            &mut near,
            &mut direct,
        );
        world.cast_rays(origin, &directions, range, &mut reference);
        assert_eq!(direct, vec![expected; 5], "range {range}");
        assert_eq!(direct, reference, "range {range}");
    }
}

/// The direct casts give the hierarchy's distances to the bit, whether a ray hits a face, an
/// edge where a pillar stands on the ground, a round shape, or nothing.
#[test]
fn direct_casts_match_the_hierarchy_bit_for_bit() {
    let world = room();
    // Looking at the pillar's foot (pillar and ground meet along its bottom edges).
    let poses = [
        (Vec3::new(0.0, 0.0, 1.2), -1.57, 0.4, 5.0),
        // Into a corner of the room, across the turned pillar.
        (Vec3::new(1.0, 1.0, 1.0), 0.785, 0.0, 5.0),
        // At the ball and the cylinder, up into the roof.
        (Vec3::new(0.0, 0.0, 1.5), 2.5, -0.3, 5.0),
        (Vec3::new(0.5, -0.5, 0.8), -0.785, 0.2, 4.0),
    ];
    for pose in poses {
        // These take the direct path; the frustum leaves out some obstacles of each.
        let all = compare(&world, pose, Cull::Not);
        assert!(all <= MAX_NEAR_OBSTACLES);
        assert!(compare(&world, pose, Cull::Frustum) < all);
        compare(&world, pose, Cull::Tiles);
    }
    // At 20 m all ten obstacles are near: the ninth sends the sweep to the hierarchy. In
    // the camera's frustum fewer: it stays direct.
    let far = (Vec3::new(0.0, 0.0, 1.0), 0.0, 0.0, 20.0);
    assert_eq!(compare(&world, far, Cull::Not), MAX_NEAR_OBSTACLES);
    assert!(compare(&world, far, Cull::Frustum) < MAX_NEAR_OBSTACLES);
    compare(&world, far, Cull::Tiles);
    // From inside the pillar every ray stops at 0, as through the hierarchy.
    for cull in [Cull::Not, Cull::Frustum, Cull::Tiles] {
        compare(&world, (Vec3::new(-0.3, -3.4, 1.0), 0.0, 0.0, 5.0), cull);
    }
}
