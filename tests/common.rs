//! Helpers shared by the integration tests.
#![allow(dead_code)]

use uavex::components::sim::RunSeed;
use uavex::components::world::WorldGeometry;
use uavex::engine::output::RunSummary;
use uavex::engine::run::{RunOptions, run};
use uavex::engine::scenario::{LoadedScenario, parse_str};
use uavex::engine::sim::Sim;
use uavex::engine::world::build_world;

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

/// For each of `seeds`: builds the world of `loaded` with nothing kept clear (only the
/// starts' `start_clearance`) and the run itself, asserts that the run's world is not
/// `blocked` and that it lacks obstacles exactly when the bare world was blocked (at most
/// `max_removed` of them); returns the seeds whose bare world was blocked, i.e. the ones a
/// run's start check used to refuse.
pub fn seeds_kept_clear(
    loaded: &LoadedScenario,
    seeds: std::ops::RangeInclusive<u64>,
    blocked: impl Fn(&WorldGeometry) -> bool,
    max_removed: usize,
) -> Vec<u64> {
    let starts: Vec<glam::Vec3> = loaded
        .scenario
        .uavs
        .iter()
        .map(|u| glam::DVec3::from_array(u.start.position).as_vec3())
        .collect();
    let mut drawn_into_it = Vec::new();
    for seed in seeds {
        let bare = build_world(
            &loaded.scenario.world,
            RunSeed(seed),
            &starts,
            &[],
            &loaded.base_dir,
        )
        .unwrap_or_else(|e| panic!("{e:?}"));
        if blocked(&bare) {
            drawn_into_it.push(seed);
        }
        let sim = Sim::build(loaded, seed).unwrap_or_else(|e| panic!("seed {seed}: {e}"));
        let world = sim.world.resource::<WorldGeometry>();
        assert!(!blocked(world), "seed {seed}");
        let removed = bare.obstacles().len() - world.obstacles().len();
        assert_eq!(
            removed > 0,
            blocked(&bare),
            "seed {seed}: {removed} removed"
        );
        assert!(removed <= max_removed, "seed {seed}: {removed} removed");
    }
    drawn_into_it
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
