//! Time-parametrised trajectories: what a UAV is asked to fly.
//!
//! A trajectory gives, at every time, the flat outputs of the quadrotor (position and yaw) and
//! their derivatives up to snap: exactly what the geometric controller needs for its
//! feed-forward terms (acceleration, and jerk for the desired body rates). The planners in
//! `uavex-systems::trajectory` produce them; the controller and the offline rollout consume them
//! through the [`Trajectory`] trait only, so a new kind of trajectory plugs in without touching
//! either.

mod hold;
mod polynomial;

pub use hold::Hold;
pub use polynomial::{
    POLYNOMIAL_COEFFICIENTS, PiecewisePolynomial, PolynomialSegment, PreparedPolynomial,
};

use glam::DVec3;
use serde::{Deserialize, Serialize};

/// The reference at one instant: position and yaw with their time derivatives.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct TrajectoryPoint {
    /// m, world frame.
    pub position: DVec3,
    /// m/s.
    pub velocity: DVec3,
    /// m/s^2.
    pub acceleration: DVec3,
    /// m/s^3.
    pub jerk: DVec3,
    /// m/s^4.
    pub snap: DVec3,
    /// Heading about +z (rad).
    pub yaw: f64,
    /// rad/s.
    pub yaw_rate: f64,
    /// rad/s^2.
    pub yaw_acceleration: f64,
}

impl TrajectoryPoint {
    /// At rest at `position`, heading `yaw`.
    pub fn at_rest(position: DVec3, yaw: f64) -> Self {
        Self {
            position,
            yaw,
            ..Self::default()
        }
    }
}

/// A reference trajectory parametrised by time since its start.
///
/// Implementations must accept any `t`: before 0 they return the start; after [`duration`]
/// the end, held at rest (zero derivatives), so a controller that outlives the trajectory holds
/// the last position.
///
/// [`duration`]: Trajectory::duration
pub trait Trajectory: Send + Sync + std::fmt::Debug {
    /// Length in time (s).
    fn duration(&self) -> f64;
    /// The reference at time `t` (s since the start).
    fn sample(&self, t: f64) -> TrajectoryPoint;

    /// The position at time `t`: `self.sample(t).position`, bit for bit. Implementations
    /// override it when the position alone is cheaper to compute (collision checks sample
    /// positions only).
    fn position(&self, t: f64) -> DVec3 {
        self.sample(t).position
    }

    /// The position at time `t` ([`Self::position`], bit for bit), for a caller that samples
    /// forward in time: `segment` is the implementation's to keep between calls (start it at
    /// 0), e.g. where the last time was found, so that the next one is found from there.
    fn position_onward(&self, t: f64, segment: &mut usize) -> DVec3 {
        let _ = segment;
        self.position(t)
    }

    /// This trajectory in a form that is cheaper to sample many times over, the same to the
    /// bit, if the implementation has one (a rollout samples its reference 100 times a
    /// second); `None` when sampling `self` is as cheap as it gets.
    fn prepared(&self) -> Option<Box<dyn Trajectory + '_>> {
        None
    }
}
