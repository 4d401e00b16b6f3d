//! Obstacles read from files: triangle meshes (OBJ, STL) and point clouds (PCD, PLY).

use super::{BuildError, display_name, require_finite, require_positive, vec3};
use crate::formats::{cloud::load_cloud, mesh::load_mesh};
use crate::scenario::ObstacleSpec;
use glam::{Quat, Vec3};
use parry3d::math::Pose;
use parry3d::shape::{SharedShape, TriMesh, TriMeshFlags};
use std::path::Path;
use uavex_components::world::Obstacle;

/// A mesh or cloud obstacle; `base_dir` is the scenario file's folder.
pub(super) fn build(
    spec: &ObstacleSpec,
    index: usize,
    field: &str,
    base_dir: &Path,
) -> Result<Obstacle, Vec<BuildError>> {
    let mut errors = Vec::new();
    match spec {
        ObstacleSpec::Mesh {
            name,
            file,
            translation,
            yaw,
            scale,
        } => {
            require_finite(&mut errors, format!("{field}.translation"), translation);
            require_finite(&mut errors, format!("{field}.yaw"), &[*yaw]);
            require_positive(&mut errors, format!("{field}.scale"), *scale);
            if !errors.is_empty() {
                return Err(errors);
            }
            let file_field = format!("{field}.file");
            let mesh = load_mesh(&base_dir.join(file))
                .map_err(|e| vec![BuildError::new(&file_field, e.to_string())])?;
            let vertices = mesh.vertices.iter().map(|v| *v * *scale as f32).collect();
            let shape = solid_or_shell(vertices, mesh.triangles)
                .map_err(|message| vec![BuildError::new(&file_field, message)])?;
            Ok(Obstacle::new(
                display_name(name, "mesh", index),
                field,
                placement(*translation, *yaw),
                SharedShape::new(shape),
            ))
        }
        ObstacleSpec::Cloud {
            name,
            file,
            point_radius,
            translation,
            yaw,
        } => {
            require_positive(&mut errors, format!("{field}.point_radius"), *point_radius);
            require_finite(&mut errors, format!("{field}.translation"), translation);
            require_finite(&mut errors, format!("{field}.yaw"), &[*yaw]);
            if !errors.is_empty() {
                return Err(errors);
            }
            let file_field = format!("{field}.file");
            let points = load_cloud(&base_dir.join(file))
                .map_err(|e| vec![BuildError::new(&file_field, e.to_string())])?;
            if points.is_empty() {
                return Err(vec![BuildError::new(file_field, "the cloud has no point")]);
            }
            let ball = SharedShape::ball(*point_radius as f32);
            let balls = points
                .into_iter()
                .map(|p| (Pose::from_translation(p), ball.clone()))
                .collect();
            Ok(Obstacle::new(
                display_name(name, "cloud", index),
                field,
                placement(*translation, *yaw),
                SharedShape::compound(balls),
            ))
        }
        _ => Err(vec![BuildError::new(
            field,
            "internal: not a file obstacle",
        )]),
    }
}

/// `p -> translation + Rz(yaw) p`, as the schema documents for meshes and clouds.
fn placement(translation: [f64; 3], yaw: f64) -> Pose {
    Pose::from_parts(vec3(translation), Quat::from_rotation_z(yaw as f32))
}

/// A parry mesh that is solid when it can be: after welding identical vertices and dropping
/// degenerate and duplicate triangles, a mesh whose half-edge topology is closed (every edge
/// shared by exactly two consistently wound triangles) encloses a volume; it is wound outwards
/// (flipped if its signed volume is negative) and marked `ORIENTED`, so that its inside counts
/// as obstacle for ground truth and start checks. Any other mesh (open, non-manifold,
/// inconsistently wound) stays a thin shell: rays hit its triangles the same either way.
fn solid_or_shell(vertices: Vec<Vec3>, triangles: Vec<[u32; 3]>) -> Result<TriMesh, String> {
    let cleanup = TriMeshFlags::MERGE_DUPLICATE_VERTICES
        | TriMeshFlags::DELETE_DEGENERATE_TRIANGLES
        | TriMeshFlags::DELETE_DUPLICATE_TRIANGLES;
    let mesh = TriMesh::with_flags(
        vertices,
        triangles,
        cleanup | TriMeshFlags::HALF_EDGE_TOPOLOGY,
    )
    .map_err(|e| format!("not a usable triangle mesh: {e}"))?;
    if mesh.indices().is_empty() {
        return Err("every triangle of the mesh is degenerate".to_owned());
    }
    let closed = mesh
        .topology()
        .is_some_and(|t| t.half_edges.iter().all(|h| h.twin != u32::MAX));
    if !closed {
        return Ok(mesh);
    }
    let vertices = mesh.vertices().to_vec();
    let mut triangles = mesh.indices().to_vec();
    if signed_volume(&vertices, &triangles) < 0.0 {
        for t in &mut triangles {
            t.swap(1, 2);
        }
    }
    TriMesh::with_flags(
        vertices,
        triangles,
        TriMeshFlags::HALF_EDGE_TOPOLOGY | TriMeshFlags::ORIENTED,
    )
    .map_err(|e| format!("not a usable triangle mesh: {e}"))
}

/// Signed volume of a closed mesh (divergence theorem): positive when wound outwards.
fn signed_volume(vertices: &[Vec3], triangles: &[[u32; 3]]) -> f64 {
    triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| vertices[i as usize].as_dvec3());
            a.dot(b.cross(c)) / 6.0
        })
        .sum()
}
