//! Every seed of a seeded pillar field builds, whatever its `start_clearance`: the pillars drawn
//! into a UAV's body where it starts are left out, so a sweep over seeds loses no run to a
//! start refused for a pillar (as it did, for explorers' start capsules, before 2026-12-07).

mod common;

use uavex::components::world::WorldGeometry;
use uavex::engine::flight::airframe_of;

/// A dense field (two trunks per square metre) that asks for no clearance around a scripted
/// UAV's start.
const DENSE_FIELD: &str = r#"
name = "dense_field"
seed = 1
time_limit_s = 1.0

[world]
ground = true
bounds = { min = [-3.0, -3.0, 0.0], max = [3.0, 3.0, 2.0] }

[[world.obstacle]]
kind = "pillars"
name = "trunks"
region_min = [-3.0, -3.0]
region_max = [3.0, 3.0]
density = 2.0
radius_min = 0.1
radius_max = 0.3
height = 2.0
start_clearance = 0.0

[[uav]]
name = "scout"
start = { position = [0.0, 0.0, 1.0], yaw = 0.0 }

[uav.behaviour]
kind = "scripted"
speed = 1.0
waypoints = [[0.0, 0.0, 1.0]]
"#;

#[test]
fn a_seeded_field_leaves_every_uavs_start_body_clear() {
    let loaded = common::scenario(DENSE_FIELD);
    let scenario = &loaded.scenario;
    let spec = &scenario.uavs[0];
    let radius = airframe_of(spec, 0).unwrap().bounding_radius() as f32;
    let start = glam::DVec3::from_array(spec.start.position).as_vec3();
    let blocked = |world: &WorldGeometry| world.intersects_ball(start, radius);
    let drawn_into_it = common::seeds_kept_clear(&loaded, 1..=20, blocked, usize::MAX);
    // The field is dense enough that the test means something: 11 of the 20 seeds drew a
    // trunk into the body, and were refused before.
    assert_eq!(drawn_into_it, [1, 2, 6, 7, 9, 14, 15, 16, 18, 19, 20]);
}
