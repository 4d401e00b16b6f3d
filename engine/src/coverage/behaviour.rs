//! The `coverage` behaviour in a run (`uavex run`): the mission is planned when the run is
//! built (altitude search, coverage.md) and its [`plan_profile`] is flown on the true quadrotor
//! by the same components as the `waypoints` behaviour (controller, reference trajectory, rotor
//! commands, energy account, completion rule), so the run's summary reports the flown energy.

use super::CoverageIoError;
use super::flight::plan_profile;
use super::scenario::scenario_field;
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

/// A coverage problem at the scenario field it concerns (`uav[0].behaviour.overlap.y`), so the
/// loader shows its line; problems of no one field stay at the behaviour.
fn located(index: usize, error: CoverageIoError) -> BuildError {
    let (field, message) = scenario_field(index, error);
    BuildError::new(field, message)
}

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
    let located = |e| located(index, e);
    let setup = coverage.resolve(base_dir, scenario_path).map_err(located)?;
    let outcome = setup.plan().map_err(located)?;
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

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::PathBuf;
    use uavex_systems::coverage::MissionError;

    #[test]
    fn spec_problems_point_at_their_field() {
        let error = located(
            2,
            CoverageIoError::Spec {
                path: PathBuf::from("s.toml"),
                field: "overlap.y".to_owned(),
                message: "must lie in [0, 1)".to_owned(),
            },
        );
        assert_eq!(error.path, "uav[2].behaviour.overlap.y");
        assert_eq!(error.message, "must lie in [0, 1)");
        let error = located(
            1,
            CoverageIoError::Plan {
                field: "altitude.step_m".to_owned(),
                source: MissionError::StepTooSmall {
                    step_m: 1e-30,
                    min_step_m: 1e-3,
                },
            },
        );
        assert_eq!(error.path, "uav[1].behaviour.altitude.step_m");
        assert!(error.message.starts_with("altitude search: step 1e-30 m"));
        let error = located(0, CoverageIoError::Flight("crashed".to_owned()));
        assert_eq!(error.path, "uav[0].behaviour");
    }
}
