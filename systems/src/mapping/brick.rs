//! Walking through saturated free space brick by brick.
//!
//! A miss cannot change a voxel already at the lower clamping bound (common.md §1: clamping), so
//! while the map update's ray walk is inside 4^3 bricks whose voxels are all saturated free
//! ([`uavex_components::map::VoxelChunk::brick_saturated`]), every update would be a no-op.
//! [`walk_saturated`] walks such stretches one brick face at a time instead of one voxel face at
//! a time, and hands back exactly the voxel, boundary times and step counts that stepping voxel
//! by voxel would have reached, ties included: the map that results is the same bit for bit.
//! Most of what a camera sees in flight was seen a few frames before, hence saturated: this is
//! where the map update's time went.
//!
//! Boundary times are the walk's fixed-point integers (`dda`): crossing `j` on axis `a` is at
//! `t_a + j dt_a` exactly, so brick faces (every fourth crossing) and the crossings between
//! them are computed, not accumulated, and equal the voxel walk's to the last bit.

use uavex_components::map::{BRICK_EDGE, BRICK_VOXELS, CHUNK_BRICKS};

/// The walk's state after a stretch of saturated bricks: boundary crossings taken on each axis
/// and the new next-boundary times. The walk stands in the voxel entered by the last crossing.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SaturatedStretch {
    pub crossings: [i64; 3],
    pub boundary_times: [i64; 3],
}

impl SaturatedStretch {
    /// Voxels passed over: the one the walk stood in and every one entered but the last.
    #[inline(always)]
    pub fn voxels_passed(&self) -> i64 {
        self.crossings[0] + self.crossings[1] + self.crossings[2]
    }
}

/// The axis whose next crossing comes first, ties to x, then y, then z (the walk's rule).
#[cfg(test)]
fn first(times: [i64; 3]) -> usize {
    if times[0] <= times[1] && times[0] <= times[2] {
        0
    } else if times[1] <= times[2] {
        1
    } else {
        2
    }
}

/// All ones if `c`, else zero.
#[inline(always)]
fn mask(c: bool) -> i64 {
    -i64::from(c)
}

/// Brick coordinates of the chunk packed one per byte, each plus 4 (so 4..=7 inside the chunk,
/// 3 or 8 just outside): one add moves along an axis, one mask test tells leaving the chunk.
#[derive(Clone, Copy)]
struct BrickCursor(i32);

impl BrickCursor {
    const BIAS: i32 = 0x0004_0404;
    const OUTSIDE_BITS: i32 = 0x00FC_FCFC;

    fn at(brick: [i64; 3]) -> Self {
        Self(Self::BIAS + (brick[0] | brick[1] << 8 | brick[2] << 16) as i32)
    }

    #[inline(always)]
    fn inside(self) -> bool {
        self.0 & Self::OUTSIDE_BITS == Self::BIAS
    }

    /// Index of the brick in the chunk (x fastest), while inside.
    #[inline(always)]
    fn index(self) -> usize {
        let c = self.0 as usize;
        (c & 3) | (c >> 6 & 0xC) | (c >> 12 & 0x30)
    }

    fn coordinate(self, axis: usize) -> i64 {
        i64::from((self.0 >> (8 * axis)) & 0xFF) - 4
    }
}

/// Walks from the voxel at chunk-local coordinates `local` (0..16 per axis), in a saturated
/// brick, with steps (+1, -1 or 0 per axis), next boundary times `t` and intervals `dt` (an
/// axis with step 0 has time `i64::MAX` and interval 0), across brick faces while the brick
/// entered is saturated in `saturated` (counts per brick of the chunk) and the face is crossed
/// before `t_limit`. Stops in the first voxel of an unsaturated brick, of the next chunk, or of
/// the last brick whose far face comes at or after `t_limit` (the walk then goes on voxel by
/// voxel). `None` if not even the first brick's face comes before `t_limit`.
///
/// Brick by brick, axis `a` reaches the face ahead after `n_a` crossings, at
/// `T_a = t_a + (n_a - 1) dt_a`, then every 4 crossings; the walk leaves each brick through the
/// least `T_a` under the tie rule. Where it stops, after crossing face `e` at `T`, each other
/// axis `b` has taken every crossing ordered before that one: all before its next face `T_b`
/// except those of `T_b - dt_b`, `T_b - 2 dt_b`, `T_b - 3 dt_b` still ahead of the walk that
/// come at or after `T` (or strictly after, when `b` loses ties to `e`).
///
/// The brick loop is the voxel walk's own loop one level up: face times in registers, the axis
/// chosen with compares and masks (a branch on it is mispredicted every other brick).
// Not inlined: the voxel loop that calls it keeps its state in registers.
#[inline(never)]
pub fn walk_saturated(
    local: [i64; 3],
    steps: [i64; 3],
    t: [i64; 3],
    dt: [i64; 3],
    t_limit: i64,
    saturated: &[u8; CHUNK_BRICKS],
) -> Option<SaturatedStretch> {
    // Per axis, by hand rather than over arrays: arrays indexed by axis, and the closures of
    // `array::map`, made this function several times longer than its arithmetic.
    let [ax, ay, az] = [
        ahead(local[0], steps[0]),
        ahead(local[1], steps[1]),
        ahead(local[2], steps[2]),
    ];
    let [dtx, dty, dtz] = dt;
    // Time of the face ahead on each axis, and the interval between faces.
    let (mut fx, mut fy, mut fz) = (
        t[0] + (ax - 1) * dtx,
        t[1] + (ay - 1) * dty,
        t[2] + (az - 1) * dtz,
    );
    let edge = i64::from(BRICK_EDGE);
    let (dx, dy, dz) = (edge * dtx, edge * dty, edge * dtz);
    let start = BrickCursor::at([local[0] >> 2, local[1] >> 2, local[2] >> 2]);
    let (sx, sy, sz) = (steps[0], steps[1] << 8, steps[2] << 16);
    let mut cursor = start;
    // The axis of the last face crossed, as masks (all zero: none yet).
    let (mut lx, mut ly, mut lz) = (0i64, 0i64, 0i64);
    loop {
        let x = mask((fx <= fy) & (fx <= fz));
        let y = !x & mask(fy <= fz);
        let z = !x & !y;
        if (x & fx) | (y & fy) | (z & fz) >= t_limit {
            break;
        }
        (lx, ly, lz) = (x, y, z);
        fx += x & dx;
        fy += y & dy;
        fz += z & dz;
        cursor.0 = cursor
            .0
            .wrapping_add(((x & sx) | (y & sy) | (z & sz)) as i32);
        if !cursor.inside() || saturated[cursor.index()] != BRICK_VOXELS {
            break;
        }
    }
    if lx | ly | lz == 0 {
        return None;
    }
    // The last face crossed (on axis e) came at `time`; the crossing index (from now) of the
    // next face on each axis follows from the bricks crossed on it.
    let time = (lx & (fx - dx)) | (ly & (fy - dy)) | (lz & (fz - dz));
    let index = |axis: usize, ahead: i64| {
        ahead - 1 + edge * (cursor.coordinate(axis) - start.coordinate(axis)).abs()
    };
    let (ix, iy, iz) = (index(0, ax), index(1, ay), index(2, az));
    // Axis e took its crossing at `time`; each other axis b the ones ordered before it, that
    // is before `time`, or at it too when b wins ties against e (b < e).
    let x = settle(fx, dtx, ix, time + i64::from(ly | lz != 0), lx);
    let y = settle(fy, dty, iy, time + i64::from(lz != 0), ly);
    let z = settle(fz, dtz, iz, time, lz);
    Some(SaturatedStretch {
        crossings: [x.0, y.0, z.0],
        boundary_times: [x.1, y.1, z.1],
    })
}

/// Crossings of an axis from chunk-local coordinate `local` with step `step` up to and
/// including the one onto the face of its brick ahead.
#[inline(always)]
fn ahead(local: i64, step: i64) -> i64 {
    let within = local & (i64::from(BRICK_EDGE) - 1);
    if step > 0 {
        i64::from(BRICK_EDGE) - within
    } else {
        within + 1
    }
}

/// Crossings taken and next boundary time of one axis at the end of a stretch: `face` is the
/// time of its next face, `index` that face's crossing index from the start, `dt` the interval.
/// For the axis of the last face crossed (`last` all ones), the crossing just before `face`
/// was that one; for the others, the crossings of the last brick (up to three before `face`)
/// at or after `before` are still ahead. (An axis that does not move has `face` = `i64::MAX`,
/// `dt` = 0 and `index` < 4: no crossings, time unchanged.)
#[inline(always)]
fn settle(face: i64, dt: i64, index: i64, before: i64, last: i64) -> (i64, i64) {
    let edge = i64::from(BRICK_EDGE);
    // Only crossings from now on count (`m <= index`): one before the start may tie with the
    // last face at time 0 (a walk starting on a face), and is not the stretch's to take.
    let pending = i64::from((index >= 1) & (face - dt >= before))
        + i64::from((index >= 2) & (face - 2 * dt >= before))
        + i64::from((index >= 3) & (face - 3 * dt >= before));
    let (k, next) = (index - pending, face - pending * dt);
    let (k_last, next_last) = (index - edge + 1, face - (edge - 1) * dt);
    (
        (last & k_last) | (!last & k),
        (last & next_last) | (!last & next),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    const MAX: i64 = i64::MAX;
    const ALL: [u8; CHUNK_BRICKS] = [BRICK_VOXELS; CHUNK_BRICKS];

    fn brick_index(local: [i64; 3]) -> usize {
        (local[0] / 4 + 4 * (local[1] / 4) + 16 * (local[2] / 4)) as usize
    }

    /// The voxel walk's own rule, one crossing at a time, stopping as `walk_saturated` does.
    fn step_by_voxel(
        mut local: [i64; 3],
        steps: [i64; 3],
        mut t: [i64; 3],
        dt: [i64; 3],
        t_limit: i64,
        saturated: &[u8; CHUNK_BRICKS],
    ) -> Option<SaturatedStretch> {
        let mut crossings = [0; 3];
        // The state on entering the brick the walk is in (None: the brick it started in).
        let mut entry = None;
        loop {
            let a = first(t);
            if t[a] >= t_limit {
                return entry;
            }
            let brick_before = local[a].div_euclid(4);
            crossings[a] += 1;
            t[a] += dt[a];
            local[a] += steps[a];
            if local[a].div_euclid(4) != brick_before {
                let state = SaturatedStretch {
                    crossings,
                    boundary_times: t,
                };
                if !(0..16).contains(&local[a]) || saturated[brick_index(local)] != BRICK_VOXELS {
                    return Some(state);
                }
                entry = Some(state);
            }
        }
    }

    #[test]
    fn along_x_to_the_chunk_face_to_an_unsaturated_brick_or_to_the_limit() {
        // From local x = 1, crossings every 10 from t = 5: brick faces at 25 (x 3 -> 4),
        // 65, 105, and 145 (x 15 -> 16, out of the chunk) after 15 crossings; next at 155.
        let from = [1, 5, 9];
        let (steps, t, dt) = ([1, 0, 0], [5, MAX, MAX], [10, 0, 0]);
        let all = walk_saturated(from, steps, t, dt, MAX, &ALL).unwrap();
        assert_eq!(all.crossings, [15, 0, 0]);
        assert_eq!(all.boundary_times, [155, MAX, MAX]);
        assert_eq!(all.voxels_passed(), 15);
        // Brick (2, 1, 2) unsaturated: stop on entering it, at x = 8 after 7 crossings.
        let mut holes = ALL;
        holes[2 + 4 + 32] = BRICK_VOXELS - 1;
        let stopped = walk_saturated(from, steps, t, dt, MAX, &holes).unwrap();
        assert_eq!(
            (stopped.crossings, stopped.boundary_times[0]),
            ([7, 0, 0], 75)
        );
        // The face at 105 is not before the limit 100: stand at the entry of brick 2 as well.
        let limited = walk_saturated(from, steps, t, dt, 100, &ALL).unwrap();
        assert_eq!(limited, stopped);
        // Not even the first face (25) before the limit.
        assert_eq!(walk_saturated(from, steps, t, dt, 25, &ALL), None);
    }

    #[test]
    fn the_other_axes_take_the_crossings_ordered_before_the_last_face() {
        // x crosses every 10 from 5 (faces at 25, 65, ...), y every 7 from 3 going -1 from
        // local y 2 (face at 3 + 2 * 7 = 17, then 45, ...). Bricks: start (0, 0, 0); y face
        // first at 17 -> out of the chunk (y = -1). By then x crossed at 5 and 15: 2 + 3 = 5.
        let s = walk_saturated([1, 2, 0], [1, -1, 0], [5, 3, MAX], [10, 7, 0], MAX, &ALL);
        let s = s.unwrap();
        assert_eq!(s.crossings, [2, 3, 0]);
        assert_eq!(s.boundary_times, [25, 24, MAX]);
        // A tie: x's face and y's face both at 25 (y from local 0 going +1: 4, 11, 18, 25).
        // x wins it and leaves first, into the unsaturated brick (1, 0, 0); y has taken its
        // crossings at 4, 11 and 18, and its face at 25 is still pending.
        let mut only_first = [0; CHUNK_BRICKS];
        only_first[0] = BRICK_VOXELS;
        let s = walk_saturated(
            [1, 0, 0],
            [1, 1, 0],
            [5, 4, MAX],
            [10, 7, 0],
            MAX,
            &only_first,
        );
        let s = s.unwrap();
        assert_eq!(s.crossings, [3, 3, 0]);
        assert_eq!(s.boundary_times, [35, 25, MAX]);
    }

    /// On random walks (small integers, so that ties are frequent, and large ones) through
    /// random saturation patterns, brick by brick equals voxel by voxel.
    #[test]
    fn brick_by_brick_equals_voxel_by_voxel() {
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        for case in 0..100_000 {
            let steps = [0; 3].map(|_| rng.random_range(-1..=1i64));
            if steps == [0; 3] {
                continue;
            }
            let mut saturated = [0; CHUNK_BRICKS];
            for count in &mut saturated {
                *count = if rng.random_bool(0.85) {
                    BRICK_VOXELS
                } else {
                    63
                };
            }
            let local = [0; 3].map(|_| rng.random_range(0..16i64));
            saturated[brick_index(local)] = BRICK_VOXELS;
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
                    t[a] = rng.random_range(0..=dt[a]);
                }
            }
            let limit = match case % 3 {
                0 if small => rng.random_range(0..80),
                0 => rng.random_range(0..1i64 << 48),
                _ => MAX - 1,
            };
            assert_eq!(
                walk_saturated(local, steps, t, dt, limit, &saturated),
                step_by_voxel(local, steps, t, dt, limit, &saturated),
                "case {case}: local {local:?} steps {steps:?} t {t:?} dt {dt:?} limit {limit}"
            );
        }
    }
}
