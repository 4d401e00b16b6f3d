//! The `coverage` behaviour in a run (`uavex run`): the mission is planned when the run is
//! built (altitude search, coverage.md) and its [`plan_profile`] is flown on the true quadrotor
//! by the same components as the `waypoints` behaviour (controller, reference trajectory, rotor
//! commands, energy account, completion rule), so the run's summary reports the flown energy.

use super::flight::plan_profile;
use super::spec::CoverageSpec;
use crate::flight::{Physics, dynamic_flight};
use crate::scenario::UavSpec;
use crate::world::BuildError;
use bevy_ecs::bundle::Bundle;
use glam::DVec3;
use std::path::Path;
use std::sync::Arc;
use uavex_components::airframe::Airframe;
use uavex_components::uav::PredictedMission;
use uavex_systems::behaviour::waypoints::WaypointTour;
use uavex_systems::flight::Completion;

/// Farthest the UAV may start from the field's start vertex (m): it takes off there.
const START_TOLERANCE_M: f64 = 1.0;

/// Plans `uav[index]`'s coverage mission and returns the components that fly it, hovering at
/// its start in `physics`. Problems come back at the scenario field they concern.
pub fn coverage_flight(
    spec: &UavSpec,
    index: usize,
    airframe: &Airframe,
    physics: &mut Physics,
    coverage: &CoverageSpec,
    base_dir: &Path,
    scenario_path: &Path,
) -> Result<impl Bundle + use<>, BuildError> {
    let behaviour = format!("uav[{index}].behaviour");
    let setup = coverage
        .resolve(base_dir, scenario_path)
        .map_err(|e| BuildError::new(behaviour.clone(), e.to_string()))?;
    let outcome = setup
        .plan()
        .map_err(|e| BuildError::new(behaviour.clone(), e.to_string()))?;
    let start = DVec3::from_array(spec.start.position);
    let vertex = setup.problem.polygon.vertices()[setup.problem.start_vertex];
    if start.truncate().distance(vertex) > START_TOLERANCE_M {
        return Err(BuildError::new(
            format!("uav[{index}].start.position"),
            format!(
                "a coverage mission takes off from its start vertex ({:.2}, {:.2}); start \
                 there",
                vertex.x, vertex.y
            ),
        ));
    }
    let profile = plan_profile(&outcome.plan, &setup.model, start.z);
    Ok((
        dynamic_flight(&spec.name, index, airframe, physics, Arc::new(profile))?,
        WaypointTour {
            completion: Completion::default(),
        },
        PredictedMission {
            energy_j: outcome.plan.energy_j,
            time_s: outcome.plan.time_s,
        },
    ))
}
