//! Contacts and endings: crashes into walls and UAVs, wrecks, empty batteries, bad setups,
//! and a collision-free tour of the Pillars scene.

use super::*;

#[test]
fn flying_into_a_wall_crashes_there() {
    let airframe = Airframe::kingfisher();
    let mut world = world(pillars(), FlightWorldConfig::default());
    // Toward the east wall, whose inner face is at x = 10.6641 - 0.075 = 10.589.
    let position = DVec3::new(7.0, 0.0, 1.25);
    let start = FlightState::hovering(&airframe, position, 0.0);
    let uav = world.add_uav(&airframe, &start).unwrap();
    let trajectory = plan_min_snap(
        &TrajectoryPoint::at_rest(position, 0.0),
        &[Waypoint::new(DVec3::new(13.0, 0.0, 1.25))],
        &DynamicLimits::of(&airframe),
    )
    .unwrap();
    let record = fly(&mut world, uav, &airframe, &trajectory);
    let UavStatus::Crashed { time_s, position } = record.status else {
        panic!("no crash: {record:?}");
    };
    eprintln!(
        "crash at t = {time_s:.3} s, {position:?}, {:?}",
        world.counts()
    );
    // The collider's front (half-length 0.14 m) meets the face when the centre reaches
    // x = 10.449; the crash is found within one step, which moves at most 5 m/s / 300 = 1.7 cm.
    assert!(
        position.x >= 10.449 && position.x < 10.449 + 0.017,
        "{position:?}"
    );
    assert!(time_s > 0.0 && time_s <= trajectory.duration());
    assert_eq!(world.status(uav), record.status);
    assert!(world.counts().pipeline_steps > 0 && world.counts().free_steps > 0);
    // `from_shapes` leaves every collider's user data at 0; no power after the crash.
    assert_eq!(
        world.crashed_into(uav),
        Some(CrashTarget::Fixed { user_data: 0 })
    );
    assert_eq!(world.power_w(uav), 0.0);
    // A crashed UAV no longer moves.
    let before = world.state(uav).position;
    world.step();
    assert_eq!(world.state(uav).position, before);
}

#[test]
fn flying_along_a_wall_does_not_crash() {
    let airframe = Airframe::kingfisher();
    let mut world = world(pillars(), FlightWorldConfig::default());
    // 25 cm between the collider and the inner face of the east wall (x = 10.589).
    let x = 10.589 - 0.14 - 0.25;
    let position = DVec3::new(x, -5.0, 1.25);
    let start = FlightState::hovering(&airframe, position, 0.0);
    let uav = world.add_uav(&airframe, &start).unwrap();
    let trajectory = plan_min_snap(
        &TrajectoryPoint::at_rest(position, 0.0),
        &[Waypoint::new(DVec3::new(x, 3.0, 1.25))],
        &DynamicLimits::of(&airframe),
    )
    .unwrap();
    let record = fly(&mut world, uav, &airframe, &trajectory);
    assert_eq!(record.status, UavStatus::Flying);
    assert!(record.arrived);
}

#[test]
fn two_uavs_that_meet_both_crash() {
    let airframe = Airframe::kingfisher();
    let mut world = world(vec![ground()], FlightWorldConfig::default());
    let a = world
        .add_uav(
            &airframe,
            &FlightState::hovering(&airframe, DVec3::new(-2.0, 0.0, 1.0), 0.0),
        )
        .unwrap();
    let b = world
        .add_uav(
            &airframe,
            &FlightState::hovering(&airframe, DVec3::new(2.0, 0.0, 1.0), 0.0),
        )
        .unwrap();
    let controller = controller(&airframe);
    // Both head for the origin.
    let target = TrajectoryPoint::at_rest(DVec3::new(0.0, 0.0, 1.0), 0.0);
    for _ in 0..900 {
        for uav in [a, b] {
            let command = controller.command(&world.state(uav), &target);
            world.set_commands(uav, command.rotor_speed_commands);
        }
        world.step();
    }
    assert!(
        matches!(world.status(a), UavStatus::Crashed { .. }),
        "{:?}",
        world.status(a)
    );
    assert!(matches!(world.status(b), UavStatus::Crashed { .. }));
    assert_eq!(world.crashed_into(a), Some(CrashTarget::Uav(b)));
    assert_eq!(world.crashed_into(b), Some(CrashTarget::Uav(a)));
}

#[test]
fn an_empty_battery_ends_the_flight() {
    let mut airframe = Airframe::kingfisher();
    // 0.05 Wh = 180 J, 80 % usable: 144 J, i.e. 144 / 123.14 = 1.169 s of hover.
    airframe.battery.capacity_wh = 0.05;
    let mut world = world(vec![ground()], FlightWorldConfig::default());
    let start = FlightState::hovering(&airframe, DVec3::new(0.0, 0.0, 1.0), 0.0);
    let uav = world.add_uav(&airframe, &start).unwrap();
    let hold = Hold {
        position: start.position,
        yaw: 0.0,
        duration: 5.0,
    };
    let record = fly(&mut world, uav, &airframe, &hold);
    let UavStatus::BatteryEmpty { time_s, .. } = record.status else {
        panic!("{record:?}");
    };
    assert!((time_s - 1.169).abs() < 0.005, "{time_s}");
    assert!((world.summary(uav).battery_soc_end - 0.2).abs() < 0.005);
    // The step that spent the battery drew power; the next ones draw none.
    assert!(world.power_w(uav) > 100.0);
    world.step();
    assert_eq!(world.power_w(uav), 0.0);
}

#[test]
fn bad_setups_are_errors() {
    let airframe = Airframe::kingfisher();
    let config = FlightWorldConfig {
        dt: 0.0,
        ..FlightWorldConfig::default()
    };
    assert!(matches!(
        FlightWorld::from_shapes(pillars(), config),
        Err(PhysicsError::InvalidStep(_))
    ));
    let mut world = world(pillars(), FlightWorldConfig::default());
    // Inside pillar 1 (centre (-0.36, -6.40), 2 m wide).
    let inside = FlightState::hovering(&airframe, DVec3::new(-0.3, -6.4, 1.0), 0.0);
    assert!(matches!(
        world.add_uav(&airframe, &inside),
        Err(PhysicsError::StartsInCollision(_))
    ));
    // Touching the ground.
    let on_ground = FlightState::hovering(&airframe, DVec3::new(0.0, 0.0, 0.02), 0.0);
    assert!(world.add_uav(&airframe, &on_ground).is_err());
    let mut nan = FlightState::hovering(&airframe, DVec3::ZERO, 0.0);
    nan.position.z = f64::NAN;
    assert_eq!(
        world.add_uav(&airframe, &nan),
        Err(PhysicsError::NonFiniteStart)
    );
    let mut broken = airframe.clone();
    broken.mass = 0.0;
    let fine = FlightState::hovering(&airframe, DVec3::new(0.0, 0.0, 1.0), 0.0);
    assert!(matches!(
        world.add_uav(&broken, &fine),
        Err(PhysicsError::InvalidAirframe(_))
    ));
    assert_eq!(world.uav_count(), 0);
}

#[test]
fn idle_rotors_fall_at_g_minus_their_thrust() {
    let airframe = Airframe::kingfisher();
    let mut world = world(vec![ground()], FlightWorldConfig::default());
    let mut start = FlightState::hovering(&airframe, DVec3::new(0.0, 0.0, 3.0), 0.0);
    start.rotor_speeds = [150.0; 4];
    let uav = world.add_uav(&airframe, &start).unwrap();
    world.set_commands(uav, [150.0; 4]);
    for _ in 0..150 {
        world.step();
    }
    // Idle thrust 4 x 1.562522e-6 x 150^2 = 0.14063 N: a = -9.81 + 0.14063 / 0.752
    // = -9.6230 m/s^2; after 0.5 s, symplectic Euler at 1/300 s drops a dt^2 n (n + 1) / 2
    // = 9.6230 / 90000 x 11325 = 1.2109 m (exact: 1.2029 m).
    let state = world.state(uav);
    assert!((3.0 - state.position.z - 1.2109).abs() < 1e-3, "{state:?}");
    assert!((state.velocity.z + 9.6230 * 0.5).abs() < 1e-3);
    // Power of four idle rotors: 4 x (6.088e-3 x 150 + 1.875e-8 x 150^3) = 3.9058 W.
    assert!((world.power_w(uav) - 3.9058).abs() < 1e-3);
}

/// Waypoints of a tour of the Pillars scene: past the pillars and along the walls.
const PILLARS_TOUR: [(f64, f64, f64); 7] = [
    (8.0, -8.0, 1.0),
    (9.8, 0.0, 1.5),
    (5.0, 8.5, 1.0),
    (-2.0, 2.0, 2.0),
    (-8.0, -3.0, 1.0),
    (-3.0, -9.5, 1.5),
    (0.0, 0.0, 1.0),
];

#[test]
fn collision_free_tour_of_the_pillars_is_flown() {
    let airframe = Airframe::kingfisher();
    let shapes = pillars();
    // Blocked: within the UAV's bounding radius plus 10 cm of any shape.
    let inflation = (airframe.bounding_radius() + 0.1) as f32;
    let blocked = |p: DVec3| {
        shapes
            .iter()
            .any(|(pose, shape)| shape.distance_to_point(pose, p.as_vec3(), true) < inflation)
    };
    let waypoints: Vec<Waypoint> = PILLARS_TOUR
        .iter()
        .map(|&(x, y, z)| Waypoint::new(DVec3::new(x, y, z)))
        .collect();
    let start = TrajectoryPoint::at_rest(DVec3::new(0.0, 0.0, 1.0), 0.0);
    let limits = DynamicLimits::of(&airframe);
    // Without the collision check, the corner at (9.8, 0) swings into the east wall.
    let plain = plan_min_snap(&start, &waypoints, &limits).unwrap();
    assert!(!is_collision_free(&plain, &blocked, 0.05, limits.max_velocity).unwrap());
    let trajectory = plan_collision_free(&start, &waypoints, &limits, &blocked, 0.05).unwrap();
    let mut world = world(shapes.clone(), FlightWorldConfig::default());
    let hover = FlightState::hovering(&airframe, start.position, 0.0);
    let uav = world.add_uav(&airframe, &hover).unwrap();
    let record = fly(&mut world, uav, &airframe, &trajectory);
    eprintln!("tour: {record:?}, {:?}", world.counts());
    assert_eq!(record.status, UavStatus::Flying);
    assert!(record.arrived);
    let summary = world.summary(uav);
    assert!(summary.path_length_m > 50.0);
}

#[test]
fn a_wreck_is_an_obstacle_for_the_others() {
    let airframe = Airframe::kingfisher();
    let mut small_battery = airframe.clone();
    small_battery.battery.capacity_wh = 0.05;
    let mut world = world(vec![ground()], FlightWorldConfig::default());
    let a_position = DVec3::new(0.0, 0.0, 1.0);
    let a = world
        .add_uav(
            &small_battery,
            &FlightState::hovering(&airframe, a_position, 0.0),
        )
        .unwrap();
    let b_start = DVec3::new(-3.0, 0.0, 1.0);
    let b = world
        .add_uav(&airframe, &FlightState::hovering(&airframe, b_start, 0.0))
        .unwrap();
    let controller = controller(&airframe);
    // Both hover until A's battery is spent (1.17 s); A stays where it stopped.
    while world.status(a) == UavStatus::Flying {
        for (uav, at) in [(a, a_position), (b, b_start)] {
            let command = controller.command(&world.state(uav), &TrajectoryPoint::at_rest(at, 0.0));
            world.set_commands(uav, command.rotor_speed_commands);
        }
        world.step();
    }
    let wreck = world.state(a).position;
    // B flies straight through the wreck's place.
    let trajectory = plan_min_snap(
        &TrajectoryPoint::at_rest(b_start, 0.0),
        &[Waypoint::new(DVec3::new(3.0, 0.0, 1.0))],
        &DynamicLimits::of(&airframe),
    )
    .unwrap();
    let record = fly(&mut world, b, &airframe, &trajectory);
    let UavStatus::Crashed { position, .. } = record.status else {
        panic!("B flew through the wreck: {record:?}");
    };
    // The boxes (0.28 m long) meet when the centres are 0.28 m apart along x.
    assert!(
        (wreck.x - position.x - 0.28).abs() < 0.03,
        "{wreck:?} {position:?}"
    );
}

#[test]
fn a_uav_can_join_a_running_world() {
    let airframe = Airframe::kingfisher();
    let mut world = world(pillars(), FlightWorldConfig::default());
    let a_position = DVec3::new(0.0, 0.0, 1.0);
    let a = world
        .add_uav(
            &airframe,
            &FlightState::hovering(&airframe, a_position, 0.0),
        )
        .unwrap();
    let controller = controller(&airframe);
    let hold = |world: &mut FlightWorld, uav: UavHandle, at: DVec3| {
        let command = controller.command(&world.state(uav), &TrajectoryPoint::at_rest(at, 0.0));
        world.set_commands(uav, command.rotor_speed_commands);
    };
    for _ in 0..300 {
        hold(&mut world, a, a_position);
        world.step();
    }
    assert_eq!(world.counts().pipeline_steps, 0);
    // B joins 0.5 m away (close enough for the pipeline) and both hover on.
    let b_position = DVec3::new(0.5, 0.0, 1.0);
    let b = world
        .add_uav(
            &airframe,
            &FlightState::hovering(&airframe, b_position, 0.0),
        )
        .unwrap();
    for _ in 0..300 {
        hold(&mut world, a, a_position);
        hold(&mut world, b, b_position);
        world.step();
    }
    assert_eq!(world.status(a), UavStatus::Flying);
    assert_eq!(world.status(b), UavStatus::Flying);
    assert!(world.counts().pipeline_steps >= 300);
    assert!(world.state(b).position.distance(b_position) < 1e-3);
}
