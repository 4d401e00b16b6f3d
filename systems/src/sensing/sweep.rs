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
    /// cast through their table of methods.
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
/// obstacles' own ray tests (benches/sensing.rs). The per-shape test is parry's own
/// (`cast_ray` is `cast_local_ray` of the ray moved into the shape's frame by the same two
/// operations), and the nearest hit closer than the range wins, as in the hierarchy's search.
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
                        let toi = obstacles[n.index].shape.cast_local_ray(
                            &Ray::new(n.local_origin.into(), local.lane(lane)),
                            best[lane],
                            true,
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
mod tests {
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
        let (mut near, mut direct, mut reference) =
            (NearObstacles::default(), Vec::new(), Vec::new());
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
        let (mut near, mut direct, mut reference) =
            (NearObstacles::default(), Vec::new(), Vec::new());
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
}
