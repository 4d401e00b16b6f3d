//! The shipped scripted tour of the Pillars scene maps the scene: the whole pipeline (scenario,
//! world, sensing, map, metrics) end to end (issue 2, "Must show").

mod common;

use uavex::components::sim::Outcome;
use uavex::engine::scenario;

#[test]
fn scripted_tour_explores_pillars_and_agrees_with_ground_truth() {
    let loaded = scenario::load("scenarios/pillars_scripted.toml").unwrap();
    let summary = common::run_quietly(&loaded);
    assert_eq!(summary.outcome, Outcome::Complete, "{}", summary.reason);
    assert!(
        summary.explored_fraction >= 0.90,
        "explored only {:.3} of the box",
        summary.explored_fraction
    );
    let accuracy = summary.map_accuracy.expect("a map was built");
    assert!(accuracy >= 0.99, "map accuracy {accuracy:.4}");
    // The thresholds are crossed in order, within the mission.
    let t50 = summary.time_to_explored_50_s.unwrap();
    let t90 = summary.time_to_explored_90_s.unwrap();
    assert!(0.0 < t50 && t50 < t90 && t90 <= summary.mission_time_s);
}
