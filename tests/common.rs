//! Helpers shared by the integration tests.
#![allow(dead_code)]

use uavex::engine::output::RunSummary;
use uavex::engine::run::{RunOptions, run};
use uavex::engine::scenario::{LoadedScenario, parse_str};

/// Parses a scenario written in a test; panics with every diagnostic if it does not load.
pub fn scenario(text: &str) -> LoadedScenario {
    parse_str(text, "test.toml").unwrap_or_else(|e| panic!("test scenario refused:\n{e}"))
}

/// Runs a loaded scenario without writing files.
pub fn run_quietly(loaded: &LoadedScenario) -> RunSummary {
    run(loaded, &RunOptions::default())
        .unwrap_or_else(|e| panic!("world refused:\n{e}"))
        .summary
}

/// A 10 x 10 x 3 m room around the origin with walls at x = +-4 m (faces at +-4.0).
pub const ROOM: &str = r#"
[world.bounds]
min = [-5.0, -5.0, 0.0]
max = [5.0, 5.0, 3.0]

[[world.obstacle]]
kind = "box"
name = "east"
center = [4.05, 0.0, 1.5]
size = [0.1, 10.0, 3.0]

[[world.obstacle]]
kind = "box"
name = "west"
center = [-4.05, 0.0, 1.5]
size = [0.1, 10.0, 3.0]
"#;
