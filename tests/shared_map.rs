//! Several UAVs with sensors of different quality write into one map, each with its own
//! log-odds increments (common.md §1-2; heterogeneous seed).

mod common;

use bevy_ecs::system::SystemState;
use glam::Vec3;
use uavex::engine::sim::Sim;
use uavex::systems::mapping::{MapReader, OccupancyMap};

fn logit(p: f32) -> f32 {
    (p / (1.0 - p)).ln()
}

#[test]
fn two_uavs_with_different_qualities_share_one_map() {
    let text = format!(
        r#"
name = "shared"
time_limit_s = 1.0
{room}
[[uav]]
name = "reliable"
start = {{ position = [0.0, -1.0, 1.0], yaw = 0.0 }}
behaviour = {{ kind = "scripted", speed = 1.0, waypoints = [[0.0, -1.0, 1.0]] }}
[[uav.sensor]]
kind = "depth_camera"
quality = {{ p_hit = 0.9, p_miss = 0.3 }}

[[uav]]
name = "noisy"
start = {{ position = [0.0, 1.0, 1.0], yaw = 3.141592653589793 }}
behaviour = {{ kind = "scripted", speed = 1.0, waypoints = [[0.0, 1.0, 1.0]] }}
[[uav.sensor]]
kind = "depth_camera"
quality = {{ p_hit = 0.6, p_miss = 0.45 }}
"#,
        room = common::ROOM
    );
    let loaded = common::scenario(&text);
    let mut sim = Sim::build(&loaded, 7).unwrap();
    // The first tick: both cameras sweep once at t = 0 and the map integrates both scans.
    sim.step();
    let mut state = SystemState::<MapReader>::new(&mut sim.world);
    let map = state.get(&sim.world).unwrap();
    let l = |p: Vec3| map.log_odds(map.config().key_of(p).unwrap());

    // Each wall seen straight ahead holds exactly one hit of its own UAV's sensor...
    let east_wall = l(Vec3::new(4.05, -1.0, 1.0)).expect("east wall seen");
    let west_wall = l(Vec3::new(-4.05, 1.0, 1.0)).expect("west wall seen");
    assert!(
        (east_wall - logit(0.9)).abs() < 1e-3,
        "east wall l = {east_wall}"
    );
    assert!(
        (west_wall - logit(0.6)).abs() < 1e-3,
        "west wall l = {west_wall}"
    );
    // ...and the free space in front of each camera one miss of that sensor.
    let east_free = l(Vec3::new(2.05, -1.05, 1.05)).expect("free space seen");
    let west_free = l(Vec3::new(-2.05, 1.05, 1.05)).expect("free space seen");
    assert!(
        (east_free - logit(0.3)).abs() < 1e-3,
        "east free l = {east_free}"
    );
    assert!(
        (west_free - logit(0.45)).abs() < 1e-3,
        "west free l = {west_free}"
    );
    // Behind both cameras nothing is known yet.
    assert_eq!(l(Vec3::new(-2.05, -1.05, 1.05)), None);
}
