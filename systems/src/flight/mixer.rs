//! The mixer: collective thrust and body torques to rotor speed commands, within the limits.
//!
//! Unsaturated, it inverts the allocation matrix `B` (rows: thrust, roll, pitch, yaw torque of
//! each rotor's thrust). When the demand does not fit the rotors' thrust range it gives things
//! up in this order, so that the vehicle stays controllable:
//! 1. roll and pitch torques are kept whole if any collective thrust allows them, else scaled
//!    down together (their direction kept) just enough to fit;
//! 2. the collective thrust is the demanded one, or the nearest that fits with (1);
//! 3. the yaw torque is scaled down last, as much as needed.
//!
//! (Thrust and attitude first, yaw last: the order PX4's and Agilicious' mixers follow.)

use super::dynamics::Wrench;
use glam::{DMat4, DVec3, DVec4};
use uavex_components::airframe::Airframe;

/// Allocation inverse and limits of one airframe.
#[derive(Debug, Clone, PartialEq)]
pub struct Mixer {
    /// Columns of `B^-1`: rotor thrusts per unit collective thrust, roll, pitch and yaw torque.
    per_thrust: [f64; 4],
    per_roll: [f64; 4],
    per_pitch: [f64; 4],
    per_yaw: [f64; 4],
    thrust_min: f64,
    thrust_max: f64,
    thrust_coefficient: f64,
    speed_min: f64,
    speed_max: f64,
}

impl Mixer {
    /// `None` when the rotor layout cannot be inverted (a validated airframe always can).
    pub fn new(airframe: &Airframe) -> Option<Self> {
        let column = |i: usize| {
            let r = &airframe.rotors[i];
            DVec4::new(1.0, r.y, -r.x, r.yaw_sign * airframe.torque_coefficient)
        };
        let allocation = DMat4::from_cols(column(0), column(1), column(2), column(3));
        if allocation.determinant().abs() < 1e-12 {
            return None;
        }
        // Row i of B^-1 is rotor i; column j holds every rotor's share of input j.
        let inverse = allocation.inverse();
        let share = |j: usize| inverse.col(j).to_array();
        let (thrust_min, thrust_max) = airframe.rotor_thrust_range();
        Some(Self {
            per_thrust: share(0),
            per_roll: share(1),
            per_pitch: share(2),
            per_yaw: share(3),
            thrust_min,
            thrust_max,
            thrust_coefficient: airframe.thrust_coefficient,
            speed_min: airframe.rotor_speed_min,
            speed_max: airframe.rotor_speed_max,
        })
    }

    /// Rotor thrusts (N) for a wrench, desaturated in the order of the module doc.
    pub fn rotor_thrusts(&self, wrench: &Wrench) -> [f64; 4] {
        let (lo, hi) = (self.thrust_min, self.thrust_max);
        let unsaturated: [f64; 4] = std::array::from_fn(|i| {
            self.per_thrust[i] * wrench.thrust
                + self.per_roll[i] * wrench.torque.x
                + self.per_pitch[i] * wrench.torque.y
                + self.per_yaw[i] * wrench.torque.z
        });
        // The usual case, and the only one without divisions: everything fits.
        if unsaturated.iter().all(|f| (lo..=hi).contains(f)) {
            return unsaturated;
        }
        let a = self.per_thrust;
        let d: [f64; 4] = std::array::from_fn(|i| {
            self.per_roll[i] * wrench.torque.x + self.per_pitch[i] * wrench.torque.y
        });
        // (1) Largest roll/pitch scale alpha <= 1 for which some collective thrust fits:
        // for every pair (i, j), (lo - alpha d_i) / a_i <= (hi - alpha d_j) / a_j.
        let mut alpha: f64 = 1.0;
        for i in 0..4 {
            for j in 0..4 {
                let growth = d[j] / a[j] - d[i] / a[i];
                if growth > 0.0 {
                    alpha = alpha.min((hi / a[j] - lo / a[i]) / growth);
                }
            }
        }
        let alpha = alpha.max(0.0);
        // (2) The collective thrust nearest the demand within the range that alpha allows.
        let mut lowest = f64::NEG_INFINITY;
        let mut highest = f64::INFINITY;
        for i in 0..4 {
            lowest = lowest.max((lo - alpha * d[i]) / a[i]);
            highest = highest.min((hi - alpha * d[i]) / a[i]);
        }
        let collective = if wrench.thrust.is_nan() {
            lowest
        } else {
            wrench.thrust.clamp(lowest, highest.max(lowest))
        };
        let base: [f64; 4] = std::array::from_fn(|i| a[i] * collective + alpha * d[i]);
        // (3) Yaw, scaled by the largest beta <= 1 that keeps every rotor in range.
        let yaw: [f64; 4] = std::array::from_fn(|i| self.per_yaw[i] * wrench.torque.z);
        let mut beta: f64 = 1.0;
        for i in 0..4 {
            if yaw[i] > 0.0 {
                beta = beta.min((hi - base[i]) / yaw[i]);
            } else if yaw[i] < 0.0 {
                beta = beta.min((lo - base[i]) / yaw[i]);
            }
        }
        let beta = if beta.is_nan() { 0.0 } else { beta.max(0.0) };
        std::array::from_fn(|i| (base[i] + beta * yaw[i]).clamp(lo, hi))
    }

    /// Rotor speed commands (rad/s) for a wrench: `w = sqrt(f / k_f)` of the desaturated
    /// thrusts, within the speed limits.
    pub fn speed_commands(&self, wrench: &Wrench) -> [f64; 4] {
        self.rotor_thrusts(wrench).map(|f| {
            (f / self.thrust_coefficient)
                .sqrt()
                .clamp(self.speed_min, self.speed_max)
        })
    }

    /// The wrench the given rotor thrusts produce, through `B` (for checks and tests).
    pub fn wrench_of(&self, airframe: &Airframe, thrusts: &[f64; 4]) -> Wrench {
        let mut wrench = Wrench::default();
        for (r, &f) in airframe.rotors.iter().zip(thrusts) {
            wrench.thrust += f;
            wrench.torque += DVec3::new(
                r.y * f,
                -r.x * f,
                r.yaw_sign * airframe.torque_coefficient * f,
            );
        }
        wrench
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn kingfisher() -> (Airframe, Mixer) {
        let airframe = Airframe::kingfisher();
        let mixer = Mixer::new(&airframe).unwrap();
        (airframe, mixer)
    }

    fn close(a: &Wrench, b: &Wrench) -> bool {
        (a.thrust - b.thrust).abs() < 1e-9 && (a.torque - b.torque).length() < 1e-9
    }

    #[test]
    fn feasible_wrench_is_reproduced_exactly() {
        let (airframe, mixer) = kingfisher();
        let wrench = Wrench {
            thrust: 9.0,
            torque: DVec3::new(0.05, -0.03, 0.01),
        };
        let thrusts = mixer.rotor_thrusts(&wrench);
        assert!(close(&mixer.wrench_of(&airframe, &thrusts), &wrench));
        // Hover: four equal thrusts m g / 4 = 1.84428 N -> 1086.43 rad/s.
        let hover = mixer.speed_commands(&Wrench {
            thrust: 0.752 * 9.81,
            torque: DVec3::ZERO,
        });
        for w in hover {
            assert!((w - 1086.43).abs() < 0.01, "{w}");
        }
    }

    #[test]
    fn yaw_is_given_up_before_roll_and_thrust() {
        let (airframe, mixer) = kingfisher();
        // Near-full thrust (4 x 8.0 N of 8.5 N max) with a roll torque that fits, and a yaw
        // torque that does not: roll and thrust stay, yaw shrinks.
        let wrench = Wrench {
            thrust: 32.0,
            torque: DVec3::new(0.08, 0.0, 0.2),
        };
        let thrusts = mixer.rotor_thrusts(&wrench);
        let got = mixer.wrench_of(&airframe, &thrusts);
        assert!((got.thrust - 32.0).abs() < 1e-9, "{got:?}");
        assert!((got.torque.x - 0.08).abs() < 1e-9, "{got:?}");
        assert!(got.torque.z > 0.0 && got.torque.z < 0.2, "{got:?}");
        assert!(thrusts.iter().all(|&f| f <= 8.5 + 1e-12));
    }

    #[test]
    fn roll_pitch_keep_their_direction_when_too_large() {
        let (airframe, mixer) = kingfisher();
        // Roll 2 N m and pitch 1 N m exceed what a 0.035 .. 8.5 N rotor range gives.
        let wrench = Wrench {
            thrust: 15.0,
            torque: DVec3::new(2.0, 1.0, 0.0),
        };
        let thrusts = mixer.rotor_thrusts(&wrench);
        let got = mixer.wrench_of(&airframe, &thrusts);
        // Same direction, smaller: the ratio roll / pitch stays 2.
        assert!((got.torque.x / got.torque.y - 2.0).abs() < 1e-9, "{got:?}");
        assert!(got.torque.x < 2.0 && got.torque.x > 0.5);
        // The extreme rotors sit on the limits.
        let max = thrusts.iter().cloned().fold(f64::MIN, f64::max);
        let min = thrusts.iter().cloned().fold(f64::MAX, f64::min);
        assert!(
            (max - 8.5).abs() < 1e-9 && (min - 0.035157).abs() < 1e-5,
            "{thrusts:?}"
        );
    }

    #[test]
    fn impossible_thrust_saturates_without_nan() {
        let (_, mixer) = kingfisher();
        for thrust in [1000.0, -5.0, f64::NAN] {
            let speeds = mixer.speed_commands(&Wrench {
                thrust,
                torque: DVec3::ZERO,
            });
            assert!(
                speeds
                    .iter()
                    .all(|w| w.is_finite() && *w >= 150.0 && *w <= 2800.0)
            );
        }
        let top = mixer.speed_commands(&Wrench {
            thrust: 1000.0,
            torque: DVec3::ZERO,
        });
        // 8.5 N per rotor: sqrt(8.5 / 1.562522e-6) = 2332.37 rad/s.
        assert!((top[0] - 2332.37).abs() < 0.01, "{top:?}");
    }
}
