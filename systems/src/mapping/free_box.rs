//! The free boxes of a scan: boxes of saturated free bricks around the sensor and beyond it,
//! grown once per scan, that the rays of the scan leave in one move each.
//!
//! Why: near itself a camera in flight sees space it saw a few frames before, saturated free,
//! where a miss changes nothing (common.md §1: clamping). The walks cross such space cube by
//! cube (`super::cube`: a brick, block or chunk per move, and a chunk visit at every chunk
//! boundary), the same space again for each of a scan's ~2,000 rays. All of them start in the
//! sensor's voxel, so a box around it serves them all:
//! - a walk from a key in the box to a key in the box stays in it (a box is convex, and each
//!   axis of a walk moves one way), so a ray that ends inside changes nothing and is skipped;
//! - any other ray leaves the box in one move with exactly the crossings and boundary times
//!   that stepping voxel by voxel would reach ([`FreeBox::cross`], the cubes' own rule), and
//!   walks on from there as before (and, once out of a box, never re-enters it).
//!
//! The map that results is the same bit for bit. A box is grown greedily, one brick layer per
//! face in turn (+x, -x, +y, -y, +z, -z), while the new layer's bricks are all full: not the
//! largest box there is, but deterministic and cheap (a few bit tests per layer, on the scan's
//! `super::full_bricks::FullBricks`). One brick that is not full stops a face across the
//! whole box, so [`FreeBoxes`] also grows two boxes that take x, or y, to the end first and
//! then the rest: along a free corridor or the length of a room they reach farther, and a ray
//! that leaves one box may still be inside another (in the shipped Pillars mission the two more
//! boxes took 3-5 % off the map update, 2-3 % off the mission, in paired rounds; a third, z
//! first, nothing more). And beyond each face of the first box it grows more, outward one past
//! the other: a walk that leaves the boxes around the sensor through a face stopped by one
//! brick (a pillar's corner, a patch of floor not yet saturated) mostly goes on through free
//! space, and a box there takes it on, or holds its end.

use super::axes::by_axis;
use super::cube::{CubeCrossing, cross_faces};
use glam::IVec3;
use uavex_components::map::BRICK_EDGE;

/// A box of voxel keys (`lo..=hi`, aligned to bricks) whose voxels inside the map are all
/// saturated free.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FreeBox {
    pub lo: IVec3,
    pub hi: IVec3,
}

/// log2 of [`BRICK_EDGE`].
const BRICK_SHIFT: i32 = BRICK_EDGE.trailing_zeros() as i32;

impl FreeBox {
    /// The box grown from the brick of `origin` (a key) within the bricks that meet the key box
    /// `limit_lo..=limit_hi`, where `all_full(lo, hi)` tells whether the bricks `lo..=hi` (by
    /// brick coordinates, key / 4) are all full of saturated free voxels: the faces of
    /// `first_axis` first, while they can grow, then all faces in turn. `None` when the
    /// origin's brick is not full.
    pub fn grow(
        origin: IVec3,
        limit_lo: IVec3,
        limit_hi: IVec3,
        first_axis: Option<usize>,
        all_full: impl Fn(IVec3, IVec3) -> bool,
    ) -> Option<Self> {
        let (limit_lo, limit_hi) = (limit_lo >> BRICK_SHIFT, limit_hi >> BRICK_SHIFT);
        let start = origin >> BRICK_SHIFT;
        if !all_full(start, start) {
            return None;
        }
        let (mut lo, mut hi) = (start, start);
        let mut open = [true; 6];
        let phases: [[bool; 6]; 2] = match first_axis {
            Some(a) => {
                let mut first = [false; 6];
                (first[2 * a], first[2 * a + 1]) = (true, true);
                [first, [true; 6]]
            }
            None => [[true; 6]; 2],
        };
        for allowed in phases {
            while (0..6).any(|f| open[f] && allowed[f]) {
                for face in 0..6 {
                    if !(open[face] && allowed[face]) {
                        continue;
                    }
                    let axis = face / 2;
                    let up = face % 2 == 0;
                    let layer = if up { hi[axis] + 1 } else { lo[axis] - 1 };
                    let (mut from, mut to) = (lo, hi);
                    (from[axis], to[axis]) = (layer, layer);
                    let inside = if up {
                        layer <= limit_hi[axis]
                    } else {
                        layer >= limit_lo[axis]
                    };
                    if inside && all_full(from, to) {
                        if up {
                            hi[axis] = layer;
                        } else {
                            lo[axis] = layer;
                        }
                    } else {
                        open[face] = false;
                    }
                }
            }
        }
        Some(Self {
            lo: lo << BRICK_SHIFT,
            hi: (hi << BRICK_SHIFT) + IVec3::splat(BRICK_EDGE - 1),
        })
    }

    #[inline]
    pub fn contains(&self, key: IVec3) -> bool {
        key.cmpge(self.lo).all() && key.cmple(self.hi).all()
    }

    /// The walk's move out of the box from `key` (inside it), with steps (+1, -1 or 0 per
    /// axis), next boundary times `t` and intervals `dt` in the walk's fixed point (an axis
    /// that does not move has time `i64::MAX` and interval 0): the crossings of each axis up
    /// to the face it leaves through, as [`super::cube::cross_cube`] defines them for a cube.
    /// The caller accepts it only if the face comes before the end of its segment.
    #[inline]
    pub fn cross(&self, key: IVec3, steps: [i64; 3], t: [i64; 3], dt: [i64; 3]) -> CubeCrossing {
        let ahead = by_axis(|a| match steps[a] {
            1 => i64::from(self.hi[a] - key[a]) + 1,
            -1 => i64::from(key[a] - self.lo[a]) + 1,
            _ => 1,
        });
        cross_faces(ahead, t, dt, |t, dt, before| {
            // The j >= 0 with t + j dt < before: ceil((before - t) / dt) of them. An axis that
            // does not move (dt = 0) has t = i64::MAX, past any `before`.
            if before > t {
                (before - t - 1) / dt.max(1) + 1
            } else {
                0
            }
        })
    }
}

/// The free boxes of one scan ([`FreeBoxes::grow`]), at most [`MAX_FREE_BOXES`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FreeBoxes {
    boxes: [FreeBox; MAX_FREE_BOXES],
    len: usize,
    /// How many of the boxes were grown around the sensor (the first ones).
    around: usize,
}

/// How many boxes a scan keeps: the three around the sensor and a chain of `CHAIN` beyond
/// each of the first one's six faces.
pub const MAX_FREE_BOXES: usize = 3 + 6 * CHAIN;

/// How many boxes are grown outward beyond each face of the first box, one past the other.
const CHAIN: usize = 2;

impl Default for FreeBoxes {
    fn default() -> Self {
        let empty = FreeBox {
            lo: IVec3::MAX,
            hi: IVec3::MIN,
        };
        Self {
            boxes: [empty; MAX_FREE_BOXES],
            len: 0,
            around: 0,
        }
    }
}

impl FreeBoxes {
    /// The boxes of a scan whose sensor is at key `origin`, within the bricks that meet the
    /// key box `limit_lo..=limit_hi` (`all_full` as for [`FreeBox::grow`]); none when the
    /// origin's brick is not full:
    /// - around the sensor, the box grown with all faces in turn, then those grown x first and
    ///   y first (each only if it differs from the ones before);
    /// - beyond each face of the first one, a chain of `CHAIN` boxes, each grown with all
    ///   faces in turn from the brick just past the centre of the last one's face on that side
    ///   (see the module documentation).
    ///
    /// In the shipped Pillars mission the boxes beyond took the walks' chunk visits from
    /// 29.0 M to 20.9 M and the rays skipped whole from 4.2 M to 6.4 M (of 17.2 M); the map
    /// update 3 % faster in paired rounds (a chain of two against one box per face: 0-1.5 %, a
    /// chain of three no faster than two). Seeds in line with the sensor instead of the faces'
    /// centres skipped 4.6 M rays whole with one box per face, boxes grown along the face's
    /// axis first 5.7 M.
    pub fn grow(
        origin: IVec3,
        limit_lo: IVec3,
        limit_hi: IVec3,
        all_full: impl Fn(IVec3, IVec3) -> bool,
    ) -> Self {
        let mut boxes = Self::default();
        for first_axis in [None, Some(0), Some(1)] {
            let Some(grown) = FreeBox::grow(origin, limit_lo, limit_hi, first_axis, &all_full)
            else {
                return boxes;
            };
            boxes.add(grown);
        }
        boxes.around = boxes.len;
        for face in 0..6 {
            // Outward from the first box through this face, a chain of boxes, each grown from
            // the brick just past the centre of the last one's face on that side.
            let (axis, up) = (face / 2, face % 2 == 0);
            let mut last = boxes.boxes[0];
            for _ in 0..CHAIN {
                let mut seed = (last.lo + last.hi) / 2;
                seed[axis] = if up {
                    last.hi[axis] + 1
                } else {
                    last.lo[axis] - 1
                };
                if !(limit_lo[axis]..=limit_hi[axis]).contains(&seed[axis]) {
                    break;
                }
                let Some(grown) = FreeBox::grow(seed, limit_lo, limit_hi, None, &all_full) else {
                    break;
                };
                boxes.add(grown);
                last = grown;
            }
        }
        boxes
    }

    /// Keeps `free` unless a box already kept equals it.
    fn add(&mut self, free: FreeBox) {
        if self.len < MAX_FREE_BOXES && !self.iter().any(|kept| *kept == free) {
            self.boxes[self.len] = free;
            self.len += 1;
        }
    }

    /// How many of the boxes (the first ones) lie around the sensor; the rest lie beyond the
    /// faces of the first.
    pub fn around(&self) -> usize {
        self.around
    }

    /// The boxes, the all-faces one around the sensor first.
    #[inline]
    pub fn iter(&self) -> std::slice::Iter<'_, FreeBox> {
        self.boxes[..self.len].iter()
    }

    /// Whether one of the boxes around the sensor holds both keys: then so does every key of a
    /// walk between them (a box is convex, and each axis of a walk moves one way), and the walk
    /// changes nothing. (Only those: every ray of a scan starts in them, and trying the boxes
    /// beyond on every ray cost more than it found; a walk that a box beyond holds whole is
    /// found as it leaves the ones around: `integrate`'s `leave_free_boxes`.)
    #[inline]
    pub fn hold(&self, start: IVec3, end: IVec3) -> bool {
        self.boxes[..self.around]
            .iter()
            .any(|b| b.contains(start) && b.contains(end))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mapping::cube::tests::{TIED_DT, random_axis, step_by_voxel_until};
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// The box test [`FreeBox::grow`] takes, from a test of one brick.
    fn each_brick(full: impl Fn(IVec3) -> bool) -> impl Fn(IVec3, IVec3) -> bool {
        move |from, to| {
            (from.z..=to.z).all(|z| {
                (from.y..=to.y).all(|y| (from.x..=to.x).all(|x| full(IVec3::new(x, y, z))))
            })
        }
    }

    #[test]
    fn grows_until_a_brick_that_is_not_full_on_every_side() {
        // Full bricks: x in -3..=5, y in -2..=1, z in 0..=0 except brick (2, 1, 0).
        let full = |b: IVec3| {
            (-3..=5).contains(&b.x)
                && (-2..=1).contains(&b.y)
                && b.z == 0
                && b != IVec3::new(2, 1, 0)
        };
        let free = FreeBox::grow(
            IVec3::new(1, 2, 3),
            IVec3::splat(-100),
            IVec3::splat(100),
            None,
            each_brick(full),
        )
        .expect("the origin's brick is full");
        // By hand, face by face (+x, -x, +y, -y; z never grows): round 1 takes x = 1, x = -1,
        // y = 1, y = -1; round 2 finds brick (2, 1, 0) in the +x layer (closed), takes x = -2,
        // finds no y = 2 (closed), takes y = -2; round 3 takes x = -3 and closes -y; round 4
        // closes -x. Bricks (-3, -2, 0) to (1, 1, 0).
        assert_eq!(free.lo, IVec3::new(-12, -8, 0));
        assert_eq!(free.hi, IVec3::new(7, 7, 3));
        for x in free.lo.x >> 2..=free.hi.x >> 2 {
            for y in free.lo.y >> 2..=free.hi.y >> 2 {
                assert!(full(IVec3::new(x, y, 0)));
            }
        }
        // x first: along y = 0 from x = -3 to 5 (brick (2, 1, 0) is not in that row), then y
        // down to -2 (the +y layer holds brick (2, 1, 0)). y first: y from -2 to 1 along
        // x = 0, then x to 1 and -3 as above: the all-faces box again, left out.
        let boxes = FreeBoxes::grow(
            IVec3::new(1, 2, 3),
            IVec3::splat(-100),
            IVec3::splat(100),
            each_brick(full),
        );
        let boxes: Vec<_> = boxes.iter().map(|b| (b.lo, b.hi)).collect();
        assert_eq!(
            boxes,
            [
                (IVec3::new(-12, -8, 0), IVec3::new(7, 7, 3)),
                (IVec3::new(-12, -8, 0), IVec3::new(23, 3, 3)),
            ]
        );
    }

    #[test]
    fn no_box_when_the_origin_brick_is_not_full_and_none_beyond_the_limits() {
        assert_eq!(
            FreeBox::grow(
                IVec3::ZERO,
                IVec3::splat(-9),
                IVec3::splat(9),
                None,
                |_, _| { false }
            ),
            None
        );
        let free = FreeBox::grow(
            IVec3::ZERO,
            IVec3::splat(-5),
            IVec3::splat(9),
            None,
            |_, _| true,
        )
        .expect("all full");
        // Keys -5..=9 meet bricks -2..=2.
        assert_eq!((free.lo, free.hi), (IVec3::splat(-8), IVec3::splat(11)));
    }

    /// Leaving a random box from a random key inside it in one move equals stepping voxel by
    /// voxel until the walk first stands outside it (ties included).
    #[test]
    fn one_move_out_of_the_box_equals_stepping_voxel_by_voxel() {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        for case in 0..20_000 {
            let lo = IVec3::new(
                rng.random_range(-40..0),
                rng.random_range(-40..0),
                rng.random_range(-40..0),
            );
            let hi = lo
                + IVec3::new(
                    rng.random_range(0..60),
                    rng.random_range(0..60),
                    rng.random_range(0..60),
                );
            let free = FreeBox { lo, hi };
            let key = IVec3::new(
                rng.random_range(lo.x..=hi.x),
                rng.random_range(lo.y..=hi.y),
                rng.random_range(lo.z..=hi.z),
            );
            let mut steps = [0i64; 3];
            let mut t = [i64::MAX; 3];
            let mut dt = [0i64; 3];
            for a in 0..3 {
                // Some axes still, some intervals shared (ties), the rest random.
                match rng.random_range(0..6) {
                    0 => continue,
                    1 => dt[a] = TIED_DT,
                    _ => dt[a] = rng.random_range(1i64 << 36..1 << 46),
                }
                (steps[a], t[a]) = random_axis(&mut rng, dt[a], dt[a]);
            }
            if steps == [0; 3] {
                continue;
            }
            let moved = free.cross(key, steps, t, dt);
            let stepped = step_by_voxel_until(key.as_i64vec3().to_array(), steps, t, dt, |k| {
                !free.contains(IVec3::new(k[0] as i32, k[1] as i32, k[2] as i32))
            });
            assert_eq!(
                moved, stepped,
                "case {case}: {free:?} from {key}, {steps:?} {t:?} {dt:?}"
            );
        }
    }
}
