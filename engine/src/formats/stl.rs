//! STL triangle soups, ASCII or binary, welded into an indexed mesh.
//!
//! Binary STL: an 80-byte header (free text), a little-endian `u32` triangle count, then per
//! triangle 12 little-endian `f32` (normal, three vertices) and a 2-byte attribute. ASCII STL:
//! `solid name`, then `facet normal nx ny nz` / `outer loop` / three `vertex x y z` / `endloop` /
//! `endfacet` per triangle, closed by `endsolid`. Normals are ignored (the winding is kept).

use std::collections::HashMap;

use glam::Vec3;

use super::mesh::{TriangleMesh, validated};
use super::{Fault, numbered_lines, parse_real};

const HEADER_BYTES: usize = 80;
const TRIANGLE_BYTES: usize = 50;

/// Parses an STL file. It is binary when its size is exactly what its triangle count says (which
/// also catches binary files whose header starts with `solid`), ASCII when it starts with
/// `solid`, and otherwise binary again (extra bytes after the declared triangles are ignored, as
/// most readers do).
pub(crate) fn parse_stl(bytes: &[u8]) -> Result<TriangleMesh, Fault> {
    let declared = declared_triangles(bytes);
    let exact_binary = declared
        .is_some_and(|n| HEADER_BYTES as u64 + 4 + n * TRIANGLE_BYTES as u64 == bytes.len() as u64);
    let starts_solid = bytes
        .trim_ascii_start()
        .get(..5)
        .is_some_and(|w| w.eq_ignore_ascii_case(b"solid"));
    let mesh = if !exact_binary && starts_solid {
        // A binary file with a "solid" header and trailing bytes also lands here: try it as
        // binary before reporting the ASCII error. (ASCII text read as a count is at least
        // 0x20202020 triangles, so a text file never passes as binary.)
        parse_ascii(bytes).or_else(|ascii| parse_binary(bytes).map_err(|_| ascii))?
    } else {
        parse_binary(bytes)?
    };
    validated(mesh)
}

fn declared_triangles(bytes: &[u8]) -> Option<u64> {
    let count = bytes.get(HEADER_BYTES..HEADER_BYTES + 4)?;
    Some(u64::from(u32::from_le_bytes(count.try_into().ok()?)))
}

fn parse_binary(bytes: &[u8]) -> Result<TriangleMesh, Fault> {
    let declared = declared_triangles(bytes).ok_or_else(|| {
        Fault::bare(format!(
            "{} bytes is too short for an STL file (binary needs 84, ASCII starts with \"solid\")",
            bytes.len()
        ))
    })?;
    let body = &bytes[HEADER_BYTES + 4..];
    let available = body.len() / TRIANGLE_BYTES;
    if (available as u64) < declared {
        return Err(Fault::bare(format!(
            "binary STL declares {declared} triangles but holds only {available} (truncated file?)"
        )));
    }
    let mut welder = Welder::with_capacity(declared as usize);
    for (t, record) in body
        .chunks_exact(TRIANGLE_BYTES)
        .take(declared as usize)
        .enumerate()
    {
        let f = |k: usize| {
            let at = 12 + 4 * k;
            f32::from_le_bytes([record[at], record[at + 1], record[at + 2], record[at + 3]])
        };
        let corners = [0, 1, 2].map(|c| Vec3::new(f(3 * c), f(3 * c + 1), f(3 * c + 2)));
        if corners.iter().any(|v| !v.is_finite()) {
            return Err(Fault::bare(format!("triangle {t} has a non-finite vertex")));
        }
        welder.push_triangle(corners)?;
    }
    Ok(welder.into_mesh())
}

/// The next expected keyword(s) of an ASCII facet.
fn expect(
    lines: &mut impl Iterator<Item = (usize, Vec<String>)>,
    keywords: &[&str],
    last_line: usize,
) -> Result<(usize, Vec<String>), Fault> {
    let (line, words) = lines.next().ok_or_else(|| {
        Fault::at(
            last_line,
            format!("file ends where {:?} was expected", keywords.join(" ")),
        )
    })?;
    let matches = words.len() >= keywords.len()
        && keywords
            .iter()
            .zip(&words)
            .all(|(k, w)| w.eq_ignore_ascii_case(k));
    if !matches {
        return Err(Fault::at(
            line,
            format!(
                "expected {:?}, found {:?}",
                keywords.join(" "),
                words.join(" ")
            ),
        ));
    }
    Ok((line, words))
}

fn parse_ascii(bytes: &[u8]) -> Result<TriangleMesh, Fault> {
    let mut lines = numbered_lines(bytes)
        .map(|(n, text)| {
            (
                n,
                text.split_whitespace()
                    .map(str::to_string)
                    .collect::<Vec<_>>(),
            )
        })
        .filter(|(_, words)| !words.is_empty());
    let mut welder = Welder::with_capacity(bytes.len() / 256);
    let mut last_line = 1;
    let mut inside_solid = false;
    while let Some((line, words)) = lines.next() {
        last_line = line;
        let keyword = words[0].to_ascii_lowercase();
        match (keyword.as_str(), inside_solid) {
            ("solid", false) => inside_solid = true,
            ("endsolid", true) => inside_solid = false,
            ("facet", true) => {
                let mut corners = [Vec3::ZERO; 3];
                let (l, _) = expect(&mut lines, &["outer", "loop"], line)?;
                last_line = l;
                for corner in &mut corners {
                    let (l, words) = expect(&mut lines, &["vertex"], last_line)?;
                    last_line = l;
                    *corner = parse_vertex(&words, l)?;
                }
                for keywords in [&["endloop"][..], &["endfacet"]] {
                    last_line = expect(&mut lines, keywords, last_line)?.0;
                }
                welder.push_triangle(corners).map_err(|f| Fault {
                    line: Some(line),
                    ..f
                })?;
            }
            (other, inside) => {
                let expected = if inside {
                    "\"facet\" or \"endsolid\""
                } else {
                    "\"solid\""
                };
                return Err(Fault::at(
                    line,
                    format!("expected {expected}, found {other:?}"),
                ));
            }
        }
    }
    if inside_solid {
        return Err(Fault::at(
            last_line,
            "file ends inside a solid (\"endsolid\" missing, truncated file?)",
        ));
    }
    Ok(welder.into_mesh())
}

fn parse_vertex(words: &[String], line: usize) -> Result<Vec3, Fault> {
    if words.len() != 4 {
        return Err(Fault::at(line, "expected \"vertex x y z\""));
    }
    let mut xyz = [0.0f32; 3];
    for (c, word) in xyz.iter_mut().zip(&words[1..]) {
        *c = parse_real(word)
            .map(|v| v as f32)
            .filter(|v| v.is_finite())
            .ok_or_else(|| {
                Fault::at(
                    line,
                    format!("vertex coordinate {word:?} is not a finite number"),
                )
            })?;
    }
    Ok(Vec3::from_array(xyz))
}

/// Merges corners with bit-identical coordinates into one vertex (after mapping -0.0 to 0.0), in
/// order of first appearance, so that the mesh is deterministic and shares edges.
struct Welder {
    index_of: HashMap<[u32; 3], u32>,
    mesh: TriangleMesh,
}

impl Welder {
    fn with_capacity(triangles: usize) -> Self {
        // Capacity from the file size only: a corrupt count must not reserve gigabytes.
        let triangles = triangles.min(1 << 20);
        Self {
            index_of: HashMap::with_capacity(triangles / 2),
            mesh: TriangleMesh {
                vertices: Vec::with_capacity(triangles / 2),
                triangles: Vec::with_capacity(triangles),
            },
        }
    }

    fn push_triangle(&mut self, corners: [Vec3; 3]) -> Result<(), Fault> {
        let mut triangle = [0u32; 3];
        for (slot, v) in triangle.iter_mut().zip(corners) {
            let v = v + Vec3::ZERO; // -0.0 + 0.0 = +0.0
            let key = v.to_array().map(f32::to_bits);
            let next = u32::try_from(self.mesh.vertices.len())
                .map_err(|_| Fault::bare("more vertices than 32-bit indices can address"))?;
            *slot = *self.index_of.entry(key).or_insert_with(|| {
                self.mesh.vertices.push(v);
                next
            });
        }
        self.mesh.triangles.push(triangle);
        Ok(())
    }

    fn into_mesh(self) -> TriangleMesh {
        self.mesh
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::formats::Problem;

    const ONE_FACET: &str = "solid t\n facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n   vertex 1 0 0\n   vertex 0 1 0\n  endloop\n endfacet\nendsolid t\n";

    #[test]
    fn ascii_facet_reads_its_three_vertices() {
        let mesh = parse_stl(ONE_FACET.as_bytes()).unwrap();
        assert_eq!(mesh.vertices, vec![Vec3::ZERO, Vec3::X, Vec3::Y]);
        assert_eq!(mesh.triangles, vec![[0, 1, 2]]);
    }

    #[test]
    fn welding_merges_shared_and_signed_zero_corners() {
        let mut w = Welder::with_capacity(2);
        w.push_triangle([Vec3::ZERO, Vec3::X, Vec3::Y]).unwrap();
        w.push_triangle([Vec3::new(-0.0, 0.0, -0.0), Vec3::Y, Vec3::Z])
            .unwrap();
        let mesh = w.into_mesh();
        assert_eq!(mesh.vertices.len(), 4);
        assert_eq!(mesh.triangles, vec![[0, 1, 2], [0, 2, 3]]);
    }

    fn binary(triangles: &[[f32; 9]], header: &[u8], declared: u32) -> Vec<u8> {
        let mut bytes = vec![b' '; HEADER_BYTES];
        bytes[..header.len()].copy_from_slice(header);
        bytes.extend(declared.to_le_bytes());
        for t in triangles {
            bytes.extend([0u8; 12]);
            bytes.extend(t.iter().flat_map(|v| v.to_le_bytes()));
            bytes.extend([0u8; 2]);
        }
        bytes
    }

    #[test]
    fn binary_with_solid_header_is_binary() {
        let bytes = binary(&[[0., 0., 0., 1., 0., 0., 0., 1., 0.]], b"solid fake", 1);
        let mesh = parse_stl(&bytes).unwrap();
        assert_eq!(mesh.triangles.len(), 1);
        assert_eq!(mesh.vertices[1], Vec3::X);
    }

    #[test]
    fn binary_truncated_or_non_finite_is_an_error() {
        let bytes = binary(&[[0., 0., 0., 1., 0., 0., 0., 1., 0.]], b"x", 2);
        let msg = parse_stl(&bytes).unwrap_err().problem.to_string();
        assert!(
            msg.contains("declares 2 triangles but holds only 1"),
            "{msg}"
        );
        let bytes = binary(&[[0., 0., 0., f32::INFINITY, 0., 0., 0., 1., 0.]], b"x", 1);
        assert!(parse_stl(&bytes).is_err());
        let bytes = binary(&[], b"x", 0);
        assert!(matches!(
            parse_stl(&bytes).unwrap_err().problem,
            Problem::EmptyMesh
        ));
        assert!(parse_stl(b"tiny").is_err());
    }

    #[test]
    fn ascii_errors_name_the_line() {
        let broken = ONE_FACET.replace("   vertex 1 0 0", "   vertex 1 0");
        assert_eq!(parse_stl(broken.as_bytes()).unwrap_err().line, Some(5));
        let broken = ONE_FACET.replace("endloop", "endloops");
        assert_eq!(parse_stl(broken.as_bytes()).unwrap_err().line, Some(7));
        let truncated = &ONE_FACET[..ONE_FACET.find("endsolid").unwrap()];
        let fault = parse_stl(truncated.as_bytes()).unwrap_err();
        assert_eq!(fault.line, Some(8));
        assert!(fault.problem.to_string().contains("endsolid"));
        let truncated = &ONE_FACET[..ONE_FACET.find("  endloop").unwrap()];
        let fault = parse_stl(truncated.as_bytes()).unwrap_err();
        assert_eq!(fault.line, Some(6));
    }

    #[test]
    fn ascii_accepts_uppercase_keywords_and_several_solids() {
        let two = format!(
            "{}{}",
            ONE_FACET.to_uppercase(),
            ONE_FACET.replace("1 0 0", "1 1 0")
        );
        let mesh = parse_stl(two.as_bytes()).unwrap();
        assert_eq!(mesh.triangles, vec![[0, 1, 2], [0, 3, 2]]);
    }
}
