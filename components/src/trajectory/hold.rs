//! Hold (hover) at one pose for a while.

use super::{Trajectory, TrajectoryPoint};
use glam::DVec3;
use serde::{Deserialize, Serialize};

/// Stay at `position` with heading `yaw` for `duration` seconds.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Hold {
    pub position: DVec3,
    pub yaw: f64,
    pub duration: f64,
}

impl Trajectory for Hold {
    fn duration(&self) -> f64 {
        self.duration
    }

    fn sample(&self, _t: f64) -> TrajectoryPoint {
        TrajectoryPoint::at_rest(self.position, self.yaw)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hold_is_at_rest_everywhere() {
        let hold = Hold {
            position: DVec3::new(1.0, 2.0, 3.0),
            yaw: 0.5,
            duration: 4.0,
        };
        for t in [-1.0, 0.0, 2.0, 10.0] {
            let point = hold.sample(t);
            assert_eq!(point.position, DVec3::new(1.0, 2.0, 3.0));
            assert_eq!(point.velocity, DVec3::ZERO);
            assert_eq!(point.yaw, 0.5);
        }
        assert_eq!(hold.duration(), 4.0);
    }
}
