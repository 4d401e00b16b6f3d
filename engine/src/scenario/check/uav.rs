//! Checks of the UAVs: names, airframes, starts, behaviours and sensors (common.md §2-3).

use std::f64::consts::PI;

use super::world::{Context, check_hit_miss};
use super::{
    KNOWN_AIRFRAMES, MAX_MOUNT_OFFSET_M, MAX_RAYS_PER_SCAN, UavPart, angle, at_least_one, inside,
    non_negative, positive, triple,
};
use crate::exploration::CandidateCount;
use crate::exploration::setup::camera_of;
use crate::scenario::diagnostic::{Finding, number};
use crate::scenario::path::FieldPath;
use crate::scenario::schema::{
    BehaviourSpec, BoundsSpec, MountSpec, QualitySpec, RayGridSpec, SensorSpec, UavSpec,
};
use crate::scenario::source_map::Anchor;
use crate::scenario::suggest::{closest, plain_list};
use uavex_components::airframe::Airframe;

/// UAV names identify UAVs in outputs: no two may share one.
pub(crate) fn check_names(uavs: &[UavPart<'_>], out: &mut Vec<Finding>) {
    let mut seen: Vec<(&str, usize)> = Vec::new();
    for part in uavs {
        let Some(spec) = part.spec else { continue };
        if let Some((_, first)) = seen.iter().find(|(name, _)| *name == spec.name) {
            out.push(Finding::must_be(
                FieldPath::root().key("uav").index(part.index).key("name"),
                format!(
                    "a name no other UAV has (uav[{first}] is also called {:?})",
                    spec.name
                ),
                format!("{:?}", spec.name),
            ));
        } else {
            seen.push((&spec.name, part.index));
        }
    }
}

/// UAVs that fly on the true quadrotor must not start overlapping: their collision boxes would
/// touch at t = 0 and the run end `crashed` before anything happened. Each airframe counts with
/// its bounding sphere (its preset's, or with its size overrides when they are valid).
pub(crate) fn check_start_separation(uavs: &[UavPart<'_>], out: &mut Vec<Finding>) {
    let flying: Vec<(usize, [f64; 3], f64)> = uavs
        .iter()
        .filter_map(|part| {
            let spec = part.spec?;
            if matches!(spec.behaviour, BehaviourSpec::Scripted { .. }) {
                return None;
            }
            let preset = Airframe::preset(&spec.airframe).ok()?;
            let mut airframe = preset.clone();
            let airframe = match airframe.apply_overrides(&spec.airframe_overrides) {
                Ok(()) => airframe,
                Err(_) => preset,
            };
            Some((part.index, spec.start.position, airframe.bounding_radius()))
        })
        .collect();
    for (k, &(index, start, radius)) in flying.iter().enumerate() {
        let distance = |other: [f64; 3]| {
            let d: f64 = (0..3).map(|a| (start[a] - other[a]).powi(2)).sum();
            d.sqrt()
        };
        if let Some(&(first, _, other)) = flying[..k]
            .iter()
            .find(|&&(_, other, r)| distance(other) <= radius + r)
        {
            out.push(Finding::must_be(
                FieldPath::root()
                    .key("uav")
                    .index(index)
                    .key("start")
                    .key("position"),
                format!(
                    "more than {:.2} m from uav[{first}]'s start (the two airframes' bounding \
                     spheres would overlap at t = 0)",
                    radius + other
                ),
                triple(start),
            ));
        }
    }
}

/// One UAV without its sensors.
pub(crate) fn check_uav(
    path: &FieldPath,
    uav: &UavSpec,
    context: &Context,
    out: &mut Vec<Finding>,
) {
    if uav.name.trim().is_empty() {
        out.push(Finding::must_be(
            path.key("name"),
            "a non-empty name",
            format!("{:?}", uav.name),
        ));
    }
    if !KNOWN_AIRFRAMES.contains(&uav.airframe.as_str()) {
        let known = plain_list(KNOWN_AIRFRAMES);
        let mut message = format!(
            "unknown airframe preset '{}': this build knows: {known}",
            uav.airframe
        );
        if let Some(near) = closest(&uav.airframe, KNOWN_AIRFRAMES) {
            message.push_str(&format!(" (did you mean '{near}'?)"));
        }
        out.push(
            Finding::new(path.key("airframe"), Anchor::Value, message)
                .expected(format!("one of: {known}")),
        );
    }
    check_position(
        path.key("start").key("position"),
        uav.start.position,
        context,
        out,
    );
    check_behaviour(&path.key("behaviour"), &uav.behaviour, context, out);
    check_standoff(&path.key("behaviour").key("standoff_m"), uav, out);
}

/// An exploring UAV's `standoff_m`: above 0, and within its depth camera's range (a viewpoint
/// farther off cannot see its cluster). Here rather than in [`check_behaviour`]: it needs the
/// UAV's sensors.
fn check_standoff(path: &FieldPath, uav: &UavSpec, out: &mut Vec<Finding>) {
    let BehaviourSpec::Explore(explore) = &uav.behaviour else {
        return;
    };
    let Some(standoff) = explore.standoff_m else {
        return;
    };
    positive(out, path.clone(), standoff);
    if let Some((_, range)) = camera_of(uav)
        && standoff > range
    {
        out.push(Finding::must_be(
            path.clone(),
            format!(
                "at most the depth camera's range_max, {} m (a viewpoint farther off cannot \
                 see its cluster's centroid)",
                number(range)
            ),
            number(standoff),
        ));
    }
}

fn within(bounds: &BoundsSpec) -> String {
    format!(
        "inside world.bounds ({} to {})",
        triple(bounds.min),
        triple(bounds.max)
    )
}

fn check_behaviour(
    path: &FieldPath,
    behaviour: &BehaviourSpec,
    context: &Context,
    out: &mut Vec<Finding>,
) {
    match behaviour {
        BehaviourSpec::Scripted {
            speed,
            waypoints,
            yaw_rate,
        } => {
            positive(out, path.key("speed"), *speed);
            positive(out, path.key("yaw_rate"), *yaw_rate);
            check_waypoints(path, waypoints, context, out);
        }
        // Files (field, energy model) and the geometry are checked where the mission is
        // planned (`CoverageSpec::resolve`), which names the field of every problem.
        BehaviourSpec::Coverage(coverage) => {
            positive(
                out,
                path.key("resolution_px_per_m"),
                coverage.resolution_px_per_m,
            );
            positive(
                out,
                path.key("available_energy_j"),
                coverage.available_energy_j,
            );
        }
        BehaviourSpec::Explore(explore) => {
            positive(out, path.key("replan_hz"), explore.replan_hz);
            if let CandidateCount::Count(n) = explore.candidates {
                at_least_one(out, path.key("candidates"), n);
            }
            if let Some(budget) = explore.energy_budget {
                non_negative(
                    out,
                    path.key("energy_budget").key("reserve_j"),
                    budget.reserve_j,
                );
            }
        }
        BehaviourSpec::Waypoints { waypoints, yaw, .. } => {
            check_waypoints(path, waypoints, context, out);
            if let Some(yaw) = yaw
                && yaw.len() != waypoints.len()
            {
                out.push(Finding::must_be(
                    path.key("yaw"),
                    format!(
                        "one heading per waypoint ({}), or no `yaw` to face the direction of travel",
                        waypoints.len()
                    ),
                    format!("{} headings", yaw.len()),
                ));
            }
        }
    }
}

/// At least one waypoint, each inside the bounds.
fn check_waypoints(
    path: &FieldPath,
    waypoints: &[[f64; 3]],
    context: &Context,
    out: &mut Vec<Finding>,
) {
    if waypoints.is_empty() {
        out.push(Finding::must_be(
            path.key("waypoints"),
            "at least one waypoint",
            "an empty list",
        ));
    }
    for (k, waypoint) in waypoints.iter().enumerate() {
        check_position(path.key("waypoints").index(k), *waypoint, context, out);
    }
}

/// A place a UAV is to be (its start, a waypoint): inside the map's bounds, and not under a
/// `ground = true` floor. Bounds may reach below the floor (to map what lies under it), but a
/// UAV cannot be there: inside the 1 m ground slab the world builder finds a start in an
/// obstacle, deeper down nothing would, and the UAV would fly, or fall, under the ground plane
/// (a waypoint there is one no flight can reach). Outside the bounds is said once, as such.
fn check_position(at: FieldPath, position: [f64; 3], context: &Context, out: &mut Vec<Finding>) {
    if let Some(bounds) = &context.bounds
        && !inside(position, bounds.min, bounds.max)
    {
        out.push(Finding::must_be(at, within(bounds), triple(position)));
    } else if context.ground == Some(true) && position[2] < 0.0 {
        out.push(Finding::must_be(
            at,
            "at or above the ground, z >= 0 (world.ground = true lays a solid floor at z = 0)",
            triple(position),
        ));
    }
}

/// One sensor (common.md §2).
pub(crate) fn check_sensor(
    path: &FieldPath,
    sensor: &SensorSpec,
    context: &Context,
    out: &mut Vec<Finding>,
) {
    match sensor {
        SensorSpec::DepthCamera {
            width,
            height,
            hfov,
            range_min,
            range_max,
            rate_hz,
            ray_grid,
            quality,
            mount,
        } => {
            at_least_one(out, path.key("width"), *width);
            at_least_one(out, path.key("height"), *height);
            angle(out, path.key("hfov"), *hfov, PI, true);
            check_ranges(path, *range_min, *range_max, context, out);
            check_rate(path, *rate_hz, context, out);
            check_mount(path, mount, out);
            check_quality(path, quality, *range_max, out);
            let rays = match ray_grid {
                RayGridSpec::Explicit([columns, rows]) => {
                    at_least_one(out, path.key("ray_grid").index(0), *columns);
                    at_least_one(out, path.key("ray_grid").index(1), *rows);
                    Some(f64::from(*columns) * f64::from(*rows))
                }
                RayGridSpec::Named(_) => {
                    auto_grid_rays(*width, *height, *hfov, *range_max, context)
                }
            };
            check_ray_count(&path.key("ray_grid"), rays, out);
        }
        SensorSpec::Lidar {
            hfov,
            beams_h,
            vfov,
            beams_v,
            range_min,
            range_max,
            rate_hz,
            quality,
            mount,
        } => {
            angle(out, path.key("hfov"), *hfov, 2.0 * PI, false);
            at_least_one(out, path.key("beams_h"), *beams_h);
            at_least_one(out, path.key("beams_v"), *beams_v);
            if *beams_v > 1 {
                angle(out, path.key("vfov"), *vfov, PI, true);
            } else if *vfov != 0.0 && vfov.is_finite() {
                out.push(Finding::must_be(
                    path.key("vfov"),
                    "0 for a planar lidar (beams_v = 1); set beams_v for a multi-beam one",
                    number(*vfov),
                ));
            }
            check_ranges(path, *range_min, *range_max, context, out);
            check_rate(path, *rate_hz, context, out);
            check_mount(path, mount, out);
            check_quality(path, quality, *range_max, out);
            check_ray_count(
                &path.key("beams_h"),
                Some(f64::from(*beams_h) * f64::from(*beams_v)),
                out,
            );
        }
    }
}

/// 0 <= range_min < range_max, and range_max beyond one voxel of the map (a shorter sensor
/// observes no voxel but its own, and the run would end "complete" at 0 % explored).
fn check_ranges(
    path: &FieldPath,
    range_min: f64,
    range_max: f64,
    context: &Context,
    out: &mut Vec<Finding>,
) {
    non_negative(out, path.key("range_min"), range_min);
    positive(out, path.key("range_max"), range_max);
    if range_min >= 0.0 && range_max > 0.0 && range_min >= range_max {
        out.push(Finding::must_be(
            path.key("range_min"),
            format!("below range_max ({})", number(range_max)),
            number(range_min),
        ));
    }
    if let Some(map) = &context.map
        && range_max > 0.0
        && range_max <= map.resolution
    {
        out.push(Finding::must_be(
            path.key("range_max"),
            format!(
                "above map.resolution ({} m): the sensor must reach past its own voxel",
                number(map.resolution)
            ),
            number(range_max),
        ));
    }
}

/// 0 < rate_hz <= physics_rate_hz: the sensing stage scans at most once per physics step.
fn check_rate(path: &FieldPath, rate_hz: f64, context: &Context, out: &mut Vec<Finding>) {
    positive(out, path.key("rate_hz"), rate_hz);
    if let Some(physics) = context.physics_rate_hz
        && rate_hz > physics
    {
        out.push(Finding::must_be(
            path.key("rate_hz"),
            format!(
                "at most physics_rate_hz ({}): a sensor scans at most once per physics step",
                number(physics)
            ),
            number(rate_hz),
        ));
    }
}

/// A mount within [`MAX_MOUNT_OFFSET_M`] of the UAV's centre.
fn check_mount(path: &FieldPath, mount: &MountSpec, out: &mut Vec<Finding>) {
    let [x, y, z] = mount.translation;
    let offset = (x * x + y * y + z * z).sqrt();
    if offset > MAX_MOUNT_OFFSET_M {
        out.push(Finding::must_be(
            path.key("mount").key("translation"),
            format!("within {MAX_MOUNT_OFFSET_M} m of the UAV's centre"),
            triple(mount.translation),
        ));
    }
}

/// The sensor model, and range noise below the range itself (a standard deviation of 1e30 m
/// scattered every reading to the range limit and "explored" more than a perfect sensor).
fn check_quality(
    sensor: &FieldPath,
    quality: &QualitySpec,
    range_max: f64,
    out: &mut Vec<Finding>,
) {
    let path = sensor.key("quality");
    check_hit_miss(&path, quality.p_hit, quality.p_miss, out);
    let noise = quality.range_noise_std;
    non_negative(out, path.key("range_noise_std"), noise);
    if noise > 0.0 && range_max > 0.0 && noise >= range_max {
        out.push(Finding::must_be(
            path.key("range_noise_std"),
            format!("below range_max ({} m)", number(range_max)),
            number(noise),
        ));
    }
}

/// Rays per frame of the "auto" grid, estimated as the sensing stage builds it (common.md §2:
/// angular step = resolution / range_max over the horizontal and vertical FoV, the vertical one
/// following from the aspect ratio); `None` when the inputs are themselves invalid.
fn auto_grid_rays(
    width: u32,
    height: u32,
    hfov: f64,
    range_max: f64,
    context: &Context,
) -> Option<f64> {
    let resolution = context.map.as_ref()?.resolution;
    let valid = width > 0 && height > 0 && hfov > 0.0 && hfov < PI && range_max > 0.0;
    if !(valid && range_max.is_finite()) {
        return None;
    }
    let step = resolution / range_max;
    let vfov = 2.0 * ((hfov / 2.0).tan() * f64::from(height) / f64::from(width)).atan();
    Some(((hfov / step).ceil() + 1.0) * ((vfov / step).ceil() + 1.0))
}

fn check_ray_count(path: &FieldPath, rays: Option<f64>, out: &mut Vec<Finding>) {
    if let Some(rays) = rays
        && rays > MAX_RAYS_PER_SCAN
    {
        out.push(Finding::must_be(
            path.clone(),
            format!(
                "a ray grid of at most {MAX_RAYS_PER_SCAN:e} rays per scan (for the auto grid: a coarser map.resolution or a shorter range_max)"
            ),
            format!("{rays:.3e} rays"),
        ));
    }
}
