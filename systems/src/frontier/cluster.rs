//! Divisive 2-means clustering of frontier voxels (eaae.md step 2).
//!
//! Start with all points as one cluster; while a cluster's `r_max` (largest member distance to
//! its centroid) exceeds the bound `tan(FoV_h / 2) * d_max`, split it in two with 2-means
//! (Euclidean, Lloyd iterations) and recurse. No K is chosen up front. The seeds come from the
//! caller's random stream (the run's seeded RNG), so runs are deterministic.

use glam::{DVec3, Vec3};
use rand::Rng;

/// Lloyd iterations per split at most. 2-means on frontier voxels settles in a handful of
/// iterations; the cap bounds the cost on a 60k-voxel frontier, and the stop rule does not need
/// a converged split, only one that separates the points (every split makes both halves
/// smaller, so the recursion ends whatever the split's quality).
pub const LLOYD_ITERATIONS: usize = 10;

/// One cluster of [`divisive_two_means`].
#[derive(Debug, Clone, PartialEq)]
pub struct Cluster {
    /// Mean of the members (accumulated in f64, so 60k points lose no precision).
    pub centroid: Vec3,
    /// Indices into the points, ascending.
    pub members: Vec<usize>,
    /// Largest member distance to `centroid` (m).
    pub r_max: f32,
}

/// Divisive 2-means (EAAE step 2): start with all points as one cluster, split with 2-means
/// (Euclidean) and recurse until `r_max <= r_max_bound`. Seeding (see `seeds`: the far ends of
/// the cluster, found from a member drawn with `rng`) comes from `rng`. Deterministic for a
/// given `rng` state.
///
/// The clusters partition `0..points.len()`, in depth-first order of the splits. A single point
/// is always a cluster (its `r_max` is 0); a negative or NaN bound is taken as 0, i.e. clusters
/// of coincident points. Points should be finite: a non-finite point ends up alone.
pub fn divisive_two_means(points: &[Vec3], r_max_bound: f32, rng: &mut impl Rng) -> Vec<Cluster> {
    let bound = if r_max_bound.is_nan() {
        0.0
    } else {
        r_max_bound.max(0.0)
    };
    let mut out = Vec::new();
    if points.is_empty() {
        return out;
    }
    // The members and a copy of their points, coordinate by coordinate, are permuted in place
    // so that every pending cluster is one contiguous range of both: the passes over a cluster
    // read memory in order, and a split moves its points within their range (a stable
    // partition) instead of copying them into new buffers.
    let mut members: Vec<usize> = (0..points.len()).collect();
    let mut pts = Coordinates::of(points);
    let mut scratch = Scratch::default();
    // The pending clusters, as ranges: the first is all of them.
    #[allow(clippy::single_range_in_vec_init)]
    let mut stack = vec![0..points.len()];
    while let Some(range) = stack.pop() {
        let view = pts.view(range.clone());
        let (total, centroid, r_max) = sum_mean_and_radius(view);
        if range.len() == 1 || r_max <= bound {
            out.push(Cluster {
                centroid,
                members: members[range].to_vec(),
                r_max,
            });
            continue;
        }
        split(view, total, rng, &mut scratch);
        // Depth first, the first half before the second.
        let middle =
            range.start + scratch.partition(&mut members[range.clone()], &mut pts, range.clone());
        stack.push(middle..range.end);
        stack.push(range.start..middle);
    }
    out
}

/// The buffers the splits reuse: the sides of a Lloyd step (the last and the next), and the
/// second side's values during a partition.
#[derive(Debug, Default)]
struct Scratch {
    side: Vec<bool>,
    next: Vec<bool>,
    members: Vec<usize>,
    values: Vec<f32>,
}

impl Scratch {
    /// Reorders `members` and the points of `range` (one cluster) so that those with `side`
    /// false come first, then those with `side` true, each in their order: how many are
    /// false.
    fn partition(
        &mut self,
        members: &mut [usize],
        pts: &mut Coordinates,
        range: std::ops::Range<usize>,
    ) -> usize {
        let first = stable_partition(members, &self.side, &mut self.members);
        for values in [&mut pts.x, &mut pts.y, &mut pts.z] {
            stable_partition(&mut values[range.clone()], &self.side, &mut self.values);
        }
        first
    }
}

/// Moves the `values` with `side` false to the front and those with `side` true after them,
/// each in order (`second` holds the latter meanwhile): how many are false.
fn stable_partition<T: Copy>(values: &mut [T], side: &[bool], second: &mut Vec<T>) -> usize {
    second.clear();
    let mut first = 0;
    for (j, &s) in side.iter().enumerate() {
        let value = values[j];
        if s {
            second.push(value);
        } else {
            // `first <= j`: the value it overwrites was moved already.
            values[first] = value;
            first += 1;
        }
    }
    values[first..].copy_from_slice(second);
    first
}

/// Points stored coordinate by coordinate (a structure of arrays): the passes over a cluster
/// read three streams and handle [`LANES`] points per step, which the compiler turns into
/// vector instructions (2-means is a sixth of a large decision's time).
#[derive(Debug, Clone, Default)]
struct Coordinates {
    x: Vec<f32>,
    y: Vec<f32>,
    z: Vec<f32>,
}

/// The points of one cluster: a range of [`Coordinates`].
#[derive(Debug, Clone, Copy)]
struct Points<'a> {
    x: &'a [f32],
    y: &'a [f32],
    z: &'a [f32],
}

/// Points per step of the passes over [`Points`]: one 128-bit vector of `f32`.
const LANES: usize = 4;

impl Coordinates {
    fn of(points: &[Vec3]) -> Self {
        Self {
            x: points.iter().map(|p| p.x).collect(),
            y: points.iter().map(|p| p.y).collect(),
            z: points.iter().map(|p| p.z).collect(),
        }
    }

    /// The points of `range`.
    fn view(&self, range: std::ops::Range<usize>) -> Points<'_> {
        Points {
            x: &self.x[range.clone()],
            y: &self.y[range.clone()],
            z: &self.z[range],
        }
    }
}

impl Points<'_> {
    fn len(self) -> usize {
        self.x.len()
    }

    fn point(self, j: usize) -> Vec3 {
        Vec3::new(self.x[j], self.y[j], self.z[j])
    }

    /// The sum of the points in f64, in [`LANES`] partial sums per coordinate.
    ///
    /// The order of the additions does not change the sum: an `f32` has 24 significant bits,
    /// so any sum or difference of up to 2^16 points within 256 m of the origin, none of whose
    /// coordinates is below 2^-6 m in magnitude unless zero, needs at most 8 + 16 + 6 + 23 = 53
    /// bits: exact in f64, whatever the order. That covers the frontiers of the thesis' scenes
    /// (voxel centres are half a voxel, 0.05 m, or more from a grid plane); larger or finer
    /// ones may round, the same way every run. (Independent partial sums let the additions
    /// overlap instead of waiting for each other.)
    fn sum(self) -> DVec3 {
        let coordinate = |values: &[f32]| {
            let mut lanes = [0.0f64; LANES];
            let whole = values.len() / LANES * LANES;
            for chunk in values[..whole].chunks_exact(LANES) {
                for (sum, &v) in lanes.iter_mut().zip(chunk) {
                    *sum += f64::from(v);
                }
            }
            for (sum, &v) in lanes.iter_mut().zip(&values[whole..]) {
                *sum += f64::from(v);
            }
            lanes.iter().fold(0.0, |s, l| s + l)
        };
        DVec3::new(coordinate(self.x), coordinate(self.y), coordinate(self.z))
    }

    /// The sum of the points `j` with `after[j]` minus that of those with `before[j]`: the
    /// points that changed side only, found eight sides at a time.
    fn change_of_sum(self, before: &[bool], after: &[bool]) -> DVec3 {
        const STRIDE: usize = 8;
        let mut change = DVec3::ZERO;
        // Eight sides as one word (`==` on the slices would call `memcmp`).
        let word = |sides: &[bool]| u64::from_ne_bytes(std::array::from_fn(|i| u8::from(sides[i])));
        let mut add = |j: usize, was: bool, is: bool| {
            if is != was {
                let p = self.point(j).as_dvec3();
                change += if is { p } else { -p };
            }
        };
        let chunks = before.chunks_exact(STRIDE).zip(after.chunks_exact(STRIDE));
        for (c, (b, a)) in chunks.enumerate() {
            if word(a) != word(b) {
                for i in 0..STRIDE {
                    add(c * STRIDE + i, b[i], a[i]);
                }
            }
        }
        let whole = before.len() / STRIDE * STRIDE;
        for j in whole..before.len() {
            add(j, before[j], after[j]);
        }
        change
    }

    /// Each point's squared distance to `from` ([`Vec3::distance_squared`]'s operations),
    /// folded lane by lane with `keep(candidate, best)` from `start`, as `(value, index)`
    /// per lane.
    #[inline(always)]
    fn fold_squared_distances(
        self,
        from: Vec3,
        start: (f32, usize),
        keep: impl Fn(f32, f32) -> bool,
    ) -> [(f32, usize); LANES] {
        let mut best = [start; LANES];
        let mut visit = |j: usize, lane: usize, x: f32, y: f32, z: f32| {
            let (dx, dy, dz) = (x - from.x, y - from.y, z - from.z);
            let d = dx * dx + dy * dy + dz * dz;
            if keep(d, best[lane].0) {
                best[lane] = (d, j);
            }
        };
        let whole = self.len() / LANES * LANES;
        let chunks = self.x[..whole]
            .chunks_exact(LANES)
            .zip(self.y[..whole].chunks_exact(LANES))
            .zip(self.z[..whole].chunks_exact(LANES));
        for (i, ((x, y), z)) in chunks.enumerate() {
            for lane in 0..LANES {
                visit(i * LANES + lane, lane, x[lane], y[lane], z[lane]);
            }
        }
        for j in whole..self.len() {
            visit(j, j - whole, self.x[j], self.y[j], self.z[j]);
        }
        best
    }
}

/// Mean of the members and their largest distance to it (the stop rule's `r_max`).
pub fn centroid_and_radius(points: &[Vec3], members: &[usize]) -> (Vec3, f32) {
    let pts: Vec<Vec3> = members.iter().map(|&m| points[m]).collect();
    let pts = Coordinates::of(&pts);
    let (_, centroid, r_max) = sum_mean_and_radius(pts.view(0..members.len()));
    (centroid, r_max)
}

/// The sum of the points (f64), their mean and their largest distance to it.
fn sum_mean_and_radius(pts: Points<'_>) -> (DVec3, Vec3, f32) {
    let sum = pts.sum();
    let centroid = (sum / pts.len().max(1) as f64).as_vec3();
    // The largest squared distance, NaN if any is (a NaN wins whatever comes after it).
    let farthest = |d: f32, best: f32| d > best || d.is_nan();
    let lanes = pts.fold_squared_distances(centroid, (0.0, 0), farthest);
    let r2 = lanes
        .iter()
        .fold(0.0f32, |a, &(d, _)| if farthest(d, a) { d } else { a });
    (sum, centroid, r2.sqrt())
}

/// Splits `pts` (at least two, whose sum is `total`) in two non-empty sides with 2-means;
/// `scratch.side[j]` tells point `j`'s side. Each Lloyd step assigns a point to the nearer
/// centre, tested as the side of the bisecting plane (`p . (c1 - c0) > (|c1|^2 - |c0|^2) / 2`,
/// one dot product per point).
fn split(pts: Points<'_>, total: DVec3, rng: &mut impl Rng, scratch: &mut Scratch) {
    let Scratch { side, next, .. } = scratch;
    side.clear();
    side.resize(pts.len(), false);
    let Some(mut centres) = seeds(pts, rng) else {
        halves(pts, side);
        return;
    };
    let mut valid = false;
    next.clear();
    next.resize(pts.len(), false);
    // The sum of the points on the second side (none yet).
    let mut sum1 = DVec3::ZERO;
    for _ in 0..LLOYD_ITERATIONS {
        let w = centres[1] - centres[0];
        let t = 0.5 * (centres[1].length_squared() - centres[0].length_squared());
        // The sides, four points a step ([`Vec3::dot`]'s operations).
        let mut changed = false;
        for ((((n, &old), &x), &y), &z) in next
            .iter_mut()
            .zip(side.iter())
            .zip(pts.x)
            .zip(pts.y)
            .zip(pts.z)
        {
            let s = x * w.x + y * w.y + z * w.z > t;
            changed |= s != old;
            *n = s;
        }
        let count1 = next.iter().filter(|&&s| s).count();
        if count1 == 0 || count1 == pts.len() {
            // Cannot happen with distinct seeds and finite points; keep the last valid split.
            break;
        }
        // The second side's sum: the last one's, plus the points that joined it, minus those
        // that left it (after the first steps, few). Exact, as every sum here (see
        // [`Points::sum`]): the sum over the side, bit for bit.
        sum1 += pts.change_of_sum(side, next);
        std::mem::swap(side, next);
        if valid && !changed {
            break;
        }
        valid = true;
        let count0 = pts.len() - count1;
        centres = [
            ((total - sum1) / count0 as f64).as_vec3(),
            (sum1 / count1 as f64).as_vec3(),
        ];
    }
    if !valid {
        halves(pts, side);
    }
}

/// Seeds: from a uniformly drawn member `r`, the member `a` farthest from `r`, then the member
/// `b` farthest from `a` (ties to the earlier member): an approximate diameter of the cluster.
/// Why not k-means++ (`b` drawn with probability proportional to squared distance): the stop
/// rule is about the farthest member, and a few far voxels (a sliver across the room) carry
/// little of the squared-distance mass, so k-means++ would often seed both centres in the bulk,
/// cut the bulk in halves and drag the sliver along, splitting a compact frontier patch into
/// many clusters. Seeding on the diameter separates the far part first. `None` when all
/// members coincide (or distances are not finite).
fn seeds(pts: Points<'_>, rng: &mut impl Rng) -> Option<[Vec3; 2]> {
    let r = pts.point(rng.random_range(0..pts.len()));
    let farthest = |from: Vec3| {
        // Per lane the first of its farthest members; of the lanes', the farthest and then
        // the earliest: the first farthest member. `from` itself when none is farther than 0.
        let lanes = pts.fold_squared_distances(from, (0.0, usize::MAX), |d, best| d > best);
        let (d, j) = lanes.into_iter().fold((0.0f32, usize::MAX), |best, c| {
            if c.0 > best.0 || (c.0 == best.0 && c.1 < best.1) {
                c
            } else {
                best
            }
        });
        if j == usize::MAX {
            (from, 0.0)
        } else {
            (pts.point(j), d)
        }
    };
    let (a, _) = farthest(r);
    let (b, d) = farthest(a);
    (d > 0.0 && d.is_finite()).then_some([a, b])
}

/// Fallback split (degenerate inputs only): the lexicographically smaller half of the members
/// against the rest. Both sides are non-empty, so the recursion still ends.
fn halves(pts: Points<'_>, side: &mut [bool]) {
    let mut order: Vec<usize> = (0..pts.len()).collect();
    order.sort_by(|&i, &j| {
        let (p, q) = (pts.point(i), pts.point(j));
        p.x.total_cmp(&q.x)
            .then(p.y.total_cmp(&q.y))
            .then(p.z.total_cmp(&q.z))
            .then(i.cmp(&j))
    });
    for (rank, &j) in order.iter().enumerate() {
        side[j] = rank >= pts.len() / 2;
    }
}
