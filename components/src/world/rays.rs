//! Ray casts against the world geometry (common.md §2: "sensing is raycasting against the world
//! geometry (parry)").

use super::WorldGeometry;
use glam::Vec3;
use parry3d::query::Ray;
use rayon::prelude::*;

/// Batches at least this long are cast on the rayon pool, in chunks of
/// `PARALLEL_RAY_CHUNK` rays. A Pillars-scene ray costs about 0.2 us (benches/sensing.rs), so
/// such a batch is ~1 ms of work, far above rayon's fork/join cost; shorter batches (the auto
/// grid's 2,255 rays of the EAAE camera) stay serial, since sweeps of many runs already keep
/// every core busy with whole runs (DESIGN.md, "Runs, sweeps and scale"). Each ray's result
/// depends on that ray alone, so the split never changes a result.
pub const PARALLEL_RAY_THRESHOLD: usize = 4096;
const PARALLEL_RAY_CHUNK: usize = 1024;

impl WorldGeometry {
    /// Distance from `origin` along the unit vector `dir` to the first obstacle surface, if one
    /// lies within `max_distance`. A ray starting inside a box, cylinder, sphere, ball of a cloud
    /// or the ground hits at distance 0 (a sensor inside a wall sees nothing).
    pub fn cast_ray(&self, origin: Vec3, dir: Vec3, max_distance: f32) -> Option<f32> {
        self.cast_ray_and_get_obstacle(origin, dir, max_distance)
            .map(|(_, distance)| distance)
    }

    /// Like [`Self::cast_ray`], also naming the obstacle hit (its index in [`Self::obstacles`]).
    pub fn cast_ray_and_get_obstacle(
        &self,
        origin: Vec3,
        dir: Vec3,
        max_distance: f32,
    ) -> Option<(usize, f32)> {
        if self.obstacles.is_empty() || max_distance.is_nan() || max_distance < 0.0 {
            return None;
        }
        let ray = Ray::new(origin, dir);
        self.bvh
            .cast_ray(&ray, max_distance, |leaf, best_so_far| {
                self.obstacles[leaf as usize].cast_ray(&ray, best_so_far)
            })
            .map(|(leaf, distance)| (leaf as usize, distance))
    }

    /// Casts one ray from `origin` along each unit vector of `directions`; `distances[i]` receives
    /// the result of [`Self::cast_ray`] for `directions[i]`. `distances` is resized to match and
    /// its allocation reused. Long batches run in parallel (see [`PARALLEL_RAY_THRESHOLD`]); the
    /// results do not depend on the thread count.
    pub fn cast_rays(
        &self,
        origin: Vec3,
        directions: &[Vec3],
        max_distance: f32,
        distances: &mut Vec<Option<f32>>,
    ) {
        distances.clear();
        distances.resize(directions.len(), None);
        if directions.len() >= PARALLEL_RAY_THRESHOLD {
            directions
                .par_chunks(PARALLEL_RAY_CHUNK)
                .zip(distances.par_chunks_mut(PARALLEL_RAY_CHUNK))
                .for_each(|(dirs, out)| self.cast_rays_serial(origin, dirs, max_distance, out));
        } else {
            self.cast_rays_serial(origin, directions, max_distance, distances);
        }
    }

    fn cast_rays_serial(
        &self,
        origin: Vec3,
        directions: &[Vec3],
        max_distance: f32,
        out: &mut [Option<f32>],
    ) {
        for (dir, slot) in directions.iter().zip(out) {
            *slot = self.cast_ray(origin, *dir, max_distance);
        }
    }
}
