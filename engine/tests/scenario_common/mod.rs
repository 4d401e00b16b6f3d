//! The base scenario and helpers shared by the scenario tests.
#![allow(dead_code)]

use uavex_engine::scenario::{Diagnostic, parse_str};

/// A valid scenario; the line numbers in the tests below refer to it.
pub const BASE: &str = r#"name = "t"
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

/// `BASE` with `old` (which must occur once) replaced by `new`.
pub fn with(old: &str, new: &str) -> String {
    assert_eq!(BASE.matches(old).count(), 1, "{old:?} must occur once");
    BASE.replacen(old, new, 1)
}

pub fn diagnostics(text: &str) -> Vec<Diagnostic> {
    match parse_str(text, "x.toml") {
        Ok(_) => Vec::new(),
        Err(errors) => errors.diagnostics,
    }
}

/// The only diagnostic of `text`.
pub fn only(text: &str) -> Diagnostic {
    let mut all = diagnostics(text);
    assert_eq!(all.len(), 1, "expected one diagnostic, got:\n{all:#?}");
    all.remove(0)
}

/// Asserts path, line, column and message of the only diagnostic of `text`.
pub fn assert_only(
    text: &str,
    path: &str,
    line: usize,
    column: usize,
    message: &str,
) -> Diagnostic {
    let d = only(text);
    assert_eq!(
        (d.path.as_str(), d.line, d.column, d.message.as_str()),
        (path, line, column, message),
        "{d}"
    );
    d
}
