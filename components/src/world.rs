//! The world's obstacles as parry shapes in one bounding-volume hierarchy: the single source of
//! truth for sensing (ray casts, common.md §2), for "does this start lie inside an obstacle",
//! and for the ground-truth occupancy that map accuracy is measured against.
//!
//! Each obstacle keeps its own name and the scenario field it came from, so that errors and tests
//! can point at it. The engine builds a [`WorldGeometry`] from the scenario (`engine::world`) and
//! derives the rapier colliders of the true flight from the same shapes.

mod cylinder_ray;
mod ground_truth;
mod rays;

pub use cylinder_ray::cast_local_cylinder;
pub use ground_truth::VOXEL_SHRINK;
pub use rays::PARALLEL_RAY_THRESHOLD;

use bevy_ecs::prelude::*;
use parry3d::bounding_volume::Aabb;
use parry3d::math::Pose;
use parry3d::partitioning::{Bvh, BvhBuildStrategy};
use parry3d::query::Ray;
use parry3d::shape::{SharedShape, TriMeshFlags};

/// One obstacle: a parry shape placed in the world.
#[derive(Clone)]
pub struct Obstacle {
    /// Human name: the scenario's `name` when given, else a generated one (`box 3`, `pillars 2 #17`).
    pub name: String,
    /// The scenario field it came from (e.g. `world.obstacle[3]`), or `world.ground`.
    pub source: String,
    /// Pose of the shape in the world frame.
    pub pose: Pose,
    pub shape: SharedShape,
}

impl Obstacle {
    pub fn new(
        name: impl Into<String>,
        source: impl Into<String>,
        pose: Pose,
        shape: SharedShape,
    ) -> Self {
        Self {
            name: name.into(),
            source: source.into(),
            pose,
            shape,
        }
    }

    /// Whether the obstacle is a closed, consistently oriented triangle mesh, whose inside counts
    /// as solid. Parry's shape-against-mesh tests see only the triangles, so the ground-truth
    /// queries add a point-inside test for these (see `ground_truth.rs`). Open meshes are thin
    /// shells: only their surface is an obstacle.
    pub fn is_solid_mesh(&self) -> bool {
        self.shape
            .as_trimesh()
            .is_some_and(|mesh| mesh.flags().contains(TriMeshFlags::ORIENTED))
    }

    /// Where the ray (in the obstacle's frame) first meets the solid shape within `max_toi`, 0
    /// from inside: parry's `cast_local_ray(ray, max_toi, true)`, but for a cylinder, which is
    /// cast in closed form ([`cast_local_cylinder`]).
    #[inline]
    pub fn cast_local_ray(&self, ray: &Ray, max_toi: f32) -> Option<f32> {
        match self.shape.as_cylinder() {
            Some(cylinder) => cast_local_cylinder(cylinder, ray.origin, ray.dir, max_toi),
            None => self.shape.cast_local_ray(ray, max_toi, true),
        }
    }

    /// [`Self::cast_local_ray`] of a world-frame ray, moved into the obstacle's frame as parry's
    /// `cast_ray` moves it.
    pub fn cast_ray(&self, ray: &Ray, max_toi: f32) -> Option<f32> {
        self.cast_local_ray(&ray.inverse_transform_by(&self.pose), max_toi)
    }

    /// World-frame bounding box.
    pub fn aabb(&self) -> Aabb {
        self.shape.compute_aabb(&self.pose)
    }
}

impl std::fmt::Debug for Obstacle {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Obstacle")
            .field("name", &self.name)
            .field("source", &self.source)
            .field("pose", &self.pose)
            .field("shape_type", &self.shape.shape_type())
            .finish()
    }
}

/// A geometry that cannot be queried (it would make parry's hierarchy meaningless).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum WorldGeometryError {
    #[error("obstacle '{name}' ({source_field}) has a non-finite pose or extent")]
    NotFinite { name: String, source_field: String },
}

/// Every obstacle of the world, with a BVH over their bounding boxes for queries
/// (DESIGN.md: "WorldGeometry (parry shapes in a BVH, for rays)").
///
/// Leaf `i` of the hierarchy is `obstacles[i]`. Composite obstacles (meshes, point clouds) carry
/// their own inner hierarchy inside their parry shape, so a query descends two levels.
#[derive(Resource, Clone, Debug)]
pub struct WorldGeometry {
    obstacles: Vec<Obstacle>,
    bvh: Bvh,
}

impl WorldGeometry {
    /// Builds the hierarchy over `obstacles`. Refuses obstacles with NaN or infinite poses or
    /// bounding boxes (the builder validates sizes; this is the last line of defence).
    pub fn new(obstacles: Vec<Obstacle>) -> Result<Self, WorldGeometryError> {
        let mut aabbs = Vec::with_capacity(obstacles.len());
        for obstacle in &obstacles {
            let aabb = obstacle.aabb();
            if !obstacle.pose.is_finite() || !aabb.mins.is_finite() || !aabb.maxs.is_finite() {
                return Err(WorldGeometryError::NotFinite {
                    name: obstacle.name.clone(),
                    source_field: obstacle.source.clone(),
                });
            }
            aabbs.push(aabb);
        }
        let bvh = if aabbs.is_empty() {
            Bvh::new()
        } else {
            Bvh::from_leaves(BvhBuildStrategy::Binned, &aabbs)
        };
        Ok(Self { obstacles, bvh })
    }

    /// A world without obstacles (every ray misses).
    pub fn empty() -> Self {
        Self {
            obstacles: Vec::new(),
            bvh: Bvh::new(),
        }
    }

    pub fn obstacles(&self) -> &[Obstacle] {
        &self.obstacles
    }

    /// The obstacle called `name`, if any (first match).
    pub fn obstacle_named(&self, name: &str) -> Option<&Obstacle> {
        self.obstacles.iter().find(|o| o.name == name)
    }

    /// Bounding box of all obstacles, `None` for an empty world.
    pub fn aabb(&self) -> Option<Aabb> {
        (!self.obstacles.is_empty()).then(|| self.bvh.root_aabb())
    }
}

#[cfg(test)]
mod tests;
