//! Semantic checks: a scenario that decodes may still make no sense (a negative range, bounds of
//! zero volume, a start outside the map). Each check is a plain function over schema values that
//! returns findings with field paths; the loader locates them in the file.
//!
//! Checks run on whatever decoded, so one bad `[[uav]]` does not hide the problems of the
//! others. Numbers that are not finite are reported once, by the finiteness scan, and every
//! check here skips them (comparisons are written so that NaN and infinities pass).

mod numbers;
mod uav;
mod world;

use std::f64::consts::PI;

use super::LoadedScenario;
use super::decode::Decoded;
use super::diagnostic::{Diagnostic, Finding, number};
use super::path::FieldPath;
use super::schema::{BoundsSpec, MapSpec, ObstacleSpec, Scenario, SensorSpec, UavSpec};
use super::source_map::Anchor;

pub(crate) use numbers::{non_finite, unusable_number, usable};

/// Fewer voxels than this along the smallest side of the bounds is too coarse to map anything.
pub const MIN_VOXELS_PER_SIDE: f64 = 4.0;
/// More voxels than this in the bounds (8 GB of log-odds at 4 bytes each) is refused: memory
/// would run out long before the run ended.
pub const MAX_VOXELS: f64 = 2e9;
/// Rays one sensor may cast per scan; beyond this one frame costs seconds of CPU, which is a
/// mistake in the file, not a study.
pub const MAX_RAYS_PER_SCAN: f64 = 1e7;
/// Pillars one generator may place (density x area).
pub const MAX_PILLARS: f64 = 1e5;
/// Physics steps per run (time_limit_s x physics_rate_hz): 1e8 steps are 3.9 simulated days at
/// 300 Hz; more is a typo that would make a run look hung.
pub const MAX_STEPS: f64 = 1e8;
/// Slowest physics and control rate (Hz): a step of 0.02 s is already below the kingfisher's
/// motor time constant (0.033 s) by little; at 1 Hz a waypoint tour flew twice its path and
/// drew 486 W peaks, at 1e-6 Hz one step outlasted the run.
pub const MIN_PHYSICS_RATE_HZ: f64 = 50.0;
/// Farthest a sensor may sit from its UAV's centre (m): a longer boom is a typo (a camera
/// mounted 100 m away looked at nothing of the world and the run "explored" 0 %).
pub const MAX_MOUNT_OFFSET_M: f64 = 2.0;
/// Airframe presets this build knows (common.md §3).
pub const KNOWN_AIRFRAMES: &[&str] = &["kingfisher", "iris"];

/// Every semantic problem of a loaded scenario, located. The loader already ran these; they are
/// public for code that edits a scenario (a sweep setting parameters) and must check it again.
/// This entry point also scans for non-finite numbers, which the loader finds in the text.
pub fn check(loaded: &LoadedScenario) -> Vec<Diagnostic> {
    let mut findings = non_finite(&loaded.scenario);
    findings.extend(check_parts(&Parts::of(&loaded.scenario)));
    let mut diagnostics: Vec<Diagnostic> = findings
        .into_iter()
        .map(|finding| finding.locate(&loaded.path, &loaded.source))
        .collect();
    diagnostics.sort_by_key(|d| (d.line, d.column));
    diagnostics
}

/// The decoded pieces of a scenario, each with its index in the file.
pub(crate) struct Parts<'a> {
    /// The top level; its `uavs` and `world.obstacles` are not read (see the lists below).
    pub root: Option<&'a Scenario>,
    /// The map and the bounds, also when the top level as a whole did not decode.
    pub map: Option<&'a MapSpec>,
    pub bounds: Option<&'a BoundsSpec>,
    pub obstacles: Vec<(usize, &'a ObstacleSpec)>,
    pub uavs: Vec<UavPart<'a>>,
    /// `[[uav]]` entries in the file, decoded or not.
    pub uav_entries: usize,
}

pub(crate) struct UavPart<'a> {
    pub index: usize,
    /// `None` when the UAV itself did not decode (its sensors may have).
    pub spec: Option<&'a UavSpec>,
    pub sensors: Vec<(usize, &'a SensorSpec)>,
}

impl<'a> Parts<'a> {
    /// All of a complete scenario.
    pub fn of(scenario: &'a Scenario) -> Self {
        Self {
            root: Some(scenario),
            map: Some(&scenario.map),
            bounds: Some(&scenario.world.bounds),
            obstacles: scenario.world.obstacles.iter().enumerate().collect(),
            uavs: scenario
                .uavs
                .iter()
                .enumerate()
                .map(|(index, uav)| UavPart {
                    index,
                    spec: Some(uav),
                    sensors: uav.sensors.iter().enumerate().collect(),
                })
                .collect(),
            uav_entries: scenario.uavs.len(),
        }
    }

    /// What decoded of a file that may have had problems.
    pub fn of_decoded(decoded: &'a Decoded) -> Self {
        Self {
            root: decoded.root.as_ref(),
            map: decoded.map.as_ref(),
            bounds: decoded.bounds.as_ref(),
            obstacles: decoded
                .obstacles
                .iter()
                .filter_map(|(index, obstacle)| Some((*index, obstacle.as_ref()?)))
                .collect(),
            uavs: decoded
                .uavs
                .iter()
                .map(|uav| UavPart {
                    index: uav.index,
                    spec: uav.spec.as_ref(),
                    sensors: uav
                        .sensors
                        .iter()
                        .filter_map(|(index, sensor)| Some((*index, sensor.as_ref()?)))
                        .collect(),
                })
                .collect(),
            uav_entries: decoded.uavs.len().max(usize::from(decoded.uav_misshapen)),
        }
    }
}

/// Every semantic finding of `parts`, in the order of the file's sections.
pub(crate) fn check_parts(parts: &Parts<'_>) -> Vec<Finding> {
    let mut out = Vec::new();
    let context = world::Context::of(
        parts.map,
        parts.bounds,
        parts.root.map(|root| root.physics_rate_hz),
        parts.root.map(|root| root.world.ground),
    );
    if let Some(root) = parts.root {
        world::check_run(root, &mut out);
    }
    if let Some(map) = parts.map {
        world::check_map(map, &mut out);
    }
    if let Some(bounds) = parts.bounds {
        world::check_bounds(bounds, &mut out);
    }
    if let (Some(map), Some(bounds)) = (parts.map, context.bounds.as_ref()) {
        world::check_resolution(map, bounds, &mut out);
    }
    for (index, obstacle) in &parts.obstacles {
        let path = FieldPath::parse("world.obstacle").index(*index);
        world::check_obstacle(&path, obstacle, &mut out);
    }
    if parts.uav_entries == 0 {
        out.push(
            Finding::new(
                FieldPath::root().key("uav"),
                Anchor::Key,
                "the scenario has no UAV: add a [[uav]] table",
            )
            .expected("at least one [[uav]] table"),
        );
    }
    uav::check_names(&parts.uavs, &mut out);
    uav::check_start_separation(&parts.uavs, &mut out);
    for part in &parts.uavs {
        let path = FieldPath::root().key("uav").index(part.index);
        if let Some(spec) = part.spec {
            uav::check_uav(&path, spec, &context, &mut out);
        }
        for (index, sensor) in &part.sensors {
            uav::check_sensor(
                &path.key("sensor").index(*index),
                sensor,
                &context,
                &mut out,
            );
        }
    }
    out
}

/// `x` must be above 0.
fn positive(out: &mut Vec<Finding>, path: FieldPath, x: f64) {
    if x <= 0.0 {
        out.push(Finding::must_be(path, "above 0", number(x)));
    }
}

/// `x` must be 0 or more.
fn non_negative(out: &mut Vec<Finding>, path: FieldPath, x: f64) {
    if x < 0.0 {
        out.push(Finding::must_be(path, "at least 0", number(x)));
    }
}

/// A count that must be at least 1.
fn at_least_one(out: &mut Vec<Finding>, path: FieldPath, n: u32) {
    if n == 0 {
        out.push(Finding::must_be(path, "at least 1", n));
    }
}

/// An angle in (0, max], or (0, max) when `open`.
fn angle(out: &mut Vec<Finding>, path: FieldPath, x: f64, max: f64, open: bool) {
    let too_big = if open { x >= max } else { x > max };
    if x <= 0.0 || too_big {
        let bound = if max == PI { "pi" } else { "2 pi" };
        let close = if open { ")" } else { "]" };
        out.push(Finding::must_be(
            path,
            format!("in (0, {bound}{close} rad"),
            number(x),
        ));
    }
}

/// A probability in (0, 1); whether it is one.
fn probability(out: &mut Vec<Finding>, path: FieldPath, p: f64) -> bool {
    if p <= 0.0 || p >= 1.0 {
        out.push(Finding::must_be(path, "a probability in (0, 1)", number(p)));
        return false;
    }
    p.is_finite()
}

/// Whether a point lies in the closed box (a non-finite coordinate counts as inside: it is
/// reported on its own).
fn inside(point: [f64; 3], min: [f64; 3], max: [f64; 3]) -> bool {
    !(0..3).any(|k| point[k] < min[k] || point[k] > max[k])
}

fn triple(v: [f64; 3]) -> String {
    format!("[{}, {}, {}]", number(v[0]), number(v[1]), number(v[2]))
}

#[cfg(test)]
mod tests;
