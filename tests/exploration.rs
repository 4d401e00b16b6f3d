//! Exploration end to end (issue 4 "Must show"): every strategy explores the EAAE scenes to at
//! least 95 % of the reachable volume without crashing, on two seeds; a seed fixes the decision
//! log; a closed room is never entered and the run still ends `complete`; a forest of round
//! trunks is explored to the end; a battery-limited run flies home; a strategy is added as one
//! system without touching the others.

mod common;

use bevy_ecs::prelude::*;
use bevy_ecs::system::SystemState;
use std::collections::BTreeSet;
use uavex::components::exploration::{
    CandidateRecord, CandidateScope, Chosen, DecisionLog, GoalKind, GoalOutcome,
};
use uavex::components::map::MapConfig;
use uavex::components::sim::Outcome;
use uavex::components::world::WorldGeometry;
use uavex::engine::exploration::setup::StartCapsule;
use uavex::engine::exploration::{
    BudgetSpec, CandidateCount, Evaluate, ExploreSpec, StrategyName, decisions_csv,
};
use uavex::engine::flight::airframe_of;
use uavex::engine::output::RunSummary;
use uavex::engine::reachable::ReachableVolume;
use uavex::engine::run::{RunOptions, run};
use uavex::engine::scenario::{BehaviourSpec, LoadedScenario, load};
use uavex::engine::sim::Sim;
use uavex::systems::exploration::DecideStep;
use uavex::systems::exploration::strategy::{
    CandidateQuery, ClassicStrategy, Deciding, choosable, first_min_by,
};
use uavex::systems::mapping::MapReader;

/// The goal options beyond the thesis: the standoff and the frontier viewpoint.
#[path = "exploration/goal_options.rs"]
mod goal_options;

/// A shipped scene with its UAV exploring by `strategy`.
fn scene(file: &str, strategy: StrategyName) -> LoadedScenario {
    let mut loaded = load(format!("{}/scenarios/{file}", env!("CARGO_MANIFEST_DIR")))
        .unwrap_or_else(|e| panic!("{e}"));
    loaded.scenario.uavs[0].behaviour = BehaviourSpec::Explore(ExploreSpec {
        strategy,
        candidates: CandidateCount::Count(3),
        evaluate: Evaluate::Needed,
        unified: false,
        replan_hz: 2.0,
        energy_budget: None,
        standoff_m: None,
        frontier_viewpoint: false,
    });
    loaded
}

fn run_seed(loaded: &LoadedScenario, seed: u64) -> RunSummary {
    run(
        loaded,
        &RunOptions {
            seed: Some(seed),
            ..RunOptions::default()
        },
    )
    .unwrap_or_else(|e| panic!("{e}"))
    .summary
}

/// Explored to >= 95 % of the reachable volume, complete, no crash.
fn assert_explored(file: &str, strategy: StrategyName, seed: u64) {
    let summary = run_seed(&scene(file, strategy), seed);
    let keys = summary
        .exploration
        .expect("an exploration run has exploration keys");
    let reachable = keys
        .explored_reachable_pct
        .expect("the reachable volume floods");
    assert_eq!(
        summary.outcome,
        Outcome::Complete,
        "{file} {strategy:?} seed {seed}: {} ({reachable:.1} % explored)",
        summary.reason
    );
    assert!(
        summary.uavs.iter().all(|u| u.status == "finished"),
        "{:?}",
        summary.uavs
    );
    assert!(
        reachable >= 95.0,
        "{file} {strategy:?} seed {seed}: {reachable:.2} % of the reachable volume"
    );
    assert!(keys.decisions >= 5, "{keys:?}");
    assert_eq!(keys.completion_time_s, Some(summary.mission_time_s));
}

macro_rules! explores {
    ($($name:ident: $file:literal, $strategy:ident, $seed:literal;)*) => {$(
        #[test]
        fn $name() {
            assert_explored($file, StrategyName::$strategy, $seed);
        }
    )*};
}

explores! {
    eaae_explores_pillars_seed_1: "eaae_pillars.toml", Eaae, 1;
    eaae_explores_pillars_seed_2: "eaae_pillars.toml", Eaae, 2;
    classic_explores_pillars_seed_1: "eaae_pillars.toml", Classic, 1;
    classic_explores_pillars_seed_2: "eaae_pillars.toml", Classic, 2;
    nearest_explores_pillars_seed_1: "eaae_pillars.toml", Nearest, 1;
    nearest_explores_pillars_seed_2: "eaae_pillars.toml", Nearest, 2;
    eaae_explores_simple_seed_1: "eaae_simple.toml", Eaae, 1;
    eaae_explores_simple_seed_2: "eaae_simple.toml", Eaae, 2;
    classic_explores_simple_seed_1: "eaae_simple.toml", Classic, 1;
    classic_explores_simple_seed_2: "eaae_simple.toml", Classic, 2;
    nearest_explores_simple_seed_1: "eaae_simple.toml", Nearest, 1;
    nearest_explores_simple_seed_2: "eaae_simple.toml", Nearest, 2;
    tour_explores_pillars_seed_1: "eaae_pillars.toml", Tour, 1;
    tour_explores_simple_seed_1: "eaae_simple.toml", Tour, 1;
}

/// The decision log of the first `seconds` of a run.
fn decision_log(loaded: &mut LoadedScenario, seed: u64, seconds: f64) -> String {
    loaded.scenario.time_limit_s = seconds;
    let mut sim = Sim::build(loaded, seed).unwrap_or_else(|e| panic!("{e}"));
    sim.run_to_end();
    decisions_csv(sim.world.resource::<DecisionLog>())
}

#[test]
fn a_seed_fixes_the_decision_log() {
    let mut loaded = scene("eaae_pillars.toml", StrategyName::Eaae);
    let first = decision_log(&mut loaded, 7, 30.0);
    let again = decision_log(&mut loaded, 7, 30.0);
    assert!(first.lines().count() > 10, "{first}");
    assert_eq!(first, again);
}

#[test]
fn a_closed_room_is_not_entered_and_the_run_completes() {
    assert_closed_room_not_entered(None);
}

/// With the standoff option too, no goal or candidate lies in the closed room, and the run
/// completes.
#[test]
fn a_closed_room_is_not_entered_with_the_standoff_either() {
    assert_closed_room_not_entered(Some(2.5));
}

/// The shipped closed-room scene explored with `standoff_m`: complete, no goal or candidate
/// in the room, >= 95 % of the reachable volume explored.
fn assert_closed_room_not_entered(standoff_m: Option<f64>) {
    let path = format!(
        "{}/scenarios/eaae_closed_room.toml",
        env!("CARGO_MANIFEST_DIR")
    );
    let mut loaded = load(&path).unwrap_or_else(|e| panic!("{e}"));
    let BehaviourSpec::Explore(explore) = &mut loaded.scenario.uavs[0].behaviour else {
        panic!("the closed room's UAV explores");
    };
    explore.standoff_m = standoff_m;
    let mut sim = Sim::build(&loaded, 1).unwrap_or_else(|e| panic!("{e}"));
    let (outcome, reason) = sim.run_to_end();
    assert_eq!(outcome, Outcome::Complete, "{reason}");
    // The room: 3 x 3 m centred at (6, -6), walls 0.15 m thick. No goal, and no candidate,
    // ever lay inside it.
    let inside = |p: [f32; 3]| (p[0] - 6.0).abs() < 1.5 && (p[1] + 6.0).abs() < 1.5;
    let log = sim.world.resource::<DecisionLog>();
    for decision in &log.decisions {
        for candidate in &decision.candidates {
            assert!(!inside(candidate.goal), "{candidate:?}");
        }
    }
    // The reachable volume excludes the room, and nearly all of it was seen.
    let (volume, explored) = reachable_explored(&mut sim);
    let room_centre = sim
        .world
        .resource::<MapConfig>()
        .key_of(glam::Vec3::new(6.0, -6.0, 1.0))
        .unwrap();
    assert!(!volume.contains(room_centre));
    assert!(explored >= 95.0, "{explored}");
}

/// The volume reachable from the start (0, 0, 1) of a run that ended, and the share of it
/// its map explored (%).
fn reachable_explored(sim: &mut Sim) -> (ReachableVolume, f64) {
    let world = &mut sim.world;
    let volume = ReachableVolume::flood(
        world.resource::<MapConfig>(),
        world.resource::<WorldGeometry>(),
        glam::Vec3::new(0.0, 0.0, 1.0),
    )
    .unwrap();
    let mut reader = SystemState::<MapReader>::new(world);
    let explored = volume.explored_pct(&reader.get(world).unwrap());
    (volume, explored)
}

/// Round trunks leave frontier voxels around their insides that no flight clears; before they
/// were ignored at a reached goal ([`uavex::systems::exploration::interior`]), this forest's
/// mission flew between them until its time limit (400 s, 99.997 % of the reachable volume
/// explored), as 13 of 24 missions in a larger study did until their batteries were empty.
#[test]
fn a_forest_of_round_trunks_is_explored_to_the_end() {
    let path = format!("{}/scenarios/eaae_forest.toml", env!("CARGO_MANIFEST_DIR"));
    let loaded = load(&path).unwrap_or_else(|e| panic!("{e}"));
    // The limit the mission without the rule ran to (the shipped scene allows 600 s).
    assert_forest_complete_within(loaded, 2, 400.0);
}

/// Runs `loaded` (a forest) on `seed` with the time limit `limit_s`: it must end `complete`
/// before it, at >= 99 % of the reachable volume.
fn assert_forest_complete_within(mut loaded: LoadedScenario, seed: u64, limit_s: f64) {
    loaded.scenario.time_limit_s = limit_s;
    let summary = run_seed(&loaded, seed);
    let reachable = summary
        .exploration
        .as_ref()
        .and_then(|keys| keys.explored_reachable_pct)
        .expect("an exploration run floods its reachable volume");
    assert_eq!(
        summary.outcome,
        Outcome::Complete,
        "{} ({reachable:.3} % explored)",
        summary.reason
    );
    assert!(summary.mission_time_s < limit_s);
    assert!(reachable >= 99.0, "{reachable}");
}

/// The slivers around trunks that a UAV passes on its way are recognised when it next reaches a
/// goal, within its sensor's range, not only when one of them is the goal: searched behind the
/// goal's own voxels alone, this forest's Classic mission flew from sliver to sliver until its
/// 600 s limit (99.998 % of the reachable volume explored); it now ends `complete` in 326 s.
#[test]
fn slivers_around_trunks_in_sight_draw_no_flight() {
    // The shipped forest, flown by Classic (the scene's behaviour but for the strategy).
    let loaded = scene("eaae_forest.toml", StrategyName::Classic);
    assert_forest_complete_within(loaded, 36, 450.0);
}

/// A seeded forest keeps the explorer's start capsule clear by itself. Seeds that drew a trunk
/// into it (6, 7 and 11 of this forest's first 12) used to be refused when the run was built, so a sweep over
/// seeds lost them; now every seed builds, without the trunks the field drew there.
#[test]
fn every_seed_of_a_forest_leaves_the_explorers_start_capsule_clear() {
    let path = format!("{}/scenarios/eaae_forest.toml", env!("CARGO_MANIFEST_DIR"));
    let loaded = load(&path).unwrap_or_else(|e| panic!("{e}"));
    let scenario = &loaded.scenario;
    let spec = &scenario.uavs[0];
    let airframe = airframe_of(spec, 0).unwrap();
    let resolution = scenario.map.resolution;
    let capsule = StartCapsule::of_explorer(spec, &airframe, resolution).unwrap();
    let blocked = |world: &WorldGeometry| {
        capsule
            .centres(resolution)
            .any(|c| world.intersects_ball(c.as_vec3(), capsule.radius as f32))
    };
    // Only the trunks in the capsule go: one or two where a seed drew any.
    let drawn_into_it = common::seeds_kept_clear(&loaded, 1..=12, blocked, 2);
    assert_eq!(drawn_into_it, [6, 7, 11]);
}

/// A start nearer a face of the map than the planner's radius (here 0.20 m below the top of a
/// scene without a ceiling) would leave no path from the start, and the run would end
/// `complete` at once with the scene unexplored; it is refused when the run is built. The
/// radius itself is fine: 0.33 m below the top, the UAV explores.
#[test]
fn a_start_within_the_planning_radius_of_the_map_is_refused() {
    let mut loaded = scene("eaae_pillars.toml", StrategyName::Eaae);
    loaded.scenario.uavs[0].start.position = [0.0, 0.0, 2.3];
    let error = refused(&loaded, "a start 0.20 m below the map's top");
    assert!(
        error.contains("uav[0].start.position")
            && error.contains("planning radius, 0.320 m")
            && error.contains("0.200 m from a face"),
        "{error}"
    );
    loaded.scenario.uavs[0].start.position = [0.0, 0.0, 2.17];
    loaded.scenario.time_limit_s = 12.0;
    assert_explores_until_the_time_limit(&loaded, "a start 0.33 m below the top");
}

/// The space ahead of the start that the planner takes as free is checked against the
/// obstacles that reach into the map only: on a 0.2 m map it reaches below the floor from the
/// thesis' start at 1 m (1.22 m around its line), which the ground under the map does not
/// contradict, so the run is built and explores (it was refused). An obstacle inside the map in
/// that space is still refused, by name.
#[test]
fn the_start_capsule_is_checked_against_obstacles_inside_the_map() {
    let mut loaded = scene("eaae_pillars.toml", StrategyName::Eaae);
    loaded.scenario.map.resolution = 0.2;
    loaded.scenario.time_limit_s = 8.0;
    assert_explores_until_the_time_limit(&loaded, "the thesis' start on a 0.2 m map");

    let mut loaded = scene("eaae_pillars.toml", StrategyName::Eaae);
    // 0.6 m in front of pillar 1's north face, facing it.
    loaded.scenario.uavs[0].start.position = [-0.3643, -4.8, 1.0];
    loaded.scenario.uavs[0].start.yaw = -std::f64::consts::FRAC_PI_2;
    let error = refused(&loaded, "a start 0.6 m from a pillar, facing it");
    assert!(
        error.contains("uav[0].start.position")
            && error.contains("needs clear space around its start")
            && error.contains("obstacle 'pillar 1' (world.obstacle[4])"),
        "{error}"
    );
}

/// On a 0.2 m map, clearance measured between voxel centres understates a gap by up to a voxel;
/// with the thesis' 0.1 m margin, this Classic mission in the forest crashed into a trunk at
/// 61.7 s (as 6 other of 96 missions at 0.2 m did): its map held one voxel of the trunk at the
/// UAV's height, 0.4 m from the UAV's voxel, outside the 0.32 m inflation and inside 0.42 m.
/// With a margin of a voxel it flies on.
#[test]
fn a_coarse_map_keeps_the_body_off_what_it_mapped() {
    let mut loaded = scene("eaae_forest.toml", StrategyName::Classic);
    loaded.scenario.map.resolution = 0.2;
    loaded.scenario.time_limit_s = 70.0;
    let mut sim = Sim::build(&loaded, 108).unwrap_or_else(|e| panic!("{e}"));
    let (outcome, reason) = sim.run_to_end();
    assert_eq!(outcome, Outcome::TimeLimit, "{reason}");
}

/// The error with which building `loaded` (seed 1) is refused; panics if `case` is accepted.
fn refused(loaded: &LoadedScenario, case: &str) -> String {
    match Sim::build(loaded, 1) {
        Ok(_) => panic!("{case} was accepted"),
        Err(error) => error.to_string(),
    }
}

/// Runs `loaded` (seed 1) to its time limit and asserts it got there flying to frontier.
fn assert_explores_until_the_time_limit(loaded: &LoadedScenario, case: &str) {
    let mut sim = Sim::build(loaded, 1).unwrap_or_else(|e| panic!("{case}: {e}"));
    let (outcome, reason) = sim.run_to_end();
    assert_eq!(outcome, Outcome::TimeLimit, "{case}: {reason}");
    let log = sim.world.resource::<DecisionLog>();
    assert!(
        log.decisions
            .iter()
            .any(|d| d.goal_kind == Some(GoalKind::Frontier)),
        "{case}: {log:?}"
    );
}

/// Exploration starts whatever the UAV's heading at its start, not only along the map's axes.
/// The planner's lattice forbids cutting corners, so the stretch ahead of the start taken as
/// free must be wide enough for a diagonal chain of lattice cells; with a core one cell wide,
/// every heading more than about 0.2 rad off an axis ended `complete` after 3 s, unexplored.
#[test]
fn exploration_starts_from_headings_off_the_axes() {
    let mut loaded = scene("eaae_pillars.toml", StrategyName::Eaae);
    loaded.scenario.time_limit_s = 8.0;
    use std::f64::consts::{FRAC_PI_4, PI};
    for yaw in [
        PI / 12.0,
        FRAC_PI_4,
        3.0 * FRAC_PI_4,
        -FRAC_PI_4,
        -2.0 * PI / 3.0,
    ] {
        loaded.scenario.uavs[0].start.yaw = yaw;
        assert_explores_until_the_time_limit(&loaded, &format!("start yaw {yaw}"));
    }
}

#[test]
fn a_battery_limited_run_returns_home() {
    let mut loaded = scene("eaae_pillars.toml", StrategyName::Eaae);
    let uav = &mut loaded.scenario.uavs[0];
    // 0.6 Wh, 80 % usable: 1728 J, about 14 s of hover at 123 W; keep 300 J in reserve.
    uav.airframe_overrides
        .insert("battery_capacity_wh".to_owned(), 0.6);
    if let BehaviourSpec::Explore(explore) = &mut uav.behaviour {
        explore.energy_budget = Some(BudgetSpec { reserve_j: 300.0 });
    }
    let mut sim = Sim::build(&loaded, 1).unwrap_or_else(|e| panic!("{e}"));
    let (outcome, reason) = sim.run_to_end();
    assert_eq!(outcome, Outcome::ReturnedHome, "{reason}");
    let log = sim.world.resource::<DecisionLog>();
    let last = log.decisions.last().unwrap();
    assert_eq!(last.goal_kind, Some(GoalKind::Home), "{last:?}");
    // Some exploring came first.
    assert!(
        log.decisions
            .iter()
            .any(|d| d.goal_kind == Some(GoalKind::Frontier))
    );
    let position = sim
        .world
        .query::<&uavex::components::uav::QuadState>()
        .single(&sim.world)
        .unwrap()
        .position;
    assert!(
        position.distance(glam::Vec3::new(0.0, 0.0, 1.0)) < 0.35,
        "{position}"
    );
    let summary = run(&loaded, &RunOptions::default())
        .unwrap_or_else(|e| panic!("{e}"))
        .summary;
    assert_eq!(summary.outcome, Outcome::ReturnedHome);
    assert_eq!(summary.uavs[0].status, "returned_home");
    // It never drew into the reserve it kept for the way home.
    assert!(
        summary.energy_j.unwrap() <= 1728.0,
        "{:?}",
        summary.energy_j
    );
}

/// A toy strategy: the smallest information gain. One marker, one system, registered from
/// outside; the shipped strategies are not edited.
#[derive(Component)]
struct SmallestGain;

fn choose_smallest_gain(
    mut commands: Commands,
    uavs: Deciding<SmallestGain>,
    candidates: CandidateQuery,
) {
    for (uav, list) in &uavs {
        let views = choosable(list, &candidates);
        if let Some(pick) = first_min_by(&views, |c| f64::from(c.information_gain)) {
            commands.entity(uav).insert(Chosen(pick.entity));
        }
    }
}

#[test]
fn a_new_strategy_is_one_system() {
    let mut loaded = scene("eaae_pillars.toml", StrategyName::Classic);
    loaded.scenario.time_limit_s = 20.0;
    let mut sim = Sim::build(&loaded, 1).unwrap_or_else(|e| panic!("{e}"));
    let uav = sim
        .world
        .query_filtered::<Entity, With<ClassicStrategy>>()
        .single(&sim.world)
        .unwrap();
    // The marker, and which clusters its choice needs evaluated: all of them (the default of
    // a UAV without a scope; Classic's scope, the largest feasible one, would not do).
    sim.world
        .entity_mut(uav)
        .remove::<ClassicStrategy>()
        .insert((SmallestGain, CandidateScope::All));
    sim.add_systems(choose_smallest_gain.in_set(DecideStep::Choose));
    sim.run_to_end();
    let log = sim.world.resource::<DecisionLog>();
    let chosen: Vec<_> = log
        .decisions
        .iter()
        .filter(|d| d.chosen.is_some())
        .collect();
    assert!(chosen.len() >= 3, "{}", chosen.len());
    for d in chosen {
        let pick = &d.candidates[d.chosen.unwrap()];
        let smallest = d
            .candidates
            .iter()
            .map(|c| c.information_gain)
            .min()
            .unwrap();
        assert_eq!(pick.information_gain, smallest, "{d:?}");
        // And with several candidates the Classic rule would have chosen otherwise.
    }
    assert!(
        log.decisions.iter().any(|d| {
            let largest = d.candidates.iter().map(|c| c.information_gain).max();
            d.chosen
                .is_some_and(|i| Some(d.candidates[i].information_gain) != largest)
        }),
        "the toy strategy never differed from Classic"
    );
}

/// Unified mode flies the evaluated candidate itself: where it did so to the goal, the flown
/// energy is the predicted one, up to the rollout's model error (its integrator and the
/// 300 Hz sample-and-hold of the true flight; 0.49 % worst in the flight tests) and the start
/// state it was predicted from.
#[test]
fn unified_mode_flies_what_it_predicted() {
    let mut loaded = scene("eaae_pillars.toml", StrategyName::Eaae);
    if let BehaviourSpec::Explore(explore) = &mut loaded.scenario.uavs[0].behaviour {
        explore.unified = true;
    }
    loaded.scenario.time_limit_s = 60.0;
    let mut sim = Sim::build(&loaded, 1).unwrap_or_else(|e| panic!("{e}"));
    sim.run_to_end();
    let log = sim.world.resource::<DecisionLog>();
    let flown: Vec<_> = log
        .decisions
        .iter()
        .filter_map(|d| d.flown)
        .filter(|f| f.flew_candidate && f.outcome == GoalOutcome::Reached)
        .collect();
    assert!(
        flown.len() >= 5,
        "{} legs flown on the candidate",
        flown.len()
    );
    for leg in &flown {
        assert!(leg.prediction_error.abs() < 0.02, "{leg:?}");
    }
    // The default mode replans with the local planner: its legs differ more.
    let mut local = scene("eaae_pillars.toml", StrategyName::Eaae);
    local.scenario.time_limit_s = 60.0;
    let mut sim = Sim::build(&local, 1).unwrap_or_else(|e| panic!("{e}"));
    sim.run_to_end();
    let log = sim.world.resource::<DecisionLog>();
    let errors: Vec<f64> = log
        .decisions
        .iter()
        .filter_map(|d| d.flown)
        .filter(|f| f.outcome == GoalOutcome::Reached)
        .map(|f| f.prediction_error.abs())
        .collect();
    let mean_local = errors.iter().sum::<f64>() / errors.len() as f64;
    let mean_unified =
        flown.iter().map(|f| f.prediction_error.abs()).sum::<f64>() / flown.len() as f64;
    assert!(mean_unified < mean_local, "{mean_unified} vs {mean_local}");
}

/// The runs of the shipped sweep plan `file`, each checked to be a valid exploration of the
/// strategy (and, where the grid sets it, the candidate count) its grid values name, without
/// map export, and to satisfy `check`: (scene, grid values, seed) of each.
fn shipped_exploration_plan(
    file: &str,
    check: impl Fn(&ExploreSpec),
) -> BTreeSet<(String, String, u64)> {
    use uavex::engine::scenario::parse_str;
    use uavex::engine::sweep::{Plan, apply_overrides, expand};
    let path = format!("{}/scenarios/{file}", env!("CARGO_MANIFEST_DIR"));
    let plan = Plan::load(std::path::Path::new(&path)).unwrap_or_else(|e| panic!("{e}"));
    let mut seen = BTreeSet::new();
    for run in &expand(&plan) {
        let text = std::fs::read_to_string(&run.scenario_file).unwrap();
        let edited = apply_overrides(&text, &run.overrides).unwrap_or_else(|e| panic!("{e}"));
        let loaded = parse_str(&edited, &run.scenario_file).unwrap_or_else(|e| panic!("{e}"));
        let BehaviourSpec::Explore(explore) = &loaded.scenario.uavs[0].behaviour else {
            panic!("{} does not explore", run.id);
        };
        for (field, value) in &run.coordinates {
            let set = match field.as_str() {
                "uav.0.behaviour.strategy" => serde_json::to_value(explore.strategy),
                "uav.0.behaviour.candidates" => serde_json::to_value(explore.candidates),
                "uav.0.behaviour.frontier_viewpoint" => {
                    serde_json::to_value(explore.frontier_viewpoint)
                }
                other => panic!("{file}: unexpected grid field {other}"),
            };
            let named = serde_json::to_value(value).unwrap();
            assert_eq!(set.unwrap(), named, "{}: {field}", run.id);
        }
        assert!(!loaded.scenario.outputs.export_map);
        check(explore);
        let values: Vec<String> = run.coordinates.iter().map(|(_, v)| v.to_string()).collect();
        seen.insert((run.scene.clone(), values.join(", "), run.seed));
    }
    seen
}

/// The shipped protocol plan: 2 scenes x 3 strategies x 5 seeds.
#[test]
fn the_protocol_plan_runs_every_strategy_on_both_scenes() {
    let thesis_goals = |explore: &ExploreSpec| assert_eq!(explore.standoff_m, None);
    assert_eq!(
        shipped_exploration_plan("eaae_protocol.toml", thesis_goals).len(),
        30
    );
}

/// The shipped protocol with the standoff option: the same 30 runs, each with the option set.
#[test]
fn the_standoff_plan_runs_the_protocol_with_the_standoff() {
    let standoff = |explore: &ExploreSpec| assert_eq!(explore.standoff_m, Some(2.5));
    assert_eq!(
        shipped_exploration_plan("standoff_comparison.toml", standoff),
        shipped_exploration_plan("eaae_protocol.toml", |_| {})
    );
}

/// The shipped comparison of EAAE's choice with the tour: 2 scenes x 2 strategies x 2
/// candidate counts x 5 seeds.
#[test]
fn the_tour_comparison_plan_runs_both_strategies_both_ways() {
    assert_eq!(
        shipped_exploration_plan("tour_comparison.toml", |_| {}).len(),
        40
    );
}

/// The shipped wide-camera comparison: 4 scenes x 2 strategies x with and without the
/// frontier viewpoint x 2 seeds.
#[test]
fn the_wide_camera_plan_runs_both_strategies_with_and_without_the_frontier_viewpoint() {
    let plan = shipped_exploration_plan("wide_camera_comparison.toml", |_| {});
    assert_eq!(plan.len(), 32);
    let with_option = plan
        .iter()
        .filter(|(_, values, _)| values.split(", ").any(|value| value == "true"));
    assert_eq!(with_option.count(), 16);
}
