//! Divisive 2-means (eaae.md step 2): the stop rule, the partition, determinism.

use super::super::cluster::{LLOYD_ITERATIONS, centroid_and_radius};
use super::super::*;
use glam::Vec3;
use proptest::prelude::*;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

/// Checks what every clustering must satisfy; returns the clusters.
fn check(points: &[Vec3], bound: f32, seed: u64) -> Vec<Cluster> {
    let clusters = divisive_two_means(points, bound, &mut ChaCha8Rng::seed_from_u64(seed));
    let mut seen = vec![false; points.len()];
    for c in &clusters {
        assert!(!c.members.is_empty());
        // The stop rule.
        assert!(c.r_max <= bound, "r_max {} > bound {bound}", c.r_max);
        assert!(
            c.members.windows(2).all(|w| w[0] < w[1]),
            "members ascending"
        );
        let (centroid, r_max) = centroid_and_radius(points, &c.members);
        assert_eq!((c.centroid, c.r_max), (centroid, r_max));
        for &m in &c.members {
            assert!(points[m].distance(c.centroid) <= c.r_max);
            assert!(!seen[m], "point {m} in two clusters");
            seen[m] = true;
        }
    }
    assert!(seen.iter().all(|&s| s), "every point in a cluster");
    clusters
}

#[test]
fn two_separated_pairs_split_once() {
    // All four: centroid (5.5, 0, 0), r_max 5.5 > 1, so one split; each pair has r_max 0.5.
    let points = [
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(10.0, 0.0, 0.0),
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::new(11.0, 0.0, 0.0),
    ];
    for seed in 0..20 {
        let mut clusters = check(&points, 1.0, seed);
        clusters.sort_by(|a, b| a.centroid.x.total_cmp(&b.centroid.x));
        assert_eq!(clusters.len(), 2, "seed {seed}");
        assert_eq!(clusters[0].members, vec![0, 2]);
        assert_eq!(clusters[0].centroid, Vec3::new(0.5, 0.0, 0.0));
        assert_eq!(clusters[0].r_max, 0.5);
        assert_eq!(clusters[1].members, vec![1, 3]);
        assert_eq!(clusters[1].centroid, Vec3::new(10.5, 0.0, 0.0));
    }
}

#[test]
fn a_cluster_within_the_bound_is_not_split() {
    // Square of side 2 m: centroid (1, 1, 0), r_max sqrt(2) = 1.414 <= 2.73.
    let points = [
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(2.0, 0.0, 0.0),
        Vec3::new(0.0, 2.0, 0.0),
        Vec3::new(2.0, 2.0, 0.0),
    ];
    let clusters = check(&points, 2.73, 1);
    assert_eq!(clusters.len(), 1);
    assert_eq!(clusters[0].centroid, Vec3::new(1.0, 1.0, 0.0));
    assert!((clusters[0].r_max - 2f32.sqrt()).abs() < 1e-6);
    // A bound just below sqrt(2) forces a split.
    assert!(check(&points, 1.41, 1).len() >= 2);
}

#[test]
fn degenerate_inputs_end() {
    assert!(divisive_two_means(&[], 1.0, &mut ChaCha8Rng::seed_from_u64(0)).is_empty());
    // Coincident points stay one cluster even with a zero bound.
    let same = [Vec3::ONE; 5];
    let c = check(&same, 0.0, 3);
    assert_eq!((c.len(), c[0].r_max), (1, 0.0));
    // A NaN bound is taken as 0: each distinct point alone.
    let points = [Vec3::ZERO, Vec3::X, Vec3::X, Vec3::Y];
    let c = divisive_two_means(&points, f32::NAN, &mut ChaCha8Rng::seed_from_u64(3));
    let mut sizes: Vec<usize> = c.iter().map(|c| c.members.len()).collect();
    sizes.sort_unstable();
    assert_eq!(sizes, vec![1, 1, 2]);
    // A non-finite point does not hang the recursion.
    let points = [Vec3::ZERO, Vec3::splat(f32::INFINITY), Vec3::X];
    let c = divisive_two_means(&points, 1.0, &mut ChaCha8Rng::seed_from_u64(3));
    assert_eq!(c.iter().map(|c| c.members.len()).sum::<usize>(), 3);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(96))]

    #[test]
    fn every_cluster_satisfies_the_r_max_rule(
        raw in prop::collection::vec((-10f32..10.0, -10f32..10.0, -2f32..2.0), 1..400),
        bound in 0.05f32..6.0,
        seed in any::<u64>(),
    ) {
        let points: Vec<Vec3> = raw.iter().map(|&(x, y, z)| Vec3::new(x, y, z)).collect();
        let first = check(&points, bound, seed);
        // Deterministic for a seed.
        let again = divisive_two_means(&points, bound, &mut ChaCha8Rng::seed_from_u64(seed));
        prop_assert_eq!(first, again);
    }

    #[test]
    fn voxel_centres_satisfy_the_r_max_rule(
        keys in prop::collection::vec((-60i32..60, -60i32..60, 0i32..25), 1..600),
        seed in any::<u64>(),
    ) {
        // Frontier-like input: voxel centres at 0.1 m, many coincident, the EAAE bound.
        let points: Vec<Vec3> = keys
            .iter()
            .map(|&(x, y, z)| (Vec3::new(x as f32, y as f32, z as f32) + 0.5) * 0.1)
            .collect();
        check(&points, 2.731_512, seed);
    }
}

/// The divisive 2-means of eaae.md step 2 written plainly: points as `Vec3`s, every sum
/// formed from scratch in order, the same seeding and stop rules.
fn plain_two_means(points: &[Vec3], bound: f32, rng: &mut impl rand::Rng) -> Vec<Cluster> {
    let sum = |pts: &[Vec3], keep: &dyn Fn(usize) -> bool| {
        (0..pts.len())
            .filter(|&j| keep(j))
            .fold(glam::DVec3::ZERO, |s, j| s + pts[j].as_dvec3())
    };
    let farthest = |pts: &[Vec3], from: Vec3| {
        pts.iter().fold((from, 0.0f32), |best, &p| {
            let d = p.distance_squared(from);
            if d > best.1 { (p, d) } else { best }
        })
    };
    let mut out = Vec::new();
    let mut stack = vec![(0..points.len()).collect::<Vec<usize>>()];
    while let Some(members) = stack.pop() {
        let pts: Vec<Vec3> = members.iter().map(|&m| points[m]).collect();
        let centroid = (sum(&pts, &|_| true) / pts.len() as f64).as_vec3();
        let r2 = pts
            .iter()
            .map(|p| p.distance_squared(centroid))
            .fold(0.0f32, f32::max);
        if members.len() == 1 || r2.sqrt() <= bound {
            out.push(Cluster {
                centroid,
                members,
                r_max: r2.sqrt(),
            });
            continue;
        }
        let r = pts[rng.random_range(0..pts.len())];
        let (a, _) = farthest(&pts, r);
        let (b, d) = farthest(&pts, a);
        assert!(d > 0.0, "these tests' points are distinct");
        let (mut centres, mut side) = ([a, b], vec![false; pts.len()]);
        for iteration in 0..LLOYD_ITERATIONS {
            let w = centres[1] - centres[0];
            let t = 0.5 * (centres[1].length_squared() - centres[0].length_squared());
            let next: Vec<bool> = pts.iter().map(|p| p.dot(w) > t).collect();
            let count1 = next.iter().filter(|&&s| s).count();
            if count1 == 0 || count1 == pts.len() {
                break;
            }
            let unchanged = next == side;
            side = next;
            if iteration > 0 && unchanged {
                break;
            }
            let sum1 = sum(&pts, &|j| side[j]);
            let count0 = pts.len() - count1;
            centres = [
                ((sum(&pts, &|_| true) - sum1) / count0 as f64).as_vec3(),
                (sum1 / count1 as f64).as_vec3(),
            ];
        }
        let half = |s: bool| {
            (0..pts.len())
                .filter(|&j| side[j] == s)
                .map(|j| members[j])
                .collect()
        };
        stack.push(half(true));
        stack.push(half(false));
    }
    out
}

/// The clustering keeps its sums in partial sums per lane and updates a side's sum by the
/// points that changed side (`cluster::Coordinates`): the same clusters, bit for bit, as the
/// plain algorithm's on frontiers of voxel centres (whose sums are exact in any order).
#[test]
fn clusters_equal_the_plain_algorithm_to_the_bit() {
    use rand::Rng;
    for case in 0..40u64 {
        let mut rng = ChaCha8Rng::seed_from_u64(case);
        let n = rng.random_range(2..3000);
        let mut keys = std::collections::BTreeSet::new();
        while keys.len() < n {
            keys.insert((
                rng.random_range(-100..100),
                rng.random_range(-100..100),
                rng.random_range(0..30),
            ));
        }
        let centre = |k: i32| (k as f32 + 0.5) * 0.1;
        let points: Vec<Vec3> = keys
            .iter()
            .map(|&(x, y, z)| Vec3::new(centre(x), centre(y), centre(z)))
            .collect();
        let bound = 0.3 + case as f32 * 0.07;
        let rng = |case| ChaCha8Rng::seed_from_u64(case + 1000);
        let fast = divisive_two_means(&points, bound, &mut rng(case));
        let plain = plain_two_means(&points, bound, &mut rng(case));
        assert_eq!(fast.len(), plain.len(), "case {case}");
        for (f, p) in fast.iter().zip(&plain) {
            assert_eq!(f.members, p.members, "case {case}");
            assert_eq!(
                f.centroid.to_array().map(f32::to_bits),
                p.centroid.to_array().map(f32::to_bits)
            );
            assert_eq!(f.r_max.to_bits(), p.r_max.to_bits(), "case {case}");
        }
    }
}
