//! Voxel traversal of a segment: Amanatides & Woo's 3D DDA ("A Fast Voxel Traversal Algorithm
//! for Ray Tracing", 1987), as common.md §1 prescribes, in voxel units (`p / resolution`, so
//! voxel `k` spans `[k, k + 1)` on each axis).
//!
//! The segment is first clipped to the map's key box (slab test), so the traversal itself never
//! checks bounds. The walk then takes exactly `|Δkey|_1` steps, one axis at a time, always the
//! axis whose next boundary the segment crosses first; an axis that has reached the end key
//! is retired. This makes the walk end exactly on the end key whatever the rounding, and the
//! path is 6-connected (a ray through an edge or corner visits one of the voxels beside it too,
//! which is conservative for free space).
//!
//! Boundary times (the segment parameter, 0 at the start, 1 at the end, at which the next
//! boundary on an axis is crossed) are fixed-point integers in units of 1 / [`T_ONE`]: the map
//! update's inner loop chooses the axis with integer compares and masks, whose step-to-step
//! latency is shorter than floating point's, and every traversal here uses the same numbers,
//! so all break exact ties (rays through edges and corners) the same way.

use super::axes::by_axis;
use glam::{DVec3, IVec3};
use uavex_components::map::floor_to_key;

/// Fixed-point one of the segment parameter: 2^44. A boundary time or interval is truncated by
/// less than 6e-14; after 2^20 steps the accumulated error is below 6e-8.
pub const T_ONE: f64 = (1u64 << 44) as f64;
/// Largest boundary time or interval of an axis with steps left (2^16 segment lengths, far
/// past any segment's end): two of them add up to 2^61, far from overflow.
const T_CAP: i64 = 1 << 60;
/// Boundary time of an axis with no step left: later than any axis with steps left.
pub const T_RETIRED: i64 = i64::MAX;

/// A segment parameter in fixed point ([`T_ONE`] per unit), saturating at 2^60 (2^16 units).
#[inline]
pub fn to_fixed(t: f64) -> i64 {
    if t < T_CAP as f64 / T_ONE {
        (t * T_ONE) as i64
    } else {
        T_CAP
    }
}

/// A segment clipped to a key box: the keys it starts and ends in.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ClippedSegment {
    pub start_key: IVec3,
    pub end_key: IVec3,
    /// Whether the segment's own end point lies in the box (else it was cut at the box).
    pub end_inside: bool,
    /// Segment parameter (0 at the start, 1 at the end) where the clipped segment ends.
    pub t_end: f64,
}

/// Clips the segment `start -> end` (voxel units) to the keys `lo..=hi`; `None` if it misses the
/// box (or only grazes its surface from outside).
pub fn clip_segment(start: DVec3, end: DVec3, lo: IVec3, hi: IVec3) -> Option<ClippedSegment> {
    SegmentClipper::new(start, lo, hi).clip(end)
}

/// [`clip_segment`] for many segments from one start (a scan's rays from its origin): the
/// start's key is found once.
#[derive(Debug, Clone, Copy)]
pub struct SegmentClipper {
    start: DVec3,
    start_key: IVec3,
    start_inside: bool,
    lo: IVec3,
    hi: IVec3,
}

impl SegmentClipper {
    pub fn new(start: DVec3, lo: IVec3, hi: IVec3) -> Self {
        let start_key = floor_to_key(start);
        Self {
            start,
            start_key,
            start_inside: start_key.cmpge(lo).all() && start_key.cmple(hi).all(),
            lo,
            hi,
        }
    }

    /// The segment from the start to `end`, clipped ([`clip_segment`]). Always inlined: its
    /// result then goes straight into the scan's clips, not through the stack (where a
    /// profile of a Simple mission found 2.5 % of its samples on the copy).
    #[inline(always)]
    pub fn clip(&self, end: DVec3) -> Option<ClippedSegment> {
        let Self {
            start,
            start_key: raw_start,
            start_inside,
            lo,
            hi,
        } = *self;
        // Points on the segment keep their key when inside (the same `floor` every key
        // computation uses); entry and exit points are clamped into the box against rounding.
        let raw_end = floor_to_key(end);
        let end_inside = raw_end.cmpge(lo).all() && raw_end.cmple(hi).all();
        if start_inside && end_inside {
            // The box is convex: nothing to clip (the common case, worth skipping the slabs).
            return Some(ClippedSegment {
                start_key: raw_start,
                end_key: raw_end,
                end_inside,
                t_end: 1.0,
            });
        }
        let d = end - start;
        let (box_lo, box_hi) = (lo.as_dvec3(), (hi + IVec3::ONE).as_dvec3());
        let key_at = |t: f64| floor_to_key(start + d * t).clamp(lo, hi);
        if start_inside {
            // Leaving the box (a ray ending on a wall or the floor beyond the map's border: a third
            // of a camera frame's rays). Only the axes on which the end lies outside can cut the
            // segment: on the others both ends lie in the slab, so their exit parameter, computed
            // as below, is at least 1 (rounding is monotonic). Same parameters, one division.
            let mut t1 = 1.0_f64;
            for axis in 0..3 {
                if raw_end[axis] < lo[axis] {
                    t1 = t1.min((box_lo[axis] - start[axis]) / d[axis]);
                } else if raw_end[axis] > hi[axis] {
                    t1 = t1.min((box_hi[axis] - start[axis]) / d[axis]);
                }
            }
            return Some(ClippedSegment {
                start_key: raw_start,
                end_key: key_at(t1),
                end_inside,
                t_end: t1,
            });
        }
        let (mut t0, mut t1) = (0.0_f64, 1.0_f64);
        for axis in 0..3 {
            if d[axis] == 0.0 {
                if start[axis] < box_lo[axis] || start[axis] >= box_hi[axis] {
                    return None;
                }
            } else {
                let ta = (box_lo[axis] - start[axis]) / d[axis];
                let tb = (box_hi[axis] - start[axis]) / d[axis];
                t0 = t0.max(ta.min(tb));
                t1 = t1.min(ta.max(tb));
            }
        }
        if t0 > t1 || (t0 == t1 && !start_inside && !end_inside) {
            return None;
        }
        Some(ClippedSegment {
            start_key: key_at(t0),
            end_key: if end_inside { raw_end } else { key_at(t1) },
            end_inside,
            t_end: t1,
        })
    }
}

/// The state of a traversal from `start_key` to `end_key` along the segment `start -> end`.
#[derive(Debug, Clone, Copy)]
pub struct VoxelWalk {
    /// The current key (an array, not an `IVec3`: indexing an `IVec3` by a run-time axis is a
    /// `match`, i.e. a mispredicted branch per step).
    key: [i32; 3],
    /// Segment parameter at which the next boundary on each axis is crossed.
    t_max: [i64; 3],
    /// Parameter increment between boundaries on each axis (1 / |d|).
    t_delta: [i64; 3],
    step: [i32; 3],
    remaining: [u32; 3],
}

impl VoxelWalk {
    /// A walk over the keys of a clipped segment (`start`, `end` are the unclipped points that
    /// parametrise it; the keys need not be the keys of those points).
    pub fn new(start: DVec3, end: DVec3, start_key: IVec3, end_key: IVec3) -> Self {
        Self::with_inverse(start, end, DVec3::ONE / (end - start), start_key, end_key)
    }

    /// [`Self::new`] given `inverse = 1 / (end - start)` per axis, computed ahead (the map
    /// update divides for all of a scan's rays in one pass, where the divisions overlap,
    /// rather than one ray at a time between walks).
    #[inline]
    pub fn with_inverse(
        start: DVec3,
        end: DVec3,
        inverse: DVec3,
        start_key: IVec3,
        end_key: IVec3,
    ) -> Self {
        let d = end - start;
        let mut walk = Self {
            key: start_key.to_array(),
            t_max: [T_RETIRED; 3],
            t_delta: [0; 3],
            step: [0; 3],
            remaining: [0; 3],
        };
        for axis in 0..3 {
            let n = end_key[axis] - start_key[axis];
            if n == 0 || d[axis] == 0.0 {
                continue;
            }
            let boundary = f64::from(start_key[axis] + i32::from(n > 0));
            walk.step[axis] = n.signum();
            walk.remaining[axis] = n.unsigned_abs();
            let inverse = inverse[axis];
            walk.t_max[axis] = to_fixed((boundary - start[axis]) * inverse);
            walk.t_delta[axis] = to_fixed(inverse.abs());
        }
        walk
    }

    /// The current key.
    #[inline]
    pub fn key(&self) -> IVec3 {
        IVec3::from_array(self.key)
    }

    /// Steps left until the end key.
    pub fn steps_left(&self) -> u64 {
        self.remaining.iter().map(|&r| u64::from(r)).sum()
    }

    /// The key the walk ends in.
    #[inline]
    pub fn last_key(&self) -> IVec3 {
        IVec3::from_array(by_axis(|a| {
            self.key[a] + self.step[a] * self.remaining[a] as i32
        }))
    }

    /// Step (+1, -1 or 0) of the walk along each axis.
    #[inline]
    pub fn steps(&self) -> [i32; 3] {
        self.step
    }

    /// Fixed-point segment parameter of the next boundary on each axis ([`T_RETIRED`] for
    /// axes with no step left).
    #[inline]
    pub fn boundary_times(&self) -> [i64; 3] {
        self.t_max
    }

    /// Fixed-point segment parameter between two boundaries on each axis.
    #[inline]
    pub fn boundary_intervals(&self) -> [i64; 3] {
        self.t_delta
    }

    /// Continues the walk at `key` with next boundary times `t_max`, after a caller's own loop
    /// (see `integrate`) took steps along the walk's axes without bookkeeping of their counts.
    #[inline]
    pub fn resume(&mut self, key: IVec3, t_max: [i64; 3]) {
        for axis in 0..3 {
            let taken = (key[axis] - self.key[axis]).unsigned_abs();
            self.remaining[axis] = self.remaining[axis].saturating_sub(taken);
            // A retired axis moves no more: its interval goes too, so that arithmetic on the
            // boundary times (`super::cube`) never adds an interval to `T_RETIRED`.
            (self.t_max[axis], self.t_delta[axis]) = if self.remaining[axis] == 0 {
                (T_RETIRED, 0)
            } else {
                (t_max[axis], self.t_delta[axis])
            };
            self.key[axis] = key[axis];
        }
    }

    /// Moves to the next voxel. Only meaningful while [`Self::steps_left`] > 0.
    ///
    /// The axis is the one with the earliest boundary; ties go to x, then y, then z (the map
    /// update's inner loop decides the same way). Only that axis' state changes: an axis with
    /// no step left already has the boundary time [`T_RETIRED`] (set when its count ran out).
    ///
    /// Every axis computes its would-be update and keeps it only if chosen (selects, not
    /// branches: which axis is as good as random). Indexing the state by the chosen axis
    /// instead kept the walk in memory, and each step waited for the last one's store: lines
    /// of sight ([`all_keys`]) took about 2.5 times as long (perf of replayed decisions).
    #[inline(always)]
    pub fn advance(&mut self) {
        let t = self.t_max;
        let x = (t[0] <= t[1]) & (t[0] <= t[2]);
        let y = !x & (t[1] <= t[2]);
        let chosen = [x, y, !x & !y];
        for axis in 0..3 {
            let remaining = self.remaining[axis].saturating_sub(1);
            let t_next = if remaining == 0 {
                T_RETIRED
            } else {
                t[axis].saturating_add(self.t_delta[axis])
            };
            let c = chosen[axis];
            self.remaining[axis] = if c { remaining } else { self.remaining[axis] };
            self.t_max[axis] = if c { t_next } else { t[axis] };
            self.key[axis] += self.step[axis] * i32::from(c);
        }
    }
}

/// Visits every key of the segment `start -> end` (voxel units) inside `lo..=hi`, in order,
/// including the end key: the plain form of the traversal for callers outside the map update
/// (line-of-sight checks, tests).
pub fn for_each_key(start: DVec3, end: DVec3, lo: IVec3, hi: IVec3, mut visit: impl FnMut(IVec3)) {
    all_keys(start, end, lo, hi, |key| {
        visit(key);
        true
    });
}

/// Whether `test` holds for every key [`for_each_key`] visits, stopping at the first that
/// fails (a line of sight is decided at its first blocked voxel).
pub fn all_keys(
    start: DVec3,
    end: DVec3,
    lo: IVec3,
    hi: IVec3,
    mut test: impl FnMut(IVec3) -> bool,
) -> bool {
    let Some(clip) = clip_segment(start, end, lo, hi) else {
        return true;
    };
    let mut walk = VoxelWalk::new(start, end, clip.start_key, clip.end_key);
    if !test(walk.key()) {
        return false;
    }
    for _ in 0..walk.steps_left() {
        walk.advance();
        if !test(walk.key()) {
            return false;
        }
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;
    use std::collections::BTreeSet;

    const LO: IVec3 = IVec3::splat(-20);
    const HI: IVec3 = IVec3::splat(19);
    /// Sampling step of the brute-force reference (voxel units).
    const SAMPLE: f64 = 2e-4;

    fn keys(start: DVec3, end: DVec3) -> Vec<IVec3> {
        let mut out = Vec::new();
        for_each_key(start, end, LO, HI, |k| out.push(k));
        out
    }

    /// Keys of points sampled every `SAMPLE` along the segment (and its end), inside the box.
    fn sampled(start: DVec3, end: DVec3) -> BTreeSet<[i32; 3]> {
        let n = ((end - start).length() / SAMPLE).ceil().max(1.0) as usize;
        (0..=n)
            // start + d t (not `lerp`, whose (1 - t) a + t b drifts off a face the ray lies on)
            .map(|i| {
                (start + (end - start) * (i as f64 / n as f64))
                    .floor()
                    .as_ivec3()
            })
            .filter(|k| k.cmpge(LO).all() && k.cmple(HI).all())
            .map(|k| k.to_array())
            .collect()
    }

    /// Length of the part of the segment inside voxel `key` (exact slab test; 0 when it only
    /// touches the voxel, `None` when it misses it).
    fn overlap(start: DVec3, end: DVec3, key: IVec3) -> Option<f64> {
        let d = end - start;
        let (mut t0, mut t1) = (0.0_f64, 1.0_f64);
        for a in 0..3 {
            let (lo, hi) = (f64::from(key[a]), f64::from(key[a] + 1));
            if d[a] == 0.0 {
                if start[a] < lo || start[a] > hi {
                    return None;
                }
            } else {
                let (ta, tb) = ((lo - start[a]) / d[a], (hi - start[a]) / d[a]);
                t0 = t0.max(ta.min(tb));
                t1 = t1.min(ta.max(tb));
            }
        }
        (t0 <= t1 + 1e-12).then(|| (t1 - t0).max(0.0) * d.length())
    }

    /// The walk agrees with brute-force sampling: every sampled voxel is visited (except one
    /// the segment only touches, when a sample falls exactly on an edge or corner), and every
    /// visited voxel the samples missed holds less than two sampling steps of the segment (0 for
    /// the voxels a walk through an edge or corner adds); the path is 6-connected, has no
    /// repeats, and runs from the first to the last sampled voxel.
    fn check(start: DVec3, end: DVec3) {
        let walk = keys(start, end);
        let samples = sampled(start, end);
        if samples.is_empty() {
            // Misses the box, or touches it over less than a sampling step.
            for k in &walk {
                assert!(overlap(start, end, *k).is_some_and(|l| l < 2.0 * SAMPLE));
            }
            return;
        }
        let visited: BTreeSet<[i32; 3]> = walk.iter().map(|k| k.to_array()).collect();
        assert_eq!(visited.len(), walk.len(), "repeat in {start} -> {end}");
        for k in samples.difference(&visited) {
            // A sample exactly on an edge or corner names a voxel the segment only touches.
            let len = overlap(start, end, IVec3::from_array(*k));
            assert!(
                len.is_some_and(|l| l < 1e-9),
                "missed {k:?} of {start} -> {end}: {len:?}"
            );
        }
        for k in visited.difference(&samples) {
            let len = overlap(start, end, IVec3::from_array(*k));
            assert!(
                len.is_some_and(|l| l < 2.0 * SAMPLE),
                "{k:?} off the segment {start} -> {end}: {len:?}"
            );
        }
        for pair in walk.windows(2) {
            assert_eq!(
                (pair[1] - pair[0]).abs().element_sum(),
                1,
                "not 6-connected"
            );
        }
        // First and last voxels are those of the first and last samples.
        let first = start.floor().as_ivec3();
        if first.cmpge(LO).all() && first.cmple(HI).all() {
            assert_eq!(walk[0], first);
        }
        let last = end.floor().as_ivec3();
        if last.cmpge(LO).all() && last.cmple(HI).all() {
            assert_eq!(*walk.last().unwrap(), last);
        }
    }

    #[test]
    fn random_rays_match_fine_sampling() {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let mut point = |r: f64| {
            DVec3::new(
                rng.random_range(-r..r),
                rng.random_range(-r..r),
                rng.random_range(-r..r),
            )
        };
        for i in 0..400 {
            // Short rays inside the box, long rays crossing its faces from outside.
            let (start, end) = if i % 2 == 0 {
                let s = point(18.0);
                (s, s + point(4.0))
            } else {
                (point(26.0), point(26.0))
            };
            check(start, end);
        }
    }

    #[test]
    fn special_rays_match_fine_sampling() {
        let v = DVec3::new;
        let rays = [
            // Along each axis, both directions, through voxel centres and along faces / edges.
            (v(0.5, 0.5, 0.5), v(7.5, 0.5, 0.5)),
            (v(0.5, -3.5, 0.5), v(0.5, -11.5, 0.5)),
            (v(-4.5, 2.0, 2.0), v(-4.5, 2.0, 9.3)),
            (v(-6.0, -6.0, 1.3), v(3.7, -6.0, 1.3)),
            // Through voxel corners exactly (the diagonal), positive and negative.
            (v(0.5, 0.5, 0.5), v(3.5, 3.5, 3.5)),
            (v(-0.5, -0.5, -0.5), v(-5.5, -5.5, -5.5)),
            (v(0.0, 0.0, 0.0), v(-4.0, 4.0, -4.0)),
            // Through edges (two axes tie).
            (v(0.5, 0.5, 0.25), v(4.5, 4.5, 0.75)),
            // Starting (and ending) on a face.
            (v(3.0, 0.5, 0.5), v(-2.0, 0.7, 0.1)),
            (v(2.5, -1.0, 0.5), v(2.7, -4.0, 0.5)),
            (v(1.2, 1.3, 1.4), v(5.0, 1.9, 1.1)),
            // Negative coordinates across chunk-like borders, entering and leaving the box.
            (v(-25.0, -19.5, -0.5), v(25.0, 19.25, 0.5)),
            (v(-19.99, -19.99, -19.99), v(19.99, 19.99, 19.99)),
            // Entirely outside, and grazing the box surface from outside.
            (v(-30.0, 25.0, 0.0), v(30.0, 25.0, 0.0)),
            (v(-30.0, 20.0, 0.0), v(30.0, 20.0, 0.0)),
        ];
        for (start, end) in rays {
            check(start, end);
        }
        assert!(keys(v(-30.0, 25.0, 0.0), v(30.0, 25.0, 0.0)).is_empty());
        assert!(keys(v(-30.0, 20.0, 0.0), v(30.0, 20.0, 0.0)).is_empty());
        // Exact paths: along +x from voxel 0 to 7; the corner diagonal takes 9 steps, x then y
        // then z at each corner.
        assert_eq!(keys(v(0.5, 0.5, 0.5), v(7.5, 0.5, 0.5)).len(), 8);
        let diagonal = keys(v(0.5, 0.5, 0.5), v(3.5, 3.5, 3.5));
        assert_eq!(diagonal.len(), 10);
        assert_eq!(
            &diagonal[..4],
            &[IVec3::ZERO, IVec3::X, IVec3::new(1, 1, 0), IVec3::ONE]
        );
    }

    #[test]
    fn zero_length_ray_visits_its_voxel() {
        let p = DVec3::new(-3.25, 0.0, 7.9);
        assert_eq!(keys(p, p), vec![IVec3::new(-4, 0, 7)]);
        assert!(keys(DVec3::splat(20.0), DVec3::splat(20.0)).is_empty());
        // On the lower face of the box the point is inside (voxel -20).
        assert_eq!(keys(DVec3::splat(-20.0), DVec3::splat(-20.0)), vec![LO]);
    }

    #[test]
    fn clipping_reports_cut_ends() {
        let c = clip_segment(
            DVec3::new(-30.5, 0.5, 0.5),
            DVec3::new(0.5, 0.5, 0.5),
            LO,
            HI,
        )
        .unwrap();
        assert_eq!(
            (c.start_key, c.end_key, c.end_inside, c.t_end),
            (IVec3::new(-20, 0, 0), IVec3::ZERO, true, 1.0)
        );
        let c = clip_segment(
            DVec3::new(0.5, 0.5, 0.5),
            DVec3::new(0.5, 40.0, 0.5),
            LO,
            HI,
        )
        .unwrap();
        assert_eq!((c.end_key, c.end_inside), (IVec3::new(0, 19, 0), false));
        assert!((c.t_end - 19.5 / 39.5).abs() < 1e-15);
        // An end exactly on the upper face lies outside (half-open box): the segment is cut.
        let c = clip_segment(DVec3::splat(0.5), DVec3::new(0.5, 20.0, 0.5), LO, HI).unwrap();
        assert_eq!((c.end_key, c.end_inside), (IVec3::new(0, 19, 0), false));
    }
}
