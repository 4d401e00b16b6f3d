//! Evaluating frontier clusters for one decision (eaae.md steps 6-7) under the UAV's
//! [`CandidateScope`]: a trajectory to each cluster (one multi-goal search, then a
//! minimum-snap fit per cluster), its rollout through the quadrotor model, and under an energy
//! budget its way home.
//!
//! `All` evaluates every cluster in one parallel batch. `Ranked` walks the clusters in the
//! strategy's order ([`evaluation_order`]) in batches of `needed`, and stops once `needed`
//! candidates are choosable (rolled out, and affordable under a budget). Every cluster's
//! evaluation is independent of which others are evaluated (its path is the one a search for
//! every goal gives, though the search runs only as far as the batches so far need:
//! [`TargetPaths`]; its fit, rollout and way home are its own), so the first `needed` choosable
//! clusters in the order are the ones an evaluation of all would rank first, and the strategy
//! picks the same one.

use super::budget::return_energies;
use super::propose::{ClusterTarget, MAX_EXPANSIONS, PlannedCandidate};
use crate::flight::{FlightState, RolloutConfig, RolloutResult, rollout};
use crate::planning::{BrakingMemo, PathSearch, SightMemo, TraversableGrid, plan_along_seen};
use crate::trajectory::DynamicLimits;
use glam::{DVec3, Vec3};
use rayon::prelude::*;
use std::time::Instant;
use uavex_components::airframe::Airframe;
use uavex_components::exploration::{CandidateScope, Ranking};
use uavex_components::trajectory::{Trajectory, TrajectoryPoint};

/// One goal of a target, as a decision plans toward it: the target's centroid (no viewpoint,
/// no heading: the heading follows the path) or one of its viewpoints.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TargetGoal {
    pub position: DVec3,
    /// Index of the viewpoint in the target's (`None` for the centroid).
    pub viewpoint: Option<usize>,
    /// The heading to arrive with (the viewpoint's).
    pub yaw: Option<f64>,
}

/// A target's goals in the order a decision tries them (eaae.md step 6: the centroid first,
/// then the viewpoints; with the standoff option the viewpoints first), the order of the goals
/// of [`TargetPaths`].
pub fn target_goals(target: &ClusterTarget) -> impl Iterator<Item = TargetGoal> + '_ {
    let centroid = TargetGoal {
        position: target.centroid.as_dvec3(),
        viewpoint: None,
        yaw: None,
    };
    let viewpoints = target
        .viewpoints
        .iter()
        .enumerate()
        .map(|(i, v)| TargetGoal {
            position: v.position.as_dvec3(),
            viewpoint: Some(i),
            yaw: Some(f64::from(v.yaw)),
        });
    let first = target.centroid_first.then_some(centroid);
    let last = (!target.centroid_first).then_some(centroid);
    first.into_iter().chain(viewpoints).chain(last)
}

/// The paths of one multi-goal search from the UAV to the targets' centroids and viewpoints,
/// searched as far as the targets asked for so far need ([`PathSearch`]): a decision that
/// finds its candidates among the first targets of its order stops there (the nearest-frontier
/// strategy ranks by distance, so those are near), and each path is the one a search for
/// every target would give.
pub struct TargetPaths<'g> {
    /// Index in the search's goals of each target's centroid (its viewpoints follow).
    first_goal: Vec<usize>,
    search: PathSearch<'g>,
    /// Each goal's path, once its target was reached.
    paths: Vec<Option<Vec<DVec3>>>,
    /// Per target, whether its goals' paths are in `paths`.
    reached: Vec<bool>,
}

impl<'g> TargetPaths<'g> {
    /// The search from `start` for the goals of `targets`, none searched yet.
    pub fn new(grid: &'g TraversableGrid, start: DVec3, targets: &[ClusterTarget]) -> Self {
        let mut goals = Vec::new();
        let mut first_goal = Vec::with_capacity(targets.len());
        for target in targets {
            first_goal.push(goals.len());
            goals.extend(target_goals(target).map(|goal| goal.position));
        }
        let search = PathSearch::new(grid, start, &goals, MAX_EXPANSIONS);
        Self {
            paths: vec![None; goals.len()],
            reached: vec![false; targets.len()],
            first_goal,
            search,
        }
    }

    /// Searches on until every goal of the targets `which` has its path (or has none).
    pub fn reach(&mut self, which: &[usize]) {
        let mut goals = Vec::new();
        for &target in which {
            if !std::mem::replace(&mut self.reached[target], true) {
                goals.extend(self.goals_of(target));
            }
        }
        for (goal, path) in goals.iter().zip(self.search.paths(&goals)) {
            self.paths[*goal] = path;
        }
    }

    /// The indices of target `target`'s goals, in [`target_goals`] order.
    fn goals_of(&self, target: usize) -> std::ops::Range<usize> {
        let end = self.first_goal.get(target + 1).copied();
        self.first_goal[target]..end.unwrap_or(self.paths.len())
    }

    /// The paths to target `target`'s goals, in [`target_goals`] order (`None` for a goal
    /// not reached, or whose target was not searched for yet).
    fn paths_of(&self, target: usize) -> &[Option<Vec<DVec3>>] {
        &self.paths[self.goals_of(target)]
    }
}

/// Eaae.md step 6 for the targets `which` (indices into `targets`, whose goals `paths` is the
/// search for; it searches on as far as they need), in parallel, results in the order of
/// `which`: the trajectory to a target's centroid, or failing that to each of its viewpoints
/// in turn; targets without a feasible trajectory are left out. Goals within `min_travel_m`
/// of the start are skipped: flying there gains nothing. The plans of each parallel job share
/// one line-of-sight memo: the paths come from one search tree and ask the same questions
/// ([`crate::planning::sight`]); all share the start's braking leg, for the paths that turn
/// back ([`crate::planning::braking`]).
pub fn plan_targets(
    grid: &TraversableGrid,
    start: &TrajectoryPoint,
    targets: &[ClusterTarget],
    paths: &mut TargetPaths<'_>,
    which: &[usize],
    limits: &DynamicLimits,
    min_travel_m: f64,
) -> Vec<PlannedCandidate> {
    paths.reach(which);
    let paths = &*paths;
    let braking = BrakingMemo::new();
    which
        .par_iter()
        .map_init(
            || SightMemo::new(grid),
            |sight, &index| {
                let mut goals = target_goals(&targets[index]).zip(paths.paths_of(index));
                goals.find_map(|(goal, path)| {
                    let path = path.as_ref()?;
                    if goal.position.distance(start.position) <= min_travel_m {
                        return None;
                    }
                    let plan =
                        plan_along_seen(sight, &braking, start, path, goal.yaw, limits).ok()?;
                    let end = plan.trajectory.sample(plan.trajectory.duration());
                    Some(PlannedCandidate {
                        target: index,
                        goal: end.position,
                        goal_yaw: end.yaw,
                        plan,
                        viewpoint: goal.viewpoint,
                    })
                })
            },
        )
        .flatten()
        .collect()
}

/// Eaae.md step 7: the predicted energy and duration of every planned candidate, from the
/// UAV's true state, in parallel; a rollout that fails (an unflyable trajectory) drops it.
pub fn roll_out_candidates(
    airframe: &Airframe,
    start: &FlightState,
    planned: &[PlannedCandidate],
    config: &RolloutConfig,
) -> Vec<Option<RolloutResult>> {
    planned
        .par_iter()
        .map(|candidate| rollout(airframe, start, &candidate.plan.trajectory, config).ok())
        .collect()
}

/// The order in which `scope` evaluates `targets` (indices): as given for `All`; for `Ranked`,
/// by the ranking, ties in the order given (the strategies break ties the same way).
pub fn evaluation_order(
    targets: &[ClusterTarget],
    position: Vec3,
    scope: CandidateScope,
) -> Vec<usize> {
    let mut order: Vec<usize> = (0..targets.len()).collect();
    match scope {
        CandidateScope::All => {}
        CandidateScope::Ranked {
            by: Ranking::InformationGain,
            ..
        } => order.sort_by_key(|&i| std::cmp::Reverse(targets[i].size)),
        CandidateScope::Ranked {
            by: Ranking::Distance,
            ..
        } => order.sort_by(|&a, &b| {
            let distance = |i: usize| targets[i].centroid.distance(position);
            distance(a).total_cmp(&distance(b))
        }),
    }
    order
}

/// Under an energy budget: what is left to spend (J) and where home is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BudgetCheck {
    pub left_j: f64,
    pub home: DVec3,
    pub home_yaw: f64,
}

/// What one decision's evaluation starts from.
#[derive(Debug, Clone)]
pub struct DecisionInputs<'a> {
    pub grid: &'a TraversableGrid,
    /// Where trajectories start (the tracked reference now).
    pub start: TrajectoryPoint,
    /// Where rollouts start (the UAV's true state).
    pub flight: FlightState,
    pub airframe: &'a Airframe,
    pub limits: DynamicLimits,
    pub rollout: RolloutConfig,
    pub min_travel_m: f64,
    pub budget: Option<BudgetCheck>,
}

/// One evaluated candidate: its trajectory, the rollout's prediction, and under a budget the
/// predicted energy home from its goal (`None` inside: no way home found).
#[derive(Debug, Clone)]
pub struct Evaluated {
    pub candidate: PlannedCandidate,
    pub result: RolloutResult,
    pub return_j: Option<Option<f64>>,
}

impl Evaluated {
    /// Whether the way there and back fits in what is left (always, without a budget).
    pub fn affordable(&self, budget: Option<&BudgetCheck>) -> bool {
        match (budget, self.return_j) {
            (Some(budget), Some(back)) => {
                back.is_some_and(|back| self.result.energy_j + back <= budget.left_j)
            }
            _ => true,
        }
    }
}

/// The evaluation of one group of targets.
#[derive(Debug, Clone, Default)]
pub struct Evaluation {
    /// Rolled-out candidates, in evaluation order.
    pub candidates: Vec<Evaluated>,
    /// Candidates with a feasible trajectory (including those whose rollout failed).
    pub planned: usize,
    /// Wall-clock time (ms) spent on trajectories (search, fits) and on energy (rollouts,
    /// ways home): EAAE Table 6.2's "trajectory generation" and "energy estimation".
    pub trajectory_ms: f64,
    pub energy_ms: f64,
}

/// Evaluates `targets` under `scope` (module documentation).
pub fn evaluate(
    inputs: &DecisionInputs<'_>,
    targets: &[ClusterTarget],
    position: Vec3,
    scope: CandidateScope,
) -> Evaluation {
    let mut evaluation = Evaluation::default();
    if targets.is_empty() {
        return evaluation;
    }
    let searching = Instant::now();
    let mut paths = TargetPaths::new(inputs.grid, inputs.start.position, targets);
    evaluation.trajectory_ms += elapsed_ms(searching);
    let order = evaluation_order(targets, position, scope);
    let (batch, needed) = match scope {
        CandidateScope::All => (order.len(), usize::MAX),
        CandidateScope::Ranked { needed, .. } => (needed.max(1), needed.max(1)),
    };
    let mut choosable = 0;
    for which in order.chunks(batch) {
        let planning = Instant::now();
        let planned = plan_targets(
            inputs.grid,
            &inputs.start,
            targets,
            &mut paths,
            which,
            &inputs.limits,
            inputs.min_travel_m,
        );
        evaluation.trajectory_ms += elapsed_ms(planning);
        evaluation.planned += planned.len();

        let estimating = Instant::now();
        let rollouts =
            roll_out_candidates(inputs.airframe, &inputs.flight, &planned, &inputs.rollout);
        let returns = inputs.budget.map(|budget| {
            return_energies(
                inputs.grid,
                inputs.airframe,
                budget.home,
                budget.home_yaw,
                &planned,
                &inputs.limits,
                &inputs.rollout,
            )
        });
        evaluation.energy_ms += elapsed_ms(estimating);

        for (k, (candidate, result)) in planned.into_iter().zip(rollouts).enumerate() {
            let Some(result) = result else { continue };
            let evaluated = Evaluated {
                candidate,
                result,
                return_j: returns.as_ref().map(|r| r[k]),
            };
            choosable += usize::from(evaluated.affordable(inputs.budget.as_ref()));
            evaluation.candidates.push(evaluated);
        }
        if choosable >= needed {
            break;
        }
    }
    evaluation
}

fn elapsed_ms(since: Instant) -> f64 {
    since.elapsed().as_secs_f64() * 1e3
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::exploration::propose::with_standoff;
    use crate::exploration::strategy::classic::largest_gain;
    use crate::exploration::strategy::eaae::least_energy_among_largest_gain;
    use crate::exploration::strategy::nearest::nearest;
    use crate::exploration::strategy::tour::first_of_tour_among_largest_gain;
    use crate::exploration::strategy::{
        CandidateView, ClassicStrategy, EaaeStrategy, NearestStrategy, TourStrategy,
    };
    use crate::mapping::{ChunkAccess, ChunkStore};
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
}
