//! The semantic checks on plain schema values (no file, no World).

use super::*;

/// A valid scenario; tests change one thing in it.
const BASE: &str = r#"
name = "t"
time_limit_s = 60.0

[world.bounds]
min = [0.0, 0.0, 0.0]
max = [10.0, 10.0, 3.0]

[[uav]]
name = "a"
start = { position = [1.0, 1.0, 1.0] }

[[uav.sensor]]
kind = "depth_camera"

[uav.behaviour]
kind = "scripted"
speed = 1.0
waypoints = [[5.0, 5.0, 1.0]]
"#;

fn scenario(text: &str) -> Scenario {
    toml::from_str(text).expect("test scenarios parse")
}

/// `(path, message, found)` of every finding of `text` (non-finite numbers included).
fn findings(text: &str) -> Vec<(String, String, Option<String>)> {
    let scenario = scenario(text);
    let mut all = non_finite(&scenario);
    all.extend(check_parts(&Parts::of(&scenario)));
    all.into_iter()
        .map(|f| (f.path.to_string(), f.message, f.found))
        .collect()
}

/// `BASE` with `old` replaced by `new` (which must occur).
fn with(old: &str, new: &str) -> String {
    assert!(BASE.contains(old), "{old} is not in the base scenario");
    BASE.replacen(old, new, 1)
}

fn one(text: &str) -> (String, String, Option<String>) {
    let mut all = findings(text);
    assert_eq!(all.len(), 1, "expected exactly one finding, got {all:#?}");
    all.remove(0)
}

fn finding(path: &str, message: &str, found: &str) -> (String, String, Option<String>) {
    (path.to_owned(), message.to_owned(), Some(found.to_owned()))
}

#[path = "tests_sensors.rs"]
mod sensors;

#[test]
fn the_base_scenario_is_clean() {
    assert_eq!(findings(BASE), vec![]);
}

#[test]
fn run_settings() {
    assert_eq!(
        one(&with("time_limit_s = 60.0", "time_limit_s = 0.0")),
        finding("time_limit_s", "must be above 0", "0.0")
    );
    assert_eq!(
        one(&with(
            "time_limit_s = 60.0",
            "time_limit_s = 60.0\nphysics_rate_hz = -300.0"
        )),
        finding(
            "physics_rate_hz",
            "must be at least 50 Hz (the motors' 0.033 s lag and the attitude loop diverge at \
             longer steps; common.md §3 runs at 300 Hz)",
            "-300.0"
        )
    );
    assert_eq!(
        findings(&with(
            "time_limit_s = 60.0",
            "time_limit_s = 60.0\nphysics_rate_hz = 50.0"
        )),
        vec![]
    );
    // 1e6 s at 300 Hz is 3e8 steps; the limit 1e8 allows 333333.33 s.
    let (path, message, _) = one(&with("time_limit_s = 60.0", "time_limit_s = 1e6"));
    assert_eq!(path, "time_limit_s");
    assert!(
        message.starts_with("must be at most 333333.33"),
        "{message}"
    );
    assert_eq!(
        one(&with(
            "time_limit_s = 60.0",
            "time_limit_s = 60.0\noutputs = { series_rate_hz = 0.0 }"
        )),
        finding("outputs.series_rate_hz", "must be above 0", "0.0")
    );
}

#[test]
fn map_probabilities() {
    let map = |body: &str| with("[world.bounds]", &format!("[map]\n{body}\n[world.bounds]"));
    assert_eq!(
        one(&map("p_hit = 1.0")),
        finding("map.p_hit", "must be a probability in (0, 1)", "1.0")
    );
    assert_eq!(
        one(&map("p_hit = 0.5")),
        finding(
            "map.p_hit",
            "must be above 0.5 (a hit must raise the occupancy)",
            "0.5"
        )
    );
    assert_eq!(
        one(&map("p_miss = 0.5")),
        finding(
            "map.p_miss",
            "must be below 0.5 (a miss must lower the occupancy)",
            "0.5"
        )
    );
    assert_eq!(
        one(&map("p_min = 0.0")),
        finding("map.p_min", "must be a probability in (0, 1)", "0.0")
    );
    assert_eq!(
        one(&map("p_min = 0.9\np_max = 0.8")),
        finding("map.p_min", "must be below p_max (0.8)", "0.9")
    );
    assert_eq!(
        one(&map("p_min = 0.6")),
        finding(
            "map.p_min",
            "must be below 0.5 (else no voxel can ever be free)",
            "0.6"
        )
    );
    assert_eq!(
        one(&map("p_max = 0.4\np_min = 0.1")),
        finding(
            "map.p_max",
            "must be at least 0.5 (else no voxel can ever be occupied)",
            "0.4"
        )
    );
}

#[test]
fn bounds_and_resolution() {
    assert_eq!(
        one(&with("max = [10.0, 10.0, 3.0]", "max = [10.0, 10.0, 0.0]")),
        finding(
            "world.bounds.max[2]",
            "must be above world.bounds.min[2] (0.0): the bounds need a positive extent along z",
            "0.0"
        )
    );
    let all = findings(&with("max = [10.0, 10.0, 3.0]", "max = [-1.0, 10.0, -3.0]"));
    let paths: Vec<&str> = all.iter().map(|(p, _, _)| p.as_str()).collect();
    // Both bad axes; no resolution or start check against bounds that make no sense.
    assert_eq!(paths, ["world.bounds.max[0]", "world.bounds.max[2]"]);

    let map = |body: &str| with("[world.bounds]", &format!("[map]\n{body}\n[world.bounds]"));
    assert_eq!(
        one(&map("resolution = -0.1")),
        finding("map.resolution", "must be above 0", "-0.1")
    );
    // Smallest side 3 m: at least 4 voxels along it means at most 0.75 m.
    assert_eq!(
        one(&map("resolution = 1.0")),
        finding(
            "map.resolution",
            "must be at most 0.75 (at least 4 voxels along the smallest side of world.bounds, 3.0 m)",
            "1.0"
        )
    );
    // 10 x 10 x 3 m at 2 mm: 5000 x 5000 x 1500 = 3.75e10 voxels; the finest allowed is
    // cbrt(300 m^3 / 2e9) = 5.3 mm. (The camera's auto grid, 2501 x 1946 rays, stays allowed.)
    let (path, message, found) = one(&map("resolution = 0.002"));
    assert_eq!(path, "map.resolution");
    assert_eq!(
        message,
        "must be at least about 0.005 (world.bounds would hold 3.750e10 voxels; the limit is 2e9)"
    );
    assert_eq!(found.as_deref(), Some("0.002"));
}

#[test]
fn uav_settings() {
    assert_eq!(
        one(&with("[1.0, 1.0, 1.0] }", "[1.0, 11.0, 1.0] }")),
        finding(
            "uav[0].start.position",
            "must be inside world.bounds ([0.0, 0.0, 0.0] to [10.0, 10.0, 3.0])",
            "[1.0, 11.0, 1.0]"
        )
    );
    assert_eq!(
        one(&with("speed = 1.0", "speed = 0.0")),
        finding("uav[0].behaviour.speed", "must be above 0", "0.0")
    );
    assert_eq!(
        one(&with("speed = 1.0", "speed = 1.0\nyaw_rate = -1.0")),
        finding("uav[0].behaviour.yaw_rate", "must be above 0", "-1.0")
    );
    assert_eq!(
        one(&with(
            "[[5.0, 5.0, 1.0]]",
            "[[5.0, 5.0, 1.0], [5.0, 5.0, 4.0]]"
        )),
        finding(
            "uav[0].behaviour.waypoints[1]",
            "must be inside world.bounds ([0.0, 0.0, 0.0] to [10.0, 10.0, 3.0])",
            "[5.0, 5.0, 4.0]"
        )
    );
    assert_eq!(
        one(&with("[[5.0, 5.0, 1.0]]", "[]")),
        finding(
            "uav[0].behaviour.waypoints",
            "must be at least one waypoint",
            "an empty list"
        )
    );
    let (path, message, _) = one(&with("name = \"a\"", "name = \"a\"\nairframe = \"irs\""));
    assert_eq!(path, "uav[0].airframe");
    assert_eq!(
        message,
        "unknown airframe preset 'irs': this build knows: kingfisher, iris (did you mean 'iris'?)"
    );
}

#[test]
fn explore_settings() {
    let explore = |settings: &str| {
        with(
            "kind = \"scripted\"\nspeed = 1.0\nwaypoints = [[5.0, 5.0, 1.0]]",
            &format!("kind = \"explore\"\nstrategy = \"eaae\"\n{settings}"),
        )
    };
    assert_eq!(findings(&explore("standoff_m = 2.5")), vec![]);
    assert_eq!(
        one(&explore("standoff_m = 0.0")),
        finding("uav[0].behaviour.standoff_m", "must be above 0", "0.0")
    );
    // The base scenario's camera reaches 5 m (the default range_max).
    assert_eq!(findings(&explore("standoff_m = 5.0")), vec![]);
    assert_eq!(
        one(&explore("standoff_m = 5.5")),
        finding(
            "uav[0].behaviour.standoff_m",
            "must be at most the depth camera's range_max, 5.0 m (a viewpoint farther off \
             cannot see its cluster's centroid)",
            "5.5"
        )
    );
    assert_eq!(
        one(&explore("candidates = 0")),
        finding("uav[0].behaviour.candidates", "must be at least 1", "0")
    );
}

/// The scenario with bounds reaching 5 m below the floor and `from` replaced by `to`: a
/// position there passes the bounds check, and below the ground slab (1 m thick) no obstacle
/// check sees it either. Asserts that `path` is refused as under the ground with `value`, and
/// that the same scenario without the ground is fine; returns the deep scenario before the
/// replacement and the one after it.
fn refused_below_the_ground(from: &str, to: &str, path: &str, value: &str) -> (String, String) {
    let deep = with("min = [0.0, 0.0, 0.0]", "min = [0.0, 0.0, -5.0]");
    let below = deep.replace(from, to);
    assert_eq!(
        one(&below),
        finding(
            path,
            "must be at or above the ground, z >= 0 (world.ground = true lays a solid floor \
             at z = 0)",
            value
        )
    );
    let no_ground = below.replace("[world.bounds]", "[world]\nground = false\n[world.bounds]");
    assert_eq!(findings(&no_ground), vec![]);
    (deep, below)
}

#[test]
fn a_start_below_the_ground_is_refused() {
    let (deep, below) = refused_below_the_ground(
        "[1.0, 1.0, 1.0] }",
        "[1.0, 1.0, -3.0] }",
        "uav[0].start.position",
        "[1.0, 1.0, -3.0]",
    );
    // A start on the floor is fine with the ground.
    assert_eq!(
        findings(&deep.replace("[1.0, 1.0, 1.0] }", "[1.0, 1.0, 0.0] }")),
        vec![]
    );
    // A start outside the bounds is reported once, as outside them.
    let (_, message, _) = one(&below.replace("-5.0]", "-1.0]"));
    assert!(
        message.starts_with("must be inside world.bounds"),
        "{message}"
    );
}

#[test]
fn a_waypoint_below_the_ground_is_refused() {
    refused_below_the_ground(
        "[[5.0, 5.0, 1.0]]",
        "[[5.0, 5.0, 1.0], [5.0, 5.0, -2.0]]",
        "uav[0].behaviour.waypoints[1]",
        "[5.0, 5.0, -2.0]",
    );
}

#[test]
fn uav_set() {
    let second = format!(
        "{BASE}\n[[uav]]\nname = \"a\"\nstart = {{ position = [2.0, 2.0, 1.0] }}\nbehaviour = {{ kind = \"scripted\", speed = 1.0, waypoints = [[1.0, 1.0, 1.0]] }}\n"
    );
    assert_eq!(
        one(&second),
        finding(
            "uav[1].name",
            "must be a name no other UAV has (uav[0] is also called \"a\")",
            "\"a\""
        )
    );
    // Two UAVs flying on the true quadrotor from one start would crash into each other at
    // t = 0; kinematic (scripted) ones have no body and may share a start.
    let flying = |position: &str| {
        let tour = "behaviour = { kind = \"waypoints\", waypoints = [[5.0, 5.0, 1.0]] }";
        format!(
            "{}\n[[uav]]\nname = \"b\"\nstart = {{ position = {position} }}\n{tour}\n",
            BASE.replace(
                "[uav.behaviour]\nkind = \"scripted\"\nspeed = 1.0\nwaypoints = [[5.0, 5.0, 1.0]]",
                "[uav.behaviour]\nkind = \"waypoints\"\nwaypoints = [[5.0, 5.0, 1.0]]",
            )
        )
    };
    let (path, message, found) = one(&flying("[1.0, 1.0, 1.0]"));
    assert_eq!(
        (path.as_str(), found.as_deref()),
        ("uav[1].start.position", Some("[1.0, 1.0, 1.0]"))
    );
    assert!(message.starts_with("must be more than 0."), "{message}");
    assert_eq!(findings(&flying("[3.0, 1.0, 1.0]")), vec![]);
    let scripted = format!(
        "{BASE}\n[[uav]]\nname = \"b\"\nstart = {{ position = [1.0, 1.0, 1.0] }}\nbehaviour = {{ kind = \"scripted\", speed = 1.0, waypoints = [[1.0, 2.0, 1.0]] }}\n"
    );
    assert_eq!(findings(&scripted), vec![]);
    let none = &BASE[..BASE.find("[[uav]]").unwrap()];
    let (path, message, found) = one(none);
    assert_eq!(path, "uav");
    assert_eq!(message, "the scenario has no UAV: add a [[uav]] table");
    assert_eq!(found, None);
}

#[test]
fn obstacle_sizes() {
    let obstacle = |body: &str| format!("{BASE}\n[[world.obstacle]]\n{body}\n");
    assert_eq!(
        one(&obstacle(
            "kind = \"box\"\ncenter = [5.0, 5.0, 1.0]\nsize = [1.0, 0.0, 1.0]"
        )),
        finding("world.obstacle[0].size[1]", "must be above 0", "0.0")
    );
    assert_eq!(
        one(&obstacle(
            "kind = \"sphere\"\ncenter = [5.0, 5.0, 1.0]\nradius = -1.0"
        )),
        finding("world.obstacle[0].radius", "must be above 0", "-1.0")
    );
    assert_eq!(
        one(&obstacle(
            "kind = \"cylinder\"\nbase = [5.0, 5.0, 0.0]\nradius = 0.5\nheight = 0.0"
        )),
        finding("world.obstacle[0].height", "must be above 0", "0.0")
    );
    assert_eq!(
        one(&obstacle("kind = \"mesh\"\nfile = \"m.obj\"\nscale = 0.0")),
        finding("world.obstacle[0].scale", "must be above 0", "0.0")
    );
    let pillars = "kind = \"pillars\"\nregion_min = [0.0, 0.0]\nregion_max = [10.0, 10.0]\n\
                   radius_min = 0.1\nradius_max = 0.2\nheight = 2.0";
    assert_eq!(
        findings(&obstacle(&format!("{pillars}\ndensity = 0.1"))),
        vec![]
    );
    assert_eq!(
        one(&obstacle(&format!("{pillars}\ndensity = 2000.0"))),
        finding(
            "world.obstacle[0].density",
            "must be at most 1000.0 per m^2 here (1e5 pillars in a region of 100.0 m^2)",
            "2000.0"
        )
    );
    assert_eq!(
        one(&obstacle(&format!(
            "{}\ndensity = 0.1",
            pillars.replace("0.2", "0.05")
        ))),
        finding(
            "world.obstacle[0].radius_max",
            "must be at least radius_min (0.1)",
            "0.05"
        )
    );
    assert_eq!(
        one(&obstacle(&format!(
            "{}\ndensity = 0.1",
            pillars.replace("region_max = [10.0, 10.0]", "region_max = [10.0, -1.0]")
        ))),
        finding(
            "world.obstacle[0].region_max[1]",
            "must be above region_min[1] (0.0)",
            "-1.0"
        )
    );
}

#[test]
fn non_finite_numbers_are_reported_once_by_path() {
    let text = with("[[5.0, 5.0, 1.0]]", "[[5.0, nan, 1.0]]").replace("speed = 1.0", "speed = inf");
    let mut all = findings(&text);
    all.sort();
    assert_eq!(
        all,
        vec![
            finding("uav[0].behaviour.speed", "must be a finite number", "inf"),
            finding(
                "uav[0].behaviour.waypoints[0][1]",
                "must be a finite number",
                "NaN"
            ),
        ]
    );
    // A NaN range triggers no ordering complaint of its own.
    let camera = with(
        "kind = \"depth_camera\"",
        "kind = \"depth_camera\"\nrange_min = nan",
    );
    assert_eq!(
        one(&camera),
        finding(
            "uav[0].sensor[0].range_min",
            "must be a finite number",
            "NaN"
        )
    );
}

#[test]
fn numbers_beyond_32_bit_floats_are_refused_on_the_typed_scenario() {
    // A sweep may set 1e39 where the file had a sane value: it must not reach the world builder,
    // where it becomes an infinite `f32` (a pillar radius of 1e39 panicked there).
    let mut scenario = scenario(&with("speed = 1.0", "speed = 1e39"));
    scenario.world.bounds.max[0] = -1e300;
    let found: Vec<(String, Option<String>)> = non_finite(&scenario)
        .iter()
        .map(|f| (f.path.to_string(), f.found.clone()))
        .collect();
    assert_eq!(
        found,
        [
            (
                "uav[0].behaviour.speed".to_string(),
                Some("1e39".to_string())
            ),
            (
                "world.bounds.max[0]".to_string(),
                Some("-1e300".to_string())
            ),
        ]
    );
}

#[test]
fn a_seed_beyond_toml_integers_does_not_hide_non_finite_numbers() {
    let mut scenario = scenario(&with("speed = 1.0", "speed = nan"));
    scenario.seed = u64::MAX;
    let paths: Vec<String> = non_finite(&scenario)
        .iter()
        .map(|f| f.path.to_string())
        .collect();
    assert_eq!(paths, ["uav[0].behaviour.speed"]);
}
