//! Point, ball and voxel queries: what is really solid. Used to refuse a UAV that starts inside an
//! obstacle and as the ground truth that map accuracy is measured against.

use super::{Obstacle, WorldGeometry};
use glam::{IVec3, Vec3};
use parry3d::bounding_volume::Aabb;
use parry3d::math::Pose;
use parry3d::query::intersection_test;
use parry3d::shape::{Ball, Cuboid, Shape};

/// Fraction of the voxel edge by which a voxel cube is shrunk on every side before the
/// ground-truth test, so that an obstacle face lying exactly on a voxel boundary marks the voxel
/// on its solid side only. 1e-3 of 0.1 m is 0.1 mm: far above f32 rounding of coordinates of tens
/// of metres (~1e-6 m), far below any feature a map at that resolution can show.
pub const VOXEL_SHRINK: f32 = 1e-3;

impl WorldGeometry {
    /// Whether `point` lies inside (or on) an obstacle.
    pub fn contains_point(&self, point: Vec3) -> bool {
        self.obstacle_containing(point).is_some()
    }

    /// The first obstacle (index into [`Self::obstacles`]) containing `point`.
    pub fn obstacle_containing(&self, point: Vec3) -> Option<usize> {
        if self.obstacles.is_empty() {
            return None;
        }
        let probe = Aabb::new(point, point);
        self.bvh
            .intersect_aabb(&probe)
            .map(|leaf| leaf as usize)
            .find(|&i| {
                let obstacle = &self.obstacles[i];
                obstacle.shape.contains_point(&obstacle.pose, point)
            })
    }

    /// Whether a ball of `radius` at `center` touches or overlaps an obstacle (e.g. a UAV's
    /// bounding sphere at its start position).
    pub fn intersects_ball(&self, center: Vec3, radius: f32) -> bool {
        self.obstacle_intersecting_ball(center, radius).is_some()
    }

    /// The first obstacle (index) touched by the ball, if any.
    pub fn obstacle_intersecting_ball(&self, center: Vec3, radius: f32) -> Option<usize> {
        self.first_intersecting(&Pose::from_translation(center), &Ball::new(radius), center)
    }

    /// The first obstacle touched by the ball that also reaches into `region` (an obstacle
    /// merely touching its faces does not), if any. Conservative: the obstacle need not touch
    /// the ball inside `region`. Why: a space the map and planner know only inside their box
    /// (an explorer's start capsule) contradicts no obstacle that stays outside the box, such
    /// as the ground slab under a map whose floor is z = 0.
    pub fn obstacle_intersecting_ball_within(
        &self,
        center: Vec3,
        radius: f32,
        region: &Aabb,
    ) -> Option<usize> {
        let inside = Cuboid::new(region.half_extents());
        let inside_pose = Pose::from_translation(region.center());
        self.first_intersecting_where(
            &Pose::from_translation(center),
            &Ball::new(radius),
            center,
            |obstacle| shape_intersects(&inside_pose, &inside, region.center(), obstacle),
        )
    }

    /// Ground truth of one voxel: whether the cube centred at `center` with edge `edge`, shrunk
    /// by [`VOXEL_SHRINK`] of the edge on every side, overlaps an obstacle. A face of an obstacle
    /// that merely touches the voxel does not count; a voxel wholly inside a solid does.
    pub fn voxel_occupied(&self, center: Vec3, edge: f32) -> bool {
        let half = 0.5 * edge * (1.0 - 2.0 * VOXEL_SHRINK);
        let cube = Cuboid::new(Vec3::splat(half));
        self.first_intersecting(&Pose::from_translation(center), &cube, center)
            .is_some()
    }

    /// Ground truth of the voxel with map key `key` (the voxel spans
    /// `[key * resolution, (key + 1) * resolution)`, as the map's `floor(p / resolution)` keys).
    pub fn voxel_key_occupied(&self, key: IVec3, resolution: f32) -> bool {
        let center = (key.as_dvec3() + 0.5) * f64::from(resolution);
        self.voxel_occupied(center.as_vec3(), resolution)
    }

    /// Whether some voxel of the keys `lo..=hi` may be occupied ([`Self::voxel_key_occupied`]):
    /// false only when no obstacle's bounding box meets the box of those voxels, each shrunk as
    /// there (by half the shrink, a margin far above rounding). One bounding-volume query for a
    /// whole block of voxels, most of which lie in open space.
    pub fn voxel_keys_may_be_occupied(&self, lo: IVec3, hi: IVec3, resolution: f32) -> bool {
        if self.obstacles.is_empty() {
            return false;
        }
        let margin = 0.5 * f64::from(VOXEL_SHRINK) * f64::from(resolution);
        let r = f64::from(resolution);
        let min = lo.as_dvec3() * r + margin;
        let max = (hi + IVec3::ONE).as_dvec3() * r - margin;
        let probe = Aabb::new(min.as_vec3(), max.as_vec3());
        self.bvh.intersect_aabb(&probe).next().is_some()
    }

    /// The first obstacle intersecting `shape` at `pose`; `center` is a point inside the shape,
    /// used for the inside test of closed meshes.
    fn first_intersecting(&self, pose: &Pose, shape: &dyn Shape, center: Vec3) -> Option<usize> {
        self.first_intersecting_where(pose, shape, center, |_| true)
    }

    /// [`Self::first_intersecting`] among the obstacles that `keep` accepts.
    fn first_intersecting_where(
        &self,
        pose: &Pose,
        shape: &dyn Shape,
        center: Vec3,
        keep: impl Fn(&Obstacle) -> bool,
    ) -> Option<usize> {
        if self.obstacles.is_empty() {
            return None;
        }
        let aabb = shape.compute_aabb(pose);
        self.bvh
            .intersect_aabb(&aabb)
            .map(|leaf| leaf as usize)
            .find(|&i| {
                let obstacle = &self.obstacles[i];
                shape_intersects(pose, shape, center, obstacle) && keep(obstacle)
            })
    }
}

/// Parry's shape-against-mesh test sees triangles only, so a query shape wholly inside a closed
/// mesh needs the extra inside test of a point of it.
fn shape_intersects(pose: &Pose, shape: &dyn Shape, center: Vec3, obstacle: &Obstacle) -> bool {
    let touches = intersection_test(pose, shape, &obstacle.pose, obstacle.shape.as_ref())
        .is_ok_and(|hit| hit.intersecting);
    touches || (obstacle.is_solid_mesh() && obstacle.shape.contains_point(&obstacle.pose, center))
}
