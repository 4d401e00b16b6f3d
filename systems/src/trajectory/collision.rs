//! Collision check of a trajectory against any "blocked" predicate (the occupancy map's
//! known-occupied voxels with inflation, and unknown ones as free or blocked: the caller's
//! choice, made in the predicate).
//!
//! The trajectory is sampled at a fixed time step `spacing / max_speed`: as the reference
//! moves at most `max_speed`, consecutive samples lie at most `spacing` apart along the path,
//! wherever it turns or loops back. Choosing `spacing` below the map resolution (e.g. half a
//! voxel) means no voxel the path crosses goes unsampled. Planned trajectories respect the
//! airframe's `max_velocity`, which is then the bound to pass.

use super::PlanError;
use glam::DVec3;
use uavex_components::trajectory::Trajectory;

/// The first sampled time and position at which `blocked` holds, if any (see module doc).
pub fn first_blocked(
    trajectory: &dyn Trajectory,
    blocked: &dyn Fn(DVec3) -> bool,
    spacing: f64,
    max_speed: f64,
) -> Result<Option<(f64, DVec3)>, PlanError> {
    if !(spacing.is_finite() && spacing > 0.0 && max_speed.is_finite() && max_speed > 0.0) {
        return Err(PlanError::InvalidLimits(format!(
            "collision sampling needs spacing > 0 and max_speed > 0, got {spacing} and {max_speed}"
        )));
    }
    let end = trajectory.duration();
    if !(end.is_finite() && end >= 0.0) {
        return Err(PlanError::NonFinite("trajectory duration".into()));
    }
    let step = spacing / max_speed;
    let samples = (end / step).ceil() as u64;
    for i in 0..=samples {
        let t = (i as f64 * step).min(end);
        let position = trajectory.position(t);
        if blocked(position) {
            return Ok(Some((t, position)));
        }
    }
    Ok(None)
}

/// Whether no sample of the trajectory is blocked (see [`first_blocked`]).
pub fn is_collision_free(
    trajectory: &dyn Trajectory,
    blocked: &dyn Fn(DVec3) -> bool,
    spacing: f64,
    max_speed: f64,
) -> Result<bool, PlanError> {
    Ok(first_blocked(trajectory, blocked, spacing, max_speed)?.is_none())
}

#[cfg(test)]
mod tests {
    use super::*;
    use uavex_components::trajectory::TrajectoryPoint;

    /// Straight line at constant speed along x.
    #[derive(Debug)]
    struct Line {
        speed: f64,
        duration: f64,
    }

    impl Trajectory for Line {
        fn duration(&self) -> f64 {
            self.duration
        }
        fn sample(&self, t: f64) -> TrajectoryPoint {
            let t = t.clamp(0.0, self.duration);
            TrajectoryPoint {
                position: DVec3::new(self.speed * t, 0.0, 1.0),
                velocity: DVec3::new(self.speed, 0.0, 0.0),
                ..Default::default()
            }
        }
    }

    #[test]
    fn thin_wall_is_found_at_its_position() {
        // A 5 cm thick wall at x in [2.0, 2.05]; 2 m/s; 4 cm spacing cannot jump over it.
        let line = Line {
            speed: 2.0,
            duration: 2.0,
        };
        let wall = |p: DVec3| (2.0..=2.05).contains(&p.x);
        let (t, p) = first_blocked(&line, &wall, 0.04, 2.0).unwrap().unwrap();
        assert!((2.0..=2.05).contains(&p.x));
        assert!((t - p.x / 2.0).abs() < 1e-12);
        // Nothing blocked: free.
        assert!(is_collision_free(&line, &|_| false, 0.04, 2.0).unwrap());
        // Blocked beyond the end: free.
        assert!(is_collision_free(&line, &|p: DVec3| p.x > 4.5, 0.04, 2.0).unwrap());
        // Nonsense sampling is an error, not a hang.
        assert!(first_blocked(&line, &wall, 0.0, 2.0).is_err());
        assert!(first_blocked(&line, &wall, 0.04, f64::NAN).is_err());
    }

    /// Out and back along x in 2 s: start and end coincide.
    #[derive(Debug)]
    struct OutAndBack;

    impl Trajectory for OutAndBack {
        fn duration(&self) -> f64 {
            2.0
        }
        fn sample(&self, t: f64) -> TrajectoryPoint {
            let t = t.clamp(0.0, 2.0);
            let x = if t < 1.0 { 3.0 * t } else { 3.0 * (2.0 - t) };
            TrajectoryPoint::at_rest(DVec3::new(x, 0.0, 1.0), 0.0)
        }
    }

    #[test]
    fn a_path_that_returns_to_its_start_is_still_checked() {
        let wall = |p: DVec3| p.x > 2.9;
        let (t, _) = first_blocked(&OutAndBack, &wall, 0.05, 3.0)
            .unwrap()
            .unwrap();
        assert!((0.96..=1.0).contains(&t), "{t}");
    }

    #[test]
    fn samples_are_never_farther_apart_than_the_spacing() {
        let line = Line {
            speed: 3.0,
            duration: 1.0,
        };
        let visited = std::cell::RefCell::new(Vec::new());
        let record = |p: DVec3| {
            visited.borrow_mut().push(p.x);
            false
        };
        assert!(first_blocked(&line, &record, 0.05, 3.0).unwrap().is_none());
        let xs = visited.into_inner();
        assert!(xs.windows(2).all(|w| w[1] - w[0] <= 0.05 + 1e-12));
        assert!((xs.last().unwrap() - 3.0).abs() < 1e-12);
    }
}
