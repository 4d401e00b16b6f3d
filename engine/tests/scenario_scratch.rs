use uavex_engine::scenario::parse_str;
const BASE: &str = r#"name = "t"
time_limit_s = 60.0

[world.bounds]
min = [0.0, 0.0, 0.0]
max = [10.0, 10.0, 3.0]

[[uav]]
name = "a"
start = { position = [1.0, 1.0, 1.0] }

[[uav.sensor]]
kind = "depth_camera"
range_min = 0.5
range_max = 5.0

[uav.behaviour]
kind = "scripted"
speed = 1.0
waypoints = [[5.0, 5.0, 1.0]]
"#;
fn show(label: &str, text: &str) {
    println!("== {label}");
    match parse_str(text, "x.toml") {
        Ok(_) => println!("OK"),
        Err(e) => println!("{e}"),
    }
}
#[test]
fn scratch() {
    show("base", BASE);
    show("typo", &BASE.replace("range_max = 5.0", "rnage_max = 5.0"));
    show("typo top", &BASE.replace("time_limit_s", "time_limt_s"));
    show(
        "type",
        &BASE.replace("range_max = 5.0", "range_max = \"far\""),
    );
    show(
        "kind",
        &BASE.replace("kind = \"scripted\"", "kind = \"eaae\""),
    );
    show(
        "sensor kind",
        &BASE.replace("kind = \"depth_camera\"", "kind = \"depth-camera\""),
    );
    show(
        "mount typo",
        &BASE.replace(
            "range_min = 0.5",
            "range_min = 0.5\nmount = { rpyy = [0, 0, 0] }",
        ),
    );
    show(
        "waypoint len",
        &BASE.replace("[[5.0, 5.0, 1.0]]", "[[5.0, 5.0, 1.0], [1.0, 2.0]]"),
    );
    show(
        "ray grid",
        &BASE.replace("range_min = 0.5", "range_min = 0.5\nray_grid = \"fine\""),
    );
    show(
        "missing start",
        &BASE.replace("start = { position = [1.0, 1.0, 1.0] }", ""),
    );
    show(
        "missing bounds max",
        &BASE.replace("max = [10.0, 10.0, 3.0]", ""),
    );
    show(
        "range order",
        &BASE.replace("range_min = 0.5", "range_min = 6.0"),
    );
    show("nan", &BASE.replace("speed = 1.0", "speed = nan"));
    show(
        "many",
        &BASE
            .replace("range_max = 5.0", "rnage_max = 5.0")
            .replace("speed = 1.0", "speed = -1.0")
            .replace("time_limit_s = 60.0", "time_limit_s = \"x\"")
            .replace("name = \"a\"", "name = \"a\"\nairframe = \"kingfsher\""),
    );
    show(
        "syntax",
        &BASE
            .replace("speed = 1.0", "speed = = 1.0")
            .replace("name = \"t\"", "name = "),
    );
    show("no uav", &BASE[..BASE.find("[[uav]]").unwrap()]);
    show("kind int", &BASE.replace("kind = \"scripted\"", "kind = 5"));
    show("no kind", &BASE.replace("kind = \"scripted\"", ""));
    show("uav int", &BASE.replace("[[uav]]", "[[uavx]]"));
    show(
        "datetime",
        &BASE.replace("speed = 1.0", "speed = 1979-05-27"),
    );
    show(
        "width neg",
        &BASE.replace("range_min = 0.5", "range_min = 0.5\nwidth = -5"),
    );
    show(
        "bounds",
        &BASE.replace("max = [10.0, 10.0, 3.0]", "max = [10.0, 0.0, 3.0]"),
    );
}
