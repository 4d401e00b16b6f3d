//! Frontier stage (eaae.md "Exploration cycle" steps 1-4): frontier voxels kept incrementally
//! from the chunks a scan changed, divisive 2-means clustering, the reachability filter and the
//! viewpoints of each cluster.
//!
//! - [`detect`]: the frontier definition and the incremental per-chunk update.
//! - [`cluster`]: divisive 2-means with the `r_max <= tan(FoV_h/2) d_max` stop rule.
//! - [`filter`]: reachability (occupied voxels near the centroid) and viewpoints.
//! - [`assemble`]: frontier set -> cluster data, and the matching that keeps entities stable.
//! - [`system`]: the ECS systems [`update_frontiers`] (Stage::Frontier) and
//!   [`refresh_clusters`] (Decide, under the lead's run condition), and
//!   [`insert_frontier_resources`].
//!
//! The data (`FrontierSet`, `FrontierCluster`, ...) lives in `uavex_components::frontier`.

pub mod assemble;
pub mod cluster;
pub mod detect;
pub mod filter;
pub mod system;

pub use assemble::{ClusterData, cluster_frontier, match_clusters};
pub use cluster::{Cluster, divisive_two_means};
pub use detect::{chunk_frontier, is_frontier, update_frontier_set};
pub use filter::{
    frontier_viewpoint, in_sight, is_clear, occupied_near_centroid, sample_viewpoints,
    standoff_viewpoints,
};
pub use system::{insert_frontier_resources, refresh_clusters, update_frontiers};

#[cfg(test)]
pub(crate) mod tests;
