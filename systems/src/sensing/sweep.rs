//! One sweep of one sensor: place its rays in the world, cast them, turn distances into the
//! endpoints and hit flags of a [`Scan`] (common.md §1-2).

use super::RayPattern;
use super::box_cast::LocalBox;
use super::frustum::{Frustum, RayTile};
use super::packet::{Directions, LANES};
use bevy_ecs::prelude::*;
use glam::{BVec4A, Quat, Vec3, Vec3A, Vec4};
use parry3d::bounding_volume::{Aabb, BoundingVolume};
use parry3d::query::Ray;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use rayon::prelude::*;
use uavex_components::sensor::{Mount, Scan};
use uavex_components::uav::QuadState;
use uavex_components::world::PARALLEL_RAY_THRESHOLD;
use uavex_components::world::WorldGeometry;

/// Where a sensor is and how it is turned, in the world frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SensorPose {
    pub origin: Vec3,
    /// Rotation from the sensor frame to the world frame.
    pub rotation: Quat,
}

impl SensorPose {
    /// The sensor's world pose = UAV pose * mount: the mount is given in the body frame.
    pub fn of(body: &QuadState, mount: &Mount) -> Self {
        Self {
            origin: body.position + body.attitude * mount.translation,
            rotation: (body.attitude * mount.rotation).normalize(),
        }
    }
}

/// When a sensor sweeps: every `period_s`, the first at t = 0.
///
/// Sweep times are `k * period_s` computed from the sweep count, not accumulated, so they never
/// drift; a sweep is due at the first tick at or after its time (within 1 ns, so that a 30 Hz
/// camera on a 300 Hz clock sweeps every 10th tick despite rounding of both time grids).
#[derive(Component, Debug, Clone, PartialEq)]
pub struct SweepSchedule {
    pub period_s: f64,
    /// Index of the next sweep; it is due at `next * period_s`.
    pub next: u64,
}

const SCHEDULE_TOLERANCE_S: f64 = 1e-9;

impl SweepSchedule {
    /// A schedule at `rate_hz` (> 0, finite; the scenario checks guarantee it).
    pub fn from_rate(rate_hz: f64) -> Self {
        Self {
            period_s: 1.0 / rate_hz,
            next: 0,
        }
    }

    pub fn next_time_s(&self) -> f64 {
        self.next as f64 * self.period_s
    }

    pub fn is_due(&self, time_s: f64) -> bool {
        time_s + SCHEDULE_TOLERANCE_S >= self.next_time_s()
    }

    /// Marks the sweep at `time_s` done: the next one is the first sweep time after it (sweeps
    /// missed by a coarse clock are skipped, never replayed).
    pub fn advance(&mut self, time_s: f64) {
        let done = ((time_s + SCHEDULE_TOLERANCE_S) / self.period_s).floor();
        self.next = (done.max(0.0) as u64 + 1).max(self.next + 1);
    }
}

/// The random stream of one sensor's range noise (`RunSeed::stream(SENSOR_NOISE, sensor id)`),
/// kept per sensor so that one sensor's draws never shift another's.
#[derive(Component, Debug, Clone)]
pub struct NoiseRng(pub ChaCha8Rng);

/// Per-sensor buffers reused from sweep to sweep (no allocation per tick after the first sweep).
#[derive(Component, Debug, Default, Clone)]
pub struct SweepScratch {
    world_directions: Vec<Vec3>,
    distances: Vec<Option<f32>>,
    near: NearObstacles,
}

/// Gaussian range noise: standard deviation (m) and the sensor's stream to draw from.
pub struct RangeNoise<'a> {
    pub std_m: f32,
    pub rng: &'a mut ChaCha8Rng,
}

/// Casts the pattern's rays from `pose` into `world` and fills `scan` in place
/// (common.md §1-2):
/// - a surface within range gives an endpoint on it, `hit = true` (its voxel becomes occupied);
/// - with noise, the measured range is the true one plus N(0, std^2), drawn in ray order;
/// - a measured range below `range_min` gives no depth: the ray is dropped;
/// - a measured range beyond `range_max`, or no surface at all, cuts the ray at `range_max` with
///   `hit = false` (free space only).
///
/// With noise, rays are cast `4 std` beyond `range_max`, so that a surface just out of range may
/// be measured inside it, as a real sensor would.
pub fn sweep(
    pattern: &RayPattern,
    pose: SensorPose,
    world: &WorldGeometry,
    mut noise: Option<RangeNoise<'_>>,
    scratch: &mut SweepScratch,
    scan: &mut Scan,
    time_s: f64,
) {
    let std_m = noise.as_ref().map_or(0.0, |n| n.std_m.max(0.0));
    let gaussian = Normal::new(0.0f32, std_m).ok().filter(|_| std_m > 0.0);
    let cast_range = pattern.range_max + 4.0 * std_m;

    rotate_all(
        pose.rotation,
        &pattern.directions,
        &mut scratch.world_directions,
    );
    cast_sweep(
        world,
        pose.origin,
        &scratch.world_directions,
        Culling {
            frustum: pattern.frustum.map(|f| f.rotated(pose.rotation)),
            tiles: Some(Tiles {
                tiles: &pattern.tiles,
                columns: pattern.columns as usize,
                rotation: pose.rotation,
            })
            .filter(|t| !t.tiles.is_empty()),
        },
        cast_range,
        &mut scratch.near,
        &mut scratch.distances,
    );

    scan.origin = pose.origin;
    scan.endpoints.clear();
    scan.hit.clear();
    for (dir, distance) in scratch.world_directions.iter().zip(&scratch.distances) {
        let measured = match (distance, &gaussian, noise.as_mut()) {
            (Some(d), Some(g), Some(n)) => Some(d + g.sample(n.rng)),
            (d, _, _) => *d,
        };
        match measured {
            Some(range) if range < pattern.range_min => {}
            Some(range) if range <= pattern.range_max => {
                scan.endpoints.push(pose.origin + *dir * range);
                scan.hit.push(true);
            }
            _ => {
                scan.endpoints.push(pose.origin + *dir * pattern.range_max);
                scan.hit.push(false);
            }
        }
    }
    scan.sequence += 1;
    scan.time_s = time_s;
}

/// `directions` rotated by `rotation` into `out` (`rotation * d` for each, four at a time:
/// the same bits, `super::packet`).
fn rotate_all(rotation: Quat, directions: &[Vec3], out: &mut Vec<Vec3>) {
    out.clear();
    let mut packets = directions.chunks_exact(LANES);
    for packet in &mut packets {
        let packet: &[Vec3; LANES] = packet.try_into().expect("a whole packet");
        let rotated = Directions::of(packet).rotated(rotation);
        out.extend((0..LANES).map(|lane| rotated.lane(lane)));
    }
    out.extend(packets.remainder().iter().map(|d| rotation * *d));
}

/// Most obstacles within a sweep's range for which the sweep casts its rays against each of them
/// directly instead of through the world's hierarchy. The thesis camera in the Pillars scene
/// sees two to four (ground, a pillar, a wall); a dense pillar field falls back to the hierarchy.
const MAX_NEAR_OBSTACLES: usize = 8;

/// Largest world whose obstacles a sweep scans for the near ones (one bounding box each per
/// sweep, about 2 us for 64); larger worlds use the hierarchy.
const MAX_SCANNED_OBSTACLES: usize = 64;

/// Relative and absolute margin (m) of [`NearObstacle::nearest`]: the ray tests round to a few
/// ulps of f32 (1e-7 relative), the directions are unit vectors to as many.
const NEAREST_MARGIN: f32 = 1e-4;

/// Rays per parallel task for long batches (as `WorldGeometry::cast_rays`).
const PARALLEL_RAY_CHUNK: usize = 1024;

/// An obstacle within a sweep's range, with the sweep's origin in its local frame.
#[derive(Debug, Clone, Copy)]
struct NearObstacle {
    index: usize,
    /// A lower bound of the distance from the sweep's origin to the obstacle: its bounding
    /// box's distance, less a margin far above the rounding of the ray tests, so that no hit on
    /// it can come nearer (0 from inside the box).
    nearest: f32,
    /// The sensor origin in the obstacle's frame (`pose.inverse_transform_point(origin)`).
    local_origin: Vec3A,
    /// Rotation from the world frame to the obstacle's frame (`pose.rotation.inverse()`).
    to_local: Quat,
    /// Its bounding box (world frame).
    aabb: Aabb,
    /// The shape when it is a box (most obstacles are): its ray test is parry's written out
    /// without branches (`super::box_cast`), inlined into the ray loop; other shapes are
    /// cast by `Obstacle::cast_local_ray` (cylinders in closed form, the rest by parry).
    cuboid: Option<LocalBox>,
}

/// The obstacles near a sweep, and those of them a tile's pyramid does not exclude (buffers
/// reused from sweep to sweep).
#[derive(Debug, Default, Clone)]
struct NearObstacles {
    all: Vec<NearObstacle>,
    tile: Vec<NearObstacle>,
}

/// What a sweep knows about where its rays can go, in the world frame.
#[derive(Debug, Clone, Copy, Default)]
struct Culling<'a> {
    /// The pyramid all rays lie in.
    frustum: Option<Frustum>,
    /// The pattern's tiles, each with the pyramid its rays lie in.
    tiles: Option<Tiles<'a>>,
}

/// A pattern's tiles ([`RayTile`], in the sensor frame) for one sweep.
#[derive(Debug, Clone, Copy)]
struct Tiles<'a> {
    tiles: &'a [RayTile],
    /// Rays per row of the pattern.
    columns: usize,
    /// Rotation from the sensor frame to the world frame.
    rotation: Quat,
}

/// Casts a ray from `origin` along each of `directions` into `out`, with the result of
/// [`WorldGeometry::cast_rays`]; `near` is a reused buffer.
///
/// All rays of a sweep share their origin and their range, so the obstacles they can reach are
/// those whose bounding box meets the box of the range sphere: found once per sweep, with the
/// origin moved into each one's frame once. Each ray is then cast against those few shapes
/// directly, skipping the hierarchy's traversal, which costs more than the box-shaped
/// obstacles' own ray tests (benches/sensing.rs). The per-shape test is the hierarchy's own
/// (`Obstacle::cast_ray` is `cast_local_ray` of the ray moved into the shape's frame by the
/// same two operations), and the nearest hit closer than the range wins, as in the
/// hierarchy's search.
/// The obstacles are tried nearest box first, and a ray stops trying once the next box lies
/// beyond its nearest hit so far: the shape in that box can only be hit farther away (in a
/// room, most rays end on the floor, a wall or a pillar before reaching the others' boxes).
/// With the `frustum` the directions lie in (world frame), obstacles whose boxes lie outside it
/// are not tried at all (the wall behind a camera, the pillar beside it); with the pattern's
/// tiles, each tile's rays try only the obstacles its own pyramid does not exclude (the ground
/// is not tried by the rays that look up: in the shipped Pillars mission, 6 % off sensing).
fn cast_sweep(
    world: &WorldGeometry,
    origin: Vec3,
    directions: &[Vec3],
    culling: Culling<'_>,
    range: f32,
    near: &mut NearObstacles,
    out: &mut Vec<Option<f32>>,
) {
    let scannable = world.obstacles().len() <= MAX_SCANNED_OBSTACLES;
    if !(scannable && origin.is_finite() && range.is_finite() && range >= 0.0) {
        world.cast_rays(origin, directions, range, out);
        return;
    }
    // The range box, widened against rounding of the boxes' bounds.
    let reach = Vec3::splat(range + 1e-3 * (1.0 + range));
    let range_box = Aabb::new(origin - reach, origin + reach);
    near.all.clear();
    for (index, obstacle) in world.obstacles().iter().enumerate() {
        let aabb = obstacle.aabb();
        if aabb.intersects(&range_box) && culling.frustum.is_none_or(|f| !f.excludes(origin, &aabb))
        {
            if near.all.len() == MAX_NEAR_OBSTACLES {
                world.cast_rays(origin, directions, range, out);
                return;
            }
            let gap = (aabb.mins - origin).max(origin - aabb.maxs).max(Vec3::ZERO);
            near.all.push(NearObstacle {
                index,
                nearest: gap.length() * (1.0 - NEAREST_MARGIN) - NEAREST_MARGIN,
                local_origin: obstacle.pose.inverse_transform_point(origin).into(),
                to_local: obstacle.pose.rotation.inverse(),
                aabb,
                cuboid: obstacle.shape.as_cuboid().map(LocalBox::of),
            });
        }
    }
    // Nearest first (ties in the world's order: a stable sort).
    near.all.sort_by(|a, b| a.nearest.total_cmp(&b.nearest));
    out.clear();
    out.resize(directions.len(), None);
    let obstacles = world.obstacles();
    // Four rays at a time (`super::packet`), each lane what the ray alone would give: tried
    // against the obstacles nearest box first, its nearest hit closer than the range winning.
    // A lane goes on past an obstacle its own ray would have stopped at (one whose box lies
    // beyond its nearest hit so far): no hit there can come nearer, so its answer stays the
    // same.
    let cast4 = |dirs: &[Vec3; LANES], near: &[NearObstacle]| -> [Option<f32>; LANES] {
        let packet = Directions::of(dirs);
        let mut best = Vec4::splat(range);
        let mut hit = BVec4A::FALSE;
        for n in near {
            if Vec4::splat(n.nearest).cmpgt(best).all() {
                break;
            }
            let local = packet.rotated(n.to_local);
            match &n.cuboid {
                Some(local_box) => {
                    let found = local_box.cast4(n.local_origin, &local, best);
                    let nearer = found.hit & found.toi.cmplt(best);
                    best = Vec4::select(nearer, found.toi, best);
                    hit |= nearer;
                }
                None => {
                    for lane in 0..LANES {
                        let toi = obstacles[n.index].cast_local_ray(
                            &Ray::new(n.local_origin.into(), local.lane(lane)),
                            best[lane],
                        );
                        if let Some(toi) = toi
                            && toi < best[lane]
                        {
                            best[lane] = toi;
                            hit.set(lane, true);
                        }
                    }
                }
            }
        }
        std::array::from_fn(|lane| hit.test(lane).then_some(best[lane]))
    };
    let cast_all = |dirs: &[Vec3], out: &mut [Option<f32>], near: &[NearObstacle]| {
        let mut packets = dirs.chunks_exact(LANES);
        let mut slots = out.chunks_exact_mut(LANES);
        for (packet, slots) in (&mut packets).zip(&mut slots) {
            let packet: &[Vec3; LANES] = packet.try_into().expect("a whole packet");
            slots.copy_from_slice(&cast4(packet, near));
        }
        // The last rays in a packet padded with copies of the last one. (Whole packets stay
        // on their own loop of fixed-size copies: one padded-packet iterator for all of them
        // made the sense stage 45 % slower, a variable-length copy per packet.)
        let (rest, rest_slots) = (packets.remainder(), slots.into_remainder());
        if let Some(&last) = rest.last() {
            let packet = std::array::from_fn(|lane| rest.get(lane).copied().unwrap_or(last));
            rest_slots.copy_from_slice(&cast4(&packet, near)[..rest.len()]);
        }
    };
    if directions.len() >= PARALLEL_RAY_THRESHOLD {
        directions
            .par_chunks(PARALLEL_RAY_CHUNK)
            .zip(out.par_chunks_mut(PARALLEL_RAY_CHUNK))
            .for_each(|(dirs, out)| cast_all(dirs, out, &near.all));
    } else if let Some(tiles) = culling.tiles {
        // Tile by tile, each ray against the obstacles its tile can reach (a subset of the
        // near ones in the same order: the same nearest hit).
        for tile in tiles.tiles {
            let frustum = tile.frustum.rotated(tiles.rotation);
            near.tile.clear();
            let reached = near
                .all
                .iter()
                .filter(|n| !frustum.excludes(origin, &n.aabb));
            near.tile.extend(reached);
            for row in tile.rows.clone() {
                let rays = row * tiles.columns..;
                cast_all(
                    &directions[rays.clone()][tile.columns.clone()],
                    &mut out[rays][tile.columns.clone()],
                    &near.tile,
                );
            }
        }
    } else {
        cast_all(directions, out, &near.all);
    }
}

#[cfg(test)]
mod tests;
