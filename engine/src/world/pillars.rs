//! The seeded `pillars` generator: random upright pillars (tree trunks) on a rectangle of the
//! floor.
//!
//! Model: a homogeneous Poisson point process of intensity `density` (pillars per square metre)
//! on the region: the count is Poisson(density x area), positions uniform, radii uniform in
//! [radius_min, radius_max]. This is the usual model of a random forest, and it makes `density`
//! the true expected number per square metre whatever the area. Pillars may overlap (their union
//! is the obstacle). Pillars closer than `start_clearance` to a UAV start are then removed, which
//! leaves the process unchanged outside those discs, and so are pillars that touch a space a UAV
//! needs clear at its start whatever the field asks (an explorer's start capsule,
//! `exploration::setup::StartCapsule`): without that, every seed that drew a trunk into it would
//! be refused when the run is built, and a sweep over seeds would lose those runs.
//!
//! Randomness: `RunSeed::stream(stream::WORLD_GENERATOR, i)` for the generator at
//! `world.obstacle[i]`; the count is drawn first, then per pillar x, y and radius, so one
//! generator's pillars depend on the seed and its own parameters only.

use super::primitives::{upright_cylinder, upright_pose};
use super::{BuildError, display_name, require_finite, require_positive};
use crate::scenario::ObstacleSpec;
use glam::{DVec2, Vec2, Vec3};
use parry3d::math::Pose;
use parry3d::query::intersection_test;
use parry3d::shape::{Capsule, Cylinder};
use rand::Rng;
use rand_distr::{Distribution, Poisson};
use uavex_components::sim::{RunSeed, stream};
use uavex_components::world::Obstacle;

/// More pillars than this from one generator is refused as a configuration mistake (a density
/// meant per hectare, say); a million cylinders would make world building alone take seconds.
pub const MAX_EXPECTED_PILLARS: f64 = 1e6;

/// The parameters of one generator, checked.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PillarField {
    pub region_min: Vec2,
    pub region_max: Vec2,
    pub density: f64,
    pub radius_min: f32,
    pub radius_max: f32,
    pub height: f32,
    pub start_clearance: f32,
}

/// One generated pillar: standing on (x, y, 0).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pillar {
    pub base: Vec2,
    pub radius: f32,
}

/// How much a space kept clear ([`generate_pillars`]'s `kept_clear`) is grown before pillars are
/// tested against it: the run's own check of that space (balls along the capsule against the
/// exact cylinder) then passes whatever the rounding of the two tests.
pub const KEPT_CLEAR_MARGIN_M: f32 = 1e-3;

/// Draws the pillars of `field` from `rng`, without those closer than `start_clearance` to a
/// start (distance from the start to the pillar's solid, in 3D) and those that touch a capsule
/// of `kept_clear` (grown by [`KEPT_CLEAR_MARGIN_M`]).
/// A region or radius range that is empty (or NaN) gives no pillars. The draws do not depend on
/// what is removed: a pillar kept is the same whatever the starts and capsules.
pub fn generate_pillars(
    field: &PillarField,
    starts: &[Vec3],
    kept_clear: &[Capsule],
    rng: &mut impl Rng,
) -> Vec<Pillar> {
    let drawable = field.region_min.x < field.region_max.x
        && field.region_min.y < field.region_max.y
        && field.radius_min <= field.radius_max;
    if !drawable {
        return Vec::new();
    }
    let extent = field.region_max - field.region_min;
    let mean = field.density * f64::from(extent.x) * f64::from(extent.y);
    let count = Poisson::new(mean).map_or(0, |p| p.sample(rng) as u64);
    let mut pillars = Vec::with_capacity(count as usize);
    for _ in 0..count {
        let base = Vec2::new(
            rng.random_range(field.region_min.x..field.region_max.x),
            rng.random_range(field.region_min.y..field.region_max.y),
        );
        let radius = rng.random_range(field.radius_min..=field.radius_max);
        let pillar = Pillar { base, radius };
        let clear_of_starts = starts
            .iter()
            .all(|s| distance_to_pillar(*s, &pillar, field.height) >= field.start_clearance);
        if clear_of_starts && !kept_clear.iter().any(|c| touches(&pillar, field.height, c)) {
            pillars.push(pillar);
        }
    }
    pillars
}

/// Whether `pillar` (of `height`) touches `capsule` grown by [`KEPT_CLEAR_MARGIN_M`].
fn touches(pillar: &Pillar, height: f32, capsule: &Capsule) -> bool {
    let grown = Capsule {
        radius: capsule.radius + KEPT_CLEAR_MARGIN_M,
        ..*capsule
    };
    intersection_test(
        &upright_pose(pillar.base.extend(0.0), height),
        &Cylinder::new(0.5 * height, pillar.radius),
        &Pose::IDENTITY,
        &grown,
    )
    .is_ok_and(|hit| hit.intersecting)
}

/// Distance from `point` to the solid cylinder of `pillar` (0 inside).
fn distance_to_pillar(point: Vec3, pillar: &Pillar, height: f32) -> f32 {
    let radial = (point.truncate().distance(pillar.base) - pillar.radius).max(0.0);
    let vertical = (point.z - height).max(-point.z).max(0.0);
    radial.hypot(vertical)
}

/// Most starts [`room_for_pillars`] examines exactly (it tries O(n^2) points against n discs);
/// with more UAVs near a field it assumes there is room.
const MAX_STARTS_EXAMINED: usize = 256;

/// Whether a pillar of `radius` can stand somewhere in `field`'s region at least
/// `start_clearance` from every start, i.e. survive [`generate_pillars`]'s removal.
///
/// Seen from above, a start removes exactly the bases within `radius + sqrt(c^2 - v^2)` of it
/// (`c` the clearance, `v` the start's height above the pillar tops or below their feet; none
/// when `v >= c`), an open disc. What is left of the region is closed, and if not empty its
/// lowest-x, then lowest-y point is a corner of the region, a crossing of a disc's rim with an
/// edge of the region, or a crossing of two rims: those points are tried. A point left on a
/// rim by rounding counts as free, so only a region certainly covered is reported as such.
fn room_for_pillars(field: &PillarField, radius: f32, starts: &[Vec3]) -> bool {
    let (lo, hi) = (field.region_min.as_dvec2(), field.region_max.as_dvec2());
    let clearance = f64::from(field.start_clearance);
    let height = f64::from(field.height);
    let discs: Vec<(DVec2, f64)> = starts
        .iter()
        .filter_map(|start| {
            let start = start.as_dvec3();
            let v = (start.z - height).max(-start.z).max(0.0);
            let reach = f64::from(radius) + (clearance * clearance - v * v).max(0.0).sqrt();
            let centre = start.truncate();
            // Only discs that reach into the region matter.
            let nearest = centre.clamp(lo, hi);
            (v < clearance && nearest.distance(centre) < reach).then_some((centre, reach))
        })
        .collect();
    if discs.len() > MAX_STARTS_EXAMINED {
        return true;
    }
    let tolerance = 1e-9 * (hi - lo).max_element().max(clearance);
    let free = |p: DVec2| {
        p.cmpge(lo - tolerance).all()
            && p.cmple(hi + tolerance).all()
            && discs
                .iter()
                .all(|&(centre, reach)| p.distance(centre) >= reach - tolerance)
    };
    let corners = [lo, DVec2::new(hi.x, lo.y), hi, DVec2::new(lo.x, hi.y)];
    if corners.into_iter().any(free) {
        return true;
    }
    for (i, &(a, ra)) in discs.iter().enumerate() {
        for x in [lo.x, hi.x] {
            let dy = (ra * ra - (x - a.x).powi(2)).max(0.0).sqrt();
            if [a.y - dy, a.y + dy]
                .into_iter()
                .any(|y| free(DVec2::new(x, y)))
            {
                return true;
            }
        }
        for y in [lo.y, hi.y] {
            let dx = (ra * ra - (y - a.y).powi(2)).max(0.0).sqrt();
            if [a.x - dx, a.x + dx]
                .into_iter()
                .any(|x| free(DVec2::new(x, y)))
            {
                return true;
            }
        }
        for &(b, rb) in &discs[i + 1..] {
            if rim_crossings(a, ra, b, rb).into_iter().flatten().any(free) {
                return true;
            }
        }
    }
    false
}

/// Where the circles of radius `ra` about `a` and `rb` about `b` cross (none when they do not
/// meet or share a centre).
fn rim_crossings(a: DVec2, ra: f64, b: DVec2, rb: f64) -> [Option<DVec2>; 2] {
    let d = a.distance(b);
    if d == 0.0 || d > ra + rb || d < (ra - rb).abs() {
        return [None, None];
    }
    let along = (d * d + ra * ra - rb * rb) / (2.0 * d);
    let across = (ra * ra - along * along).max(0.0).sqrt();
    let u = (b - a) / d;
    let mid = a + u * along;
    let perp = u.perp() * across;
    [Some(mid + perp), Some(mid - perp)]
}

/// The error for a field [`room_for_pillars`] finds no room in, at its cause: the clearance
/// when it alone covers the region (no pillar, however thin, could stand), else the smallest
/// radius (thin pillars could, but the field draws none thinner than `radius_min`; its
/// `radius_max` removes only some, as radii are drawn down to `radius_min`).
fn cleared_field(field: &PillarField, field_path: &str, starts: &[Vec3]) -> BuildError {
    let region = format!(
        "[{}, {}] to [{}, {}]",
        field.region_min.x, field.region_min.y, field.region_max.x, field.region_max.y
    );
    if room_for_pillars(field, 0.0, starts) {
        BuildError::new(
            format!("{field_path}.radius_min"),
            format!(
                "must leave room for pillars: no pillar of radius {} m or more fits anywhere in \
                 the region {region} at least start_clearance ({} m) from the UAV starts, so \
                 every pillar of the region would be removed (for no pillars, set density = 0)",
                field.radius_min, field.start_clearance
            ),
        )
    } else {
        BuildError::new(
            format!("{field_path}.start_clearance"),
            format!(
                "must leave room for pillars: {} m around the UAV starts covers the whole region \
                 {region}, so every pillar of the region would be removed (for no pillars, set \
                 density = 0)",
                field.start_clearance
            ),
        )
    }
}

/// The pillars of the generator at `world.obstacle[index]`, as obstacles named `"{name} #{k}"`,
/// kept clear of the `starts` and the capsules `kept_clear` ([`generate_pillars`]).
pub(super) fn build(
    spec: &ObstacleSpec,
    index: usize,
    field_path: &str,
    seed: RunSeed,
    starts: &[Vec3],
    kept_clear: &[Capsule],
) -> Result<Vec<Obstacle>, Vec<BuildError>> {
    let ObstacleSpec::Pillars {
        name,
        region_min,
        region_max,
        density,
        radius_min,
        radius_max,
        height,
        start_clearance,
    } = spec
    else {
        return Err(vec![BuildError::new(
            field_path,
            "internal: not a pillars generator",
        )]);
    };
    let mut errors = Vec::new();
    require_finite(&mut errors, format!("{field_path}.region_min"), region_min);
    require_finite(&mut errors, format!("{field_path}.region_max"), region_max);
    // Compared in f32, the precision positions are drawn in (an empty f32 range cannot be drawn).
    let (lo, hi) = (region_min.map(|v| v as f32), region_max.map(|v| v as f32));
    if errors.is_empty() && !(lo[0] < hi[0] && lo[1] < hi[1]) {
        errors.push(BuildError::new(
            format!("{field_path}.region_max"),
            format!("must exceed region_min {region_min:?} on both axes, got {region_max:?}"),
        ));
    }
    if !(density.is_finite() && *density >= 0.0) {
        errors.push(BuildError::new(
            format!("{field_path}.density"),
            format!("must be finite and >= 0, got {density}"),
        ));
    }
    require_positive(&mut errors, format!("{field_path}.radius_min"), *radius_min);
    require_positive(&mut errors, format!("{field_path}.radius_max"), *radius_max);
    if radius_min > radius_max {
        errors.push(BuildError::new(
            format!("{field_path}.radius_max"),
            format!("must be >= radius_min ({radius_min}), got {radius_max}"),
        ));
    }
    require_positive(&mut errors, format!("{field_path}.height"), *height);
    if !(start_clearance.is_finite() && *start_clearance >= 0.0) {
        errors.push(BuildError::new(
            format!("{field_path}.start_clearance"),
            format!("must be finite and >= 0, got {start_clearance}"),
        ));
    }
    if !errors.is_empty() {
        return Err(errors);
    }
    let area = (region_max[0] - region_min[0]) * (region_max[1] - region_min[1]);
    if density * area > MAX_EXPECTED_PILLARS {
        return Err(vec![BuildError::new(
            format!("{field_path}.density"),
            format!(
                "{density} per m^2 over {area} m^2 expects {} pillars, more than the limit of \
                 {MAX_EXPECTED_PILLARS}",
                density * area
            ),
        )]);
    }
    let field = PillarField {
        region_min: Vec2::new(region_min[0] as f32, region_min[1] as f32),
        region_max: Vec2::new(region_max[0] as f32, region_max[1] as f32),
        density: *density,
        radius_min: *radius_min as f32,
        radius_max: *radius_max as f32,
        height: *height as f32,
        start_clearance: *start_clearance as f32,
    };
    // A field that asks for pillars (density > 0) yet can hold none, because the clearance
    // around the starts removes every one wherever it is drawn, is almost surely a mistake (a
    // clearance meant in decimetres, a region placed around the start), and its runs would
    // silently fly an empty world. It is refused whatever the seed, as it holds for every draw.
    // A density of 0 asks for no pillars (a study's obstacle-free baseline) and stays allowed.
    if *density > 0.0 && !room_for_pillars(&field, field.radius_min, starts) {
        return Err(vec![cleared_field(&field, field_path, starts)]);
    }
    let mut rng = seed.stream(stream::WORLD_GENERATOR, index as u64);
    let base_name = display_name(name, "pillars", index);
    Ok(generate_pillars(&field, starts, kept_clear, &mut rng)
        .into_iter()
        .enumerate()
        .map(|(k, p)| {
            upright_cylinder(
                format!("{base_name} #{k}"),
                field_path,
                p.base.extend(0.0),
                p.radius,
                field.height,
            )
        })
        .collect())
}

#[cfg(test)]
mod tests {
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
        assert!(
            field_errors(&field("radius_max = 0.6\nstart_clearance = 2.5"), &[START]).is_empty()
        );
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
        let errors = super::super::build_world(&spec, RunSeed(0), &[START], &[], Path::new("."))
            .unwrap_err();
        assert_eq!(errors[0].path, "world.obstacle[0].density");
        assert!(errors[0].message.contains("4000000"), "{}", errors[0]);
    }
}
