//! The scenario schema. Units: metres, seconds, radians, hertz; positions in the world frame
//! (z up, the floor at z = 0).
//!
//! Every table refuses unknown fields: a typo is an error, never a silently ignored setting.
//! The types also serialize (same field names), so a run can record the scenario it ran.

use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::PathBuf;

/// One scenario file: a world, the UAVs in it and what they do.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scenario {
    pub name: String,
    /// Seed of the run; a run is a pure function of the scenario and this seed.
    #[serde(default)]
    pub seed: u64,
    /// Simulated seconds after which the run ends as `time_limit`.
    pub time_limit_s: f64,
    /// Fixed physics/control step rate (EAAE: 300 Hz).
    #[serde(default = "defaults::physics_rate_hz")]
    pub physics_rate_hz: f64,
    #[serde(default)]
    pub map: MapSpec,
    pub world: WorldSpec,
    #[serde(rename = "uav", default)]
    pub uavs: Vec<UavSpec>,
    #[serde(default)]
    pub outputs: OutputSpec,
}

/// The occupancy map (common.md section 1; OctoMap defaults).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MapSpec {
    /// Voxel edge length (m).
    #[serde(default = "defaults::resolution")]
    pub resolution: f64,
    /// Default hit probability of sensors that do not set their own.
    #[serde(default = "defaults::p_hit")]
    pub p_hit: f64,
    /// Default miss probability of sensors that do not set their own.
    #[serde(default = "defaults::p_miss")]
    pub p_miss: f64,
    /// Clamping bounds of the occupancy probability.
    #[serde(default = "defaults::p_min")]
    pub p_min: f64,
    #[serde(default = "defaults::p_max")]
    pub p_max: f64,
}

impl Default for MapSpec {
    fn default() -> Self {
        Self {
            resolution: defaults::resolution(),
            p_hit: defaults::p_hit(),
            p_miss: defaults::p_miss(),
            p_min: defaults::p_min(),
            p_max: defaults::p_max(),
        }
    }
}

/// The mission volume and the obstacles in it.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WorldSpec {
    /// Bounding box of the mission volume; the map covers exactly this box.
    pub bounds: BoundsSpec,
    /// A solid floor below z = 0 (rays end on it; touching it is a crash).
    #[serde(default = "defaults::yes")]
    pub ground: bool,
    #[serde(rename = "obstacle", default)]
    pub obstacles: Vec<ObstacleSpec>,
}

#[derive(Debug, Clone, Copy, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BoundsSpec {
    pub min: [f64; 3],
    pub max: [f64; 3],
}

/// One obstacle, or a generator of many.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum ObstacleSpec {
    /// A box; `size` along its own axes, turned by `yaw` about +z.
    Box {
        #[serde(default, skip_serializing_if = "Option::is_none")]
        name: Option<String>,
        center: [f64; 3],
        size: [f64; 3],
        #[serde(default)]
        yaw: f64,
    },
    /// An upright cylinder standing on `base` (centre of its bottom disc).
    Cylinder {
        #[serde(default, skip_serializing_if = "Option::is_none")]
        name: Option<String>,
        base: [f64; 3],
        radius: f64,
        height: f64,
    },
    Sphere {
        #[serde(default, skip_serializing_if = "Option::is_none")]
        name: Option<String>,
        center: [f64; 3],
        radius: f64,
    },
    /// A triangle mesh from an OBJ or STL file (path relative to the scenario file).
    Mesh {
        #[serde(default, skip_serializing_if = "Option::is_none")]
        name: Option<String>,
        file: PathBuf,
        #[serde(default)]
        translation: [f64; 3],
        #[serde(default)]
        yaw: f64,
        #[serde(default = "defaults::one")]
        scale: f64,
    },
    /// A point cloud from a PCD or PLY file (ASCII or binary); each point is a ball of
    /// `point_radius`.
    Cloud {
        #[serde(default, skip_serializing_if = "Option::is_none")]
        name: Option<String>,
        file: PathBuf,
        point_radius: f64,
        #[serde(default)]
        translation: [f64; 3],
        #[serde(default)]
        yaw: f64,
    },
    /// Random upright pillars (tree trunks) in a rectangle of the floor, drawn from the run seed.
    Pillars {
        #[serde(default, skip_serializing_if = "Option::is_none")]
        name: Option<String>,
        /// Opposite corners (x, y) of the region.
        region_min: [f64; 2],
        region_max: [f64; 2],
        /// Pillars per square metre.
        density: f64,
        radius_min: f64,
        radius_max: f64,
        height: f64,
        /// Pillars closer than this to a UAV start are not placed (m).
        #[serde(default = "defaults::start_clearance")]
        start_clearance: f64,
    },
}

/// One UAV: where it starts, what it is, what it carries and what it does.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct UavSpec {
    pub name: String,
    pub start: StartSpec,
    /// Airframe preset name ("kingfisher", "iris").
    #[serde(default = "defaults::airframe")]
    pub airframe: String,
    /// Fields of the preset to override, by name.
    #[serde(default)]
    pub airframe_overrides: BTreeMap<String, f64>,
    #[serde(rename = "sensor", default)]
    pub sensors: Vec<SensorSpec>,
    pub behaviour: BehaviourSpec,
}

#[derive(Debug, Clone, Copy, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StartSpec {
    pub position: [f64; 3],
    #[serde(default)]
    pub yaw: f64,
}

/// A range sensor on a UAV.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum SensorSpec {
    /// Pinhole depth camera looking along the mount's +x; vertical FoV follows from the aspect.
    DepthCamera {
        #[serde(default = "defaults::camera_width")]
        width: u32,
        #[serde(default = "defaults::camera_height")]
        height: u32,
        /// Horizontal field of view (rad).
        #[serde(default = "defaults::camera_hfov")]
        hfov: f64,
        #[serde(default = "defaults::camera_range_min")]
        range_min: f64,
        #[serde(default = "defaults::camera_range_max")]
        range_max: f64,
        #[serde(default = "defaults::camera_rate_hz")]
        rate_hz: f64,
        #[serde(default)]
        mount: MountSpec,
        #[serde(default)]
        ray_grid: RayGridSpec,
        #[serde(default)]
        quality: QualitySpec,
    },
    /// Lidar: planar when `beams_v = 1`, multi-beam otherwise.
    Lidar {
        /// Horizontal field of view (rad); 270 deg by default (heterogeneous seed).
        #[serde(default = "defaults::lidar_hfov")]
        hfov: f64,
        #[serde(default = "defaults::lidar_beams_h")]
        beams_h: u32,
        /// Vertical field of view (rad), centred on the horizontal plane; 0 when planar.
        #[serde(default)]
        vfov: f64,
        #[serde(default = "defaults::one_u32")]
        beams_v: u32,
        #[serde(default = "defaults::lidar_range_min")]
        range_min: f64,
        #[serde(default = "defaults::lidar_range_max")]
        range_max: f64,
        #[serde(default = "defaults::lidar_rate_hz")]
        rate_hz: f64,
        #[serde(default)]
        mount: MountSpec,
        #[serde(default)]
        quality: QualitySpec,
    },
}

/// Pose of a sensor on its UAV (body frame: x forward, y left, z up).
#[derive(Debug, Clone, Copy, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MountSpec {
    #[serde(default)]
    pub translation: [f64; 3],
    /// Roll, pitch, yaw (rad), applied yaw first (intrinsic z-y-x).
    #[serde(default)]
    pub rpy: [f64; 3],
}

/// Which rays a camera casts: `"auto"` (angular step = resolution / max range), or an explicit
/// `[columns, rows]` grid (the camera resolution reproduces one ray per pixel).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum RayGridSpec {
    Named(RayGridName),
    Explicit([u32; 2]),
}

impl Default for RayGridSpec {
    fn default() -> Self {
        RayGridSpec::Named(RayGridName::Auto)
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RayGridName {
    Auto,
}

/// Sensor quality; unset probabilities fall back to the map's defaults.
#[derive(Debug, Clone, Copy, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct QualitySpec {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub p_hit: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub p_miss: Option<f64>,
    /// Standard deviation of Gaussian range noise (m).
    #[serde(default)]
    pub range_noise_std: f64,
}

/// What a UAV does.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum BehaviourSpec {
    /// Kinematic: the pose follows the waypoints at a constant speed, set directly each tick
    /// (no dynamics); for mapping-only studies.
    Scripted {
        /// Cruise speed along the polyline (m/s).
        speed: f64,
        /// Positions to visit in order, after the start position.
        waypoints: Vec<[f64; 3]>,
        /// Turn rate used to face the next leg (rad/s).
        #[serde(default = "defaults::yaw_rate")]
        yaw_rate: f64,
    },
    /// Dynamic: a minimum-snap trajectory through the waypoints (Richter, Bry & Roy), planned
    /// when the run is built within the airframe's `max_velocity` and `max_acceleration`, and
    /// flown on the true quadrotor (rapier) by the geometric controller, with its energy
    /// integrated every physics step. Done once the UAV has arrived at the last waypoint.
    Waypoints {
        /// Positions to pass through in order, after the start position; the UAV stops at the
        /// last one.
        waypoints: Vec<[f64; 3]>,
        /// Heading at each waypoint (rad), one per waypoint. Absent: each waypoint faces the
        /// direction of travel there ("follow").
        #[serde(default, skip_serializing_if = "Option::is_none")]
        yaw: Option<Vec<f64>>,
        /// Refuse (or bend around obstacles, where a midpoint helps) a plan that comes within
        /// the airframe's bounding radius plus a 0.1 m margin of known geometry. `false` flies
        /// the polynomial as it is, e.g. to study crashes.
        #[serde(default = "defaults::yes")]
        collision_check: bool,
    },
    /// Energy-aware coverage of a polygon with a nadir camera (coverage.md): planned by
    /// `uavex cover`, which also flies the plan on the true quadrotor with `--fly`.
    Coverage(crate::coverage::CoverageSpec),
    /// Frontier exploration (eaae.md): every next frontier cluster chosen by the `strategy`
    /// (`eaae`: least predicted energy; `classic`, `nearest`: the baselines), flown on the true
    /// quadrotor with a local reactive planner until no reachable frontier is left.
    Explore(crate::exploration::ExploreSpec),
}

/// What a run writes besides `summary.json`.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OutputSpec {
    /// Rows per simulated second in the time series.
    #[serde(default = "defaults::series_rate_hz")]
    pub series_rate_hz: f64,
    /// Write the final map as OctoMap `.bt` and as a PLY cloud of occupied voxel centres.
    #[serde(default = "defaults::yes")]
    pub export_map: bool,
}

impl Default for OutputSpec {
    fn default() -> Self {
        Self {
            series_rate_hz: defaults::series_rate_hz(),
            export_map: true,
        }
    }
}

/// Defaults, each with its origin.
pub mod defaults {
    /// EAAE: control and physics at 300 Hz.
    pub fn physics_rate_hz() -> f64 {
        300.0
    }
    /// EAAE: 0.1 m voxels.
    pub fn resolution() -> f64 {
        0.1
    }
    /// OctoMap / octomap_server sensor model defaults.
    pub fn p_hit() -> f64 {
        0.7
    }
    pub fn p_miss() -> f64 {
        0.4
    }
    pub fn p_min() -> f64 {
        0.12
    }
    pub fn p_max() -> f64 {
        0.97
    }
    pub fn yes() -> bool {
        true
    }
    pub fn one() -> f64 {
        1.0
    }
    pub fn one_u32() -> u32 {
        1
    }
    pub fn start_clearance() -> f64 {
        1.0
    }
    pub fn airframe() -> String {
        "kingfisher".to_owned()
    }
    /// EAAE Table 5.1 depth camera: 640x480, 1.0 rad, 0.5-5 m, 30 Hz.
    pub fn camera_width() -> u32 {
        640
    }
    pub fn camera_height() -> u32 {
        480
    }
    pub fn camera_hfov() -> f64 {
        1.0
    }
    pub fn camera_range_min() -> f64 {
        0.5
    }
    pub fn camera_range_max() -> f64 {
        5.0
    }
    pub fn camera_rate_hz() -> f64 {
        30.0
    }
    /// Heterogeneous seed: planar 270 deg lidar, 20 m.
    pub fn lidar_hfov() -> f64 {
        270f64.to_radians()
    }
    pub fn lidar_beams_h() -> u32 {
        1080
    }
    pub fn lidar_range_min() -> f64 {
        0.1
    }
    pub fn lidar_range_max() -> f64 {
        20.0
    }
    pub fn lidar_rate_hz() -> f64 {
        10.0
    }
    pub fn yaw_rate() -> f64 {
        1.5
    }
    pub fn series_rate_hz() -> f64 {
        2.0
    }
}
