//! Crossing a brick of saturated free voxels in one move.
//!
//! A miss cannot change a voxel already at the lower clamping bound (common.md §1: clamping), so
//! while the map update's ray walk is inside a 4^3 brick whose voxels are all saturated free
//! ([`uavex_components::map::VoxelChunk::brick_saturated`]), every update would be a no-op.
//! [`cross_brick`] moves the walk to the first voxel of the next brick in one step, with
//! exactly the crossings and boundary times that stepping voxel by voxel would have reached,
//! ties included: the map that results is the same bit for bit. Most of what a camera sees in
//! flight was seen a few frames before, hence saturated: this is where the map update's time
//! went.
//!
//! Boundary times are the walk's fixed-point integers (`dda`): crossing `j` (from now) on axis
//! `a` is at `t_a + j dt_a` exactly, so the brick's faces and the crossings before them are
//! computed, not accumulated, and equal the voxel walk's to the last bit.

use uavex_components::map::BRICK_EDGE;

/// All ones if `c`, else zero.
#[inline(always)]
fn mask(c: bool) -> i64 {
    -i64::from(c)
}

/// Crossings of an axis from chunk-local coordinate `local` with step `step` up to and
/// including the one onto the face of its brick ahead (1 to 4; any value for an axis that does
/// not move).
#[inline(always)]
fn ahead(local: i64, step: i64) -> i64 {
    let within = local & (i64::from(BRICK_EDGE) - 1);
    if step > 0 {
        i64::from(BRICK_EDGE) - within
    } else {
        within + 1
    }
}

/// The walk's move out of its brick: how many boundaries it crosses on each axis, their new
/// next-boundary times, and the time of the face it leaves through.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct BrickCrossing {
    pub crossings: [i64; 3],
    pub boundary_times: [i64; 3],
    pub face_time: i64,
}

impl BrickCrossing {
    /// Voxels passed: the one the walk stood in and every one entered but the last.
    #[inline(always)]
    pub fn voxels_passed(&self) -> i64 {
        self.crossings[0] + self.crossings[1] + self.crossings[2]
    }
}

/// From the voxel at chunk-local coordinates `local` (per axis; only the position within the
/// brick matters), with steps (+1, -1 or 0 per axis), next boundary times `t` and intervals
/// `dt` (an axis with step 0 has time `i64::MAX` and interval 0), the walk's way out of the
/// brick: it leaves through the face reached first, at `F = min_a t_a + (n_a - 1) dt_a` where
/// axis `a` reaches its face after `n_a` crossings (ties to x, then y, then z, the walk's
/// rule); every other axis `b` has taken its crossings before `F`, and the one at `F` too when
/// it wins the tie (`b` before the leaving axis). The caller makes sure `F` comes before the
/// end of its segment.
///
/// Branch-free, on registers: the axis a walk leaves by is as good as random.
#[inline(always)]
pub fn cross_brick(local: [i64; 3], steps: [i64; 3], t: [i64; 3], dt: [i64; 3]) -> BrickCrossing {
    let [tx, ty, tz] = t;
    let [dtx, dty, dtz] = dt;
    let fx = tx + (ahead(local[0], steps[0]) - 1) * dtx;
    let fy = ty + (ahead(local[1], steps[1]) - 1) * dty;
    let fz = tz + (ahead(local[2], steps[2]) - 1) * dtz;
    let x = mask((fx <= fy) & (fx <= fz));
    let y = !x & mask(fy <= fz);
    let z = !x & !y;
    let face = (x & fx) | (y & fy) | (z & fz);
    // The crossings of an axis strictly before `before` (at most three: its own face, the
    // fourth, comes at or after the leaving face).
    let taken = |t: i64, dt: i64, before: i64| {
        i64::from(t < before) + i64::from(t + dt < before) + i64::from(t + 2 * dt < before)
    };
    // x wins ties against y and z, y against z: at `face`, those go first.
    let kx = taken(tx, dtx, face + (1 & !x)) + (1 & x);
    let ky = taken(ty, dty, face + (1 & z)) + (1 & y);
    let kz = taken(tz, dtz, face) + (1 & z);
    BrickCrossing {
        crossings: [kx, ky, kz],
        boundary_times: [tx + kx * dtx, ty + ky * dty, tz + kz * dtz],
        face_time: face,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    const MAX: i64 = i64::MAX;

    /// The axis whose next crossing comes first, ties to x, then y, then z (the walk's rule).
    fn first(times: [i64; 3]) -> usize {
        if times[0] <= times[1] && times[0] <= times[2] {
            0
        } else if times[1] <= times[2] {
            1
        } else {
            2
        }
    }

    /// The voxel walk's own rule, one crossing at a time, until it enters another brick.
    fn step_by_voxel(
        mut local: [i64; 3],
        steps: [i64; 3],
        mut t: [i64; 3],
        dt: [i64; 3],
    ) -> BrickCrossing {
        let mut crossings = [0; 3];
        loop {
            let a = first(t);
            let face_time = t[a];
            let brick_before = local[a].div_euclid(4);
            crossings[a] += 1;
            t[a] += dt[a];
            local[a] += steps[a];
            if local[a].div_euclid(4) != brick_before {
                return BrickCrossing {
                    crossings,
                    boundary_times: t,
                    face_time,
                };
            }
        }
    }

    #[test]
    fn along_x_to_the_face_of_the_brick() {
        // From local x = 1, crossings every 10 from t = 5: the face (x 3 -> 4) at 25, after 3.
        let c = cross_brick([1, 5, 9], [1, 0, 0], [5, MAX, MAX], [10, 0, 0]);
        assert_eq!(c.crossings, [3, 0, 0]);
        assert_eq!(c.boundary_times, [35, MAX, MAX]);
        assert_eq!((c.face_time, c.voxels_passed()), (25, 3));
        // Going -1 from local x = 6: crossings 6 -> 5 -> 4 -> 3, the face at the third.
        let c = cross_brick([6, 0, 0], [-1, 0, 0], [5, MAX, MAX], [10, 0, 0]);
        assert_eq!((c.crossings, c.face_time), ([3, 0, 0], 25));
    }

    #[test]
    fn the_other_axes_take_the_crossings_ordered_before_the_face() {
        // x crosses every 10 from 5 (its face at 25), y every 7 from 3 going -1 from local
        // y 2 (its face, 2 -> 1 -> 0 -> -1, at 3 + 2 * 7 = 17): y leaves first, by when x has
        // crossed at 5 and 15.
        let c = cross_brick([1, 2, 0], [1, -1, 0], [5, 3, MAX], [10, 7, 0]);
        assert_eq!(c.crossings, [2, 3, 0]);
        assert_eq!(c.boundary_times, [25, 24, MAX]);
        // A tie: x's face and y's face both at 25 (y from local 0 going +1: 4, 11, 18, 25).
        // x wins it and leaves; y has taken its crossings at 4, 11 and 18, not the one at 25.
        let c = cross_brick([1, 0, 0], [1, 1, 0], [5, 4, MAX], [10, 7, 0]);
        assert_eq!(c.crossings, [3, 3, 0]);
        assert_eq!(c.boundary_times, [35, 25, MAX]);
        // y's face against an interior x crossing at 18 (x from local 0: 4, 11, 18, face 25;
        // y from local 2: 8, face 18): x, first in ties, takes it before y leaves.
        let c = cross_brick([0, 2, 0], [1, 1, 0], [4, 8, MAX], [7, 10, 0]);
        assert_eq!(c.crossings, [3, 2, 0]);
        assert_eq!(c.boundary_times, [25, 28, MAX]);
        assert_eq!(c.face_time, 18);
    }

    /// On random walks (small integers, so that ties are frequent, and large ones), one move
    /// equals stepping voxel by voxel out of the brick.
    #[test]
    fn one_move_equals_stepping_voxel_by_voxel() {
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        for case in 0..200_000 {
            let steps = [0; 3].map(|_| rng.random_range(-1..=1i64));
            if steps == [0; 3] {
                continue;
            }
            let local = [0; 3].map(|_| rng.random_range(0..16i64));
            let mut t = [0; 3];
            let mut dt = [0; 3];
            let small = case % 2 == 0;
            for a in 0..3 {
                if steps[a] == 0 {
                    t[a] = MAX;
                } else {
                    dt[a] = if small {
                        rng.random_range(1..6)
                    } else {
                        rng.random_range(1..1i64 << 44)
                    };
                    // A boundary may be due at once (t = 0): a walk starting on a face.
                    t[a] = rng.random_range(0..=dt[a]);
                }
            }
            assert_eq!(
                cross_brick(local, steps, t, dt),
                step_by_voxel(local, steps, t, dt),
                "case {case}: local {local:?} steps {steps:?} t {t:?} dt {dt:?}"
            );
        }
    }
}
