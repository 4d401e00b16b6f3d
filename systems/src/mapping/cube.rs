//! Crossing a cube of saturated free voxels (a 4^3 brick, an 8^3 block of 2 x 2 x 2 bricks,
//! or a whole 16^3 chunk) in one move.
//!
//! A miss cannot change a voxel already at the lower clamping bound (common.md §1: clamping), so
//! while the map update's ray walk is inside a cube whose voxels are all saturated free
//! ([`uavex_components::map::BrickSaturation`]), every update would be a no-op.
//! [`cross_cube`] moves the walk to the first voxel past the cube in one step, with exactly
//! the crossings and boundary times that stepping voxel by voxel would have reached, ties
//! included: the map that results is the same bit for bit. Most of what a camera sees in
//! flight was seen a few frames before, hence saturated: this is where the map update's time
//! went.
//!
//! Boundary times are the walk's fixed-point integers (`dda`): crossing `j` (from now) on axis
//! `a` is at `t_a + j dt_a` exactly, so the cube's faces and the crossings before them are
//! computed, not accumulated, and equal the voxel walk's to the last bit.

use super::axes::{by_axis, mask, per_axis};
use uavex_components::map::block_bricks;

/// Intervals above this (2^47 fixed point: 8 segment lengths) are clamped to it in the
/// comparisons: an axis that slow reaches no second boundary before the segment's end (2^44),
/// so the counts of crossings before an accepted face are the same, and `t + 15 dt` cannot
/// overflow.
pub(super) const DT_COMPARE_CAP: i64 = 1 << 47;

/// Crossings of an axis from chunk-local coordinate `local` with step `step` up to and
/// including the one onto the face of its cube of edge `EDGE` ahead (1 to `EDGE`; any value
/// for an axis that does not move).
#[inline(always)]
fn ahead<const EDGE: i64>(local: i64, step: i64) -> i64 {
    let within = local & (EDGE - 1);
    if step > 0 { EDGE - within } else { within + 1 }
}

/// The crossings of an axis (next at `t`, every `dt`) strictly before `before`, knowing there
/// are fewer than `EDGE` (its own face comes at or after the leaving face): a branch-free
/// binary search over the count.
///
/// (Estimating the count in floating point from a reciprocal and correcting it by one exact
/// test each way was tried: 13 % more map-update instructions, Rust's saturating
/// float-to-integer cast and the clamping outweigh the three halvings saved. An exact integer
/// division, `ceil((before - t) / dt)`, saved 6 % of a flight's instructions but ran 1-2 %
/// slower: three divisions sit on the walk's dependency chain.)
#[inline(always)]
fn taken<const EDGE: i64>(t: i64, dt: i64, before: i64) -> i64 {
    let mut count = 0;
    let mut half = EDGE / 2;
    while half > 0 {
        // Is crossing number `count + half - 1` (from 0) before `before`?
        count += half & mask(t + (count + half - 1) * dt < before);
        half /= 2;
    }
    count
}

/// The walk's move out of its cube: how many boundaries it crosses on each axis, their new
/// next-boundary times, and the time of the face it leaves through.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CubeCrossing {
    pub crossings: [i64; 3],
    pub boundary_times: [i64; 3],
    pub face_time: i64,
}

impl CubeCrossing {
    /// Voxels passed: the one the walk stood in and every one entered but the last.
    #[inline(always)]
    pub fn voxels_passed(&self) -> i64 {
        self.crossings[0] + self.crossings[1] + self.crossings[2]
    }
}

/// From the voxel at chunk-local coordinates `local` (per axis; only the position within the
/// cube of edge `EDGE`, a power of two, matters), with steps (+1, -1 or 0 per axis), next
/// boundary times `t` and intervals `dt` (an axis with step 0 has time `i64::MAX` and interval
/// 0), the walk's way out of the cube: it leaves through the face reached first, at
/// `F = min_a t_a + (n_a - 1) dt_a` where axis `a` reaches its face after `n_a` crossings (ties
/// to x, then y, then z, the walk's rule); every other axis `b` has taken its crossings before
/// `F`, and the one at `F` too when it wins the tie (`b` before the leaving axis). The caller
/// makes sure `F` comes before the end of its segment (`face_time` is exact then; otherwise it
/// is only known to be past 2^47).
///
/// Branch-free, on registers: the axis a walk leaves by is as good as random.
#[inline(always)]
pub fn cross_cube<const EDGE: i64>(
    local: [i64; 3],
    steps: [i64; 3],
    t: [i64; 3],
    dt: [i64; 3],
) -> CubeCrossing {
    let ahead = by_axis(|a| ahead::<EDGE>(local[a], steps[a]));
    cross_faces(ahead, t, dt, taken::<EDGE>)
}

/// The walk's move out of a box whose faces lie `ahead[a]` crossings away on each axis (at
/// least 1; any value for an axis that does not move), as [`cross_cube`] describes it;
/// `taken(t, dt, before)` counts an axis' crossings strictly before `before`, knowing there
/// are fewer than its `ahead`. Shared by the cubes and the free box of a scan
/// (`super::free_box`).
#[inline(always)]
pub(super) fn cross_faces(
    ahead: [i64; 3],
    t: [i64; 3],
    dt: [i64; 3],
    taken: impl Fn(i64, i64, i64) -> i64,
) -> CubeCrossing {
    leaving_face(ahead, t, dt).crossing(t, dt, taken)
}

/// The face a walk leaves its box through (see [`cross_faces`]), before the crossings up to
/// it are counted: its time alone tells whether the move comes before the walk's end.
#[derive(Debug, Clone, Copy)]
pub(super) struct LeavingFace {
    pub(super) time: i64,
    /// All ones for the leaving axis, zero for the others.
    pub(super) axis: [i64; 3],
}

/// The face reached first, at `F = min_a t_a + (ahead_a - 1) dt_a`, ties to x, then y, then z.
#[inline(always)]
pub(super) fn leaving_face(ahead: [i64; 3], t: [i64; 3], dt: [i64; 3]) -> LeavingFace {
    let [cx, cy, cz] = per_axis(dt, |dt| dt.min(DT_COMPARE_CAP));
    let fx = t[0] + (ahead[0] - 1) * cx;
    let fy = t[1] + (ahead[1] - 1) * cy;
    let fz = t[2] + (ahead[2] - 1) * cz;
    let x = mask((fx <= fy) & (fx <= fz));
    let y = !x & mask(fy <= fz);
    let z = !x & !y;
    LeavingFace {
        time: (x & fx) | (y & fy) | (z & fz),
        axis: [x, y, z],
    }
}

impl LeavingFace {
    /// The crossings of every axis up to this face, and the boundary times after them.
    #[inline(always)]
    pub(super) fn crossing(
        self,
        t: [i64; 3],
        dt: [i64; 3],
        taken: impl Fn(i64, i64, i64) -> i64,
    ) -> CubeCrossing {
        let [tx, ty, tz] = t;
        let [dtx, dty, dtz] = dt;
        let [cx, cy, cz] = per_axis(dt, |dt| dt.min(DT_COMPARE_CAP));
        let [x, y, z] = self.axis;
        let face = self.time;
        // x wins ties against y and z, y against z: at `face`, those go first.
        let kx = taken(tx, cx, face + (1 & !x)) + (1 & x);
        let ky = taken(ty, cy, face + (1 & z)) + (1 & y);
        let kz = taken(tz, cz, face) + (1 & z);
        CubeCrossing {
            crossings: [kx, ky, kz],
            // Exact for an accepted crossing (an axis slower than the cap then takes at most
            // one); wrapping, so that a rejected one cannot overflow.
            boundary_times: [
                tx.wrapping_add(kx.wrapping_mul(dtx)),
                ty.wrapping_add(ky.wrapping_mul(dty)),
                tz.wrapping_add(kz.wrapping_mul(dtz)),
            ],
            face_time: face,
        }
    }
}

/// The cubes the map update crosses in one move.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Cube {
    /// A 4^3 brick.
    Brick = 0,
    /// An 8^3 block of 2 x 2 x 2 bricks.
    Block = 1,
    /// A whole 16^3 chunk.
    Chunk = 2,
}

/// The cubes a walk may still cross in one move: those smaller than the smallest it could
/// not leave before its end. A cube the walk cannot leave before `t_safe` holds the rest of
/// the walk (cubes are convex), so trying it again, or a larger cube around a later voxel
/// (which contains it), can only fail again: without this bound, a ray ending inside a
/// saturated brick tried all three cubes again at every one of its last voxels.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CubeLimit(u8);

impl CubeLimit {
    /// Every cube may be crossed (a walk's start).
    pub const ANY: Self = Self(3);
    /// No cube may be crossed.
    pub const NONE: Self = Self(0);

    /// Whether some cube may still be crossed.
    #[inline(always)]
    pub fn open(self) -> bool {
        self.0 > 0
    }

    /// Whether `cube` may be crossed.
    #[inline(always)]
    pub fn allows(self, cube: Cube) -> bool {
        self.0 > cube as u8
    }

    /// The walk could not leave a saturated `cube` before its end.
    #[inline(always)]
    pub fn failed(&mut self, cube: Cube) {
        self.0 = self.0.min(cube as u8);
    }
}

/// What stays fixed while a walk crosses one chunk: its steps (+1, -1 or 0 per axis) and
/// boundary intervals (see [`cross_cube`]), the time before which a move must leave its cube
/// (the segment's safe end), and its end key in the chunk's local coordinates (outside
/// `0..16` when it ends in another chunk).
#[derive(Debug, Clone, Copy)]
pub struct WalkInChunk {
    pub steps: [i64; 3],
    pub dt: [i64; 3],
    pub t_safe: i64,
    pub end: [i64; 3],
}

/// What a walk does at a saturated cube around its voxel ([`leave_cube`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CubeMove {
    /// It leaves the cube in one move, before its end.
    Cross(Cube, CubeCrossing),
    /// Its end lies in the cube: every voxel it has left to visit does (a walk keeps within
    /// the box of its current and end keys, each axis moving one way) and is saturated, where
    /// a miss changes nothing. The walk is done.
    EndsInside,
    /// Neither: it steps on (or tries a smaller cube).
    Step,
}

/// The walk, at chunk-local `local` with next boundary times `t`, at the saturated cube of
/// edge `EDGE` around its voxel (of kind `cube`): the move out of it when its face comes
/// before `walk.t_safe` (the crossings counted only then); else, the limit lowered, whether
/// the cube holds the walk's end.
#[inline(always)]
pub fn leave_cube<const EDGE: i64>(
    cube: Cube,
    walk: &WalkInChunk,
    local: [i64; 3],
    t: [i64; 3],
    limit: &mut CubeLimit,
) -> CubeMove {
    // The face first, the crossings only for a move taken: a quarter of the tries fail.
    // (`cross_cube` finds the face again; handing it this one made the mission 1 % slower.)
    let ahead = by_axis(|a| ahead::<EDGE>(local[a], walk.steps[a]));
    if leaving_face(ahead, t, walk.dt).time < walk.t_safe {
        return CubeMove::Cross(cube, cross_cube::<EDGE>(local, walk.steps, t, walk.dt));
    }
    limit.failed(cube);
    let shift = EDGE.trailing_zeros();
    if (0..3).all(|a| local[a] >> shift == walk.end[a] >> shift) {
        CubeMove::EndsInside
    } else {
        CubeMove::Step
    }
}

/// The walk at the largest saturated cube around its voxel (its brick is full: bit `brick` of
/// `full_bricks`; see [`leave_cube`]): the whole chunk when every brick is full, else the
/// voxel's 8^3 block when its eight bricks are, else the brick; a larger cube whose face comes
/// too late, and does not hold the end, gives way to the smaller ones. Only the cubes `limit`
/// allows are tried, and each one that fails lowers it.
#[inline(always)]
pub fn cross_saturated(
    full_bricks: u64,
    brick: usize,
    walk: &WalkInChunk,
    local: [i64; 3],
    t: [i64; 3],
    limit: &mut CubeLimit,
) -> CubeMove {
    if limit.allows(Cube::Chunk) && full_bricks == u64::MAX {
        let moved = leave_cube::<16>(Cube::Chunk, walk, local, t, limit);
        if moved != CubeMove::Step {
            return moved;
        }
    }
    let block = block_bricks(brick);
    if limit.allows(Cube::Block) && full_bricks & block == block {
        let moved = leave_cube::<8>(Cube::Block, walk, local, t, limit);
        if moved != CubeMove::Step {
            return moved;
        }
    }
    if limit.allows(Cube::Brick) {
        return leave_cube::<4>(Cube::Brick, walk, local, t, limit);
    }
    CubeMove::Step
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    const MAX: i64 = i64::MAX;
    /// The segment's end in fixed point (`dda::T_ONE`): the map update accepts only crossings
    /// whose face comes before it.
    const SEGMENT_END: i64 = 1 << 44;

    /// The interval the random test walks give the axes that are to tie: they all start half
    /// an interval in ([`random_axis`]), so their crossings coincide.
    pub(in crate::mapping) const TIED_DT: i64 = 1 << 40;

    /// A random step (+1 or -1) and first boundary time for an axis of a random test walk with
    /// interval `dt`: half an interval in for [`TIED_DT`], else uniform below `first_below`.
    pub(in crate::mapping) fn random_axis(
        rng: &mut impl Rng,
        dt: i64,
        first_below: i64,
    ) -> (i64, i64) {
        let step = if rng.random() { 1 } else { -1 };
        let t = if dt == TIED_DT {
            TIED_DT / 2
        } else {
            rng.random_range(0..first_below)
        };
        (step, t)
    }

    /// The axis whose next crossing comes first, ties to x, then y, then z (the walk's rule).
    pub(in crate::mapping) fn first(times: [i128; 3]) -> usize {
        if times[0] <= times[1] && times[0] <= times[2] {
            0
        } else if times[1] <= times[2] {
            1
        } else {
            2
        }
    }

    /// The voxel walk's own rule, one crossing at a time (in i128: no overflow whatever the
    /// intervals), until it enters another cube of edge `edge`.
    fn step_by_voxel(
        edge: i64,
        local: [i64; 3],
        steps: [i64; 3],
        t: [i64; 3],
        dt: [i64; 3],
    ) -> CubeCrossing {
        let cube = local.map(|l| l.div_euclid(edge));
        step_by_voxel_until(local, steps, t, dt, |k| {
            k.map(|l| l.div_euclid(edge)) != cube
        })
    }

    /// The voxel walk's own rule from `key`, one crossing at a time, until it enters a key
    /// for which `left` holds.
    pub(in crate::mapping) fn step_by_voxel_until(
        mut key: [i64; 3],
        steps: [i64; 3],
        t: [i64; 3],
        dt: [i64; 3],
        left: impl Fn([i64; 3]) -> bool,
    ) -> CubeCrossing {
        let mut crossings = [0; 3];
        let dt = dt.map(i128::from);
        let mut t = t.map(|t| if t == MAX { i128::MAX } else { i128::from(t) });
        loop {
            let a = first(t);
            let face_time = t[a];
            crossings[a] += 1;
            t[a] += dt[a];
            key[a] += steps[a];
            if left(key) {
                let fixed = |t: i128| i64::try_from(t).unwrap_or(MAX);
                return CubeCrossing {
                    crossings,
                    boundary_times: t.map(fixed),
                    face_time: fixed(face_time),
                };
            }
        }
    }

    #[test]
    fn along_x_to_the_face_of_the_brick() {
        // From local x = 1, crossings every 10 from t = 5: the face (x 3 -> 4) at 25, after 3.
        let c = cross_cube::<4>([1, 5, 9], [1, 0, 0], [5, MAX, MAX], [10, 0, 0]);
        assert_eq!(c.crossings, [3, 0, 0]);
        assert_eq!(c.boundary_times, [35, MAX, MAX]);
        assert_eq!((c.face_time, c.voxels_passed()), (25, 3));
        // Going -1 from local x = 6: crossings 6 -> 5 -> 4 -> 3, the face at the third.
        let c = cross_cube::<4>([6, 0, 0], [-1, 0, 0], [5, MAX, MAX], [10, 0, 0]);
        assert_eq!((c.crossings, c.face_time), ([3, 0, 0], 25));
        // The same walk out of its 8^3 block (face 7 -> 8 after 7) and its chunk (15 -> 16).
        let c = cross_cube::<8>([1, 5, 9], [1, 0, 0], [5, MAX, MAX], [10, 0, 0]);
        assert_eq!((c.crossings, c.face_time), ([7, 0, 0], 65));
        let c = cross_cube::<16>([1, 5, 9], [1, 0, 0], [5, MAX, MAX], [10, 0, 0]);
        assert_eq!((c.crossings, c.face_time), ([15, 0, 0], 145));
    }

    #[test]
    fn the_other_axes_take_the_crossings_ordered_before_the_face() {
        // x crosses every 10 from 5 (its face at 25), y every 7 from 3 going -1 from local
        // y 2 (its face, 2 -> 1 -> 0 -> -1, at 3 + 2 * 7 = 17): y leaves first, by when x has
        // crossed at 5 and 15.
        let c = cross_cube::<4>([1, 2, 0], [1, -1, 0], [5, 3, MAX], [10, 7, 0]);
        assert_eq!(c.crossings, [2, 3, 0]);
        assert_eq!(c.boundary_times, [25, 24, MAX]);
        // A tie: x's face and y's face both at 25 (y from local 0 going +1: 4, 11, 18, 25).
        // x wins it and leaves; y has taken its crossings at 4, 11 and 18, not the one at 25.
        let c = cross_cube::<4>([1, 0, 0], [1, 1, 0], [5, 4, MAX], [10, 7, 0]);
        assert_eq!(c.crossings, [3, 3, 0]);
        assert_eq!(c.boundary_times, [35, 25, MAX]);
        // y's face against an interior x crossing at 18 (x from local 0: 4, 11, 18, face 25;
        // y from local 2: 8, face 18): x, first in ties, takes it before y leaves.
        let c = cross_cube::<4>([0, 2, 0], [1, 1, 0], [4, 8, MAX], [7, 10, 0]);
        assert_eq!(c.crossings, [3, 2, 0]);
        assert_eq!(c.boundary_times, [25, 28, MAX]);
        assert_eq!(c.face_time, 18);
    }

    /// On random walks (small integers, so that ties are frequent; large ones; and intervals
    /// up to the walk's cap of 2^60, past the comparisons' cap), one move equals stepping
    /// voxel by voxel out of the cube whenever its face comes before the segment's end, and
    /// says it comes later otherwise.
    fn one_move_equals_stepping_voxel_by_voxel<const EDGE: i64>(seed: u64) {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mut accepted = 0;
        for case in 0..200_000 {
            let steps = [0; 3].map(|_| rng.random_range(-1..=1i64));
            if steps == [0; 3] {
                continue;
            }
            let local = [0; 3].map(|_| rng.random_range(0..16i64));
            let mut t = [0; 3];
            let mut dt = [0; 3];
            for a in 0..3 {
                if steps[a] == 0 {
                    t[a] = MAX;
                } else {
                    dt[a] = match case % 3 {
                        0 => rng.random_range(1..6),
                        1 => rng.random_range(1..1i64 << 41),
                        _ => 1i64 << rng.random_range(30..=60),
                    };
                    // A boundary may be due at once (t = 0): a walk starting on a face.
                    t[a] = rng.random_range(0..=dt[a]);
                }
            }
            let expected = step_by_voxel(EDGE, local, steps, t, dt);
            let moved = cross_cube::<EDGE>(local, steps, t, dt);
            let context = format!("case {case}: local {local:?} steps {steps:?} t {t:?} dt {dt:?}");
            if expected.face_time < SEGMENT_END {
                assert_eq!(moved, expected, "{context}");
                accepted += 1;
            } else {
                assert!(moved.face_time >= SEGMENT_END, "{context}");
            }
        }
        assert!(
            accepted > 100_000,
            "only {accepted} cases crossed before the end"
        );
    }

    /// A walk along +x from local x = 1 (crossings every 10 from t = 5: the brick's face at
    /// 25, the block's at 65, the chunk's at 145) in brick 0 of a chunk whose full bricks are
    /// `full`, ending at local x `end`, whose moves must come before `t_safe`.
    fn along_x(full: u64, end: i64, t_safe: i64, limit: &mut CubeLimit) -> CubeMove {
        let walk = WalkInChunk {
            steps: [1, 0, 0],
            dt: [10, 0, 0],
            t_safe,
            end: [end, 1, 2],
        };
        cross_saturated(full, 0, &walk, [1, 1, 2], [5, MAX, MAX], limit)
    }

    #[test]
    fn a_walk_ends_inside_the_first_saturated_cube_that_holds_its_end() {
        let (chunk, block, brick) = (u64::MAX, block_bricks(0), 1);
        let ends = |full: u64, end: i64, t_safe: i64| {
            let mut limit = CubeLimit::ANY;
            (along_x(full, end, t_safe, &mut limit), limit)
        };
        // The chunk's face comes too late and the end is in the chunk: done, whatever the
        // smaller cubes would do.
        assert_eq!(ends(chunk, 14, 100), (CubeMove::EndsInside, CubeLimit(2)));
        // The end in the next chunk: the chunk fails, the block's face comes in time.
        let (CubeMove::Cross(Cube::Block, crossing), CubeLimit(2)) = ends(chunk, 17, 100) else {
            panic!("expected the block crossed");
        };
        assert_eq!((crossing.crossings, crossing.face_time), ([7, 0, 0], 65));
        // Only the block is saturated (the chunk is not tried): the end in it, or past it.
        assert_eq!(ends(block, 6, 50), (CubeMove::EndsInside, CubeLimit(1)));
        let (CubeMove::Cross(Cube::Brick, _), CubeLimit(1)) = ends(block, 9, 50) else {
            panic!("expected the brick crossed");
        };
        assert_eq!(ends(block, 9, 20), (CubeMove::Step, CubeLimit::NONE));
        // Only the brick: the end in it, or in the next brick.
        assert_eq!(ends(brick, 3, 20), (CubeMove::EndsInside, CubeLimit::NONE));
        assert_eq!(ends(brick, 4, 20), (CubeMove::Step, CubeLimit::NONE));
        // An end in another chunk never lies inside (local -1 below, 16 above; going -x from
        // local 1, every cube's face comes at 15).
        let walk_down = WalkInChunk {
            steps: [-1, 0, 0],
            dt: [10, 0, 0],
            t_safe: 10,
            end: [-1, 1, 2],
        };
        let mut limit = CubeLimit::ANY;
        let moved = cross_saturated(chunk, 0, &walk_down, [1, 1, 2], [5, MAX, MAX], &mut limit);
        assert_eq!((moved, limit), (CubeMove::Step, CubeLimit::NONE));
    }

    #[test]
    fn one_move_out_of_a_brick_equals_stepping_voxel_by_voxel() {
        one_move_equals_stepping_voxel_by_voxel::<4>(11);
    }

    #[test]
    fn one_move_out_of_a_block_equals_stepping_voxel_by_voxel() {
        one_move_equals_stepping_voxel_by_voxel::<8>(12);
    }

    #[test]
    fn one_move_out_of_a_chunk_equals_stepping_voxel_by_voxel() {
        one_move_equals_stepping_voxel_by_voxel::<16>(13);
    }
}
