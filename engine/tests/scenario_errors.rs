//! Bad scenario files, structure: syntax, unknown fields, types, kinds, missing fields and
//! non-finite numbers each give their own message at their field path, line and column, and
//! all problems of a file are reported at once.

mod scenario_common;

use scenario_common::{BASE, assert_only, diagnostics, only, with};
use uavex_engine::scenario::{load, parse_str};

#[test]
fn the_base_scenario_loads() {
    let loaded = parse_str(BASE, "scenarios/x.toml").unwrap();
    assert_eq!(loaded.scenario.uavs.len(), 1);
    assert_eq!(loaded.base_dir, std::path::Path::new("scenarios"));
    assert_eq!(
        parse_str(BASE, "x.toml").unwrap().base_dir,
        std::path::Path::new(".")
    );
}

#[test]
fn display_has_file_line_column_path_message_and_what_was_found() {
    let d = only(&with("range_min = 0.5", "range_min = 6.0"));
    assert_eq!(
        d.to_string(),
        "x.toml:14:13: uav[0].sensor[0].range_min: must be below range_max (5.0), got 6.0"
    );
    assert_eq!(d.expected.as_deref(), Some("below range_max (5.0)"));
    assert_eq!(d.found.as_deref(), Some("6.0"));
}

#[test]
fn unknown_field_suggests_the_closest_name() {
    let d = assert_only(
        &with("range_max = 5.0", "rnage_max = 5.0"),
        "uav[0].sensor[0].rnage_max",
        15,
        1,
        "unknown field `rnage_max`, did you mean `range_max`?",
    );
    let expected = d.expected.unwrap();
    assert!(
        expected.starts_with("one of `width`, `height`, `hfov`"),
        "{expected}"
    );
    // At the top level, and inside an inline table of a `kind` table.
    assert_only(
        &with("time_limit_s = 60.0", "time_limit_s = 60.0\nsed = 3"),
        "sed",
        3,
        1,
        "unknown field `sed`, did you mean `seed`?",
    );
    assert_only(
        &with(
            "range_min = 0.5",
            "range_min = 0.5\nmount = { rpyy = [0, 0, 0] }",
        ),
        "uav[0].sensor[0].mount.rpyy",
        15,
        11,
        "unknown field `rpyy`, did you mean `rpy`?",
    );
}

#[test]
fn unknown_field_without_a_near_name_lists_the_valid_ones() {
    assert_only(
        &with("[world.bounds]", "[world.bounds]\ncolour = 1"),
        "world.bounds.colour",
        5,
        1,
        "unknown field `colour`, expected one of `min` or `max`",
    );
    // A field of another kind: `radius` is a sphere's, not a box's.
    let text = format!(
        "{BASE}\n[[world.obstacle]]\nkind = \"box\"\ncenter = [5.0, 5.0, 1.0]\nsize = [1.0, 1.0, 1.0]\nradius = 2.0\n"
    );
    let d = assert_only(
        &text,
        "world.obstacle[0].radius",
        26,
        1,
        "unknown field `radius`, expected one of `name`, `center`, `size` or `yaw`",
    );
    assert_eq!(
        d.expected.as_deref(),
        Some("one of `name`, `center`, `size` or `yaw`")
    );
}

#[test]
fn type_errors_name_the_value_and_what_was_expected() {
    let d = assert_only(
        &with("range_max = 5.0", "range_max = \"far\""),
        "uav[0].sensor[0].range_max",
        15,
        13,
        "expected a number",
    );
    assert_eq!(d.found.as_deref(), Some("string \"far\""));
    let d = assert_only(
        &with("time_limit_s = 60.0", "time_limit_s = [60]"),
        "time_limit_s",
        2,
        16,
        "expected a number",
    );
    assert_eq!(d.found.as_deref(), Some("an array"));
    let d = assert_only(
        &with("range_min = 0.5", "range_min = 0.5\nwidth = -640"),
        "uav[0].sensor[0].width",
        15,
        9,
        "expected a whole number from 0 to 4294967295",
    );
    assert_eq!(d.found.as_deref(), Some("integer `-640`"));
    let d = assert_only(
        &with("[[5.0, 5.0, 1.0]]", "[[5.0, 5.0, 1.0], [1.0, 2.0]]"),
        "uav[0].behaviour.waypoints[1]",
        20,
        31,
        "expected an array of length 3",
    );
    assert_eq!(d.found.as_deref(), Some("2 elements"));
    assert_only(
        &with("range_min = 0.5", "range_min = 0.5\nray_grid = \"fine\""),
        "uav[0].sensor[0].ray_grid",
        15,
        12,
        "expected \"auto\" or [columns, rows]",
    );
    assert_only(
        &with("speed = 1.0", "speed = 1979-05-27"),
        "uav[0].behaviour.speed",
        19,
        9,
        "expected a number, string, boolean, array or table",
    );
}

#[test]
fn errors_in_an_exploration_behaviour_are_reported_at_their_field() {
    // These were all reported at `kind` or the behaviour table ("unknown behaviour 'greedy'").
    let explore = |settings: &str| {
        with(
            "kind = \"scripted\"\nspeed = 1.0\nwaypoints = [[5.0, 5.0, 1.0]]",
            &format!("kind = \"explore\"\n{settings}"),
        )
    };
    assert_only(
        &explore("strategy = \"greedy\""),
        "uav[0].behaviour.strategy",
        19,
        12,
        "unknown value 'greedy', expected one of: eaae, classic, nearest, tour",
    );
    assert_only(
        &explore("strategy = \"eaae\"\nevaluate = \"most\""),
        "uav[0].behaviour.evaluate",
        20,
        12,
        "unknown value 'most', expected one of: needed, all",
    );
    assert_only(
        &explore("strategy = \"eaae\"\ncandidates = \"some\""),
        "uav[0].behaviour.candidates",
        20,
        14,
        "expected a whole number of clusters, or \"all\"",
    );
    assert_only(
        &explore("strategy = \"eaae\"\nenergy_budget = {}"),
        "uav[0].behaviour.energy_budget.reserve_j",
        20,
        1,
        "required field is missing",
    );
}

#[test]
fn unknown_kinds_name_what_this_build_knows() {
    assert_only(
        &with("kind = \"scripted\"", "kind = \"eaae\""),
        "uav[0].behaviour.kind",
        18,
        8,
        "unknown behaviour 'eaae' for uav[0]: this build knows: scripted, waypoints, coverage, explore",
    );
    assert_only(
        &with("kind = \"depth_camera\"", "kind = \"depth-camera\""),
        "uav[0].sensor[0].kind",
        13,
        8,
        "unknown sensor kind 'depth-camera': this build knows: depth_camera, lidar \
         (did you mean 'depth_camera'?)",
    );
    let text = format!("{BASE}\n[[world.obstacle]]\nkind = \"cone\"\n");
    assert_only(
        &text,
        "world.obstacle[0].kind",
        23,
        8,
        "unknown obstacle kind 'cone': this build knows: box, cylinder, sphere, mesh, cloud, pillars",
    );
    assert_only(
        &with("kind = \"scripted\"", "kind = 5"),
        "uav[0].behaviour.kind",
        18,
        8,
        "expected a kind name (a string)",
    );
}

#[test]
fn missing_fields_point_at_their_table() {
    assert_only(
        &with("start = { position = [1.0, 1.0, 1.0] }", ""),
        "uav[0].start",
        8,
        1,
        "required field is missing",
    );
    assert_only(
        &with("max = [10.0, 10.0, 3.0]", ""),
        "world.bounds.max",
        4,
        1,
        "required field is missing",
    );
    assert_only(
        &with("kind = \"scripted\"", ""),
        "uav[0].behaviour.kind",
        17,
        1,
        "required field is missing; this build knows: scripted, waypoints, coverage, explore",
    );
    assert_only(
        &with("time_limit_s = 60.0", ""),
        "time_limit_s",
        1,
        1,
        "required field is missing",
    );
}

#[test]
fn syntax_errors_are_located() {
    let all =
        diagnostics(&with("speed = 1.0", "speed = = 1.0").replacen("name = \"t\"", "name = ", 1));
    let lines: Vec<usize> = all.iter().map(|d| d.line).collect();
    assert!(lines.contains(&1) && lines.contains(&19), "{all:#?}");
    assert!(
        all.iter()
            .all(|d| d.path.is_empty() && d.message.starts_with("TOML syntax: "))
    );
}

#[test]
fn non_finite_numbers_are_refused_where_written() {
    let d = assert_only(
        &with("speed = 1.0", "speed = nan"),
        "uav[0].behaviour.speed",
        19,
        9,
        "must be a finite number",
    );
    assert_eq!(d.found.as_deref(), Some("NaN"));
    let d = assert_only(
        &with("max = [10.0, 10.0, 3.0]", "max = [10.0, inf, 3.0]"),
        "world.bounds.max[1]",
        6,
        14,
        "must be a finite number",
    );
    assert_eq!(d.found.as_deref(), Some("inf"));
    // Finite in the file but infinite as the 32-bit float the geometry stores (a pillar radius of
    // 1e39 used to panic while the world was built).
    let d = assert_only(
        &with("max = [10.0, 10.0, 3.0]", "max = [10.0, 1e39, 3.0]"),
        "world.bounds.max[1]",
        6,
        14,
        "must be at most 3.4e38 in magnitude (positions and sizes are 32-bit floats)",
    );
    assert_eq!(d.found.as_deref(), Some("1e39"));
}

#[test]
fn every_problem_of_a_file_is_reported_at_once_in_file_order() {
    let text = r#"name = "many"
time_limit_s = "soon"
colour = "red"

[world.bounds]
min = [0.0, 0.0, 0.0]
max = [10.0, 10.0, 0.0]

[[world.obstacle]]
kind = "box"
center = [1.0, 1.0, 1.0]
size = [1.0, -1.0, 1.0]

[[world.obstacle]]
kind = "sphere"
centre = [1.0, 1.0, 1.0]
radius = "big"

[[uav]]
name = "a"
airframe = "kingfsher"
start = { position = [1.0, 1.0, 1.0] }
behaviour = { kind = "scripted", speed = 0.0, waypoints = [[1.0, 2.0, 1.0]] }

[[uav.sensor]]
kind = "depth_camera"
range_min = 6.0

[[uav.sensor]]
kind = "lidar"
beams_h = "many"

[[uav]]
name = "b"
start = { position = [1.0, 1.0, 1.0] }
behaviour = { kind = "patrol" }
"#;
    let all = diagnostics(text);
    let got: Vec<(usize, &str, &str)> = all
        .iter()
        .map(|d| (d.line, d.path.as_str(), d.message.as_str()))
        .collect();
    let expected: Vec<(usize, &str, &str)> = vec![
        // Structure (unknown fields, types, kinds), in file order.
        (2, "time_limit_s", "expected a number"),
        (
            3,
            "colour",
            "unknown field `colour`, expected one of `name`, `seed`, `time_limit_s`, \
                       `physics_rate_hz`, `map`, `world`, `uav` or `outputs`",
        ),
        (
            16,
            "world.obstacle[1].centre",
            "unknown field `centre`, did you mean `center`?",
        ),
        (17, "world.obstacle[1].radius", "expected a number"),
        (
            31,
            "uav[0].sensor[1].beams_h",
            "expected a whole number from 0 to 4294967295",
        ),
        (
            36,
            "uav[1].behaviour.kind",
            "unknown behaviour 'patrol' for uav[1]: this build knows: scripted, waypoints, coverage, explore",
        ),
        // Meaning, of every piece that decoded, in file order.
        (
            7,
            "world.bounds.max[2]",
            "must be above world.bounds.min[2] (0.0): the bounds need a positive extent along z",
        ),
        (12, "world.obstacle[0].size[1]", "must be above 0"),
        (
            21,
            "uav[0].airframe",
            "unknown airframe preset 'kingfsher': this build knows: kingfisher, iris (did you mean 'kingfisher'?)",
        ),
        (23, "uav[0].behaviour.speed", "must be above 0"),
        (
            27,
            "uav[0].sensor[0].range_min",
            "must be below range_max (5.0)",
        ),
    ];
    assert_eq!(got, expected, "{all:#?}");
    // The missing `center` of the sphere is not reported: `centre` was reported instead and
    // the loader cut it out; a missing field ends its entry, which is why no error follows.
}

#[test]
fn one_bad_entry_does_not_hide_the_next() {
    let text = format!(
        "{BASE}\n[[uav.sensor]]\nkind = \"lidar\"\nrate_hz = \"fast\"\n\
         [[uav.sensor]]\nkind = \"lidar\"\nrange_max = \"far\"\n"
    );
    let paths: Vec<String> = diagnostics(&text).into_iter().map(|d| d.path).collect();
    assert_eq!(
        paths,
        ["uav[0].sensor[1].rate_hz", "uav[0].sensor[2].range_max"]
    );
}

#[test]
fn unreadable_and_non_utf8_files() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("missing.toml");
    let errors = load(&missing).unwrap_err();
    assert_eq!(errors.diagnostics.len(), 1);
    let d = &errors.diagnostics[0];
    assert_eq!((d.line, d.column), (0, 0));
    assert!(
        d.message.starts_with("cannot read the scenario file"),
        "{d}"
    );
    assert!(
        d.to_string()
            .starts_with(&format!("{}: cannot read", missing.display()))
    );

    let latin1 = dir.path().join("latin1.toml");
    std::fs::write(&latin1, b"name = \"t\"\n# caf\xe9\n").unwrap();
    let d = load(&latin1).unwrap_err().diagnostics.remove(0);
    assert_eq!(
        (d.line, d.column, d.message.as_str()),
        (2, 6, "the file is not valid UTF-8 text")
    );
}
