//! The goal options beyond the thesis (eaae.md steps 4 and 6): viewpoints at a standoff
//! distance, and the frontier voxel nearest to a cluster's centroid as a last viewpoint.

use super::*;
use uavex::engine::scenario::SensorSpec;

/// With the standoff option (beyond the thesis) a goal is a viewpoint 2.5 m from its
/// cluster's centroid, level with it, unless no viewpoint had a feasible trajectory (then the
/// centroid, as eaae.md step 6 plans); the mission still explores Pillars to the end.
#[test]
fn standoff_goals_view_their_clusters_from_a_distance() {
    let mut loaded = scene("eaae_pillars.toml", StrategyName::Eaae);
    if let BehaviourSpec::Explore(explore) = &mut loaded.scenario.uavs[0].behaviour {
        explore.standoff_m = Some(2.5);
    }
    let mut sim = Sim::build(&loaded, 1).unwrap_or_else(|e| panic!("{e}"));
    let (outcome, reason) = sim.run_to_end();
    assert_eq!(outcome, Outcome::Complete, "{reason}");
    let log = sim.world.resource::<DecisionLog>();
    let goals: Vec<_> = log
        .decisions
        .iter()
        .filter_map(|d| d.chosen.map(|i| &d.candidates[i]))
        .collect();
    let off = |c: &&CandidateRecord| {
        let [gx, gy, gz] = c.goal;
        let [cx, cy, cz] = c.centroid;
        ((gx - cx).hypot(gy - cy), (gz - cz).abs())
    };
    // A goal the planner could not reach exactly ends at the nearest traversable point (a
    // centroid near the floor, say), within a voxel layer or a few of it.
    let exactly_at_standoff = goals
        .iter()
        .filter(|c| {
            let (horizontal, vertical) = off(c);
            (horizontal - 2.5).abs() < 1e-3 && vertical < 1e-3
        })
        .count();
    let near_standoff_or_centroid = goals
        .iter()
        .filter(|c| {
            let (horizontal, vertical) = off(c);
            (horizontal - 2.5).abs() < 0.5 || horizontal.hypot(vertical) < 1.0
        })
        .count();
    assert_eq!(near_standoff_or_centroid, goals.len());
    assert!(
        goals.len() >= 20 && exactly_at_standoff * 4 >= goals.len() * 3,
        "{exactly_at_standoff} of {} goals at the standoff",
        goals.len()
    );
    let (_, explored) = reachable_explored(&mut sim);
    assert!(explored >= 95.0, "{explored}");
}

/// With a camera of wide field and long range (1.5 rad, 8 m: clusters up to 7.45 m in radius)
/// large clusters curve around the unexplored space they face, their centroids and the
/// thesis' viewpoints 0.5 m off lying out in it: this Pillars mission ended `complete` at 90 %
/// of the reachable volume, its last decisions finding no goal for the 2 clusters left. With
/// the frontier viewpoint it explores the rest.
#[test]
fn the_frontier_viewpoint_reaches_clusters_centred_in_unknown_space() {
    let explored = |frontier_viewpoint: bool| {
        let mut loaded = scene("eaae_pillars.toml", StrategyName::Eaae);
        let uav = &mut loaded.scenario.uavs[0];
        let SensorSpec::DepthCamera {
            hfov, range_max, ..
        } = &mut uav.sensors[0]
        else {
            panic!("Pillars' UAV carries a depth camera");
        };
        (*hfov, *range_max) = (1.5, 8.0);
        let BehaviourSpec::Explore(explore) = &mut uav.behaviour else {
            panic!("the UAV explores");
        };
        explore.frontier_viewpoint = frontier_viewpoint;
        let summary = run_seed(&loaded, 112);
        assert_eq!(summary.outcome, Outcome::Complete, "{}", summary.reason);
        summary
            .exploration
            .and_then(|keys| keys.explored_reachable_pct)
            .expect("the reachable volume floods")
    };
    let thesis = explored(false);
    assert!(thesis < 95.0, "{thesis}");
    let with_frontier_viewpoint = explored(true);
    assert!(with_frontier_viewpoint >= 99.0, "{with_frontier_viewpoint}");
}
