//! Boxes with yaw, upright cylinders, spheres and the ground as parry shapes.

use super::{BuildError, display_name, obstacle_or, require_finite, require_positive, vec3};
use crate::scenario::{BoundsSpec, ObstacleSpec};
use glam::{Quat, Vec3};
use parry3d::math::Pose;
use parry3d::shape::SharedShape;
use std::f32::consts::FRAC_PI_2;
use uavex_components::world::Obstacle;

/// The ground slab reaches this far (m) beyond the bounds on every side, so that rays of
/// long-range sensors near the edge of the mission volume still end on the floor, as they would
/// on a real field; 1 km is beyond any range sensor a scenario may carry while f32 coordinates
/// at 1 km are still good to 0.1 mm.
pub const GROUND_MARGIN: f32 = 1000.0;
/// Thickness of the ground slab below z = 0 (m): solid, not a surface, so that nothing slips
/// through it and points just below the floor count as inside.
pub const GROUND_THICKNESS: f32 = 1.0;

/// The ground: a solid slab whose top face is the floor z = 0.
pub(super) fn ground(bounds: BoundsSpec) -> Result<Obstacle, BuildError> {
    let values = [bounds.min[0], bounds.min[1], bounds.max[0], bounds.max[1]];
    if values.iter().any(|v| !v.is_finite()) {
        return Err(BuildError::new(
            "world.bounds",
            format!("must be finite to lay the ground, got {values:?}"),
        ));
    }
    let (min, max) = (vec3(bounds.min), vec3(bounds.max));
    let half = Vec3::new(
        0.5 * (max.x - min.x).abs() + GROUND_MARGIN,
        0.5 * (max.y - min.y).abs() + GROUND_MARGIN,
        0.5 * GROUND_THICKNESS,
    );
    let center = Vec3::new(
        0.5 * (min.x + max.x),
        0.5 * (min.y + max.y),
        -0.5 * GROUND_THICKNESS,
    );
    Ok(Obstacle::new(
        "ground",
        "world.ground",
        Pose::from_translation(center),
        SharedShape::cuboid(half.x, half.y, half.z),
    ))
}

/// Box, cylinder or sphere (the caller routes the other kinds elsewhere).
pub(super) fn build(
    spec: &ObstacleSpec,
    index: usize,
    field: &str,
) -> Result<Obstacle, Vec<BuildError>> {
    let mut errors = Vec::new();
    match spec {
        ObstacleSpec::Box {
            name,
            center,
            size,
            yaw,
        } => {
            require_finite(&mut errors, format!("{field}.center"), center);
            for (axis, value) in ["x", "y", "z"].iter().zip(size) {
                require_positive(&mut errors, format!("{field}.size.{axis}"), *value);
            }
            require_finite(&mut errors, format!("{field}.yaw"), &[*yaw]);
            obstacle_or(errors, || {
                let half = vec3(*size) * 0.5;
                Obstacle::new(
                    display_name(name, "box", index),
                    field,
                    Pose::from_parts(vec3(*center), Quat::from_rotation_z(*yaw as f32)),
                    SharedShape::cuboid(half.x, half.y, half.z),
                )
            })
        }
        ObstacleSpec::Cylinder {
            name,
            base,
            radius,
            height,
        } => {
            require_finite(&mut errors, format!("{field}.base"), base);
            require_positive(&mut errors, format!("{field}.radius"), *radius);
            require_positive(&mut errors, format!("{field}.height"), *height);
            obstacle_or(errors, || {
                upright_cylinder(
                    display_name(name, "cylinder", index),
                    field,
                    vec3(*base),
                    *radius as f32,
                    *height as f32,
                )
            })
        }
        ObstacleSpec::Sphere {
            name,
            center,
            radius,
        } => {
            require_finite(&mut errors, format!("{field}.center"), center);
            require_positive(&mut errors, format!("{field}.radius"), *radius);
            obstacle_or(errors, || {
                Obstacle::new(
                    display_name(name, "sphere", index),
                    field,
                    Pose::from_translation(vec3(*center)),
                    SharedShape::ball(*radius as f32),
                )
            })
        }
        _ => Err(vec![BuildError::new(
            field,
            "internal: not a primitive obstacle",
        )]),
    }
}

/// A cylinder standing on `base` (centre of its bottom disc), axis +z.
pub(super) fn upright_cylinder(
    name: String,
    source: &str,
    base: Vec3,
    radius: f32,
    height: f32,
) -> Obstacle {
    Obstacle::new(
        name,
        source,
        upright_pose(base, height),
        SharedShape::cylinder(0.5 * height, radius),
    )
}

/// The pose of parry's cylinder of `height` standing on `base`: its centre half the height up,
/// and a quarter turn about x, since parry's cylinder runs along its local +y.
pub(super) fn upright_pose(base: Vec3, height: f32) -> Pose {
    Pose::from_parts(
        base + Vec3::Z * (0.5 * height),
        Quat::from_rotation_x(FRAC_PI_2),
    )
}
