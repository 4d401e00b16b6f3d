//! The true flight: hover, tracking, step, rollout agreement (here); crashes, wrecks,
//! battery and bad setups (`contacts`).
//!
//! Tracking and step bounds are those of `uavex_systems::flight` (its tests' doc gives the
//! reasons): RMS error below 2 cm on a 3 m/s circle and figure-eight, step overshoot below 5 %
//! and within 2 % after 2.5 s.

mod contacts;

use super::*;
use glam::DVec3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rapier3d::prelude::{Pose, Rotation, SharedShape, Vector};
use std::f32::consts::{FRAC_PI_2, PI};
use uavex_components::airframe::Airframe;
use uavex_components::trajectory::{Hold, Trajectory, TrajectoryPoint};
use uavex_systems::flight::{
    Completion, ControllerGains, FlightState, GeometricController, RolloutConfig, rollout,
};
use uavex_systems::trajectory::{
    CurveReference, DynamicLimits, Waypoint, is_collision_free, plan_collision_free, plan_min_snap,
};

/// The ground: the top face of a large slab at z = 0.
fn ground() -> (Pose, SharedShape) {
    (
        Pose::from_translation(Vector::new(0.0, 0.0, -0.5)),
        SharedShape::cuboid(100.0, 100.0, 0.5),
    )
}

/// The EAAE "Pillars" scene (worlds/eaae.md): walls and pillars as yawed boxes, and the ground
/// (the table's yaws 1.5708 and 3.14159 are written as pi/2 and pi).
fn pillars() -> Vec<(Pose, SharedShape)> {
    let boxes: [([f32; 3], [f32; 3], f32); 7] = [
        ([10.6641, 0.1746, 1.25], [22.5, 0.15, 2.5], -FRAC_PI_2),
        ([-0.1359, -11.0004, 1.25], [21.75, 0.15, 2.5], PI),
        ([-10.9359, 0.1746, 1.25], [22.5, 0.15, 2.5], FRAC_PI_2),
        ([-0.1359, 11.3497, 1.25], [21.75, 0.15, 2.5], 0.0),
        ([-0.3643, -6.3997, 1.25], [2.0, 2.0, 2.5], 0.0),
        ([5.2752, 4.8380, 1.25], [2.0, 2.0, 2.5], -FRAC_PI_2),
        ([-5.1558, 4.5622, 1.25], [2.0, 2.0, 2.5], -FRAC_PI_2),
    ];
    let mut shapes: Vec<_> = boxes
        .iter()
        .map(|(c, s, yaw)| {
            (
                Pose::from_parts(Vector::from_array(*c), Rotation::from_rotation_z(*yaw)),
                SharedShape::cuboid(s[0] / 2.0, s[1] / 2.0, s[2] / 2.0),
            )
        })
        .collect();
    shapes.push(ground());
    shapes
}

fn world(shapes: Vec<(Pose, SharedShape)>, config: FlightWorldConfig) -> FlightWorld {
    FlightWorld::from_shapes(shapes, config).unwrap()
}

fn controller(airframe: &Airframe) -> GeometricController {
    GeometricController::new(airframe, ControllerGains::default()).unwrap()
}

fn fly(
    world: &mut FlightWorld,
    uav: UavHandle,
    airframe: &Airframe,
    trajectory: &dyn Trajectory,
) -> FlightRecord {
    fly_trajectory(
        world,
        uav,
        &controller(airframe),
        trajectory,
        &Completion::default(),
        &mut |_, _, _| {},
    )
}

#[test]
fn hover_holds_at_hover_speed_and_123_w() {
    let airframe = Airframe::kingfisher();
    let mut world = world(pillars(), FlightWorldConfig::default());
    let start = FlightState::hovering(&airframe, DVec3::new(0.0, 0.0, 1.0), 0.0);
    let uav = world.add_uav(&airframe, &start).unwrap();
    let hold = Hold {
        position: start.position,
        yaw: 0.0,
        duration: 10.0,
    };
    let record = fly(&mut world, uav, &airframe, &hold);
    assert_eq!(record.status, UavStatus::Flying);
    for w in world.state(uav).rotor_speeds {
        assert!((w / 1086.43 - 1.0).abs() < 0.01, "{w}");
    }
    let power = record.energy_j / record.duration_s;
    assert!((power / 123.0 - 1.0).abs() < 0.01, "{power}");
    assert!(world.state(uav).position.distance(start.position) < 1e-3);
    let summary = world.summary(uav);
    assert!((summary.avg_power_w - power).abs() < 1e-9);
    assert!(summary.battery_soc_end < 1.0 && summary.battery_soc_end > 0.98);
    // Far from the walls, no step needed the whole pipeline.
    assert_eq!(world.counts().pipeline_steps, 0);
}

#[test]
fn circle_and_figure_eight_at_3_m_s_are_tracked() {
    let airframe = Airframe::kingfisher();
    let centre = DVec3::new(2.0, -1.0, 1.5);
    for reference in [
        CurveReference::circle(centre, 3.0, 3.0, 2.0, 2.0),
        CurveReference::figure_eight(centre, 3.0, 3.0, 2.0, 2.0),
    ] {
        let mut world = world(pillars(), FlightWorldConfig::default());
        let start = FlightState::hovering(&airframe, reference.sample(0.0).position, 0.0);
        let uav = world.add_uav(&airframe, &start).unwrap();
        let record = fly(&mut world, uav, &airframe, &reference);
        assert_eq!(record.status, UavStatus::Flying);
        assert!(record.arrived);
        eprintln!(
            "{:?}: rms {:.4} m, max {:.4} m, {:.1} J over {:.2} s",
            reference.curve,
            record.rms_tracking_error_m,
            record.max_tracking_error_m,
            record.energy_j,
            record.duration_s
        );
        assert!(
            record.rms_tracking_error_m < 0.02,
            "{reference:?}: {record:?}"
        );
    }
}

#[test]
fn one_metre_step_settles_without_overshoot() {
    let airframe = Airframe::kingfisher();
    let mut world = world(vec![ground()], FlightWorldConfig::default());
    let start = FlightState::hovering(&airframe, DVec3::new(0.0, 0.0, 1.0), 0.0);
    let uav = world.add_uav(&airframe, &start).unwrap();
    let hold = Hold {
        position: DVec3::new(1.0, 0.0, 1.0),
        yaw: 0.0,
        duration: 4.0,
    };
    let mut overshoot: f64 = 0.0;
    let mut late_error: f64 = 0.0;
    fly_trajectory(
        &mut world,
        uav,
        &controller(&airframe),
        &hold,
        &Completion::default(),
        &mut |t, state, _| {
            overshoot = overshoot.max(state.position.x - 1.0);
            if t >= 2.5 {
                late_error = late_error.max(state.position.distance(hold.position));
            }
        },
    );
    eprintln!("step: overshoot {overshoot:.4} m, largest error after 2.5 s {late_error:.4} m");
    assert!(overshoot < 0.05, "{overshoot}");
    assert!(late_error < 0.02, "{late_error}");
}

/// A random feasible trajectory from `start`: 1 to 4 waypoints 1.5 to 6 m apart at 0.8 to
/// 2.5 m height, some with a heading.
fn random_trajectory(rng: &mut ChaCha8Rng, start: DVec3, airframe: &Airframe) -> impl Trajectory {
    let count = rng.random_range(1..=4);
    let mut waypoints = Vec::new();
    let mut previous = start;
    for _ in 0..count {
        let angle = rng.random_range(0.0..std::f64::consts::TAU);
        let distance = rng.random_range(1.5..6.0);
        let position = DVec3::new(
            previous.x + distance * angle.cos(),
            previous.y + distance * angle.sin(),
            rng.random_range(0.8..2.5),
        );
        let yaw = rng.random_bool(0.5).then(|| rng.random_range(-3.0..3.0));
        waypoints.push(Waypoint { position, yaw });
        previous = position;
    }
    let start = TrajectoryPoint::at_rest(start, 0.0);
    plan_min_snap(&start, &waypoints, &DynamicLimits::of(airframe)).unwrap()
}

#[test]
fn rollouts_predict_the_flown_energy_within_2_percent() {
    let airframe = Airframe::kingfisher();
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let mut worst: f64 = 0.0;
    for _ in 0..20 {
        let position = DVec3::new(0.0, 0.0, 1.0);
        let trajectory = random_trajectory(&mut rng, position, &airframe);
        let start = FlightState::hovering(&airframe, position, 0.0);
        let predicted = rollout(&airframe, &start, &trajectory, &RolloutConfig::default()).unwrap();
        let mut world = world(vec![ground()], FlightWorldConfig::default());
        let uav = world.add_uav(&airframe, &start).unwrap();
        let flown = fly(&mut world, uav, &airframe, &trajectory);
        assert_eq!(flown.status, UavStatus::Flying);
        assert!(flown.arrived && predicted.arrived);
        let error = predicted.energy_j / flown.energy_j - 1.0;
        worst = worst.max(error.abs());
        assert!(error.abs() < 0.02, "{predicted:?} {flown:?}");
        // Durations: the same completion rule, checked every 0.02 s vs every 1/300 s.
        assert!(
            (predicted.duration_s - flown.duration_s).abs() <= 0.02 + 1e-9,
            "{} vs {}",
            predicted.duration_s,
            flown.duration_s
        );
    }
    eprintln!("worst relative energy error over 20 trajectories: {worst:.5}");
}

#[test]
fn fast_path_matches_the_full_pipeline() {
    let airframe = Airframe::kingfisher();
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let position = DVec3::new(0.0, 0.0, 1.2);
    let trajectory = random_trajectory(&mut rng, position, &airframe);
    let start = FlightState::hovering(&airframe, position, 0.0);
    let mut results = Vec::new();
    for always_full_pipeline in [false, true] {
        let config = FlightWorldConfig {
            always_full_pipeline,
            ..FlightWorldConfig::default()
        };
        let mut world = world(vec![ground()], config);
        let uav = world.add_uav(&airframe, &start).unwrap();
        let record = fly(&mut world, uav, &airframe, &trajectory);
        let counts = world.counts();
        if always_full_pipeline {
            assert_eq!(counts.free_steps, 0);
        } else {
            assert_eq!(counts.pipeline_steps, 0);
        }
        results.push((record, world.state(uav)));
    }
    let ((fast, fast_state), (full, full_state)) = (results[0], results[1]);
    assert!(fast_state.position.distance(full_state.position) < 2e-3);
    assert!(
        (fast.energy_j / full.energy_j - 1.0).abs() < 1e-4,
        "{fast:?} {full:?}"
    );
}
