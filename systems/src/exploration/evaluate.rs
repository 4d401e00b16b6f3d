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
#[path = "evaluate_tests.rs"]
mod tests;
