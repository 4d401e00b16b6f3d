//! Local reactive planner (EAAE step 9): from the current reference state (possibly moving),
//! toward the chosen goal on the latest grid, but only as far as a horizon of path length
//! (about 1.5x the sensor range: beyond it the map is too old or unknown to commit to), ending
//! at rest there so that the plan is safe even if no replan follows. The caller replans at a
//! fixed rate and whenever [`super::remains_traversable`] turns false.

use super::global::plan_along;
use super::search::{MIN_POINT_SEPARATION_M, find_path, shortcut_indices};
use super::traversable::TraversableGrid;
use crate::trajectory::{DynamicLimits, PlanError};
use glam::DVec3;
use uavex_components::trajectory::{PiecewisePolynomial, TrajectoryPoint};

/// A local plan: the trajectory, and whether it ends at the goal (else at the horizon).
#[derive(Debug, Clone, PartialEq)]
pub struct LocalPlan {
    pub trajectory: PiecewisePolynomial,
    pub reaches_goal: bool,
}

/// A dynamically feasible, collision-free trajectory from `start` toward `goal`, along the
/// shortest path but only up to `horizon_m` of its (shortened) length; it ends at rest at the
/// horizon point (facing the direction of travel) or, when the path is shorter, at the path's
/// end (the goal, or the traversable point a blocked goal was attached to) with `goal_yaw`.
pub fn plan_local(
    grid: &TraversableGrid,
    start: &TrajectoryPoint,
    goal: DVec3,
    goal_yaw: Option<f64>,
    horizon_m: f64,
    limits: &DynamicLimits,
) -> Result<LocalPlan, PlanError> {
    if !(horizon_m.is_finite() && horizon_m > 0.0) {
        return Err(PlanError::InvalidLimits(format!("horizon {horizon_m} m")));
    }
    let path =
        find_path(grid, start.position, goal, usize::MAX).ok_or(PlanError::NoPath { goal })?;
    let (path, reaches_goal) = truncate(grid, path, horizon_m);
    let end_yaw = if reaches_goal { goal_yaw } else { None };
    let plan = plan_along(grid, start, &path, end_yaw, limits)?;
    Ok(LocalPlan {
        trajectory: plan.trajectory,
        reaches_goal,
    })
}

/// The path cut at `horizon_m` along its shortened form: the original points up to the last
/// kept one before the horizon, then the point of the chord at the horizon (on a chord of
/// traversable voxels, so traversable itself). Returns whether the whole path was kept.
fn truncate(grid: &TraversableGrid, path: Vec<DVec3>, horizon_m: f64) -> (Vec<DVec3>, bool) {
    let kept = shortcut_indices(&path, |a, b| grid.line_of_sight(a, b));
    let mut travelled = 0.0;
    for pair in kept.windows(2) {
        let (a, b) = (path[pair[0]], path[pair[1]]);
        let length = a.distance(b);
        if travelled + length > horizon_m {
            let rest = horizon_m - travelled;
            let mut cut = path[..=pair[0]].to_vec();
            if rest >= MIN_POINT_SEPARATION_M {
                cut.push(a + (b - a) * (rest / length));
            }
            return (cut, false);
        }
        travelled += length;
    }
    (path, true)
}
