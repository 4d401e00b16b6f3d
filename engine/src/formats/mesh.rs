//! Triangle meshes for world geometry, read from OBJ or STL files by extension.

use std::path::Path;

use glam::Vec3;

use super::{Fault, FormatError, Problem, load_by_extension, obj, stl};

/// An indexed triangle mesh, in the file's own units and frame (metres, as scenarios assume).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TriangleMesh {
    /// Vertex positions, all finite.
    pub vertices: Vec<Vec3>,
    /// Triangles as indices into `vertices`, all in range.
    pub triangles: Vec<[u32; 3]>,
}

/// Extensions [`load_mesh`] accepts.
pub const MESH_EXTENSIONS: &str = ".obj, .stl";

/// Loads a triangle mesh, choosing the format by extension (case-insensitive): `.obj`
/// (Wavefront; all objects and groups merged into one mesh, polygons fan-triangulated) or `.stl`
/// (ASCII or binary, told apart by content; identical vertices welded).
///
/// Errors name the file and, for text formats, the line; a mesh without any triangle, a
/// non-finite vertex and an out-of-range index are errors.
pub fn load_mesh(path: &Path) -> Result<TriangleMesh, FormatError> {
    load_by_extension(
        path,
        &[("obj", obj::parse_obj), ("stl", stl::parse_stl)],
        MESH_EXTENSIONS,
    )
}

/// Checks what every reader promises: at least one triangle, indices in range, finite vertices.
/// Readers check as they go (to report lines); this is the last word for both.
pub(crate) fn validated(mesh: TriangleMesh) -> Result<TriangleMesh, Fault> {
    if mesh.triangles.is_empty() {
        return Err(Fault::problem(Problem::EmptyMesh));
    }
    if let Some(i) = mesh.vertices.iter().position(|v| !v.is_finite()) {
        return Err(Fault::bare(format!("vertex {i} is not finite")));
    }
    let n = mesh.vertices.len();
    if let Some(t) = mesh
        .triangles
        .iter()
        .position(|t| t.iter().any(|&i| i as usize >= n))
    {
        return Err(Fault::bare(format!(
            "triangle {t} indexes past the {n} vertices"
        )));
    }
    Ok(mesh)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn data(name: &str) -> std::path::PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tests/data")
            .join(name)
    }

    #[test]
    fn unknown_extension_is_refused_before_reading() {
        let e = load_mesh(Path::new("/nonexistent/world.fbx")).unwrap_err();
        assert!(matches!(
            e.problem,
            Problem::UnsupportedExtension { ref found, .. } if found == "fbx"
        ));
        assert_eq!(e.path, Path::new("/nonexistent/world.fbx"));
    }

    #[test]
    fn missing_file_is_an_io_error_naming_the_file() {
        let e = load_mesh(Path::new("/nonexistent/world.obj")).unwrap_err();
        assert!(matches!(e.problem, Problem::Io(_)));
        assert!(
            e.to_string()
                .starts_with("/nonexistent/world.obj: cannot read")
        );
    }

    /// The OBJ fixture is a unit cube (8 vertices, 6 quads = 12 triangles) split into two objects,
    /// the second one written with negative (relative) indices.
    #[test]
    fn obj_fixture_loads_as_one_merged_cube() {
        let mesh = load_mesh(&data("cube.obj")).unwrap();
        assert_eq!(mesh.vertices.len(), 8);
        assert_eq!(mesh.triangles.len(), 12);
        assert_eq!(mesh.vertices[0], Vec3::new(0.0, 0.0, 0.0));
        assert_eq!(mesh.vertices[6], Vec3::new(1.0, 1.0, 1.0));
        // First quad `f 1 4 3 2` fans into (1 4 3), (1 3 2), 0-based.
        assert_eq!(mesh.triangles[0], [0, 3, 2]);
        assert_eq!(mesh.triangles[1], [0, 2, 1]);
        // Last quad `f -4 -3 -2 -1` (relative to the 8 vertices) is 5 6 7 8.
        assert_eq!(mesh.triangles[10], [4, 5, 6]);
        assert_eq!(mesh.triangles[11], [4, 6, 7]);
        assert_cube_surface(&mesh);
    }

    /// Both STL fixtures hold the same unit-cube triangles (12 facets, 36 corners welded to 8).
    #[test]
    fn stl_fixtures_ascii_and_binary_load_the_same_cube() {
        let ascii = load_mesh(&data("cube_ascii.stl")).unwrap();
        let binary = load_mesh(&data("cube_binary.stl")).unwrap();
        assert_eq!(ascii.vertices.len(), 8);
        assert_eq!(ascii.triangles.len(), 12);
        assert_eq!(ascii, binary);
        assert_cube_surface(&ascii);
    }

    /// Binary STL whose header starts with "solid " (as some CAD tools write) is still binary.
    #[test]
    fn binary_stl_with_solid_header_loads() {
        let mesh = load_mesh(&data("cube_binary_solid_header.stl")).unwrap();
        assert_eq!(mesh.triangles.len(), 12);
        assert_cube_surface(&mesh);
    }

    /// A closed unit cube has area 6 and volume 1 (divergence theorem, outward winding).
    fn assert_cube_surface(mesh: &TriangleMesh) {
        let (mut area, mut volume) = (0.0f32, 0.0f32);
        for t in &mesh.triangles {
            let [a, b, c] = t.map(|i| mesh.vertices[i as usize]);
            area += 0.5 * (b - a).cross(c - a).length();
            volume += a.dot(b.cross(c)) / 6.0;
        }
        assert!((area - 6.0).abs() < 1e-5, "area {area}");
        assert!((volume - 1.0).abs() < 1e-5, "volume {volume}");
    }

    #[test]
    fn validation_refuses_empty_non_finite_and_out_of_range() {
        let empty = TriangleMesh {
            vertices: vec![Vec3::ZERO; 3],
            triangles: vec![],
        };
        assert!(matches!(
            validated(empty).unwrap_err().problem,
            Problem::EmptyMesh
        ));
        let nan = TriangleMesh {
            vertices: vec![Vec3::ZERO, Vec3::X, Vec3::new(f32::NAN, 0.0, 0.0)],
            triangles: vec![[0, 1, 2]],
        };
        assert!(validated(nan).is_err());
        let out = TriangleMesh {
            vertices: vec![Vec3::ZERO, Vec3::X, Vec3::Y],
            triangles: vec![[0, 1, 3]],
        };
        assert!(validated(out).is_err());
    }
}
