//! Bad scenario files, meaning: every semantic class has its own message at its field path,
//! line and column; problems found after loading (by the world builder, by a sweep editing the
//! scenario) are located the same way.

mod scenario_common;

use scenario_common::{BASE, assert_only, only, with};
use uavex_engine::scenario::parse_str;

/// `(replacement of a line of BASE, path, line, column, message)` for the semantic classes.
const SEMANTIC: &[(&str, &str, &str, usize, usize, &str)] = &[
    (
        "time_limit_s = 60.0",
        "time_limit_s = -1.0",
        "time_limit_s",
        2,
        16,
        "must be above 0",
    ),
    (
        "time_limit_s = 60.0",
        "time_limit_s = 60.0\nphysics_rate_hz = 0.0",
        "physics_rate_hz",
        3,
        19,
        "must be at least 50 Hz (the motors' 0.033 s lag and the attitude loop diverge at \
         longer steps; common.md §3 runs at 300 Hz)",
    ),
    (
        // At 1 Hz a waypoint tour flew twice its path; at 1e-6 Hz one step outlasted the run.
        "time_limit_s = 60.0",
        "time_limit_s = 60.0\nphysics_rate_hz = 1.0",
        "physics_rate_hz",
        3,
        19,
        "must be at least 50 Hz (the motors' 0.033 s lag and the attitude loop diverge at \
         longer steps; common.md §3 runs at 300 Hz)",
    ),
    (
        "max = [10.0, 10.0, 3.0]",
        "max = [10.0, 10.0, 0.0]",
        "world.bounds.max[2]",
        6,
        20,
        "must be above world.bounds.min[2] (0.0): the bounds need a positive extent along z",
    ),
    (
        "range_min = 0.5",
        "range_min = -0.5",
        "uav[0].sensor[0].range_min",
        14,
        13,
        "must be at least 0",
    ),
    (
        "range_max = 5.0",
        "range_max = 0.0",
        "uav[0].sensor[0].range_max",
        15,
        13,
        "must be above 0",
    ),
    (
        "range_min = 0.5",
        "range_min = 0.5\nrate_hz = 0.0",
        "uav[0].sensor[0].rate_hz",
        15,
        11,
        "must be above 0",
    ),
    (
        "range_min = 0.5",
        "range_min = 0.5\nhfov = 3.5",
        "uav[0].sensor[0].hfov",
        15,
        8,
        "must be in (0, pi) rad",
    ),
    (
        "range_min = 0.5",
        "range_min = 0.5\nheight = 0",
        "uav[0].sensor[0].height",
        15,
        10,
        "must be at least 1",
    ),
    (
        "start = { position = [1.0, 1.0, 1.0] }",
        "start = { position = [1.0, 1.0, -1.0] }",
        "uav[0].start.position",
        10,
        22,
        "must be inside world.bounds ([0.0, 0.0, 0.0] to [10.0, 10.0, 3.0])",
    ),
    (
        "speed = 1.0",
        "speed = -1.5",
        "uav[0].behaviour.speed",
        19,
        9,
        "must be above 0",
    ),
    (
        "waypoints = [[5.0, 5.0, 1.0]]",
        "waypoints = [[5.0, 5.0, 1.0], [50.0, 5.0, 1.0]]",
        "uav[0].behaviour.waypoints[1]",
        20,
        31,
        "must be inside world.bounds ([0.0, 0.0, 0.0] to [10.0, 10.0, 3.0])",
    ),
    (
        "name = \"a\"",
        "name = \"a\"\nairframe = \"hummingbird\"",
        "uav[0].airframe",
        10,
        12,
        "unknown airframe preset 'hummingbird': this build knows: kingfisher, iris",
    ),
    (
        "[world.bounds]",
        "[map]\nresolution = 0.0\n[world.bounds]",
        "map.resolution",
        5,
        14,
        "must be above 0",
    ),
    (
        "[world.bounds]",
        "[map]\nresolution = 1.0\n[world.bounds]",
        "map.resolution",
        5,
        14,
        "must be at most 0.75 (at least 4 voxels along the smallest side of world.bounds, 3.0 m)",
    ),
    (
        "[world.bounds]",
        "[map]\nresolution = 0.002\n[world.bounds]",
        "map.resolution",
        5,
        14,
        "must be at least about 0.005 (world.bounds would hold 3.750e10 voxels; the limit is 2e9)",
    ),
    (
        "[world.bounds]",
        "[map]\np_hit = 0.4\n[world.bounds]",
        "map.p_hit",
        5,
        9,
        "must be above 0.5 (a hit must raise the occupancy)",
    ),
    (
        "[world.bounds]",
        "[map]\np_miss = 0.6\n[world.bounds]",
        "map.p_miss",
        5,
        10,
        "must be below 0.5 (a miss must lower the occupancy)",
    ),
    (
        "[world.bounds]",
        "[map]\np_min = 1.2\n[world.bounds]",
        "map.p_min",
        5,
        9,
        "must be a probability in (0, 1)",
    ),
    (
        "[world.bounds]",
        "[map]\np_min = 0.3\np_max = 0.2\n[world.bounds]",
        "map.p_min",
        5,
        9,
        "must be below p_max (0.2)",
    ),
];

#[test]
fn each_semantic_class_has_its_own_message_at_its_line() {
    for &(old, new, path, line, column, message) in SEMANTIC {
        let d = only(&with(old, new));
        assert_eq!(
            (d.path.as_str(), d.line, d.column, d.message.as_str()),
            (path, line, column, message),
            "for {new:?}: {d}"
        );
    }
}

#[test]
fn uav_set_problems() {
    let second = format!(
        "{BASE}\n[[uav]]\nname = \"a\"\nstart = {{ position = [2.0, 2.0, 1.0] }}\n\
         behaviour = {{ kind = \"scripted\", speed = 1.0, waypoints = [[1.0, 1.0, 1.0]] }}\n"
    );
    assert_only(
        &second,
        "uav[1].name",
        23,
        8,
        "must be a name no other UAV has (uav[0] is also called \"a\")",
    );
    let none = &BASE[..BASE.find("[[uav]]").unwrap()];
    assert_only(
        none,
        "uav",
        1,
        1,
        "the scenario has no UAV: add a [[uav]] table",
    );
}

#[test]
fn problems_found_after_loading_are_located_by_field_path() {
    let text = format!("{BASE}\n[[world.obstacle]]\nkind = \"mesh\"\nfile = \"gone.obj\"\n");
    let loaded = parse_str(&text, "scenarios/x.toml").unwrap();
    let d = loaded.diagnostic("world.obstacle[0].file", "mesh file not found");
    assert_eq!(
        d.to_string(),
        "scenarios/x.toml:24:8: world.obstacle[0].file: mesh file not found"
    );
    // A path the file does not write is shown at its enclosing table.
    assert_eq!(loaded.locate("world.obstacle[0].scale").line, 22);
    let errors = loaded.errors([("uav[0].start.position", "starts inside obstacle 'crate'")]);
    assert_eq!(errors.diagnostics[0].line, 10);
    assert_eq!(
        loaded.resolve(std::path::Path::new("meshes/a.obj")),
        std::path::Path::new("scenarios/meshes/a.obj")
    );
}

#[test]
fn check_again_after_editing_a_loaded_scenario() {
    use uavex_engine::scenario::{SensorSpec, check};
    let mut loaded = parse_str(BASE, "x.toml").unwrap();
    assert!(check(&loaded).is_empty());
    // A sweep sets parameters on the typed scenario; the same checks, at the same places.
    if let SensorSpec::DepthCamera { range_min, .. } = &mut loaded.scenario.uavs[0].sensors[0] {
        *range_min = 6.0;
    }
    loaded.scenario.time_limit_s = f64::NAN;
    let all: Vec<String> = check(&loaded).iter().map(ToString::to_string).collect();
    assert_eq!(
        all,
        [
            "x.toml:2:16: time_limit_s: must be a finite number, got NaN",
            "x.toml:14:13: uav[0].sensor[0].range_min: must be below range_max (5.0), got 6.0",
        ]
    );
}
