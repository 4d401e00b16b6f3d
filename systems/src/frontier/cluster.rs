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
    // Each pending cluster carries its member indices and a contiguous copy of their points,
    // so that the passes over a cluster read memory in order.
    let mut stack = vec![((0..points.len()).collect::<Vec<usize>>(), points.to_vec())];
    let mut side = Vec::new();
    while let Some((members, pts)) = stack.pop() {
        let (centroid, r_max) = mean_and_radius(&pts);
        if members.len() == 1 || r_max <= bound {
            out.push(Cluster {
                centroid,
                members,
                r_max,
            });
            continue;
        }
        split(&pts, rng, &mut side);
        let n1 = side.iter().filter(|&&s| s).count();
        let mut first = (
            Vec::with_capacity(pts.len() - n1),
            Vec::with_capacity(pts.len() - n1),
        );
        let mut second = (Vec::with_capacity(n1), Vec::with_capacity(n1));
        for ((&m, &p), &s) in members.iter().zip(&pts).zip(&side) {
            let half = if s { &mut second } else { &mut first };
            half.0.push(m);
            half.1.push(p);
        }
        // Depth first, the first half before the second.
        stack.push(second);
        stack.push(first);
    }
    out
}

/// Mean of the members and their largest distance to it (the stop rule's `r_max`).
pub fn centroid_and_radius(points: &[Vec3], members: &[usize]) -> (Vec3, f32) {
    let pts: Vec<Vec3> = members.iter().map(|&m| points[m]).collect();
    mean_and_radius(&pts)
}

fn mean_and_radius(pts: &[Vec3]) -> (Vec3, f32) {
    let sum = pts.iter().fold(DVec3::ZERO, |s, p| s + p.as_dvec3());
    let centroid = (sum / pts.len().max(1) as f64).as_vec3();
    let r2 = pts
        .iter()
        .map(|p| p.distance_squared(centroid))
        .fold(0.0f32, |a, d| if d > a || d.is_nan() { d } else { a });
    (centroid, r2.sqrt())
}

/// Splits `pts` (at least two) in two non-empty sides with 2-means; `side[j]` tells point `j`'s
/// side. Each Lloyd step assigns a point to the nearer centre, tested as the side of the
/// bisecting plane (`p . (c1 - c0) > (|c1|^2 - |c0|^2) / 2`, one dot product per point).
fn split(pts: &[Vec3], rng: &mut impl Rng, side: &mut Vec<bool>) {
    side.clear();
    side.resize(pts.len(), false);
    let Some(mut centres) = seeds(pts, rng) else {
        halves(pts, side);
        return;
    };
    let total = pts.iter().fold(DVec3::ZERO, |s, p| s + p.as_dvec3());
    let mut valid = false;
    let mut next = vec![false; pts.len()];
    for _ in 0..LLOYD_ITERATIONS {
        let w = centres[1] - centres[0];
        let t = 0.5 * (centres[1].length_squared() - centres[0].length_squared());
        let mut sum1 = DVec3::ZERO;
        let mut count1 = 0usize;
        let mut changed = false;
        for ((p, n), &old) in pts.iter().zip(next.iter_mut()).zip(side.iter()) {
            let s = p.dot(w) > t;
            changed |= s != old;
            *n = s;
            if s {
                sum1 += p.as_dvec3();
                count1 += 1;
            }
        }
        if count1 == 0 || count1 == pts.len() {
            // Cannot happen with distinct seeds and finite points; keep the last valid split.
            break;
        }
        side.copy_from_slice(&next);
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
fn seeds(pts: &[Vec3], rng: &mut impl Rng) -> Option<[Vec3; 2]> {
    let r = pts[rng.random_range(0..pts.len())];
    let farthest = |from: Vec3| {
        pts.iter()
            .map(|&p| (p, p.distance_squared(from)))
            .fold(
                (from, 0.0f32),
                |best, c| if c.1 > best.1 { c } else { best },
            )
    };
    let (a, _) = farthest(r);
    let (b, d) = farthest(a);
    (d > 0.0 && d.is_finite()).then_some([a, b])
}

/// Fallback split (degenerate inputs only): the lexicographically smaller half of the members
/// against the rest. Both sides are non-empty, so the recursion still ends.
fn halves(pts: &[Vec3], side: &mut [bool]) {
    let mut order: Vec<usize> = (0..pts.len()).collect();
    order.sort_by(|&i, &j| {
        let (p, q) = (pts[i], pts[j]);
        p.x.total_cmp(&q.x)
            .then(p.y.total_cmp(&q.y))
            .then(p.z.total_cmp(&q.z))
            .then(i.cmp(&j))
    });
    for (rank, &j) in order.iter().enumerate() {
        side[j] = rank >= pts.len() / 2;
    }
}
