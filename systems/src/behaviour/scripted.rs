//! The kinematic `scripted` behaviour: the UAV follows a polyline of waypoints at a constant
//! speed, turning in place at each waypoint to face the next leg. The pose is set directly each
//! tick (no dynamics), so mapping can be studied on its own.

use bevy_ecs::prelude::*;
use glam::{Quat, Vec3};
use uavex_components::sim::SimClock;
use uavex_components::uav::{QuadState, UavEnded};

/// Where a scripted UAV is on its route.
#[derive(Component, Debug, Clone, PartialEq)]
pub struct ScriptedRoute {
    /// The points to visit in order (the start position is not included).
    pub waypoints: Vec<Vec3>,
    /// Cruise speed (m/s).
    pub speed: f32,
    /// Turn rate in place (rad/s).
    pub yaw_rate: f32,
    /// Index of the waypoint currently headed for.
    pub next: usize,
}

/// Heading (yaw about +z) that faces from `from` toward `to`; `None` when the leg is vertical
/// or empty (the heading is then kept).
fn heading(from: Vec3, to: Vec3) -> Option<f32> {
    let d = to - from;
    (d.x.hypot(d.y) > 1e-6).then(|| d.y.atan2(d.x))
}

/// Wraps an angle to (-pi, pi].
fn wrap_angle(a: f32) -> f32 {
    let a = a.rem_euclid(std::f32::consts::TAU);
    if a > std::f32::consts::PI {
        a - std::f32::consts::TAU
    } else {
        a
    }
}

/// Advances the route by `dt` seconds: first turn toward the next leg, then fly along it; time
/// left over at a waypoint carries into the next leg. Returns true when the last waypoint has
/// been reached.
pub fn advance(route: &mut ScriptedRoute, state: &mut QuadState, dt: f32) -> bool {
    let mut time_left = dt;
    let mut yaw = yaw_of(state.attitude);
    let start = state.position;
    while time_left > 0.0 {
        let Some(&target) = route.waypoints.get(route.next) else {
            break;
        };
        if let Some(wanted) = heading(state.position, target) {
            let error = wrap_angle(wanted - yaw);
            let turn_time = error.abs() / route.yaw_rate;
            if turn_time > time_left {
                yaw += error.signum() * route.yaw_rate * time_left;
                break;
            }
            yaw = wanted;
            time_left -= turn_time;
        }
        let to_go = target - state.position;
        let distance = to_go.length();
        let reach = route.speed * time_left;
        if reach < distance {
            state.position += to_go * (reach / distance);
            time_left = 0.0;
        } else {
            state.position = target;
            time_left -= distance / route.speed;
            route.next += 1;
        }
    }
    state.attitude = Quat::from_rotation_z(wrap_angle(yaw));
    state.velocity = if dt > 0.0 {
        (state.position - start) / dt
    } else {
        Vec3::ZERO
    };
    state.body_rates = Vec3::ZERO;
    route.next >= route.waypoints.len()
}

/// Yaw of an attitude (rotation about +z of its forward axis).
pub fn yaw_of(attitude: Quat) -> f32 {
    let forward = attitude * Vec3::X;
    forward.y.atan2(forward.x)
}

/// Control stage: moves every scripted UAV that is still under way.
pub fn fly_scripted(
    clock: Res<SimClock>,
    mut commands: Commands,
    mut uavs: Query<(Entity, &mut ScriptedRoute, &mut QuadState), Without<UavEnded>>,
) {
    for (entity, mut route, mut state) in &mut uavs {
        if advance(&mut route, &mut state, clock.dt as f32) {
            commands.entity(entity).insert(UavEnded::Finished);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn route(waypoints: Vec<Vec3>) -> ScriptedRoute {
        ScriptedRoute {
            waypoints,
            speed: 2.0,
            yaw_rate: 1.0,
            next: 0,
        }
    }

    #[test]
    fn flies_straight_at_speed_when_already_facing() {
        let mut r = route(vec![Vec3::new(10.0, 0.0, 1.0)]);
        let mut s = QuadState::at_rest(Vec3::new(0.0, 0.0, 1.0), 0.0);
        assert!(!advance(&mut r, &mut s, 1.0));
        assert!((s.position - Vec3::new(2.0, 0.0, 1.0)).length() < 1e-5);
        assert!((s.velocity - Vec3::new(2.0, 0.0, 0.0)).length() < 1e-4);
    }

    #[test]
    fn turns_in_place_before_moving() {
        // Facing +x, next waypoint along +y: a quarter turn at 1 rad/s takes pi/2 s.
        let mut r = route(vec![Vec3::new(0.0, 4.0, 1.0)]);
        let mut s = QuadState::at_rest(Vec3::new(0.0, 0.0, 1.0), 0.0);
        advance(&mut r, &mut s, 1.0);
        assert_eq!(s.position, Vec3::new(0.0, 0.0, 1.0));
        assert!((yaw_of(s.attitude) - 1.0).abs() < 1e-5);
        // The remaining 0.5708 s of turning, then 0.4292 s of flight at 2 m/s.
        advance(&mut r, &mut s, 1.0);
        let flown = 2.0 * (2.0 - std::f32::consts::FRAC_PI_2);
        assert!((s.position.y - flown).abs() < 1e-4, "{}", s.position.y);
        assert!((yaw_of(s.attitude) - std::f32::consts::FRAC_PI_2).abs() < 1e-5);
    }

    #[test]
    fn carries_time_across_waypoints_and_finishes() {
        let mut r = route(vec![Vec3::new(1.0, 0.0, 1.0), Vec3::new(2.0, 0.0, 1.0)]);
        let mut s = QuadState::at_rest(Vec3::new(0.0, 0.0, 1.0), 0.0);
        // 2 m in a straight line at 2 m/s: done after 1 s, no turn needed.
        assert!(advance(&mut r, &mut s, 1.0));
        assert_eq!(s.position, Vec3::new(2.0, 0.0, 1.0));
    }

    #[test]
    fn takes_the_short_way_round() {
        // Facing +x at yaw 3.0; target behind-left at yaw -3.0: shortest turn is +0.283 rad.
        let mut r = route(vec![Vec3::new((-3.0f32).cos(), (-3.0f32).sin(), 0.0) * 5.0]);
        let mut s = QuadState::at_rest(Vec3::ZERO, 3.0);
        advance(&mut r, &mut s, 0.1);
        assert!((wrap_angle(yaw_of(s.attitude) - 3.1)).abs() < 1e-4);
    }

    #[test]
    fn vertical_legs_keep_heading() {
        let mut r = route(vec![Vec3::new(0.0, 0.0, 3.0)]);
        let mut s = QuadState::at_rest(Vec3::new(0.0, 0.0, 1.0), 0.7);
        assert!(advance(&mut r, &mut s, 1.0));
        assert!((yaw_of(s.attitude) - 0.7).abs() < 1e-5);
    }
}
