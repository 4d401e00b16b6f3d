//! Checks of the run settings, the map (common.md §1) and the world: bounds and obstacles.

use super::{
    MAX_PILLARS, MAX_STEPS, MAX_VOXELS, MIN_PHYSICS_RATE_HZ, MIN_VOXELS_PER_SIDE, non_negative,
    positive, probability, usable,
};
use crate::scenario::diagnostic::{Finding, number};
use crate::scenario::path::FieldPath;
use crate::scenario::schema::{BoundsSpec, MapSpec, ObstacleSpec, Scenario};

const AXES: [&str; 3] = ["x", "y", "z"];

/// What later checks need from the top level, when it decoded and made sense.
#[derive(Debug, Clone, Default)]
pub(crate) struct Context {
    /// The bounds, when finite with min < max on every axis.
    pub bounds: Option<BoundsSpec>,
    /// The map, when its resolution is finite and above 0.
    pub map: Option<MapSpec>,
    /// The physics rate (Hz), when the top level decoded and the rate is valid.
    pub physics_rate_hz: Option<f64>,
    /// `world.ground`, when the top level decoded.
    pub ground: Option<bool>,
}

impl Context {
    pub fn of(
        map: Option<&MapSpec>,
        bounds: Option<&BoundsSpec>,
        physics_rate_hz: Option<f64>,
        ground: Option<bool>,
    ) -> Self {
        let bounds = bounds.filter(|b| {
            (0..3).all(|k| usable(b.min[k]) && usable(b.max[k]) && b.min[k] < b.max[k])
        });
        let map = map.filter(|m| usable(m.resolution) && m.resolution > 0.0);
        Self {
            bounds: bounds.copied(),
            map: map.cloned(),
            physics_rate_hz: physics_rate_hz
                .filter(|r| r.is_finite() && *r >= super::MIN_PHYSICS_RATE_HZ),
            ground,
        }
    }
}

/// Time limit, physics rate, output rate, names.
pub(crate) fn check_run(root: &Scenario, out: &mut Vec<Finding>) {
    if root.name.trim().is_empty() {
        out.push(Finding::must_be(
            FieldPath::root().key("name"),
            "a non-empty name",
            format!("{:?}", root.name),
        ));
    }
    positive(
        out,
        FieldPath::root().key("time_limit_s"),
        root.time_limit_s,
    );
    if root.physics_rate_hz < MIN_PHYSICS_RATE_HZ {
        out.push(Finding::must_be(
            FieldPath::root().key("physics_rate_hz"),
            format!(
                "at least {MIN_PHYSICS_RATE_HZ} Hz (the motors' 0.033 s lag and the attitude \
                 loop diverge at longer steps; common.md §3 runs at 300 Hz)"
            ),
            number(root.physics_rate_hz),
        ));
    }
    let steps = root.time_limit_s * root.physics_rate_hz;
    if root.physics_rate_hz > 0.0 && steps > MAX_STEPS {
        let longest = MAX_STEPS / root.physics_rate_hz;
        out.push(Finding::must_be(
            FieldPath::root().key("time_limit_s"),
            format!(
                "at most {} s at physics_rate_hz = {} (a run takes at most {MAX_STEPS:e} physics steps)",
                number(longest),
                number(root.physics_rate_hz)
            ),
            number(root.time_limit_s),
        ));
    }
    positive(
        out,
        FieldPath::parse("outputs.series_rate_hz"),
        root.outputs.series_rate_hz,
    );
}

/// The sensor model and clamping (common.md §1): probabilities in (0, 1), a hit raises the
/// log-odds (p_hit > 0.5), a miss lowers them (p_miss < 0.5), and the clamping range lets a
/// voxel become both free (p < 0.5) and occupied (p >= 0.5).
pub(crate) fn check_map(map: &MapSpec, out: &mut Vec<Finding>) {
    let map_path = FieldPath::root().key("map");
    positive(out, map_path.key("resolution"), map.resolution);
    check_hit_miss(&map_path, Some(map.p_hit), Some(map.p_miss), out);
    let min_ok = probability(out, map_path.key("p_min"), map.p_min);
    let max_ok = probability(out, map_path.key("p_max"), map.p_max);
    if !(min_ok && max_ok) {
        return;
    }
    if map.p_min >= map.p_max {
        out.push(Finding::must_be(
            map_path.key("p_min"),
            format!("below p_max ({})", number(map.p_max)),
            number(map.p_min),
        ));
        return;
    }
    if map.p_min >= 0.5 {
        out.push(Finding::must_be(
            map_path.key("p_min"),
            "below 0.5 (else no voxel can ever be free)",
            number(map.p_min),
        ));
    }
    if map.p_max < 0.5 {
        out.push(Finding::must_be(
            map_path.key("p_max"),
            "at least 0.5 (else no voxel can ever be occupied)",
            number(map.p_max),
        ));
    }
}

/// Hit and miss probabilities of the map or of one sensor's quality (`table` holds them).
pub(crate) fn check_hit_miss(
    table: &FieldPath,
    p_hit: Option<f64>,
    p_miss: Option<f64>,
    out: &mut Vec<Finding>,
) {
    if let Some(p_hit) = p_hit
        && probability(out, table.key("p_hit"), p_hit)
        && p_hit <= 0.5
    {
        out.push(Finding::must_be(
            table.key("p_hit"),
            "above 0.5 (a hit must raise the occupancy)",
            number(p_hit),
        ));
    }
    if let Some(p_miss) = p_miss
        && probability(out, table.key("p_miss"), p_miss)
        && p_miss >= 0.5
    {
        out.push(Finding::must_be(
            table.key("p_miss"),
            "below 0.5 (a miss must lower the occupancy)",
            number(p_miss),
        ));
    }
}

/// min < max on every axis (a box of positive volume).
pub(crate) fn check_bounds(bounds: &BoundsSpec, out: &mut Vec<Finding>) {
    let path = FieldPath::parse("world.bounds");
    for (k, axis) in AXES.iter().enumerate() {
        if bounds.min[k] >= bounds.max[k] {
            out.push(Finding::must_be(
                path.key("max").index(k),
                format!(
                    "above world.bounds.min[{k}] ({}): the bounds need a positive extent along {axis}",
                    number(bounds.min[k])
                ),
                number(bounds.max[k]),
            ));
        }
    }
}

/// The voxel size against the box: at least a few voxels along its smallest side, at most
/// `MAX_VOXELS` in all. Only called with valid bounds.
pub(crate) fn check_resolution(map: &MapSpec, bounds: &BoundsSpec, out: &mut Vec<Finding>) {
    let resolution = map.resolution;
    if !(resolution.is_finite() && resolution > 0.0) {
        return;
    }
    let sides: Vec<f64> = (0..3).map(|k| bounds.max[k] - bounds.min[k]).collect();
    let smallest = sides.iter().copied().fold(f64::INFINITY, f64::min);
    let path = FieldPath::parse("map.resolution");
    if smallest / resolution < MIN_VOXELS_PER_SIDE {
        out.push(Finding::must_be(
            path,
            format!(
                "at most {} (at least {MIN_VOXELS_PER_SIDE} voxels along the smallest side of world.bounds, {} m)",
                number(smallest / MIN_VOXELS_PER_SIDE),
                number(smallest)
            ),
            number(resolution),
        ));
        return;
    }
    let voxels: f64 = sides
        .iter()
        .map(|side| (side / resolution).ceil())
        .product();
    if voxels > MAX_VOXELS {
        let volume: f64 = sides.iter().product();
        let finest = (volume / MAX_VOXELS).cbrt();
        out.push(Finding::must_be(
            path,
            format!(
                "at least about {finest:.3} (world.bounds would hold {voxels:.3e} voxels; the limit is {MAX_VOXELS:e})"
            ),
            number(resolution),
        ));
    }
}

/// Sizes of the obstacle kinds; files are the world builder's to check.
pub(crate) fn check_obstacle(path: &FieldPath, obstacle: &ObstacleSpec, out: &mut Vec<Finding>) {
    match obstacle {
        ObstacleSpec::Box { size, .. } => {
            for (k, &extent) in size.iter().enumerate() {
                positive(out, path.key("size").index(k), extent);
            }
        }
        ObstacleSpec::Cylinder { radius, height, .. } => {
            positive(out, path.key("radius"), *radius);
            positive(out, path.key("height"), *height);
        }
        ObstacleSpec::Sphere { radius, .. } => positive(out, path.key("radius"), *radius),
        ObstacleSpec::Mesh { scale, .. } => positive(out, path.key("scale"), *scale),
        ObstacleSpec::Cloud { point_radius, .. } => {
            positive(out, path.key("point_radius"), *point_radius);
        }
        ObstacleSpec::Pillars {
            region_min,
            region_max,
            density,
            radius_min,
            radius_max,
            height,
            start_clearance,
            ..
        } => {
            let mut region_ok = true;
            for k in 0..2 {
                if region_min[k] >= region_max[k] {
                    region_ok = false;
                    out.push(Finding::must_be(
                        path.key("region_max").index(k),
                        format!("above region_min[{k}] ({})", number(region_min[k])),
                        number(region_max[k]),
                    ));
                }
            }
            non_negative(out, path.key("density"), *density);
            positive(out, path.key("radius_min"), *radius_min);
            if *radius_min > 0.0 && radius_min > radius_max {
                out.push(Finding::must_be(
                    path.key("radius_max"),
                    format!("at least radius_min ({})", number(*radius_min)),
                    number(*radius_max),
                ));
            }
            positive(out, path.key("height"), *height);
            non_negative(out, path.key("start_clearance"), *start_clearance);
            let area = (region_max[0] - region_min[0]) * (region_max[1] - region_min[1]);
            let count = density * area;
            if region_ok && count > MAX_PILLARS {
                out.push(Finding::must_be(
                    path.key("density"),
                    format!(
                        "at most {} per m^2 here ({MAX_PILLARS:e} pillars in a region of {} m^2)",
                        number(MAX_PILLARS / area),
                        number(area)
                    ),
                    number(*density),
                ));
            }
        }
    }
}
