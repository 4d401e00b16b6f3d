//! Wavefront OBJ geometry: `v` positions and `f` faces, the part of the format a world obstacle
//! needs. Texture coordinates, normals, materials, groups, smoothing, points (`p`) and lines
//! (`l`) are ignored; vertex indices are global in OBJ, so all objects and groups merge into one
//! mesh by construction.

use glam::Vec3;

use super::mesh::{TriangleMesh, validated};
use super::{Fault, numbered_lines, parse_real};

/// Parses an OBJ file. Polygons with more than three corners are fan-triangulated from their
/// first corner (as `tobj` and tinyobjloader do, exact for the convex faces exporters write).
/// Positive indices are 1-based and may point at vertices defined later in the file; negative
/// indices count back from the vertices defined so far (`-1` is the last one).
pub(crate) fn parse_obj(bytes: &[u8]) -> Result<TriangleMesh, Fault> {
    let mut vertices: Vec<Vec3> = Vec::new();
    let mut triangles: Vec<[u32; 3]> = Vec::new();
    let mut corners: Vec<u32> = Vec::new();
    // The largest positive index seen and its line, checked once all vertices are known.
    let mut largest: Option<(u32, usize)> = None;
    for (line, text) in numbered_lines(bytes) {
        let mut words = text.split_whitespace();
        match words.next() {
            Some("v") => vertices.push(parse_position(words, line)?),
            Some("f") => {
                corners.clear();
                for word in words {
                    let index = parse_corner(word, vertices.len(), line)?;
                    if largest.is_none_or(|(max, _)| index > max) {
                        largest = Some((index, line));
                    }
                    corners.push(index);
                }
                if corners.len() < 3 {
                    return Err(Fault::at(
                        line,
                        format!("a face needs 3 corners or more, found {}", corners.len()),
                    ));
                }
                triangles.extend(corners.windows(2).skip(1).map(|w| [corners[0], w[0], w[1]]));
            }
            _ => {}
        }
    }
    if let Some((index, line)) = largest
        && index as usize >= vertices.len()
    {
        return Err(Fault::at(
            line,
            format!(
                "face index {} is past the {} vertices of the file",
                u64::from(index) + 1,
                vertices.len()
            ),
        ));
    }
    if vertices.len() > u32::MAX as usize {
        return Err(Fault::bare("more vertices than 32-bit indices can address"));
    }
    validated(TriangleMesh {
        vertices,
        triangles,
    })
}

/// `v x y z [w | r g b]`: the three coordinates; extras (weight, colour) are ignored.
fn parse_position<'a>(
    mut words: impl Iterator<Item = &'a str>,
    line: usize,
) -> Result<Vec3, Fault> {
    let mut xyz = [0.0f32; 3];
    for c in &mut xyz {
        let word = words
            .next()
            .ok_or_else(|| Fault::at(line, "a vertex needs three coordinates"))?;
        let value = parse_real(word)
            .ok_or_else(|| Fault::at(line, format!("vertex coordinate {word:?} is not a number")))?
            as f32;
        if !value.is_finite() {
            return Err(Fault::at(
                line,
                format!("vertex coordinate {word:?} is not finite"),
            ));
        }
        *c = value;
    }
    Ok(Vec3::from_array(xyz))
}

/// One face corner `v`, `v/vt`, `v//vn` or `v/vt/vn`, as a 0-based vertex index.
/// `defined` is the number of vertices defined before this line (for negative indices).
fn parse_corner(word: &str, defined: usize, line: usize) -> Result<u32, Fault> {
    let vertex = word.split('/').next().unwrap_or_default();
    let index: i64 = vertex
        .parse()
        .map_err(|_| Fault::at(line, format!("face corner {word:?} has no vertex index")))?;
    let zero_based = match index {
        0 => return Err(Fault::at(line, "face index 0 (OBJ indices start at 1)")),
        i if i > 0 => i - 1,
        i => {
            let from_end = i.unsigned_abs();
            if from_end > defined as u64 {
                return Err(Fault::at(
                    line,
                    format!(
                        "relative face index {i} reaches before the first vertex ({defined} defined so far)"
                    ),
                ));
            }
            (defined as u64 - from_end) as i64
        }
    };
    u32::try_from(zero_based)
        .map_err(|_| Fault::at(line, format!("face index {index} does not fit 32 bits")))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::formats::Problem;

    fn err_line(src: &str) -> (Option<usize>, String) {
        let fault = parse_obj(src.as_bytes()).unwrap_err();
        (fault.line, fault.problem.to_string())
    }

    #[test]
    fn triangle_with_texture_and_normal_indices() {
        let src = "v 0 0 0\nv 1 0 0\nv 0 2 0.5\nvt 0 0\nvn 0 0 1\nf 1/1/1 2//1 3/1\n";
        let mesh = parse_obj(src.as_bytes()).unwrap();
        assert_eq!(
            mesh.vertices,
            vec![Vec3::ZERO, Vec3::X, Vec3::new(0.0, 2.0, 0.5)]
        );
        assert_eq!(mesh.triangles, vec![[0, 1, 2]]);
    }

    #[test]
    fn pentagon_fans_into_three_triangles() {
        let src = "v 0 0 0\nv 1 0 0\nv 2 1 0\nv 1 2 0\nv 0 1 0\nf 1 2 3 4 5\n";
        let mesh = parse_obj(src.as_bytes()).unwrap();
        assert_eq!(mesh.triangles, vec![[0, 1, 2], [0, 2, 3], [0, 3, 4]]);
    }

    #[test]
    fn forward_reference_is_resolved_at_the_end() {
        let src = "f 1 2 3\nv 0 0 0\nv 1 0 0\nv 0 1 0\n";
        assert_eq!(
            parse_obj(src.as_bytes()).unwrap().triangles,
            vec![[0, 1, 2]]
        );
    }

    #[test]
    fn errors_name_the_offending_line() {
        let (line, msg) = err_line("v 0 0 0\nv 1 0 0\nv 0 1 0\n# c\nf 1 2 4\n");
        assert_eq!(line, Some(5));
        assert!(msg.contains("face index 4 is past the 3 vertices"), "{msg}");

        let (line, msg) = err_line("v 0 0 0\nv 1 0\n");
        assert_eq!(line, Some(2));
        assert!(msg.contains("three coordinates"), "{msg}");

        let (line, _) = err_line("v 0 0 0\nv 1 0 x\n");
        assert_eq!(line, Some(2));

        let (line, msg) = err_line("v 0 0 nan\n");
        assert_eq!(line, Some(1));
        assert!(msg.contains("not finite"), "{msg}");

        let (line, msg) = err_line("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 0\n");
        assert_eq!(line, Some(4));
        assert!(msg.contains("index 0"), "{msg}");

        let (line, msg) = err_line("v 0 0 0\nv 1 0 0\nf 1 -3 2\nv 0 1 0\n");
        assert_eq!(line, Some(3));
        assert!(msg.contains("reaches before the first vertex"), "{msg}");

        let (line, msg) = err_line("v 0 0 0\nv 1 0 0\nf 1 2\n");
        assert_eq!(line, Some(3));
        assert!(msg.contains("3 corners"), "{msg}");

        let (line, _) = err_line("v 0 0 0\nf 1 -9223372036854775808 1\n");
        assert_eq!(line, Some(2));
        let (line, _) = err_line("v 0 0 0\nf 1 1 99999999999\n");
        assert_eq!(line, Some(2));
        let (line, _) = err_line("v 0 0 0\nf 1 1 /2\n");
        assert_eq!(line, Some(2));
    }

    #[test]
    fn vertices_without_faces_are_an_empty_mesh() {
        let fault = parse_obj(b"v 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2\np 3\n").unwrap_err();
        assert!(matches!(fault.problem, Problem::EmptyMesh));
    }
}
