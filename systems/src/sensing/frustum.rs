//! The pyramid a camera's rays lie in, to pass over the obstacles beside and behind it.
//!
//! A sweep casts its rays against the obstacles whose bounding boxes lie within its range
//! (`super::sweep`), and most of that box around a camera lies outside its field of view: the
//! wall behind it, the pillar beside it. Four planes through the sensor's origin that every ray
//! lies behind bound where any ray can go; an obstacle whose bounding box lies wholly in front
//! of one of them cannot be hit by any ray of the sweep and is not tried. The same holds for
//! each tile of 8 x 8 rays ([`RayTile`]) and the narrower pyramid it lies in.

use glam::{Quat, Vec3};
use parry3d::bounding_volume::Aabb;
use std::ops::Range;

/// Margin in slope (tangent) by which the planes stand off the outermost rays: far above the
/// rounding of a direction turned into the world frame (1e-7), so that every ray lies strictly
/// behind every plane there too.
const SLOPE_MARGIN: f32 = 1e-3;

/// How far (m, along a plane's normal, of length >= 1) a bounding box must lie in front of a
/// plane to be passed over: far above the rounding of the ray tests near it (1e-6 m).
const BOX_MARGIN: f32 = 1e-4;

/// Rays whose component along +x is below this have no enclosing pyramid here (a lidar's).
const MIN_FORWARD: f32 = 0.1;

/// Four planes through the sensor's origin, by normals: every ray direction `d` of the pattern
/// has `n . d < 0` for each.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frustum {
    normals: [Vec3; 4],
}

impl Frustum {
    /// The pyramid around +x (the sensor frame's forward axis) that holds every direction, its
    /// sides at the extreme slopes `y / x` and `z / x` of the directions plus a margin; `None`
    /// when some direction does not point well forward (a lidar's beams) or is not finite.
    pub fn enclosing(directions: &[Vec3]) -> Option<Self> {
        let (mut y_min, mut y_max) = (f32::INFINITY, f32::NEG_INFINITY);
        let (mut z_min, mut z_max) = (f32::INFINITY, f32::NEG_INFINITY);
        for d in directions {
            if !(d.is_finite() && d.x >= MIN_FORWARD * d.length()) {
                return None;
            }
            let (y, z) = (d.y / d.x, d.z / d.x);
            (y_min, y_max) = (y_min.min(y), y_max.max(y));
            (z_min, z_max) = (z_min.min(z), z_max.max(z));
        }
        if directions.is_empty() {
            return None;
        }
        // n . d = d.x (slope - bound) <= -SLOPE_MARGIN d.x < 0.
        Some(Self {
            normals: [
                Vec3::new(-(y_max + SLOPE_MARGIN), 1.0, 0.0),
                Vec3::new(y_min - SLOPE_MARGIN, -1.0, 0.0),
                Vec3::new(-(z_max + SLOPE_MARGIN), 0.0, 1.0),
                Vec3::new(z_min - SLOPE_MARGIN, 0.0, -1.0),
            ],
        })
    }

    /// The same pyramid turned by `rotation` (the sensor's orientation in the world).
    pub fn rotated(&self, rotation: Quat) -> Self {
        Self {
            normals: self.normals.map(|n| rotation * n),
        }
    }

    /// Whether no ray from `origin` inside the pyramid can meet `aabb`: the box lies wholly in
    /// front of one of the planes (a ray's points `origin + t d`, `t >= 0`, all lie behind
    /// each plane).
    pub fn excludes(&self, origin: Vec3, aabb: &Aabb) -> bool {
        let (lo, hi) = (aabb.mins - origin, aabb.maxs - origin);
        self.normals.iter().any(|n| {
            // The box's point nearest the plane's back side.
            let nearest = (*n * lo).min(*n * hi);
            nearest.x + nearest.y + nearest.z > BOX_MARGIN
        })
    }
}

/// Rows and columns of rays in one [`RayTile`] (fewer at the image's right and bottom edges).
pub const TILE_EDGE: usize = 8;

/// A block of a camera pattern's rays (row-major, `columns` per row) and the pyramid they lie
/// in. A sweep tries, for a tile's rays, only the obstacles its pyramid does not exclude: the
/// ground for the tiles that look up, a pillar for the tiles beside it.
#[derive(Debug, Clone, PartialEq)]
pub struct RayTile {
    pub rows: Range<usize>,
    pub columns: Range<usize>,
    pub frustum: Frustum,
}

impl RayTile {
    /// The pattern's rays in tiles of `TILE_EDGE`^2, covering each ray once; none when some
    /// tile has no enclosing pyramid (rays that do not all look forward).
    pub fn tile(directions: &[Vec3], columns: usize, rows: usize) -> Vec<Self> {
        if columns * rows != directions.len() {
            return Vec::new();
        }
        let starts = |n: usize| {
            (0..n)
                .step_by(TILE_EDGE)
                .map(move |s| s..(s + TILE_EDGE).min(n))
        };
        let mut tiles = Vec::new();
        for tile_rows in starts(rows) {
            for tile_columns in starts(columns) {
                let rays: Vec<Vec3> = tile_rows
                    .clone()
                    .flat_map(|r| {
                        directions[r * columns..][tile_columns.clone()]
                            .iter()
                            .copied()
                    })
                    .collect();
                let Some(frustum) = Frustum::enclosing(&rays) else {
                    return Vec::new();
                };
                tiles.push(Self {
                    rows: tile_rows.clone(),
                    columns: tile_columns,
                    frustum,
                });
            }
        }
        tiles
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn camera() -> Frustum {
        let directions: Vec<Vec3> = (0..9)
            .map(|i| {
                Vec3::new(
                    1.0,
                    0.5 * (i % 3) as f32 - 0.5,
                    0.25 * (i / 3) as f32 - 0.25,
                )
            })
            .map(Vec3::normalize)
            .collect();
        Frustum::enclosing(&directions).expect("a forward pattern")
    }

    #[test]
    fn boxes_behind_and_beside_are_excluded_those_in_view_are_not() {
        let f = camera();
        let cube = |c: Vec3| Aabb::new(c - Vec3::splat(0.5), c + Vec3::splat(0.5));
        // Behind, far left (slope 4 > 0.5), far below: outside.
        for c in [
            Vec3::new(-3.0, 0.0, 0.0),
            Vec3::new(1.0, 4.0, 0.0),
            Vec3::new(2.0, 0.0, -3.0),
        ] {
            assert!(f.excludes(Vec3::ZERO, &cube(c)), "{c}");
        }
        // Ahead, at the edge of view, around the origin, and a long wall across the view.
        for c in [
            Vec3::new(3.0, 0.0, 0.0),
            Vec3::new(3.0, 1.9, 0.0),
            Vec3::ZERO,
        ] {
            assert!(!f.excludes(Vec3::ZERO, &cube(c)), "{c}");
        }
        let wall = Aabb::new(Vec3::new(-5.0, 3.0, -1.0), Vec3::new(20.0, 3.2, 2.0));
        assert!(!f.excludes(Vec3::ZERO, &wall));
        // Turned half a turn about z, the pyramid looks along -x.
        let back = f.rotated(Quat::from_rotation_z(std::f32::consts::PI));
        assert!(!back.excludes(Vec3::ZERO, &cube(Vec3::new(-3.0, 0.0, 0.0))));
        assert!(back.excludes(Vec3::ZERO, &cube(Vec3::new(3.0, 0.0, 0.0))));
    }

    /// The thesis camera's `auto` pattern (640 x 480 px, 1.0 rad, 0.5-5 m, 0.1 m map).
    fn thesis_camera() -> crate::sensing::RayPattern {
        use crate::sensing::{PinholeCamera, RayGrid, camera_pattern};
        let camera = PinholeCamera {
            width: 640,
            height: 480,
            hfov: 1.0,
        };
        camera_pattern(camera, RayGrid::Auto { resolution: 0.1 }, 0.5, 5.0).expect("pattern")
    }

    /// The thesis camera's `auto` rays all lie strictly behind every plane, however the camera
    /// is turned, and a direction just past the corner ray (by 2.5e-3 in slope) does not.
    #[test]
    fn every_ray_lies_behind_every_plane_and_the_planes_are_tight() {
        let pattern = thesis_camera();
        let frustum = pattern.frustum.expect("a camera's frustum");
        for rotation in [
            Quat::IDENTITY,
            Quat::from_euler(glam::EulerRot::ZYX, 2.3, -0.4, 0.1),
            Quat::from_rotation_z(-1.2),
        ] {
            let turned = frustum.rotated(rotation);
            for d in &pattern.directions {
                let w = rotation * *d;
                assert!(turned.normals.iter().all(|n| n.dot(w) < 0.0), "{w}");
            }
        }
        let corner = pattern.directions[0];
        let past = corner + Vec3::new(0.0, 2.5e-3 * corner.x, 0.0);
        assert!(frustum.normals.iter().any(|n| n.dot(past) > 0.0));
    }

    /// The thesis camera's `auto` rays (55 x 41) fall in 7 x 6 tiles, each ray in exactly one,
    /// strictly behind every plane of its tile; a tile's pyramid is narrower than the
    /// camera's.
    #[test]
    fn tiles_cover_every_ray_once_each_inside_its_pyramid() {
        let pattern = thesis_camera();
        let columns = pattern.columns as usize;
        assert_eq!((columns, pattern.rows), (55, 41));
        assert_eq!(pattern.tiles.len(), 7 * 6);
        let mut covered = vec![0; pattern.directions.len()];
        for tile in &pattern.tiles {
            for row in tile.rows.clone() {
                for column in tile.columns.clone() {
                    let i = row * columns + column;
                    covered[i] += 1;
                    let d = pattern.directions[i];
                    assert!(
                        tile.frustum.normals.iter().all(|n| n.dot(d) < 0.0),
                        "ray {i}"
                    );
                }
            }
        }
        assert!(covered.iter().all(|&n| n == 1));
        // The middle tile excludes a box the whole camera sees (left of the middle).
        let middle = &pattern.tiles[2 * 7 + 3];
        let left = Aabb::new(Vec3::new(4.0, 1.0, -0.2), Vec3::new(4.5, 1.5, 0.2));
        assert!(middle.frustum.excludes(Vec3::ZERO, &left));
        assert!(!pattern.frustum.unwrap().excludes(Vec3::ZERO, &left));
        // Rays that do not fill the grid, or look back, have no tiles.
        assert!(RayTile::tile(&pattern.directions, columns + 1, 41).is_empty());
        assert!(RayTile::tile(&[Vec3::X, Vec3::NEG_X], 2, 1).is_empty());
    }

    #[test]
    fn a_pattern_that_looks_sideways_or_back_has_none() {
        assert!(Frustum::enclosing(&[Vec3::X, Vec3::Y]).is_none());
        assert!(Frustum::enclosing(&[Vec3::X, Vec3::NEG_X]).is_none());
        assert!(Frustum::enclosing(&[]).is_none());
        assert!(Frustum::enclosing(&[Vec3::new(1.0, f32::NAN, 0.0)]).is_none());
    }
}
