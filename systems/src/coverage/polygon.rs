//! The area to survey: a simple polygon (convex or concave, no holes) in metres.
//!
//! Users' fields come from hand-typed vertex lists, GeoJSON and WKT files, so the constructor
//! checks everything the planner relies on and says exactly what is wrong: too few vertices,
//! non-finite coordinates, repeated vertices (zero-length edges), zero area and self-intersection
//! (tested with exact orientation predicates, so touching and overlapping edges count too).

use glam::DVec2;
use thiserror::Error;

/// Why a vertex list is not a simple polygon. Indices are those of the input list.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum PolygonError {
    #[error("a polygon needs at least 3 vertices, got {0}")]
    TooFewVertices(usize),
    #[error("vertex {index} has a non-finite coordinate ({x}, {y})")]
    NonFinite { index: usize, x: f64, y: f64 },
    #[error(
        "vertex {index} at ({x:?}, {y:?}) lies beyond {limit:e} m of the origin: a field is planned \
         in a local plane in metres"
    )]
    TooFar {
        index: usize,
        x: f64,
        y: f64,
        limit: f64,
    },
    #[error("a field may have at most {limit} vertices, got {count}")]
    TooManyVertices { count: usize, limit: usize },
    #[error("vertices {first} and {second} coincide at ({x}, {y}): zero-length edge")]
    RepeatedVertex {
        first: usize,
        second: usize,
        x: f64,
        y: f64,
    },
    #[error("the polygon has zero area: its vertices lie on one line")]
    ZeroArea,
    #[error(
        "the polygon intersects itself: edge {first} (from vertex {first}) meets edge {second} \
         (from vertex {second}) near ({x:.3}, {y:.3})"
    )]
    SelfIntersecting {
        first: usize,
        second: usize,
        x: f64,
        y: f64,
    },
}

/// Largest coordinate accepted (m). UTM northings reach 10^7 m, so projected fields fit; beyond
/// 10^8 m a field is no local plane, and spans, areas and the planner's tolerances would lose
/// their meaning (or overflow).
pub const MAX_COORDINATE_M: f64 = 1e8;

/// Most vertices of a field: the simplicity check is quadratic in them and the planner's
/// sub-areas grow with them.
pub const MAX_VERTICES: usize = 10_000;

/// A validated simple polygon, stored counter-clockwise (interior on the left of every edge).
#[derive(Debug, Clone, PartialEq)]
pub struct Polygon {
    vertices: Vec<DVec2>,
    /// The input was clockwise and has been reversed (vertex 0 kept first).
    reversed: bool,
}

impl Polygon {
    /// Validates `vertices` (a closing copy of the first vertex at the end is accepted and
    /// dropped) and orients them counter-clockwise.
    pub fn new(vertices: Vec<DVec2>) -> Result<Self, PolygonError> {
        let mut vertices = vertices;
        if vertices.len() > MAX_VERTICES {
            return Err(PolygonError::TooManyVertices {
                count: vertices.len(),
                limit: MAX_VERTICES,
            });
        }
        for (index, v) in vertices.iter().enumerate() {
            if !v.is_finite() {
                return Err(PolygonError::NonFinite {
                    index,
                    x: v.x,
                    y: v.y,
                });
            }
            if v.abs().max_element() > MAX_COORDINATE_M {
                return Err(PolygonError::TooFar {
                    index,
                    x: v.x,
                    y: v.y,
                    limit: MAX_COORDINATE_M,
                });
            }
        }
        if vertices.len() > 3 && vertices.first() == vertices.last() {
            vertices.pop();
        }
        let n = vertices.len();
        if n < 3 {
            return Err(PolygonError::TooFewVertices(n));
        }
        for i in 0..n {
            let j = (i + 1) % n;
            if vertices[i] == vertices[j] {
                let (first, second) = if j == 0 { (0, i) } else { (i, j) };
                return Err(PolygonError::RepeatedVertex {
                    first,
                    second,
                    x: vertices[i].x,
                    y: vertices[i].y,
                });
            }
        }
        if all_collinear(&vertices) {
            return Err(PolygonError::ZeroArea);
        }
        check_simple(&vertices)?;
        let area = signed_area(&vertices);
        let reversed = area < 0.0;
        if reversed {
            vertices[1..].reverse();
        }
        Ok(Self { vertices, reversed })
    }

    /// Vertices, counter-clockwise.
    pub fn vertices(&self) -> &[DVec2] {
        &self.vertices
    }

    pub fn len(&self) -> usize {
        self.vertices.len()
    }

    pub fn is_empty(&self) -> bool {
        self.vertices.is_empty()
    }

    /// Where the input's vertex `input_index` is stored (inputs given clockwise are reversed).
    pub fn index_of_input(&self, input_index: usize) -> Option<usize> {
        let n = self.vertices.len();
        if input_index >= n {
            None
        } else if self.reversed && input_index > 0 {
            Some(n - input_index)
        } else {
            Some(input_index)
        }
    }

    /// Area (m^2), positive.
    pub fn area(&self) -> f64 {
        signed_area(&self.vertices)
    }

    /// Perimeter (m).
    pub fn perimeter(&self) -> f64 {
        edges(&self.vertices).map(|(a, b)| a.distance(b)).sum()
    }

    /// Index `i` of the longest edge (from vertex `i` to vertex `i + 1`); the first on ties.
    pub fn longest_edge(&self) -> usize {
        longest_edge(&self.vertices)
    }

    /// Whether `p` lies inside or on the boundary (even-odd rule; boundary within `tolerance`).
    pub fn contains(&self, p: DVec2, tolerance: f64) -> bool {
        contains(&self.vertices, p, tolerance)
    }
}

/// Shoelace area, positive when counter-clockwise.
pub(crate) fn signed_area(vertices: &[DVec2]) -> f64 {
    edges(vertices).map(|(a, b)| a.perp_dot(b)).sum::<f64>() / 2.0
}

/// Edges as (start, end) pairs, closing the ring.
pub(crate) fn edges(vertices: &[DVec2]) -> impl Iterator<Item = (DVec2, DVec2)> + '_ {
    let n = vertices.len();
    (0..n).map(move |i| (vertices[i], vertices[(i + 1) % n]))
}

pub(crate) fn longest_edge(vertices: &[DVec2]) -> usize {
    let mut best = 0;
    let mut best_len = f64::NEG_INFINITY;
    for (i, (a, b)) in edges(vertices).enumerate() {
        let len = a.distance_squared(b);
        if len > best_len {
            best = i;
            best_len = len;
        }
    }
    best
}

/// Point in polygon (even-odd), with points within `tolerance` of an edge counted inside.
pub(crate) fn contains(vertices: &[DVec2], p: DVec2, tolerance: f64) -> bool {
    let mut inside = false;
    for (a, b) in edges(vertices) {
        if distance_to_segment(p, a, b) <= tolerance {
            return true;
        }
        if (a.y > p.y) != (b.y > p.y) {
            let x = a.x + (p.y - a.y) * (b.x - a.x) / (b.y - a.y);
            if p.x < x {
                inside = !inside;
            }
        }
    }
    inside
}

pub(crate) fn distance_to_segment(p: DVec2, a: DVec2, b: DVec2) -> f64 {
    let ab = b - a;
    let len2 = ab.length_squared();
    let t = if len2 > 0.0 {
        ((p - a).dot(ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    p.distance(a + ab * t)
}

fn orient(a: DVec2, b: DVec2, c: DVec2) -> f64 {
    let coord = |p: DVec2| robust::Coord { x: p.x, y: p.y };
    robust::orient2d(coord(a), coord(b), coord(c))
}

fn all_collinear(vertices: &[DVec2]) -> bool {
    let a = vertices[0];
    let b = vertices[1];
    vertices[2..].iter().all(|&c| orient(a, b, c) == 0.0)
}

/// Whether `c`, known collinear with segment `ab`, lies on it (endpoints included).
fn on_segment(a: DVec2, b: DVec2, c: DVec2) -> bool {
    c.x >= a.x.min(b.x) && c.x <= a.x.max(b.x) && c.y >= a.y.min(b.y) && c.y <= a.y.max(b.y)
}

/// Exact closed-segment intersection test (touching and collinear overlap count).
fn segments_intersect(a: DVec2, b: DVec2, c: DVec2, d: DVec2) -> bool {
    let o1 = orient(a, b, c);
    let o2 = orient(a, b, d);
    let o3 = orient(c, d, a);
    let o4 = orient(c, d, b);
    if o1 * o2 < 0.0 && o3 * o4 < 0.0 {
        return true;
    }
    (o1 == 0.0 && on_segment(a, b, c))
        || (o2 == 0.0 && on_segment(a, b, d))
        || (o3 == 0.0 && on_segment(c, d, a))
        || (o4 == 0.0 && on_segment(c, d, b))
}

/// Refuses any contact between edges other than the shared vertex of neighbours, and neighbours
/// that fold back onto each other. O(n^2), which is fine for fields of thousands of vertices.
fn check_simple(vertices: &[DVec2]) -> Result<(), PolygonError> {
    let n = vertices.len();
    let intersection = |i: usize, j: usize| {
        let (a, b) = (vertices[i], vertices[(i + 1) % n]);
        let (c, d) = (vertices[j], vertices[(j + 1) % n]);
        let near = [c, d]
            .into_iter()
            .min_by(|p, q| distance_to_segment(*p, a, b).total_cmp(&distance_to_segment(*q, a, b)))
            .unwrap_or(c);
        PolygonError::SelfIntersecting {
            first: i,
            second: j,
            x: near.x,
            y: near.y,
        }
    };
    for i in 0..n {
        // Neighbouring edges i and i+1 share vertex i+1; they overlap only when they fold back.
        let j = (i + 1) % n;
        let (a, b, c) = (vertices[i], vertices[j], vertices[(j + 1) % n]);
        if orient(a, b, c) == 0.0 && (b - a).dot(c - b) < 0.0 {
            return Err(intersection(i, j));
        }
        for j in (i + 2)..n {
            if i == 0 && j == n - 1 {
                continue; // neighbours through vertex 0
            }
            let (c, d) = (vertices[j], vertices[(j + 1) % n]);
            if segments_intersect(a, b, c, d) {
                return Err(intersection(i, j));
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn poly(points: &[(f64, f64)]) -> Result<Polygon, PolygonError> {
        Polygon::new(points.iter().map(|&(x, y)| DVec2::new(x, y)).collect())
    }

    #[test]
    fn square_area_perimeter_and_orientation() {
        // Clockwise input is reversed, keeping vertex 0 first.
        let p = poly(&[(0.0, 0.0), (0.0, 2.0), (3.0, 2.0), (3.0, 0.0)]).unwrap();
        assert_eq!(p.area(), 6.0);
        assert_eq!(p.perimeter(), 10.0);
        assert_eq!(p.vertices()[0], DVec2::ZERO);
        assert_eq!(p.vertices()[1], DVec2::new(3.0, 0.0));
        assert_eq!(p.index_of_input(1), Some(3));
        assert_eq!(p.vertices()[3], DVec2::new(0.0, 2.0));
        assert_eq!(p.longest_edge(), 0);
        assert!(p.contains(DVec2::new(1.0, 1.0), 0.0));
        assert!(p.contains(DVec2::new(3.0, 1.0), 1e-12));
        assert!(!p.contains(DVec2::new(3.5, 1.0), 1e-12));
    }

    #[test]
    fn closing_vertex_is_accepted() {
        let p = poly(&[(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (0.0, 0.0)]).unwrap();
        assert_eq!(p.len(), 3);
        assert_eq!(p.area(), 0.5);
    }

    #[test]
    fn degenerate_polygons_are_refused() {
        assert_eq!(
            poly(&[(0.0, 0.0), (1.0, 0.0)]),
            Err(PolygonError::TooFewVertices(2))
        );
        assert_eq!(
            poly(&[(0.0, 0.0), (1.0, 1.0), (2.0, 2.0)]),
            Err(PolygonError::ZeroArea)
        );
        assert!(matches!(
            poly(&[(0.0, 0.0), (1.0, 0.0), (1.0, 0.0), (0.0, 1.0)]),
            Err(PolygonError::RepeatedVertex {
                first: 1,
                second: 2,
                ..
            })
        ));
        assert!(matches!(
            poly(&[(0.0, 0.0), (f64::NAN, 0.0), (0.0, 1.0)]),
            Err(PolygonError::NonFinite { index: 1, .. })
        ));
    }

    #[test]
    fn far_away_and_oversized_fields_are_refused() {
        // 1e30 m once overflowed the planner's stripe count into an index panic.
        let err = poly(&[(0.0, 0.0), (1e30, 0.0), (1e30, 1e30), (0.0, 1e30)]).unwrap_err();
        assert!(
            matches!(err, PolygonError::TooFar { index: 1, .. }),
            "{err}"
        );
        // UTM-sized coordinates are fine.
        assert!(poly(&[(5e5, 9.9e6), (5e5 + 10.0, 9.9e6), (5e5, 9.9e6 + 10.0)]).is_ok());
        let many: Vec<DVec2> = (0..=MAX_VERTICES)
            .map(|i| DVec2::from_angle(i as f64 * 1e-4))
            .collect();
        assert!(matches!(
            Polygon::new(many),
            Err(PolygonError::TooManyVertices { .. })
        ));
    }

    #[test]
    fn self_intersecting_polygons_are_refused() {
        // Bow tie: edges 0 and 2 cross at (1, 1).
        let err = poly(&[(0.0, 0.0), (2.0, 2.0), (2.0, 0.0), (0.0, 2.0)]).unwrap_err();
        assert!(matches!(
            err,
            PolygonError::SelfIntersecting {
                first: 0,
                second: 2,
                ..
            }
        ));
        assert!(err.to_string().contains("intersects itself"));
        // A vertex touching another edge.
        assert!(matches!(
            poly(&[(0.0, 0.0), (4.0, 0.0), (4.0, 4.0), (2.0, 0.0), (0.0, 4.0)]),
            Err(PolygonError::SelfIntersecting { .. })
        ));
        // A spike folding back along its own edge.
        assert!(matches!(
            poly(&[(0.0, 0.0), (4.0, 0.0), (2.0, 0.0), (2.0, 3.0)]),
            Err(PolygonError::SelfIntersecting { .. })
        ));
    }

    #[test]
    fn concave_polygon_is_accepted() {
        // U shape.
        let p = poly(&[
            (0.0, 0.0),
            (3.0, 0.0),
            (3.0, 3.0),
            (2.0, 3.0),
            (2.0, 1.0),
            (1.0, 1.0),
            (1.0, 3.0),
            (0.0, 3.0),
        ])
        .unwrap();
        assert_eq!(p.area(), 7.0);
        assert!(!p.contains(DVec2::new(1.5, 2.0), 1e-9));
        assert!(p.contains(DVec2::new(0.5, 2.0), 1e-9));
    }
}
