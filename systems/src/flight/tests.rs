//! Closed-loop checks of controller + quadrotor model through the offline rollout.
//!
//! Bounds, with their reasons:
//! - hover: rotor speeds within 1 % of sqrt(m g / (4 k_f)) = 1086.43 rad/s, power within 1 %
//!   of 123 W (the acceptance values);
//! - tracking of a 3 m/s circle (r = 3 m) and figure-eight: RMS error below 2 cm. With the
//!   acceleration and jerk feed-forward, what is left is the lag of the thrust vector
//!   (attitude loop and motors, about tau = 0.033 s) while it turns at the path's rate
//!   (1 rad/s on the circle): an acceleration error of about |a| w tau = 3 x 1 x 0.033
//!   = 0.1 m/s^2, which the position loop turns into 0.1 / |kp - w^2 + i kd w|
//!   = 0.1 / |9 + 6i| = 9 mm. 2 cm leaves a factor two;
//! - 1 m step: overshoot below 5 % and within 2 % of the step after 2.5 s. The position loop
//!   s^2 + 6 s + 10 (damping 0.95) overshoots by 0.01 % and settles to 2 % in 1.7 s;
//!   the attitude and motor lags add to both.

use super::*;
use crate::trajectory::{CurveReference, DynamicLimits, Waypoint, plan_min_snap};
use glam::DVec3;
use uavex_components::airframe::Airframe;
use uavex_components::trajectory::{Hold, Trajectory, TrajectoryPoint};

fn kingfisher() -> Airframe {
    Airframe::kingfisher()
}

/// Rollout at the true flight's 300 Hz rate, for closed-loop behaviour checks.
fn fine() -> RolloutConfig {
    RolloutConfig {
        step: 1.0 / 300.0,
        ..RolloutConfig::default()
    }
}

#[test]
fn hover_holds_at_hover_speed_and_123_w() {
    let airframe = kingfisher();
    let start = FlightState::hovering(&airframe, DVec3::new(0.0, 0.0, 1.0), 0.0);
    let hold = Hold {
        position: start.position,
        yaw: 0.0,
        duration: 10.0,
    };
    let result = rollout(&airframe, &start, &hold, &RolloutConfig::default()).unwrap();
    for w in result.final_state.rotor_speeds {
        assert!((w / 1086.43 - 1.0).abs() < 0.01, "{w}");
    }
    let power = result.energy_j / result.duration_s;
    assert!((power / 123.0 - 1.0).abs() < 0.01, "{power}");
    assert!(result.final_state.position.distance(start.position) < 1e-6);
    assert!((result.duration_s - 10.0).abs() < 1e-9);
}

#[test]
fn circle_and_figure_eight_at_3_m_s_are_tracked() {
    let airframe = kingfisher();
    let centre = DVec3::new(0.0, 0.0, 1.5);
    let references = [
        CurveReference::circle(centre, 3.0, 3.0, 2.0, 2.0),
        CurveReference::figure_eight(centre, 3.0, 3.0, 2.0, 2.0),
    ];
    for reference in references {
        let start = FlightState::hovering(&airframe, reference.sample(0.0).position, 0.0);
        let rk4 = RolloutConfig {
            integrator: Integrator::RungeKutta4,
            ..RolloutConfig::default()
        };
        for config in [fine(), RolloutConfig::default(), rk4] {
            let result = rollout(&airframe, &start, &reference, &config).unwrap();
            assert!(
                result.rms_tracking_error_m < 0.02,
                "{reference:?}: {result:?}"
            );
            assert!(result.arrived);
        }
    }
}

#[test]
fn one_metre_step_settles_without_overshoot() {
    let airframe = kingfisher();
    let start = FlightState::hovering(&airframe, DVec3::new(0.0, 0.0, 1.0), 0.0);
    let hold = Hold {
        position: DVec3::new(1.0, 0.0, 1.0),
        yaw: 0.0,
        duration: 4.0,
    };
    let mut overshoot: f64 = 0.0;
    let mut error_after_2_5_s: f64 = 0.0;
    rollout_observed(&airframe, &start, &hold, &fine(), &mut |t, state| {
        overshoot = overshoot.max(state.position.x - 1.0);
        if t >= 2.5 {
            error_after_2_5_s = error_after_2_5_s.max(state.position.distance(hold.position));
        }
    })
    .unwrap();
    assert!(overshoot < 0.05, "{overshoot}");
    assert!(error_after_2_5_s < 0.02, "{error_after_2_5_s}");
}

fn planned_trajectory(airframe: &Airframe) -> (FlightState, impl Trajectory) {
    let start = TrajectoryPoint::at_rest(DVec3::new(0.0, 0.0, 1.0), 0.0);
    let waypoints = [
        Waypoint::new(DVec3::new(4.0, 1.0, 1.5)),
        Waypoint {
            position: DVec3::new(6.0, -3.0, 1.0),
            yaw: Some(-1.0),
        },
    ];
    let trajectory = plan_min_snap(&start, &waypoints, &DynamicLimits::of(airframe)).unwrap();
    (
        FlightState::hovering(airframe, start.position, 0.0),
        trajectory,
    )
}

#[test]
fn the_eaae_step_predicts_the_energy_of_the_fine_one() {
    let airframe = kingfisher();
    let (start, trajectory) = planned_trajectory(&airframe);
    let fine = rollout(
        &airframe,
        &start,
        &trajectory,
        &RolloutConfig {
            integrator: Integrator::RungeKutta4,
            ..fine()
        },
    )
    .unwrap();
    for integrator in [Integrator::Midpoint, Integrator::RungeKutta4] {
        let config = RolloutConfig {
            integrator,
            ..RolloutConfig::default()
        };
        let coarse = rollout(&airframe, &start, &trajectory, &config).unwrap();
        let error = coarse.energy_j / fine.energy_j - 1.0;
        eprintln!("{integrator:?} at 0.02 s: energy {error:+.5} relative to RK4 at 1/300 s");
        assert!(error.abs() < 0.005, "{coarse:?} {fine:?}");
        assert!((coarse.duration_s - fine.duration_s).abs() <= 0.02 + 1e-9);
    }
    // Flying costs more than hovering for the same time (123.14 W).
    assert!(fine.energy_j > 123.14 * fine.duration_s);
}

#[test]
fn batch_rollouts_equal_serial_ones() {
    let airframe = kingfisher();
    let (start, trajectory) = planned_trajectory(&airframe);
    let hold = Hold {
        position: start.position,
        yaw: 0.0,
        duration: 2.0,
    };
    let jobs: Vec<(FlightState, &dyn Trajectory)> =
        vec![(start, &trajectory), (start, &hold), (start, &trajectory)];
    let config = RolloutConfig::default();
    let batch = rollout_batch(&airframe, &jobs, &config);
    for ((s, t), result) in jobs.iter().zip(&batch) {
        assert_eq!(
            result.as_ref().unwrap(),
            &rollout(&airframe, s, *t, &config).unwrap()
        );
    }
}

#[test]
fn bad_inputs_are_errors() {
    let airframe = kingfisher();
    let (start, trajectory) = planned_trajectory(&airframe);
    let config = RolloutConfig {
        step: 0.0,
        ..RolloutConfig::default()
    };
    assert_eq!(
        rollout(&airframe, &start, &trajectory, &config),
        Err(FlightError::InvalidStep(0.0))
    );
    let mut nan_start = start;
    nan_start.velocity.y = f64::NAN;
    assert_eq!(
        rollout(
            &airframe,
            &nan_start,
            &trajectory,
            &RolloutConfig::default()
        ),
        Err(FlightError::NonFiniteStart)
    );
    let mut heavy = kingfisher();
    heavy.mass = -1.0;
    assert!(matches!(
        rollout(&heavy, &start, &trajectory, &RolloutConfig::default()),
        Err(FlightError::InvalidAirframe(_))
    ));
}

#[test]
fn iris_hovers_at_its_measured_power_and_tracks_with_the_same_gains() {
    let iris = Airframe::iris();
    let start = FlightState::hovering(&iris, DVec3::new(0.0, 0.0, 2.0), 0.0);
    let hold = Hold {
        position: start.position,
        yaw: 0.0,
        duration: 5.0,
    };
    let hover = rollout(&iris, &start, &hold, &RolloutConfig::default()).unwrap();
    // Calibrated to Di Franco & Buttazzo's P(0) = 221.28 W.
    let power = hover.energy_j / hover.duration_s;
    assert!((power / 221.28 - 1.0).abs() < 0.01, "{power}");
    let (trajectory_start, trajectory) = planned_trajectory(&iris);
    let flight = rollout(&iris, &trajectory_start, &trajectory, &fine()).unwrap();
    assert!(
        flight.arrived && flight.rms_tracking_error_m < 0.05,
        "{flight:?}"
    );
}
