//! Tests of the ranked evaluation and the goal options (standoff, frontier viewpoint) on a
//! hand-made room.

use super::*;
use crate::exploration::propose::{with_frontier_viewpoints, with_standoff};
use crate::exploration::strategy::classic::largest_gain;
use crate::exploration::strategy::eaae::least_energy_among_largest_gain;
use crate::exploration::strategy::nearest::nearest;
use crate::exploration::strategy::tour::first_of_tour_among_largest_gain;
use crate::exploration::strategy::{
    CandidateView, ClassicStrategy, EaaeStrategy, NearestStrategy, TourStrategy,
};
use crate::mapping::{ChunkAccess, ChunkStore};
use crate::planning::search::GOAL_SNAP_RADIUS_M;
use bevy_ecs::entity::Entity;
use glam::IVec3;
use uavex_components::map::{ChunkCoord, MapConfig, MapSettings, local_index};

/// A 6.4 x 6.4 x 1.6 m room, known free, with a wall at x 3.0..3.2 m for y < 4 m and a
/// closed 1 m pocket (walls 0.2 m thick) from 4.6 to 6.0 m on x and y.
fn room() -> (MapConfig, ChunkStore, TraversableGrid) {
    let config = MapConfig::new(&MapSettings {
        resolution: 0.1,
        bounds_min: DVec3::ZERO,
        bounds_max: DVec3::new(6.4, 6.4, 1.6),
        ..MapSettings::default()
    })
    .unwrap();
    let mut store = ChunkStore::new(&config);
    let (lo, hi) = (config.key_min(), config.key_max());
    for z in lo.z..=hi.z {
        for y in lo.y..=hi.y {
            for x in lo.x..=hi.x {
                let key = IVec3::new(x, y, z);
                let pocket = |k: i32| (46..=47).contains(&k) || (58..=59).contains(&k);
                let around = |k: i32| (46..=59).contains(&k);
                let wall = (30..=31).contains(&x) && y < 40
                    || around(x) && around(y) && (pocket(x) || pocket(y));
                let coord = ChunkCoord::of_key(key);
                let flat = config.chunk_grid().flat(coord).unwrap();
                store.chunk_mut(flat, coord).0.voxels_mut()[local_index(key)].log_odds =
                    if wall { 3476 } else { -1992 };
            }
        }
    }
    let mut grid = TraversableGrid::new(&config, 0.27);
    grid.mark_all();
    grid.refresh(&store);
    (config, store, grid)
}

/// Clusters all over the room (the largest in the closed pocket, out of reach), with gains
/// that tie in places.
fn targets() -> Vec<ClusterTarget> {
    let spots = [
        ([5.0, 1.0, 0.8], 120),
        ([1.0, 5.5, 0.8], 300),
        ([5.3, 5.3, 0.8], 500), // in the pocket
        ([3.5, 5.5, 0.8], 300),
        ([2.0, 3.0, 0.8], 80),
        ([4.5, 3.0, 0.8], 200),
        ([0.8, 0.8, 0.8], 150),
    ];
    spots
        .iter()
        .enumerate()
        .map(|(i, &(c, size))| ClusterTarget {
            entity: Entity::from_raw_u32(i as u32 + 1).unwrap(),
            centroid: Vec3::from_array(c),
            size,
            viewpoints: Vec::new(),
            centroid_first: true,
        })
        .collect()
}

fn views(evaluation: &Evaluation, targets: &[ClusterTarget], at: Vec3) -> Vec<CandidateView> {
    evaluation
        .candidates
        .iter()
        .map(|e| {
            let target = &targets[e.candidate.target];
            CandidateView {
                entity: target.entity,
                goal: e.candidate.goal.as_vec3(),
                information_gain: target.size,
                centroid_distance_m: target.centroid.distance(at),
                path_length_m: e.candidate.plan.path_length_m as f32,
                energy_j: e.result.energy_j,
                duration_s: e.result.duration_s,
            }
        })
        .collect()
}

/// A decision's inputs for a kingfisher at rest at `position` (heading 0), no budget.
fn inputs_at_rest<'a>(
    grid: &'a TraversableGrid,
    airframe: &'a Airframe,
    position: DVec3,
) -> DecisionInputs<'a> {
    let start = TrajectoryPoint::at_rest(position, 0.0);
    DecisionInputs {
        grid,
        start,
        flight: FlightState::hovering(airframe, position, 0.0),
        airframe,
        limits: DynamicLimits::of(airframe),
        rollout: RolloutConfig::default(),
        min_travel_m: 0.3,
        budget: None,
    }
}

/// With the standoff option a decision plans to a viewpoint at the standoff distance,
/// level with the centroid and facing it, not to the centroid; without it, to the
/// centroid whenever that is feasible.
#[test]
fn standoff_targets_are_planned_to_their_viewpoints_first() {
    let (_, store, grid) = room();
    let airframe = Airframe::kingfisher();
    let inputs = inputs_at_rest(&grid, &airframe, DVec3::new(1.5, 1.5, 0.8));
    let at = inputs.start.position.as_vec3();
    let thesis = targets();
    let standoff = with_standoff(&thesis, &store, 1.5, 0.25, at);
    let centroid_goals = evaluate(&inputs, &thesis, at, CandidateScope::All).candidates;
    assert!(!centroid_goals.is_empty());
    assert!(
        centroid_goals
            .iter()
            .all(|c| c.candidate.viewpoint.is_none()),
        "every centroid of the room is feasible"
    );
    let viewpoint_goals = evaluate(&inputs, &standoff, at, CandidateScope::All).candidates;
    // The cluster in the closed pocket stays infeasible: its standoff viewpoints outside
    // the pocket are not in sight of its centroid.
    assert_eq!(viewpoint_goals.len(), centroid_goals.len());
    for evaluated in &viewpoint_goals {
        let candidate = &evaluated.candidate;
        let target = &standoff[candidate.target];
        let viewpoint = candidate.viewpoint.expect("a standoff viewpoint");
        assert_eq!(
            candidate.goal.as_vec3(),
            target.viewpoints[viewpoint].position
        );
        let to_centroid = target.centroid.as_dvec3() - candidate.goal;
        assert!(
            (to_centroid.length() - 1.5).abs() < 1e-5 && to_centroid.z.abs() < 1e-9,
            "{to_centroid:?}"
        );
        let facing = DVec3::new(candidate.goal_yaw.cos(), candidate.goal_yaw.sin(), 0.0);
        assert!(facing.dot(to_centroid.normalize()) > 1.0 - 1e-5);
    }
}

/// With the frontier viewpoint (beyond the thesis), a cluster whose centroid and viewpoints
/// cannot be planned to (here: its centroid in the closed pocket, no viewpoints) is planned to
/// its frontier voxel nearest to the centroid, outside the pocket; without it, it is dropped.
#[test]
fn a_cluster_out_of_reach_is_planned_to_its_frontier_viewpoint() {
    let (config, _, grid) = room();
    let airframe = Airframe::kingfisher();
    let inputs = inputs_at_rest(&grid, &airframe, DVec3::new(1.5, 1.5, 0.8));
    let at = inputs.start.position.as_vec3();
    let pocket = &targets()[2..3];
    assert!(
        evaluate(&inputs, pocket, at, CandidateScope::All)
            .candidates
            .is_empty()
    );
    // Frontier west of the pocket's wall (x 4.6..4.8 m): 1.25 m and 0.85 m from its centroid.
    let members = [IVec3::new(40, 53, 8), IVec3::new(44, 53, 8)];
    let with = with_frontier_viewpoints(pocket, &config, |_| Some(&members[..]));
    let nearest = config.center_of(members[1]);
    assert_eq!(with[0].viewpoints.len(), 1);
    assert_eq!(with[0].viewpoints[0].position, nearest);
    let planned = evaluate(&inputs, &with, at, CandidateScope::All).candidates;
    assert_eq!(planned.len(), 1);
    let candidate = &planned[0].candidate;
    assert_eq!(candidate.viewpoint, Some(0));
    // 0.15 m from the wall, inside the inflation: the path ends at the nearest open cell.
    let off = candidate.goal.distance(nearest.as_dvec3());
    assert!(off <= GOAL_SNAP_RADIUS_M, "{off}");
    // A cluster without members (none known) keeps its viewpoints as they are.
    let without = with_frontier_viewpoints(pocket, &config, |_| None);
    assert_eq!(without[0].viewpoints, pocket[0].viewpoints);
}

/// Each shipped strategy picks the same cluster from its ranked evaluation as from the
/// evaluation of every cluster, with fewer clusters evaluated.
#[test]
fn ranked_evaluation_picks_what_evaluating_all_would() {
    let (_, _, grid) = room();
    let airframe = Airframe::kingfisher();
    let inputs = inputs_at_rest(&grid, &airframe, DVec3::new(1.5, 1.5, 0.8));
    let (start, at) = (inputs.start, inputs.start.position.as_vec3());
    let targets = targets();
    let all = evaluate(&inputs, &targets, at, CandidateScope::All);
    assert_eq!(all.candidates.len(), 6, "all but the cluster in the pocket");
    let every = views(&all, &targets, at);
    type Choice = fn(&[CandidateView]) -> Option<Entity>;
    let eaae3: Choice = |c| least_energy_among_largest_gain(c, Some(3));
    let eaae1: Choice = |c| least_energy_among_largest_gain(c, Some(1));
    let tour3: Choice = |c| first_of_tour_among_largest_gain(c, Some(3));
    let cases: [(CandidateScope, Choice, usize); 5] = [
        (ClassicStrategy.scope(), largest_gain, 1),
        (NearestStrategy.scope(), nearest, 1),
        (EaaeStrategy { shortlist: Some(3) }.scope(), eaae3, 3),
        (EaaeStrategy { shortlist: Some(1) }.scope(), eaae1, 1),
        (TourStrategy { shortlist: Some(3) }.scope(), tour3, 3),
    ];
    for (scope, choose, needed) in cases {
        let ranked = evaluate(&inputs, &targets, at, scope);
        assert!(ranked.candidates.len() >= needed && ranked.candidates.len() < 6);
        assert_eq!(
            choose(&views(&ranked, &targets, at)),
            choose(&every),
            "{scope:?}"
        );
    }
    // Classic skips the infeasible largest cluster (in the pocket) for the next: one of the
    // two tied at 300, the first in the clusters' order.
    assert_eq!(largest_gain(&every), Some(targets[1].entity));
    // A budget that affords only short trips: the ranked evaluation goes on until it has
    // an affordable one, and finds the same pick.
    let tight = DecisionInputs {
        budget: Some(BudgetCheck {
            left_j: 900.0,
            home: start.position,
            home_yaw: 0.0,
        }),
        ..inputs.clone()
    };
    let all = evaluate(&tight, &targets, at, CandidateScope::All);
    let affordable = |e: &Evaluation| -> Vec<CandidateView> {
        let views = views(e, &targets, at);
        e.candidates
            .iter()
            .zip(views)
            .filter(|(c, _)| c.affordable(tight.budget.as_ref()))
            .map(|(_, v)| v)
            .collect()
    };
    let choosable_all = affordable(&all);
    assert!(!choosable_all.is_empty() && choosable_all.len() < all.candidates.len());
    let ranked = evaluate(&tight, &targets, at, ClassicStrategy.scope());
    assert_eq!(
        largest_gain(&affordable(&ranked)),
        largest_gain(&choosable_all)
    );
}

#[test]
fn the_orders_rank_by_gain_or_distance_and_keep_ties_in_order() {
    let targets = targets();
    let at = Vec3::new(1.5, 1.5, 0.8);
    assert_eq!(
        evaluation_order(&targets, at, CandidateScope::All),
        vec![0, 1, 2, 3, 4, 5, 6]
    );
    assert_eq!(
        evaluation_order(&targets, at, ClassicStrategy.scope()),
        vec![2, 1, 3, 5, 6, 0, 4]
    );
    let by_distance = evaluation_order(&targets, at, NearestStrategy.scope());
    assert_eq!(by_distance[0], 6, "(0.8, 0.8) is nearest to (1.5, 1.5)");
    let d: Vec<f32> = by_distance
        .iter()
        .map(|&i| targets[i].centroid.distance(at))
        .collect();
    assert!(d.windows(2).all(|w| w[0] <= w[1]));
}
