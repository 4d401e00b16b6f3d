//! World building: from the scenario's `[world]` table to the [`WorldGeometry`] that sensing,
//! ground truth and (through [`colliders`]) the rapier flight all share, and from each
//! `[[uav.sensor]]` to the components of a sensor entity ([`sensor_bundle`]).
//!
//! Every problem is reported with the scenario field it comes from (`world.obstacle[3].file`), so
//! the scenario loader can turn it into a located diagnostic; all problems are collected, not
//! just the first.

mod colliders;
mod files;
mod pillars;
mod primitives;
mod sensors;

pub use colliders::colliders;
pub use pillars::{KEPT_CLEAR_MARGIN_M, Pillar, PillarField, generate_pillars};
pub use primitives::{GROUND_MARGIN, GROUND_THICKNESS};
pub use sensors::{SensorBundle, mount_from_spec, sensor_bundle};

use crate::scenario::{ObstacleSpec, WorldSpec};
use glam::Vec3;
use parry3d::shape::Capsule;
use std::path::Path;
use uavex_components::sim::RunSeed;
use uavex_components::world::{Obstacle, WorldGeometry, WorldGeometryError};

/// A problem with the scenario found while building the world: the field it concerns and what
/// is wrong.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{path}: {message}")]
pub struct BuildError {
    /// Field path in the scenario, e.g. `world.obstacle[3].file` or `uav[0].start.position`.
    pub path: String,
    pub message: String,
}

impl BuildError {
    pub fn new(path: impl Into<String>, message: impl Into<String>) -> Self {
        Self {
            path: path.into(),
            message: message.into(),
        }
    }
}

/// Builds the world geometry of `spec`: every obstacle (boxes, cylinders, spheres, meshes and
/// clouds from files relative to `base_dir`, seeded pillar fields kept clear of `starts` and of
/// the capsules `kept_clear`, e.g. explorers' start capsules) plus the ground. Collects every
/// problem before giving up.
pub fn build_world(
    spec: &WorldSpec,
    seed: RunSeed,
    starts: &[Vec3],
    kept_clear: &[Capsule],
    base_dir: &Path,
) -> Result<WorldGeometry, Vec<BuildError>> {
    let mut obstacles = Vec::new();
    let mut errors = Vec::new();
    if spec.ground {
        match primitives::ground(spec.bounds) {
            Ok(ground) => obstacles.push(ground),
            Err(e) => errors.push(e),
        }
    }
    for (index, obstacle) in spec.obstacles.iter().enumerate() {
        let field = format!("world.obstacle[{index}]");
        let built = match obstacle {
            ObstacleSpec::Mesh { .. } | ObstacleSpec::Cloud { .. } => {
                files::build(obstacle, index, &field, base_dir).map(|o| vec![o])
            }
            ObstacleSpec::Pillars { .. } => {
                pillars::build(obstacle, index, &field, seed, starts, kept_clear)
            }
            _ => primitives::build(obstacle, index, &field).map(|o| vec![o]),
        };
        match built {
            Ok(mut built) => obstacles.append(&mut built),
            Err(mut e) => errors.append(&mut e),
        }
    }
    if !errors.is_empty() {
        return Err(errors);
    }
    WorldGeometry::new(obstacles).map_err(|e| {
        let WorldGeometryError::NotFinite { source_field, .. } = &e;
        vec![BuildError::new(source_field.clone(), e.to_string())]
    })
}

/// Refuses UAV starts that put a ball of `body_radius` (the airframe's bounding sphere) into an
/// obstacle; `starts[i]` is reported as `uav[i].start.position`.
pub fn check_starts(world: &WorldGeometry, starts: &[Vec3], body_radius: f32) -> Vec<BuildError> {
    check_starts_with_radii(world, starts, &vec![body_radius; starts.len()])
}

/// [`check_starts`] with each UAV's own radius: `body_radii[i]` for `starts[i]`.
pub fn check_starts_with_radii(
    world: &WorldGeometry,
    starts: &[Vec3],
    body_radii: &[f32],
) -> Vec<BuildError> {
    starts
        .iter()
        .zip(body_radii)
        .enumerate()
        .filter_map(|(i, (&start, &body_radius))| {
            let hit = world.obstacle_intersecting_ball(start, body_radius)?;
            let obstacle = &world.obstacles()[hit];
            Some(BuildError::new(
                format!("uav[{i}].start.position"),
                format!(
                    "the UAV (radius {body_radius} m) at ({}, {}, {}) starts inside or within \
                     its radius of obstacle '{}' ({})",
                    start.x, start.y, start.z, obstacle.name, obstacle.source
                ),
            ))
        })
        .collect()
}

/// The obstacle's own name, or `"{kind} {index}"`.
fn display_name(name: &Option<String>, kind: &str, index: usize) -> String {
    name.clone().unwrap_or_else(|| format!("{kind} {index}"))
}

/// Pushes an error unless every value is finite.
fn require_finite(errors: &mut Vec<BuildError>, path: String, values: &[f64]) {
    if values.iter().any(|v| !v.is_finite()) {
        errors.push(BuildError::new(
            path,
            format!("must be finite, got {values:?}"),
        ));
    }
}

/// Pushes an error unless `value` is finite and positive.
fn require_positive(errors: &mut Vec<BuildError>, path: String, value: f64) {
    if !(value.is_finite() && value > 0.0) {
        errors.push(BuildError::new(
            path,
            format!("must be finite and positive, got {value}"),
        ));
    }
}

fn vec3(v: [f64; 3]) -> Vec3 {
    Vec3::new(v[0] as f32, v[1] as f32, v[2] as f32)
}

/// Keeps a built obstacle's pieces together for the error path.
fn obstacle_or(
    errors: Vec<BuildError>,
    obstacle: impl FnOnce() -> Obstacle,
) -> Result<Obstacle, Vec<BuildError>> {
    if errors.is_empty() {
        Ok(obstacle())
    } else {
        Err(errors)
    }
}

#[cfg(test)]
mod fidelity_tests;
#[cfg(test)]
mod tests;
