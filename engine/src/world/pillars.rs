//! The seeded `pillars` generator: random upright pillars (tree trunks) on a rectangle of the
//! floor.
//!
//! Model: a homogeneous Poisson point process of intensity `density` (pillars per square metre)
//! on the region: the count is Poisson(density x area), positions uniform, radii uniform in
//! [radius_min, radius_max]. This is the usual model of a random forest, and it makes `density`
//! the true expected number per square metre whatever the area. Pillars may overlap (their union
//! is the obstacle). Pillars closer than `start_clearance` to a UAV start are then removed, which
//! leaves the process unchanged outside those discs, and so are pillars that touch a space a UAV
//! needs clear at its start whatever the field asks (its body's bounding sphere, and an
//! explorer's start capsule, `exploration::setup::StartCapsule`): without that, every seed that
//! drew a trunk into it would be refused when the run is built, and a sweep over seeds would
//! lose those runs.
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
#[path = "pillars_tests.rs"]
mod tests;
