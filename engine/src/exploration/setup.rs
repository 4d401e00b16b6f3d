//! What an exploring UAV and its run need: the flight components hovering at the start, the
//! `Explorer` settings and the strategy marker, the resources of the frontier, planning and
//! decision stages, and their systems.

use super::spec::{ExploreSpec, StrategyName};
use crate::flight::{Physics, dynamic_flight};
use crate::scenario::{BehaviourSpec, SensorSpec, UavSpec};
use crate::world::BuildError;
use bevy_ecs::prelude::*;
use glam::{DVec3, IVec3};
use parry3d::bounding_volume::Aabb;
use parry3d::shape::Capsule;
use std::sync::Arc;
use uavex_components::airframe::Airframe;
use uavex_components::exploration::{
    CandidateScope, EnergyBudget, Explorer, ExplorerSettings, NeedsDecision,
};
use uavex_components::frontier::ClusterSettings;
use uavex_components::map::MapConfig;
use uavex_components::trajectory::Hold;
use uavex_components::world::{VOXEL_SHRINK, WorldGeometry};
use uavex_systems::behaviour::waypoints::CLEARANCE_MARGIN_M;
use uavex_systems::exploration::strategy::{
    ClassicStrategy, EaaeStrategy, NearestStrategy, TourStrategy, choose_by_tour,
    choose_largest_gain, choose_least_energy, choose_nearest,
};
use uavex_systems::exploration::{
    DecideStep, add_exploration_systems, insert_exploration_resources,
};
use uavex_systems::frontier::insert_frontier_resources;
use uavex_systems::planning::{Traversability, TraversableGrid, inflation_radius};

/// The horizontal field of view (rad) and range (m) of the UAV's first depth camera: the
/// clustering stop rule and the planning horizon are made for it (eaae.md steps 2 and 9).
pub fn camera_of(spec: &UavSpec) -> Option<(f64, f64)> {
    first_camera(spec).map(|c| (c.hfov, c.range_max))
}

/// What exploration needs to know of a camera.
#[derive(Debug, Clone, Copy, PartialEq)]
struct CameraView {
    hfov: f64,
    /// Vertical field of view (rad), from the aspect ratio (pinhole, common.md §2).
    vfov: f64,
    range_max: f64,
}

fn first_camera(spec: &UavSpec) -> Option<CameraView> {
    spec.sensors.iter().find_map(|sensor| match sensor {
        SensorSpec::DepthCamera {
            hfov,
            range_max,
            width,
            height,
            ..
        } => Some(CameraView {
            hfov: *hfov,
            vfov: 2.0 * ((hfov / 2.0).tan() * f64::from(*height) / f64::from(*width)).atan(),
            range_max: *range_max,
        }),
        SensorSpec::Lidar { .. } => None,
    })
}

/// The stretch ahead of an explorer's start that the planner takes as known free
/// (`TraversableGrid::assume_free_ball` along it): a capsule from the start along its heading.
///
/// Why: the planner keeps the whole inflated body in known free space, on a lattice of 2-voxel
/// cells, and a forward camera sees a tube that wide only from `radius / tan(vfov / 2)` ahead;
/// beside and below the UAV it sees nothing. Without this, the first decision finds the UAV
/// boxed in. The radius leaves a core two lattice cells wide around the axis once the body is
/// taken off (`inflation + 4 voxels`): the lattice forbids cutting corners, so a chain of cells
/// along a heading off the axes needs the cells beside it, and a one-cell core (`inflation + 2
/// voxels`) connected the start to nothing for every heading more than about 0.2 rad off an
/// axis. The scenario must keep the capsule clear of obstacles (checked when the run is built),
/// as a take-off area is kept clear.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StartCapsule {
    pub from: DVec3,
    pub to: DVec3,
    pub radius: f64,
}

impl StartCapsule {
    pub fn new(start: DVec3, yaw: f64, vfov: f64, inflation: f64, resolution: f64) -> Self {
        // Two lattice cells of 2 voxels each beyond the body (see the type's comment).
        let radius = inflation + 4.0 * resolution;
        let length = radius / (vfov / 2.0).tan().max(1e-3) + resolution;
        Self {
            from: start,
            to: start + length * DVec3::new(yaw.cos(), yaw.sin(), 0.0),
            radius,
        }
    }

    /// The capsule of an exploring UAV `spec` (flying `airframe`, mapping at `resolution`),
    /// or `None` if it does not explore or has no depth camera (its run is refused then).
    pub fn of_explorer(spec: &UavSpec, airframe: &Airframe, resolution: f64) -> Option<Self> {
        if !matches!(spec.behaviour, BehaviourSpec::Explore(_)) {
            return None;
        }
        first_camera(spec).map(|camera| Self::ahead_of(spec, &camera, airframe, resolution))
    }

    /// The capsule ahead of `spec`'s start for its `camera`.
    fn ahead_of(spec: &UavSpec, camera: &CameraView, airframe: &Airframe, resolution: f64) -> Self {
        Self::new(
            DVec3::from_array(spec.start.position),
            spec.start.yaw,
            camera.vfov,
            inflation_of(airframe, resolution),
            resolution,
        )
    }

    /// The capsule as parry's shape (the space a seeded world keeps clear, `world::build_world`).
    pub fn shape(&self) -> Capsule {
        Capsule::new(self.from.as_vec3(), self.to.as_vec3(), self.radius as f32)
    }

    /// Ball centres along the capsule, a voxel apart.
    pub fn centres(&self, resolution: f64) -> impl Iterator<Item = DVec3> + '_ {
        let n = (self.from.distance(self.to) / resolution).ceil().max(1.0) as usize;
        (0..=n).map(move |i| self.from.lerp(self.to, i as f64 / n as f64))
    }
}

/// The planner's inflation radius for an airframe on a map of `resolution`: its radius and the
/// tour's margin, or one voxel if that is larger ([`inflation_radius`]).
pub fn inflation_of(airframe: &Airframe, resolution: f64) -> f64 {
    inflation_radius(airframe.bounding_radius(), CLEARANCE_MARGIN_M, resolution)
}

/// The components of an exploring `uav[index]`: the true flight hovering at its start, its
/// `Explorer` settings, its strategy's marker, and a first decision to make.
#[allow(clippy::too_many_arguments)]
pub fn explorer_components(
    spec: &UavSpec,
    index: usize,
    airframe: &Airframe,
    physics: &mut Physics,
    explore: &ExploreSpec,
    geometry: &WorldGeometry,
    map: &MapConfig,
) -> Result<(impl Bundle + use<>, StrategyMarker), BuildError> {
    let resolution = map.resolution();
    let camera = first_camera(spec).ok_or_else(|| {
        BuildError::new(
            format!("uav[{index}].sensor"),
            "an exploring UAV needs a depth camera (its field of view and range set the \
             frontier clusters' size and the planning horizon)",
        )
    })?;
    let range = camera.range_max;
    let start = DVec3::from_array(spec.start.position);
    let capsule = StartCapsule::ahead_of(spec, &camera, airframe, resolution);
    // Seeded pillar fields keep the capsule clear by themselves; any other obstacle in it is
    // the scenario's to move. Only obstacles that reach into the map count: the planner takes
    // the capsule as free only inside the map, and everything outside as occupied (so the
    // ground slab under a map whose floor is z = 0 never contradicts it, however low the start).
    let map_min = map.key_min().as_dvec3() * resolution;
    let map_max = (map.key_max() + IVec3::ONE).as_dvec3() * resolution;
    let shrink = f64::from(VOXEL_SHRINK) * resolution;
    let map_box = Aabb::new((map_min + shrink).as_vec3(), (map_max - shrink).as_vec3());
    if let Some(obstacle) = capsule.centres(resolution).find_map(|c| {
        geometry.obstacle_intersecting_ball_within(c.as_vec3(), capsule.radius as f32, &map_box)
    }) {
        let obstacle = &geometry.obstacles()[obstacle];
        return Err(BuildError::new(
            format!("uav[{index}].start.position"),
            format!(
                "an exploring UAV needs clear space around its start: {:.2} m around the \
                 line from the start {:.2} m ahead along its heading (its body, the planner's \
                 margin, and what its camera cannot see beside and below it); obstacle '{}' \
                 ({}) lies closer",
                capsule.radius,
                capsule.from.distance(capsule.to),
                obstacle.name,
                obstacle.source
            ),
        ));
    }
    // The planner counts voxels outside the map as occupied (`TraversableGrid`): from a start
    // nearer a face of the map than its inflation radius no path leaves the start, and every
    // cluster would look unreachable (a run that ends `complete` at once).
    let inflation = inflation_of(airframe, resolution);
    let clearance = (start - map_min).min(map_max - start).min_element();
    if clearance < inflation {
        let corner = |p: DVec3| format!("({:.2}, {:.2}, {:.2})", p.x, p.y, p.z);
        return Err(BuildError::new(
            format!("uav[{index}].start.position"),
            format!(
                "an exploring UAV must start at least its planning radius, {inflation:.3} m \
                 (its body and the planner's margin), inside the map ({} to {}: world.bounds \
                 on voxel faces), since the planner counts what lies outside the map as \
                 occupied; this start is {clearance:.3} m from a face",
                corner(map_min),
                corner(map_max)
            ),
        ));
    }
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
    settings.standoff_m = explore.standoff_m.map(|d| d as f32);
    settings.frontier_viewpoint = explore.frontier_viewpoint;
    let explorer = Explorer {
        settings,
        home: start.as_vec3(),
        home_yaw: spec.start.yaw as f32,
        start_clear: [capsule.from.as_vec3(), capsule.to.as_vec3()],
        start_clear_radius: capsule.radius,
    };
    let marker = match explore.strategy {
        StrategyName::Eaae => StrategyMarker::Eaae(EaaeStrategy {
            shortlist: explore.candidates.limit(),
        }),
        StrategyName::Classic => StrategyMarker::Classic,
        StrategyName::Nearest => StrategyMarker::Nearest,
        StrategyName::Tour => StrategyMarker::Tour(TourStrategy {
            shortlist: explore.candidates.limit(),
        }),
    };
    Ok(((flight, explorer, NeedsDecision), marker))
}

/// The strategy component an exploring UAV carries.
#[derive(Debug, Clone, Copy)]
pub enum StrategyMarker {
    Eaae(EaaeStrategy),
    Classic,
    Nearest,
    Tour(TourStrategy),
}

impl StrategyMarker {
    /// Inserts the marker and the candidate scope its choice needs (every cluster when
    /// `evaluate_all`).
    pub fn insert(self, entity: &mut EntityWorldMut, evaluate_all: bool) {
        let scope = match self {
            StrategyMarker::Eaae(s) => {
                entity.insert(s);
                s.scope()
            }
            StrategyMarker::Classic => {
                entity.insert(ClassicStrategy);
                ClassicStrategy.scope()
            }
            StrategyMarker::Nearest => {
                entity.insert(NearestStrategy);
                NearestStrategy.scope()
            }
            StrategyMarker::Tour(s) => {
                entity.insert(s);
                s.scope()
            }
        };
        entity.insert(if evaluate_all {
            CandidateScope::All
        } else {
            scope
        });
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
        .map(|a| inflation_of(a, map.resolution()))
        .fold(0.0, f64::max);
    insert_frontier_resources(world, ClusterSettings::for_camera(camera.0, camera.1));
    let mut grid = TraversableGrid::new(&map, inflation);
    for explorer in world.query::<&Explorer>().iter(world) {
        let [from, to] = explorer.start_clear.map(|p| p.as_dvec3());
        let capsule = StartCapsule {
            from,
            to,
            radius: explorer.start_clear_radius,
        };
        for centre in capsule.centres(map.resolution()) {
            grid.assume_free_ball(centre, capsule.radius);
        }
    }
    world.insert_resource(Traversability(grid));
    insert_exploration_resources(world);
    add_exploration_systems(schedule);
    schedule.add_systems(
        (
            choose_least_energy,
            choose_largest_gain,
            choose_nearest,
            choose_by_tour,
        )
            .in_set(DecideStep::Choose),
    );
}
