//! Time series beside the 3D view: how much of the map is known and occupied, and each UAV's
//! power and speed, at the recording's log times (the rerun viewer plots scalars over time).

use super::entity_path;
use re_chunk::EntityPath;
use re_sdk_types::archetypes::Scalars;
use uavex_components::map::MapMetrics;

/// Known share of the map's box (%).
pub const EXPLORED: &str = "plots/explored_pct";
/// Occupied voxels of the map (the count the voxel boxes add up to).
pub const OCCUPIED_VOXELS: &str = "plots/occupied_voxels";

/// The map's series at one log time.
pub fn map_scalars(metrics: &MapMetrics) -> [(EntityPath, Scalars); 2] {
    [
        (
            EntityPath::from(EXPLORED),
            Scalars::single(100.0 * metrics.explored_fraction),
        ),
        (
            EntityPath::from(OCCUPIED_VOXELS),
            Scalars::single(metrics.occupied_voxels as f64),
        ),
    ]
}

/// One UAV's series: speed always, rotor power for UAVs flown on the quadrotor model.
pub fn uav_scalars(uav: &str, speed: f32, power_w: Option<f64>) -> Vec<(EntityPath, Scalars)> {
    let mut series = vec![(
        entity_path(&["plots", uav, "speed_m_s"]),
        Scalars::single(f64::from(speed)),
    )];
    if let Some(power_w) = power_w {
        series.push((
            entity_path(&["plots", uav, "power_w"]),
            Scalars::single(power_w),
        ));
    }
    series
}
