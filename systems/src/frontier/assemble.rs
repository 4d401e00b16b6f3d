//! From the frontier set to cluster data (eaae.md steps 2-4 together), and the rule that keeps
//! cluster entities stable from one clustering to the next. Plain functions, no ECS.

use super::super::mapping::OccupancyMap;
use super::cluster::divisive_two_means;
use super::filter::{occupied_near_centroid, sample_viewpoints};
use glam::{IVec3, Vec3};
use rand::Rng;
use uavex_components::frontier::{
    ClusterMembers, ClusterSettings, FrontierCluster, FrontierSet, Viewpoints,
};

/// Everything one cluster entity carries.
#[derive(Debug, Clone, PartialEq)]
pub struct ClusterData {
    pub cluster: FrontierCluster,
    pub members: ClusterMembers,
    pub viewpoints: Viewpoints,
    /// Passed the reachability filter (EAAE step 3, first rule).
    pub reachable: bool,
}

/// Clusters the frontier voxels of `set` (their centres) with [`divisive_two_means`] and the
/// bound `settings.r_max_m`, drops clusters smaller than `settings.min_cluster_voxels`, and
/// adds the reachability verdict and the viewpoints of each. Order: that of the clustering
/// (deterministic for an `rng` state).
pub fn cluster_frontier(
    set: &FrontierSet,
    map: &impl OccupancyMap,
    settings: &ClusterSettings,
    rng: &mut impl Rng,
) -> Vec<ClusterData> {
    let config = map.config();
    let keys: Vec<IVec3> = set.iter().collect();
    let points: Vec<Vec3> = keys.iter().map(|&k| config.center_of(k)).collect();
    divisive_two_means(&points, settings.r_max_m, rng)
        .into_iter()
        .filter(|c| c.members.len() >= settings.min_cluster_voxels as usize)
        .map(|c| {
            let (bbox_min, bbox_max) = c
                .members
                .iter()
                .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), &m| {
                    (lo.min(points[m]), hi.max(points[m]))
                });
            // Ascending indices into the set's order: already sorted (see ClusterMembers).
            let members: Vec<IVec3> = c.members.iter().map(|&m| keys[m]).collect();
            ClusterData {
                cluster: FrontierCluster {
                    centroid: c.centroid,
                    size: c.members.len() as u32,
                    r_max: c.r_max,
                    bbox_min,
                    bbox_max,
                },
                members: ClusterMembers(members),
                viewpoints: Viewpoints(sample_viewpoints(map, c.centroid, settings)),
                reachable: !occupied_near_centroid(map, c.centroid, settings.occupied_radius_xy_m),
            }
        })
        .collect()
}

/// Which old cluster each new one continues (so its entity is updated in place rather than
/// despawned and spawned again): for each new cluster in order, the nearest not yet matched old
/// cluster whose centroid lies within `0.5 * max(r_new, r_old, min_radius)` of the new one;
/// ties go to the earlier old cluster. Clusters are given as (centroid, r_max). Deterministic.
pub fn match_clusters(
    old: &[(Vec3, f32)],
    new: &[(Vec3, f32)],
    min_radius: f32,
) -> Vec<Option<usize>> {
    let mut taken = vec![false; old.len()];
    new.iter()
        .map(|&(c_new, r_new)| {
            let mut best: Option<(usize, f32)> = None;
            for (j, &(c_old, r_old)) in old.iter().enumerate() {
                if taken[j] {
                    continue;
                }
                let d = c_new.distance(c_old);
                let reach = 0.5 * r_new.max(r_old).max(min_radius);
                if d <= reach && best.is_none_or(|(_, bd)| d < bd) {
                    best = Some((j, d));
                }
            }
            let j = best?.0;
            taken[j] = true;
            Some(j)
        })
        .collect()
}
