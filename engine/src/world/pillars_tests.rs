//! Tests of the seeded `pillars` generator (`super`).

use super::*;
use crate::scenario::WorldSpec;
use std::path::Path;

/// 20 x 20 m centred on the origin, 0.1 pillars / m^2, all of radius 0.2 and height 3.
const FIELD: PillarField = PillarField {
    region_min: Vec2::new(-10.0, -10.0),
    region_max: Vec2::new(10.0, 10.0),
    density: 0.1,
    radius_min: 0.2,
    radius_max: 0.2,
    height: 3.0,
    start_clearance: 1.0,
};
const START: Vec3 = Vec3::new(0.0, 0.0, 1.0);

fn draw(seed: u64, field: &PillarField, starts: &[Vec3]) -> Vec<Pillar> {
    let mut rng = RunSeed(seed).stream(stream::WORLD_GENERATOR, 0);
    generate_pillars(field, starts, &[], &mut rng)
}

#[test]
fn same_seed_same_pillars_other_seed_other_pillars() {
    let a = draw(42, &FIELD, &[START]);
    assert!(!a.is_empty());
    assert_eq!(a, draw(42, &FIELD, &[START]));
    assert_ne!(a, draw(43, &FIELD, &[START]));
    // Through the builder: the generator's stream is keyed by its obstacle index.
    let spec: WorldSpec = toml::from_str(
        r#"
        bounds = { min = [-10, -10, 0], max = [10, 10, 3] }
        [[obstacle]]
        kind = "pillars"
        name = "forest"
        region_min = [-10, -10]
        region_max = [10, 10]
        density = 0.1
        radius_min = 0.1
        radius_max = 0.3
        height = 3
        "#,
    )
    .unwrap();
    let build = |seed| {
        super::super::build_world(&spec, RunSeed(seed), &[START], &[], Path::new(".")).unwrap()
    };
    let poses = |w: &uavex_components::world::WorldGeometry| {
        w.obstacles().iter().map(|o| o.pose).collect::<Vec<_>>()
    };
    let (w1, w2, w3) = (build(7), build(7), build(8));
    assert_eq!(poses(&w1), poses(&w2));
    assert_ne!(poses(&w1), poses(&w3));
    assert_eq!(w1.obstacles()[1].name, "forest #0");
    assert_eq!(w1.obstacles()[1].source, "world.obstacle[0]");
    // Each pillar stands on the floor and reaches 3 m: a ray down onto its axis from 5 m
    // meets its top 2 m below.
    let axis = w1.obstacles()[1].pose.translation;
    assert!((axis.z - 1.5).abs() < 1e-6);
    let d = w1.cast_ray(Vec3::new(axis.x, axis.y, 5.0), -Vec3::Z, 10.0);
    assert!((d.unwrap() - 2.0).abs() < 1e-5);
}

#[test]
fn density_is_respected_within_poisson_bounds() {
    // Expected count: 0.1 x (400 - pi (1.0 + 0.2)^2) = 39.548 (the start's exclusion disc
    // reaches the clearance plus the radius from the axis). Over 400 seeds the mean has a
    // standard deviation of sqrt(39.548 / 400) = 0.314; allow 4 of them. A Poisson count
    // has variance = mean: allow the sample's dispersion 25 % either way (~3.5 sigma).
    let expected = 0.1 * (400.0 - std::f64::consts::PI * 1.2f64.powi(2));
    let counts: Vec<f64> = (0..400)
        .map(|seed| draw(seed, &FIELD, &[START]).len() as f64)
        .collect();
    let mean = counts.iter().sum::<f64>() / 400.0;
    let var = counts.iter().map(|c| (c - mean).powi(2)).sum::<f64>() / 399.0;
    assert!(
        (mean - expected).abs() < 4.0 * (expected / 400.0).sqrt(),
        "{mean}"
    );
    assert!((var / mean - 1.0).abs() < 0.25, "dispersion {}", var / mean);
    // Positions uniform: mean x and y near 0 (std of one coordinate 20 / sqrt(12) = 5.77,
    // over ~15,800 pillars 0.046: allow 0.2).
    let all: Vec<Pillar> = (0..400).flat_map(|s| draw(s, &FIELD, &[START])).collect();
    let mean_x = all.iter().map(|p| p.base.x).sum::<f32>() / all.len() as f32;
    let mean_y = all.iter().map(|p| p.base.y).sum::<f32>() / all.len() as f32;
    assert!(
        mean_x.abs() < 0.2 && mean_y.abs() < 0.2,
        "{mean_x} {mean_y}"
    );
}

#[test]
fn clearance_is_kept_from_every_start_in_3d() {
    let starts = [START, Vec3::new(5.0, 5.0, 1.5), Vec3::new(-5.0, 5.0, 4.5)];
    let field = PillarField {
        density: 0.5,
        radius_min: 0.1,
        radius_max: 0.5,
        start_clearance: 1.5,
        ..FIELD
    };
    let mut below_high_start = 0;
    for seed in 0..50 {
        for p in draw(seed, &field, &starts) {
            for s in &starts[..2] {
                assert!(s.truncate().distance(p.base) - p.radius >= 1.5 - 1e-5);
            }
            // The third start is 1.5 m above the pillar tops (z = 3): pillars right below
            // it are 1.5 m away, exactly the clearance, and may stand.
            if starts[2].truncate().distance(p.base) < p.radius {
                below_high_start += 1;
            }
        }
    }
    assert!(below_high_start > 0);
    // With a clearance covering the whole region nothing is placed.
    let none = PillarField {
        start_clearance: 30.0,
        ..FIELD
    };
    assert!(draw(1, &none, &[START]).is_empty());
}

/// The errors of a world with one pillar field (`extra` added to its table) for UAVs
/// starting at `starts`; none when it builds.
/// An explorer's start capsule (`exploration::setup::StartCapsule`) removes exactly the
/// pillars that touch it: every other pillar is drawn as without it, and none kept comes
/// within its radius (measured in closed form: the capsule's axis is level, so the nearest
/// points of axis and pillar are apart by the horizontal gap and the height above the top).
#[test]
fn a_capsule_kept_clear_removes_the_pillars_that_touch_it_and_no_other() {
    let (from, to, radius) = (Vec3::new(0.0, 0.0, 1.0), Vec3::new(2.0, 1.0, 1.0), 0.7);
    let capsule = Capsule::new(from, to, radius);
    let field = PillarField {
        density: 0.5,
        radius_min: 0.1,
        radius_max: 0.4,
        start_clearance: 0.0,
        ..FIELD
    };
    // Distance from the level segment to the pillar's solid.
    let gap = |p: &Pillar| {
        let (a, b) = (from.truncate(), to.truncate());
        let along = ((p.base - a).dot(b - a) / (b - a).length_squared()).clamp(0.0, 1.0);
        let horizontal = (p.base.distance(a + along * (b - a)) - p.radius).max(0.0);
        let vertical = (from.z - field.height).max(0.0);
        horizontal.hypot(vertical)
    };
    let mut removed = 0;
    for seed in 0..40 {
        let all = draw(seed, &field, &[]);
        let mut rng = RunSeed(seed).stream(stream::WORLD_GENERATOR, 0);
        let kept = generate_pillars(&field, &[], &[capsule], &mut rng);
        let expected: Vec<Pillar> = all
            .iter()
            .copied()
            .filter(|p| gap(p) > radius + KEPT_CLEAR_MARGIN_M + 1e-4)
            .collect();
        // Pillars within rounding of the grown capsule may go either way.
        let borderline = all
            .iter()
            .filter(|p| (gap(p) - radius - KEPT_CLEAR_MARGIN_M).abs() <= 1e-4)
            .count();
        assert!(kept.len() >= expected.len() && kept.len() <= expected.len() + borderline);
        assert!(expected.iter().all(|p| kept.contains(p)), "seed {seed}");
        assert!(kept.iter().all(|p| gap(p) >= radius), "seed {seed}");
        removed += all.len() - kept.len();
    }
    // The field is dense enough that the capsule held pillars in many draws.
    assert!(removed >= 10, "{removed}");
}

fn field_errors(extra: &str, starts: &[Vec3]) -> Vec<BuildError> {
    let spec: WorldSpec = toml::from_str(&format!(
        r#"
        bounds = {{ min = [-10, -10, 0], max = [10, 10, 3] }}
        [[obstacle]]
        kind = "pillars"
        region_min = [-2, -2]
        region_max = [2, 2]
        height = 3
        {extra}
        "#
    ))
    .unwrap();
    super::super::build_world(&spec, RunSeed(0), starts, &[], Path::new("."))
        .err()
        .unwrap_or_default()
}

#[test]
fn a_field_whose_every_pillar_would_be_removed_is_refused() {
    let field = |extra: &str| format!("density = 0.5\nradius_min = 0.1\n{extra}");
    // The region's far corners are 2.83 m from a start at its centre.
    let errors = field_errors(&field("radius_max = 0.2\nstart_clearance = 3.0"), &[START]);
    assert_eq!(errors.len(), 1, "{errors:?}");
    assert_eq!(errors[0].path, "world.obstacle[0].start_clearance");
    assert!(
        errors[0]
            .message
            .contains("every pillar of the region would be removed"),
        "{}",
        errors[0]
    );
    // A clearance that leaves the corners free for thin pillars, but not for pillars of
    // at least 0.5 m: their radius is the cause.
    let errors = field_errors(
        &field("radius_max = 0.6\nstart_clearance = 2.5").replace("0.1", "0.5"),
        &[START],
    );
    assert_eq!(errors.len(), 1, "{errors:?}");
    assert_eq!(errors[0].path, "world.obstacle[0].radius_min");
    // radius_max alone removes only some: thin pillars still stand in the corners.
    assert!(field_errors(&field("radius_max = 0.6\nstart_clearance = 2.5"), &[START]).is_empty());
    // Two starts whose clearances cover the region only together: the points farthest
    // from both, (0, -2) and (0, 2), are 2.83 m from each.
    let pair = [Vec3::new(-2.0, 0.0, 1.0), Vec3::new(2.0, 0.0, 1.0)];
    let errors = field_errors(&field("radius_max = 0.1\nstart_clearance = 2.9"), &pair);
    assert_eq!(errors.len(), 1, "{errors:?}");
    assert_eq!(errors[0].path, "world.obstacle[0].start_clearance");
    // ... and with a gap between them there (each clears 1.9 m around it).
    assert!(field_errors(&field("radius_max = 0.1\nstart_clearance = 1.8"), &pair).is_empty());
    // A start high above the pillars is farther from them than its horizontal distance.
    let high = [Vec3::new(0.0, 0.0, 5.5)];
    assert!(field_errors(&field("radius_max = 0.1\nstart_clearance = 3.0"), &high).is_empty());
    // No pillars asked for (density 0, e.g. a study's baseline): nothing to remove.
    assert!(
        field_errors(
            "density = 0.0\nradius_min = 0.1\nradius_max = 0.2\nstart_clearance = 30.0",
            &[START]
        )
        .is_empty()
    );
}

#[test]
fn absurd_densities_are_refused() {
    let spec: WorldSpec = toml::from_str(
        r#"
        bounds = { min = [-10, -10, 0], max = [10, 10, 3] }
        [[obstacle]]
        kind = "pillars"
        region_min = [-1000, -1000]
        region_max = [1000, 1000]
        density = 1.0
        radius_min = 0.1
        radius_max = 0.3
        height = 3
        "#,
    )
    .unwrap();
    let errors =
        super::super::build_world(&spec, RunSeed(0), &[START], &[], Path::new(".")).unwrap_err();
    assert_eq!(errors[0].path, "world.obstacle[0].density");
    assert!(errors[0].message.contains("4000000"), "{}", errors[0]);
}
