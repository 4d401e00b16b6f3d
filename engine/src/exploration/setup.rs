//! What an exploring UAV and its run need: the flight components hovering at the start, the
//! `Explorer` settings and the strategy marker, the resources of the frontier, planning and
//! decision stages, and their systems.

use super::spec::{ExploreSpec, StrategyName};
use crate::flight::{Physics, dynamic_flight};
use crate::scenario::{SensorSpec, UavSpec};
use crate::world::BuildError;
use bevy_ecs::prelude::*;
use glam::DVec3;
use std::sync::Arc;
use uavex_components::airframe::Airframe;
use uavex_components::exploration::{EnergyBudget, Explorer, ExplorerSettings, NeedsDecision};
use uavex_components::frontier::ClusterSettings;
use uavex_components::map::MapConfig;
use uavex_components::trajectory::Hold;
use uavex_systems::behaviour::waypoints::CLEARANCE_MARGIN_M;
use uavex_systems::exploration::strategy::{
    ClassicStrategy, EaaeStrategy, NearestStrategy, choose_largest_gain, choose_least_energy,
    choose_nearest,
};
use uavex_systems::exploration::{
    DecideStep, add_exploration_systems, insert_exploration_resources,
};
use uavex_systems::frontier::insert_frontier_resources;
use uavex_systems::planning::{Traversability, TraversableGrid};

/// The horizontal field of view (rad) and range (m) of the UAV's first depth camera: the
/// clustering stop rule and the planning horizon are made for it (eaae.md steps 2 and 9).
pub fn camera_of(spec: &UavSpec) -> Option<(f64, f64)> {
    spec.sensors.iter().find_map(|sensor| match sensor {
        SensorSpec::DepthCamera {
            hfov, range_max, ..
        } => Some((*hfov, *range_max)),
        SensorSpec::Lidar { .. } => None,
    })
}

/// The components of an exploring `uav[index]`: the true flight hovering at its start, its
/// `Explorer` settings, its strategy's marker, and a first decision to make.
pub fn explorer_components(
    spec: &UavSpec,
    index: usize,
    airframe: &Airframe,
    physics: &mut Physics,
    explore: &ExploreSpec,
) -> Result<(impl Bundle + use<>, StrategyMarker), BuildError> {
    let (_, range) = camera_of(spec).ok_or_else(|| {
        BuildError::new(
            format!("uav[{index}].sensor"),
            "an exploring UAV needs a depth camera (its field of view and range set the \
             frontier clusters' size and the planning horizon)",
        )
    })?;
    let start = DVec3::from_array(spec.start.position);
    let hover = Hold {
        position: start,
        yaw: spec.start.yaw,
        duration: 0.0,
    };
    let flight = dynamic_flight(&spec.name, index, airframe, physics, Arc::new(hover))?;
    let mut settings = ExplorerSettings::for_range(range);
    settings.unified = explore.unified;
    settings.replan_period_s = 1.0 / explore.replan_hz;
    settings.budget = explore.energy_budget.map(|b| EnergyBudget {
        reserve_j: b.reserve_j,
    });
    let explorer = Explorer {
        settings,
        home: start.as_vec3(),
        home_yaw: spec.start.yaw as f32,
    };
    let marker = match explore.strategy {
        StrategyName::Eaae => StrategyMarker::Eaae(EaaeStrategy {
            shortlist: explore.candidates.limit(),
        }),
        StrategyName::Classic => StrategyMarker::Classic,
        StrategyName::Nearest => StrategyMarker::Nearest,
    };
    Ok(((flight, explorer, NeedsDecision), marker))
}

/// The strategy component an exploring UAV carries.
#[derive(Debug, Clone, Copy)]
pub enum StrategyMarker {
    Eaae(EaaeStrategy),
    Classic,
    Nearest,
}

impl StrategyMarker {
    pub fn insert(self, entity: &mut EntityWorldMut) {
        match self {
            StrategyMarker::Eaae(s) => entity.insert(s),
            StrategyMarker::Classic => entity.insert(ClassicStrategy),
            StrategyMarker::Nearest => entity.insert(NearestStrategy),
        };
    }
}

/// The resources and systems of exploration, for a run whose explorers fly `airframes` with
/// cameras of field of view `hfov` and range `range` (the first explorer's camera sets the
/// clustering rule for all).
pub fn add_exploration(
    world: &mut World,
    schedule: &mut Schedule,
    camera: (f64, f64),
    airframes: &[&Airframe],
) {
    let map = world.resource::<MapConfig>().clone();
    let inflation = airframes
        .iter()
        .map(|a| a.bounding_radius() + CLEARANCE_MARGIN_M)
        .fold(0.0, f64::max);
    insert_frontier_resources(world, ClusterSettings::for_camera(camera.0, camera.1));
    world.insert_resource(Traversability(TraversableGrid::new(&map, inflation)));
    insert_exploration_resources(world);
    add_exploration_systems(schedule);
    schedule.add_systems(
        (choose_least_energy, choose_largest_gain, choose_nearest).in_set(DecideStep::Choose),
    );
}
