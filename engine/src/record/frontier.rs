//! Frontier clusters in the recording (eaae.md step 2): each cluster's box around its member
//! voxels and its centroid, labelled with its information gain; orange when it passed the
//! reachability filter (a goal the strategies could pick), grey when not.

use re_sdk_types::AnyValues;
use re_sdk_types::archetypes::{Boxes3D, Points3D};
use re_sdk_types::components::{Color, FillMode, Radius};
use re_sdk_types::datatypes::Rgba32;
use re_sdk_types::external::arrow::array::UInt32Array;
use std::sync::Arc;
use uavex_components::frontier::FrontierCluster;

/// The clusters' boxes.
pub const CLUSTERS: &str = "world/frontier/clusters";
/// The clusters' centroids, with their information gain as a number.
pub const CENTROIDS: &str = "world/frontier/centroids";
/// Field name of the information gain logged beside the centroids.
pub const INFORMATION_GAIN: &str = "information_gain";

const REACHABLE: Color = Color(Rgba32::from_rgb(255, 140, 0));
const UNREACHABLE: Color = Color(Rgba32::from_rgb(128, 128, 128));

/// One cluster as the recording shows it.
#[derive(Debug, Clone, PartialEq)]
pub struct ClusterSketch {
    pub centroid: [f32; 3],
    pub bbox_min: [f32; 3],
    pub bbox_max: [f32; 3],
    pub information_gain: u32,
    pub reachable: bool,
}

impl ClusterSketch {
    pub fn of(cluster: &FrontierCluster, reachable: bool) -> Self {
        Self {
            centroid: cluster.centroid.to_array(),
            bbox_min: cluster.bbox_min.to_array(),
            bbox_max: cluster.bbox_max.to_array(),
            information_gain: cluster.size,
            reachable,
        }
    }

    fn colour(&self) -> Color {
        if self.reachable {
            REACHABLE
        } else {
            UNREACHABLE
        }
    }
}

/// Wireframe boxes around the member voxels (their centres' box grown by half a voxel).
pub fn cluster_boxes(clusters: &[ClusterSketch], resolution: f64) -> Boxes3D {
    let half_voxel = resolution as f32 / 2.0;
    let centre = |c: &ClusterSketch| std::array::from_fn(|k| (c.bbox_min[k] + c.bbox_max[k]) / 2.0);
    let half = |c: &ClusterSketch| {
        std::array::from_fn(|k| (c.bbox_max[k] - c.bbox_min[k]) / 2.0 + half_voxel)
    };
    Boxes3D::from_centers_and_half_sizes(
        clusters.iter().map(|c| -> [f32; 3] { centre(c) }),
        clusters.iter().map(|c| -> [f32; 3] { half(c) }),
    )
    .with_colors(clusters.iter().map(ClusterSketch::colour))
    .with_fill_mode(FillMode::MajorWireframe)
}

/// The centroids, labelled `IG n`.
pub fn cluster_centroids(clusters: &[ClusterSketch]) -> Points3D {
    Points3D::new(clusters.iter().map(|c| c.centroid))
        .with_colors(clusters.iter().map(ClusterSketch::colour))
        .with_radii([Radius::new_scene_units(0.08)])
        .with_labels(
            clusters
                .iter()
                .map(|c| format!("IG {}", c.information_gain)),
        )
}

/// Each centroid's information gain as a number, in the same order.
pub fn cluster_values(clusters: &[ClusterSketch]) -> AnyValues {
    AnyValues::default().with_component_from_data(
        INFORMATION_GAIN,
        Arc::new(UInt32Array::from_iter_values(
            clusters.iter().map(|c| c.information_gain),
        )),
    )
}
