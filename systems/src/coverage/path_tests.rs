//! Coverage tests of the planner: every point of the polygon lies in the footprint of a shot.

use super::camera::{Camera, Overlaps, SurveyGeometry};
use super::path::{CoveragePath, MAX_SHOTS, PathError, ScanDirection, plan_path};
use super::polygon::Polygon;
use glam::DVec2;
use proptest::prelude::*;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::f64::consts::{PI, TAU};

/// 90 deg camera, 4:3 image, at 10 m: L_x = 20 m, L_y = 15 m; d_x = 16 m, d_y = 10.5 m.
fn survey() -> SurveyGeometry {
    let camera = Camera {
        angle_of_view: PI / 2.0,
        width_px: 4000,
        height_px: 3000,
        shot_period_s: 1.0,
    };
    camera.survey(10.0, Overlaps { x: 0.2, y: 0.3 }).unwrap()
}

fn polygon(points: &[(f64, f64)]) -> Polygon {
    Polygon::new(points.iter().map(|&(x, y)| DVec2::new(x, y)).collect()).unwrap()
}

fn in_footprint(p: DVec2, shot: DVec2, along: DVec2, survey: &SurveyGeometry) -> bool {
    let d = p - shot;
    let tol = 1e-6;
    d.dot(along).abs() <= survey.footprint.l_y / 2.0 + tol
        && d.dot(along.perp()).abs() <= survey.footprint.l_x / 2.0 + tol
}

/// Points of the polygon: a grid of `step` inside, points every `step` along each edge, and the
/// vertices.
fn sample(polygon: &Polygon, step: f64) -> Vec<DVec2> {
    let v = polygon.vertices();
    let (lo, hi) = v
        .iter()
        .fold((v[0], v[0]), |(lo, hi), &p| (lo.min(p), hi.max(p)));
    let mut points = v.to_vec();
    let n = v.len();
    for i in 0..n {
        let (a, b) = (v[i], v[(i + 1) % n]);
        let k = (a.distance(b) / step).ceil() as usize;
        points.extend((1..k).map(|j| a.lerp(b, j as f64 / k as f64)));
    }
    let (nx, ny) = (
        ((hi.x - lo.x) / step).ceil() as usize,
        ((hi.y - lo.y) / step).ceil() as usize,
    );
    for ix in 0..=nx {
        for iy in 0..=ny {
            let p = lo + DVec2::new(ix as f64, iy as f64) * step;
            if polygon.contains(p, 0.0) {
                points.push(p);
            }
        }
    }
    points
}

/// Asserts full coverage and returns the number of uncovered points (always 0).
fn assert_covered(polygon: &Polygon, path: &CoveragePath, survey: &SurveyGeometry, step: f64) {
    let shots: Vec<(DVec2, DVec2)> = path.shots().collect();
    assert!(!shots.is_empty());
    let missed: Vec<DVec2> = sample(polygon, step)
        .into_iter()
        .filter(|&p| {
            !shots
                .iter()
                .any(|&(s, along)| in_footprint(p, s, along, survey))
        })
        .collect();
    assert!(
        missed.is_empty(),
        "{} of the sampled points are in no footprint, e.g. {:?}",
        missed.len(),
        &missed[..missed.len().min(5)]
    );
}

fn assert_closed_tour(polygon: &Polygon, start: usize, path: &CoveragePath) {
    let start = polygon.vertices()[start];
    assert_eq!(path.waypoints.first().unwrap().position, start);
    assert_eq!(path.waypoints.last().unwrap().position, start);
    for w in path.waypoints.windows(2) {
        assert!(w[0].position.distance(w[1].position) > 0.0);
    }
}

fn rectangle() -> Polygon {
    polygon(&[(0.0, 0.0), (200.0, 0.0), (200.0, 70.0), (0.0, 70.0)])
}

fn l_shape() -> Polygon {
    polygon(&[
        (0.0, 0.0),
        (150.0, 0.0),
        (150.0, 50.0),
        (60.0, 50.0),
        (60.0, 130.0),
        (0.0, 130.0),
    ])
}

/// A rectangle with a V notch cut down into its top edge.
fn notched() -> Polygon {
    polygon(&[
        (0.0, 0.0),
        (180.0, 0.0),
        (180.0, 100.0),
        (110.0, 100.0),
        (90.0, 30.0),
        (70.0, 100.0),
        (0.0, 100.0),
    ])
}

/// A 50-vertex concave polygon: a wobbly star, radius 120 m +- 45 m.
fn fifty_vertices() -> Polygon {
    let points: Vec<DVec2> = (0..50)
        .map(|i| {
            let theta = TAU * i as f64 / 50.0;
            let r = 120.0 + 30.0 * (3.0 * theta).sin() + 15.0 * (7.0 * theta + 1.0).cos();
            let r = if i % 2 == 0 { r } else { r * 0.8 };
            DVec2::new(r * theta.cos(), r * theta.sin())
        })
        .collect();
    Polygon::new(points).unwrap()
}

#[test]
fn rectangle_is_covered_with_an_even_number_of_stripes_along_its_long_side() {
    let s = survey();
    let field = rectangle();
    let path = plan_path(&field, 0, &s, ScanDirection::LongestEdge).unwrap();
    assert_covered(&field, &path, &s, 1.0);
    assert_closed_tour(&field, 0, &path);
    // n_s = ceil(70 / 16) = 5, made even: 6 stripes, Delta_x = (70 - 20) / 5 = 10 m, at
    // y = 10, 20, ..., 60, each 200 m long: m = ceil(200 / 10.5) = 20 shots.
    assert_eq!(path.stripes, 6);
    assert_eq!(path.areas, 1);
    let stripe_shots: Vec<DVec2> = path
        .shots()
        .map(|(p, _)| p)
        .filter(|p| (p.y - 10.0).abs() < 1e-9)
        .collect();
    assert_eq!(stripe_shots.len(), 20);
    let xs: Vec<f64> = stripe_shots.iter().map(|p| p.x).collect();
    let delta = (200.0 - 15.0) / 19.0;
    for (i, x) in xs.iter().enumerate() {
        assert!((x - (7.5 + delta * i as f64)).abs() < 1e-9, "{xs:?}");
    }
    for k in 1..=6 {
        let level = 10.0 * k as f64;
        assert_eq!(
            path.shots()
                .filter(|(p, _)| (p.y - level).abs() < 1e-9)
                .count(),
            20
        );
    }
    // Even stripes: the sweep ends on the side it started, at (7.5, 60), and part 3 returns down
    // the left edge (7 shots 10 m inside it). Legs: climb-out to the first shot, 6 stripes, 5
    // crossings, to the first return shot, the return, and down to the start: 15.
    assert_eq!(path.legs().len(), 15);
    assert_eq!(path.turn_angles().len(), 14);
    assert_eq!(
        path.shots()
            .filter(|(p, _)| (p.x - 10.0).abs() < 1e-9)
            .count(),
        7
    );
}

#[test]
fn l_shape_is_covered() {
    let s = survey();
    let field = l_shape();
    for start in 0..field.len() {
        let path = plan_path(&field, start, &s, ScanDirection::LongestEdge).unwrap();
        assert_covered(&field, &path, &s, 1.0);
        assert_closed_tour(&field, start, &path);
    }
}

#[test]
fn notched_polygon_recurses_into_both_sides_of_the_notch() {
    let s = survey();
    let field = notched();
    let path = plan_path(&field, 0, &s, ScanDirection::LongestEdge).unwrap();
    assert_covered(&field, &path, &s, 1.0);
    assert_closed_tour(&field, 0, &path);
    // The base cell ends at the notch's tip; the two prongs are cut off and covered on their own.
    assert_eq!(path.areas, 3);
}

#[test]
fn fifty_vertex_polygon_is_covered() {
    let s = survey();
    let field = fifty_vertices();
    for start in [0, 17, 33] {
        let path = plan_path(&field, start, &s, ScanDirection::LongestEdge).unwrap();
        assert_covered(&field, &path, &s, 1.5);
        assert_closed_tour(&field, start, &path);
        assert!(path.areas > 1);
    }
}

/// The paper scans parallel to the longest edge because that needs fewer turns. It holds on the
/// rectangle (14 turns against 30), the L-shape (22 against 22) and the 50-vertex polygon (280
/// against 445). It is a heuristic, not a theorem: on `notched()` the notch runs across the
/// stripes, each prong needs its own back-and-forth, and sweeping across the longest edge, where
/// the notch splits nothing, needs fewer turns (42 against 26).
#[test]
fn longest_edge_needs_no_more_turns_than_across_it() {
    let s = survey();
    for field in [rectangle(), l_shape(), fifty_vertices()] {
        let along = plan_path(&field, 0, &s, ScanDirection::LongestEdge).unwrap();
        let across = plan_path(&field, 0, &s, ScanDirection::AcrossLongestEdge).unwrap();
        assert_covered(&field, &across, &s, 1.5);
        assert!(
            along.turn_angles().len() <= across.turn_angles().len(),
            "{} turns along the longest edge, {} across it",
            along.turn_angles().len(),
            across.turn_angles().len()
        );
    }
    let field = rectangle();
    let along = plan_path(&field, 0, &s, ScanDirection::LongestEdge).unwrap();
    let across = plan_path(&field, 0, &s, ScanDirection::AcrossLongestEdge).unwrap();
    // Across: n_s = ceil(200 / 16) = 13, made even: 14 stripes.
    assert_eq!((along.stripes, across.stripes), (6, 14));
    assert_eq!(
        (along.turn_angles().len(), across.turn_angles().len()),
        (14, 30)
    );
}

#[test]
fn field_smaller_than_one_footprint_takes_one_shot() {
    let s = survey();
    let field = polygon(&[(0.0, 0.0), (10.0, 0.0), (10.0, 8.0), (0.0, 8.0)]);
    let path = plan_path(&field, 2, &s, ScanDirection::LongestEdge).unwrap();
    assert_eq!(path.shots().count(), 1);
    assert_covered(&field, &path, &s, 0.5);
    assert!(plan_path(&field, 4, &s, ScanDirection::LongestEdge).is_err());
}

/// A star-shaped polygon: sorted random angles, random radii.
fn star(angles: &[f64], radii: &[f64]) -> Option<Polygon> {
    let mut a: Vec<f64> = angles.to_vec();
    a.sort_by(f64::total_cmp);
    a.dedup_by(|x, y| (*x - *y).abs() < 1e-3);
    let points = a
        .iter()
        .zip(radii)
        .map(|(&t, &r)| DVec2::new(r * t.cos(), r * t.sin()))
        .collect();
    Polygon::new(points).ok()
}

/// Random simple polygon: random points joined in random order, then crossings undone by 2-opt
/// moves (each strictly shortens the tour, so it ends).
fn two_opt_polygon(seed: u64, n: usize, size: f64) -> Option<Polygon> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut p: Vec<DVec2> = (0..n)
        .map(|_| DVec2::new(rng.random_range(0.0..size), rng.random_range(0.0..size)))
        .collect();
    for _ in 0..10_000 {
        let mut changed = false;
        for i in 0..n {
            for j in (i + 2)..n {
                if i == 0 && j == n - 1 {
                    continue;
                }
                let (a, b, c, d) = (p[i], p[i + 1], p[j], p[(j + 1) % n]);
                if a.distance(b) + c.distance(d) > a.distance(c) + b.distance(d) + 1e-9
                    && crosses(a, b, c, d)
                {
                    p[i + 1..=j].reverse();
                    changed = true;
                }
            }
        }
        if !changed {
            break;
        }
    }
    Polygon::new(p).ok()
}

fn crosses(a: DVec2, b: DVec2, c: DVec2, d: DVec2) -> bool {
    let o = |p: DVec2, q: DVec2, r: DVec2| (q - p).perp_dot(r - p);
    o(a, b, c) * o(a, b, d) < 0.0 && o(c, d, a) * o(c, d, b) < 0.0
}

/// 64 random polygons of each kind per run; `PROPTEST_CASES` asks for more.
fn cases() -> u32 {
    std::env::var("PROPTEST_CASES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(64)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(cases()))]

    #[test]
    fn random_star_polygons_are_covered(
        angles in prop::collection::vec(0.0..TAU, 5..24),
        radii in prop::collection::vec(20.0..160.0f64, 24),
        start in 0usize..5,
    ) {
        if let Some(field) = star(&angles, &radii) {
            let s = survey();
            let path = plan_path(&field, start % field.len(), &s, ScanDirection::LongestEdge).unwrap();
            assert_covered(&field, &path, &s, 2.0);
            assert_closed_tour(&field, start % field.len(), &path);
        }
    }

    #[test]
    fn random_simple_polygons_are_covered(seed in any::<u64>(), n in 4usize..20, start in 0usize..4) {
        if let Some(field) = two_opt_polygon(seed, n, 250.0) {
            let s = survey();
            for direction in [ScanDirection::LongestEdge, ScanDirection::AcrossLongestEdge] {
                let path = plan_path(&field, start % field.len(), &s, direction).unwrap();
                assert_covered(&field, &path, &s, 2.0);
                assert_closed_tour(&field, start % field.len(), &path);
            }
        }
    }
}

fn rectangle_160_by_100() -> Polygon {
    polygon(&[(0.0, 0.0), (160.0, 0.0), (160.0, 100.0), (0.0, 100.0)])
}

fn too_many_shots(survey: &SurveyGeometry, area: &Polygon) -> bool {
    matches!(
        plan_path(area, 0, survey, ScanDirection::LongestEdge),
        Err(PathError::TooManyShots {
            limit: MAX_SHOTS,
            ..
        })
    )
}

#[test]
fn overlap_next_to_one_is_refused_before_allocating() {
    // d_y = 15 m * 1e-9: 1e10 photos a stripe (64 GB of offsets before the limit).
    let survey = Camera {
        angle_of_view: PI / 2.0,
        width_px: 4000,
        height_px: 3000,
        shot_period_s: 1.0,
    }
    .survey(
        10.0,
        Overlaps {
            x: 0.2,
            y: 0.999999999,
        },
    )
    .unwrap();
    assert!(too_many_shots(&survey, &rectangle_160_by_100()));
}

#[test]
fn a_sliver_image_is_refused_before_allocating() {
    // 4294967295 x 1 px: L_y = L_x / 4.3e9, photos 3.7e-9 m apart.
    let survey = Camera {
        angle_of_view: 1.2,
        width_px: u32::MAX,
        height_px: 1,
        shot_period_s: 1.0,
    }
    .survey(120.0, Overlaps { x: 0.2, y: 0.3 })
    .unwrap();
    let err = plan_path(
        &rectangle_160_by_100(),
        0,
        &survey,
        ScanDirection::LongestEdge,
    )
    .unwrap_err();
    assert!(err.to_string().contains("the planner's limit"), "{err}");
}

#[test]
fn a_huge_area_is_refused_not_a_panic() {
    // 10^7 m square at 16 m between stripes and 10.5 m between photos: 6e11 photos. The stripe
    // count once overflowed into an empty stripe list and an index panic.
    let side = 1e7;
    let area = polygon(&[(0.0, 0.0), (side, 0.0), (side, side), (0.0, side)]);
    assert!(too_many_shots(&survey(), &area));
    // Just inside the limit is planned.
    let area = polygon(&[(0.0, 0.0), (1000.0, 0.0), (1000.0, 1000.0), (0.0, 1000.0)]);
    let path = plan_path(&area, 0, &survey(), ScanDirection::LongestEdge).unwrap();
    assert!(path.shots().count() < MAX_SHOTS);
}

#[test]
fn an_area_thinner_than_the_tolerance_is_an_error_or_one_shot() {
    // 100 m long and 1e-9 m wide: no sweep, and more than one footprint long.
    let sliver = polygon(&[(0.0, 0.0), (100.0, 0.0), (100.0, 1e-9), (0.0, 1e-9)]);
    let err = plan_path(&sliver, 0, &survey(), ScanDirection::LongestEdge).unwrap_err();
    assert!(matches!(err, PathError::TooThin { .. }), "{err}");
    // A speck inside one footprint: one photo on it, not none.
    let speck = polygon(&[(5.0, 5.0), (5.0 + 1e-9, 5.0), (5.0, 5.0 + 1e-9)]);
    let path = plan_path(&speck, 0, &survey(), ScanDirection::LongestEdge).unwrap();
    let shots: Vec<_> = path.shots().collect();
    assert_eq!(shots.len(), 1);
    assert!(shots[0].0.distance(DVec2::new(5.0, 5.0)) < 1e-6);
}
