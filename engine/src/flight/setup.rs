//! What a run needs before its first tick to fly a UAV: its airframe (preset plus overrides)
//! and, for the `waypoints` behaviour, its plan through the known geometry. Every problem comes
//! back as a [`BuildError`] at the scenario field it concerns, for the loader to locate.

use super::systems::{Physics, PhysicsBody};
use crate::scenario::UavSpec;
use crate::world::BuildError;
use bevy_ecs::bundle::Bundle;
use glam::DVec3;
use std::sync::Arc;
use uavex_components::airframe::{Airframe, OVERRIDE_NAMES};
use uavex_components::trajectory::{PiecewisePolynomial, Trajectory};
use uavex_components::uav::QuadState;
use uavex_components::world::WorldGeometry;
use uavex_systems::behaviour::waypoints::{CLEARANCE_MARGIN_M, WaypointTour, plan_tour};
use uavex_systems::flight::{
    Completion, ControllerGains, FlightController, FlightEnergy, FlightState, GeometricController,
    ReferenceTrajectory, RotorCommands,
};
use uavex_systems::trajectory::PlanError;

/// The airframe of `uav[index]`: its preset with its `airframe_overrides` applied and checked.
///
/// An unknown preset is reported at `uav[i].airframe`; an unknown override name, or a value
/// that makes the airframe unflyable, at `uav[i].airframe_overrides.<name>` (the override the
/// airframe's complaint names first), else at the overrides table.
pub fn airframe_of(spec: &UavSpec, index: usize) -> Result<Airframe, Vec<BuildError>> {
    let field = |rest: &str| format!("uav[{index}].{rest}");
    let mut airframe = Airframe::preset(&spec.airframe)
        .map_err(|message| vec![BuildError::new(field("airframe"), message)])?;
    let unknown: Vec<BuildError> = spec
        .airframe_overrides
        .keys()
        .filter(|name| !OVERRIDE_NAMES.contains(&name.as_str()))
        .map(|name| {
            BuildError::new(
                field(&format!("airframe_overrides.{name}")),
                format!(
                    "unknown airframe field `{name}`; valid fields: {}",
                    OVERRIDE_NAMES.join(", ")
                ),
            )
        })
        .collect();
    if !unknown.is_empty() {
        return Err(unknown);
    }
    airframe
        .apply_overrides(&spec.airframe_overrides)
        .map_err(|message| {
            let blamed = first_named(&message, spec.airframe_overrides.keys());
            let path = match blamed {
                Some(name) => field(&format!("airframe_overrides.{name}")),
                None => field("airframe_overrides"),
            };
            vec![BuildError::new(
                path,
                format!(
                    "the '{}' airframe with these overrides cannot fly: {message}",
                    spec.airframe
                ),
            )]
        })?;
    Ok(airframe)
}

/// Of `names`, the one `message` mentions first as a whole word.
fn first_named<'a>(message: &str, names: impl Iterator<Item = &'a String>) -> Option<&'a str> {
    let is_word = |c: char| c.is_ascii_alphanumeric() || c == '_';
    names
        .filter_map(|name| {
            message
                .match_indices(name.as_str())
                .find(|&(at, _)| {
                    let before = message[..at].chars().next_back();
                    let after = message[at + name.len()..].chars().next();
                    !before.is_some_and(is_word) && !after.is_some_and(is_word)
                })
                .map(|(at, _)| (at, name.as_str()))
        })
        .min_by_key(|&(at, _)| at)
        .map(|(_, name)| name)
}

/// The `waypoints` behaviour of `uav[index]`: its plan ([`plan_waypoints`]), its body in
/// `physics`, hovering at the start, and the components that fly it (controller, reference
/// from time 0, rotor commands, energy account, completion rule).
#[allow(clippy::too_many_arguments)]
pub fn waypoint_flight(
    spec: &UavSpec,
    index: usize,
    airframe: &Airframe,
    geometry: &WorldGeometry,
    physics: &mut Physics,
    waypoints: &[[f64; 3]],
    yaw: Option<&[f64]>,
    collision_check: bool,
) -> Result<impl Bundle + use<>, BuildError> {
    let tour = plan_waypoints(
        spec,
        index,
        airframe,
        geometry,
        waypoints,
        yaw,
        collision_check,
    )?;
    Ok((
        dynamic_flight(&spec.name, index, airframe, physics, Arc::new(tour))?,
        WaypointTour {
            completion: Completion::default(),
        },
    ))
}

/// The components that fly `uav[index]` on the true quadrotor: its body in `physics`, hovering
/// where `reference` starts, the geometric controller tracking `reference` from time 0, its
/// rotor commands and its energy account. Every dynamic behaviour starts from these.
pub fn dynamic_flight(
    name: &str,
    index: usize,
    airframe: &Airframe,
    physics: &mut Physics,
    reference: Arc<dyn Trajectory>,
) -> Result<impl Bundle + use<>, BuildError> {
    let controller =
        GeometricController::new(airframe, ControllerGains::default()).ok_or_else(|| {
            BuildError::new(
                format!("uav[{index}].airframe_overrides"),
                "the rotor layout cannot be mixed into thrust and torques",
            )
        })?;
    let first = reference.sample(0.0);
    let start = FlightState::hovering(airframe, first.position, first.yaw);
    let body = physics
        .add(name, airframe, &start)
        .map_err(|e| BuildError::new(format!("uav[{index}].start.position"), e.to_string()))?;
    Ok((
        QuadState::from(&start),
        PhysicsBody(body),
        FlightController(controller),
        ReferenceTrajectory {
            trajectory: reference,
            start_s: 0.0,
        },
        RotorCommands(start.rotor_speeds),
        FlightEnergy::new(&airframe.battery),
    ))
}

/// The `waypoints` behaviour's plan for `uav[index]`: a minimum-snap tour from its start,
/// checked (when `collision_check`) against the world's true geometry inflated by the
/// airframe's bounding radius and [`CLEARANCE_MARGIN_M`]. A plan that cannot be made is an
/// error at the waypoint, start or behaviour it concerns.
pub fn plan_waypoints(
    spec: &UavSpec,
    index: usize,
    airframe: &Airframe,
    geometry: &WorldGeometry,
    waypoints: &[[f64; 3]],
    yaw: Option<&[f64]>,
    collision_check: bool,
) -> Result<PiecewisePolynomial, BuildError> {
    let clearance = (airframe.bounding_radius() + CLEARANCE_MARGIN_M) as f32;
    let blocked = |p: DVec3| geometry.intersects_ball(p.as_vec3(), clearance);
    let positions: Vec<DVec3> = waypoints.iter().map(|&w| DVec3::from_array(w)).collect();
    let start = DVec3::from_array(spec.start.position);
    plan_tour(
        airframe,
        start,
        spec.start.yaw,
        &positions,
        yaw,
        collision_check.then_some(&blocked as &dyn Fn(DVec3) -> bool),
    )
    .map_err(|error| plan_error(index, f64::from(clearance), error))
}

/// A planning error at the scenario field it concerns, in the words of the file.
fn plan_error(index: usize, clearance: f64, error: PlanError) -> BuildError {
    let behaviour = format!("uav[{index}].behaviour");
    let waypoint = |k: usize| format!("{behaviour}.waypoints[{k}]");
    let near =
        format!("within {clearance:.2} m (the airframe's radius and a margin) of an obstacle");
    let at = |time_s: f64, position: DVec3| {
        format!(
            "t = {time_s:.2} s near ({:.2}, {:.2}, {:.2})",
            position.x, position.y, position.z
        )
    };
    match error {
        PlanError::StartBlocked => BuildError::new(
            format!("uav[{index}].start.position"),
            format!("the waypoint tour cannot start here: the start lies {near}"),
        ),
        PlanError::WaypointBlocked { index: k, .. } => {
            BuildError::new(waypoint(k), format!("the waypoint lies {near}"))
        }
        PlanError::CoincidentWaypoints { index: k } => BuildError::new(
            waypoint(k),
            "the waypoint repeats the point before it (and its heading)",
        ),
        PlanError::Collision { time_s, position } => BuildError::new(
            format!("{behaviour}.waypoints"),
            format!(
                "the tour passes {near} at {}, and the straight leg there is blocked too: add a \
                 waypoint that leads around it",
                at(time_s, position)
            ),
        ),
        // The legs are clear but the polynomial bulges off them, even with midpoints added.
        PlanError::StillBlocked {
            added,
            time_s,
            position,
        } => BuildError::new(
            format!("{behaviour}.waypoints"),
            format!(
                "the tour passes {near} at {}, and still does with {added} waypoints added along \
                 its legs: add waypoints that hold it to a straighter path there",
                at(time_s, position)
            ),
        ),
        other => BuildError::new(behaviour, format!("no tour could be planned: {other}")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::{BehaviourSpec, StartSpec};
    use std::collections::BTreeMap;

    fn uav(airframe: &str, overrides: &[(&str, f64)]) -> UavSpec {
        UavSpec {
            name: "u".to_owned(),
            start: StartSpec {
                position: [0.0, 0.0, 1.0],
                yaw: 0.0,
            },
            airframe: airframe.to_owned(),
            airframe_overrides: overrides
                .iter()
                .map(|&(k, v)| (k.to_owned(), v))
                .collect::<BTreeMap<_, _>>(),
            sensors: Vec::new(),
            behaviour: BehaviourSpec::Waypoints {
                waypoints: vec![[1.0, 0.0, 1.0]],
                yaw: None,
                collision_check: true,
            },
        }
    }

    #[test]
    fn overrides_apply_and_problems_point_at_their_field() {
        let airframe = airframe_of(&uav("iris", &[("mass", 1.5)]), 0).unwrap();
        assert_eq!((airframe.name.as_str(), airframe.mass), ("iris", 1.5));

        let errors =
            airframe_of(&uav("kingfisher", &[("wieght", 1.0), ("mass", 0.8)]), 2).unwrap_err();
        assert_eq!(errors.len(), 1);
        assert_eq!(errors[0].path, "uav[2].airframe_overrides.wieght");
        assert!(errors[0].message.contains("mass"), "{}", errors[0].message);

        // 4 kg on rotors that lift 4 x 8.5 N = 34 N < 39.2 N: the mass is blamed.
        let errors = airframe_of(&uav("kingfisher", &[("mass", 4.0)]), 0).unwrap_err();
        assert_eq!(errors[0].path, "uav[0].airframe_overrides.mass");
        // rotor_speed_min above rotor_speed_max: the override named first in the complaint.
        let errors = airframe_of(
            &uav(
                "kingfisher",
                &[("rotor_speed_max", 2000.0), ("rotor_speed_min", 2500.0)],
            ),
            0,
        )
        .unwrap_err();
        assert_eq!(errors[0].path, "uav[0].airframe_overrides.rotor_speed_min");

        let errors = airframe_of(&uav("hummingbird", &[]), 1).unwrap_err();
        assert_eq!(errors[0].path, "uav[1].airframe");
    }

    #[test]
    fn a_blocked_tour_points_at_its_waypoints() {
        let position = DVec3::new(1.0, 2.0, 3.0);
        for error in [
            PlanError::Collision {
                time_s: 1.5,
                position,
            },
            PlanError::StillBlocked {
                added: 24,
                time_s: 1.5,
                position,
            },
        ] {
            let built = plan_error(3, 0.3, error);
            assert_eq!(built.path, "uav[3].behaviour.waypoints");
            assert!(
                built.message.contains("t = 1.50 s near (1.00, 2.00, 3.00)")
                    && built.message.contains(": add "),
                "{}",
                built.message
            );
        }
        let other = plan_error(3, 0.3, PlanError::Singular);
        assert_eq!(other.path, "uav[3].behaviour");
    }

    #[test]
    fn whole_words_only() {
        let names = ["max".to_owned(), "mass".to_owned()];
        assert_eq!(
            first_named("rotor_speed_max is low; mass too", names.iter()),
            Some("mass")
        );
        assert_eq!(first_named("nothing here", names.iter()), None);
    }
}
