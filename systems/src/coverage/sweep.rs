//! Sweeping a polygon with lines parallel to the scan direction (coverage.md, "Path" and
//! "Concavities").
//!
//! In a frame whose `u` axis is the scan direction and whose `v` axis points across the stripes,
//! the horizontal lines through every vertex cut the polygon into trapezoids. The back-and-forth
//! covers in one go the *cell* that grows from the base (the longest edge) through trapezoids
//! joined one-to-one: there the polygon's cross-section is a single interval, so every stripe meets
//! the same two sides. Where the next stripe would meet a side not contiguous with the current one
//! (the polygon splits around a concavity, or another part joins), the cell ends, and each part
//! beyond it is cut off along a *chord*, a horizontal segment whose ends lie on the boundary, to be
//! covered by running the whole procedure on it.

use super::polygon::{edges, signed_area};
use glam::DVec2;

/// A right-handed frame: `u` along the stripes, `v = u.perp()` across them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Frame {
    pub origin: DVec2,
    pub u: DVec2,
    pub v: DVec2,
}

impl Frame {
    /// `direction` need not be normalised but must not be zero.
    pub fn new(origin: DVec2, direction: DVec2) -> Self {
        let u = direction.normalize();
        Self {
            origin,
            u,
            v: u.perp(),
        }
    }

    pub fn to_frame(self, p: DVec2) -> DVec2 {
        let d = p - self.origin;
        DVec2::new(d.dot(self.u), d.dot(self.v))
    }

    pub fn to_world(self, q: DVec2) -> DVec2 {
        self.origin + self.u * q.x + self.v * q.y
    }
}

/// The part of the polygon between two consecutive vertex levels bounded by two edges.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Trapezoid {
    pub bottom: f64,
    pub top: f64,
    /// Index of the edge (from vertex `i` to `i + 1`) bounding it on the low-`u` side.
    pub left_edge: usize,
    pub right_edge: usize,
    pub bottom_left: f64,
    pub bottom_right: f64,
    pub top_left: f64,
    pub top_right: f64,
}

impl Trapezoid {
    fn side_at(&self, bottom_u: f64, top_u: f64, w: f64) -> f64 {
        let t = (w - self.bottom) / (self.top - self.bottom);
        bottom_u + (top_u - bottom_u) * t.clamp(0.0, 1.0)
    }

    pub fn left_at(&self, w: f64) -> f64 {
        self.side_at(self.bottom_left, self.top_left, w)
    }

    pub fn right_at(&self, w: f64) -> f64 {
        self.side_at(self.bottom_right, self.top_right, w)
    }
}

/// The trapezoidal decomposition of a polygon in a frame.
#[derive(Debug, Clone)]
pub(crate) struct Sweep {
    pub frame: Frame,
    /// Vertices in frame coordinates, `v` snapped onto `levels`.
    pub points: Vec<DVec2>,
    /// Distinct vertex levels, increasing.
    pub levels: Vec<f64>,
    /// `slabs[j]`: trapezoids between `levels[j]` and `levels[j + 1]`, by increasing `u`.
    pub slabs: Vec<Vec<Trapezoid>>,
    /// Length below which two levels or two positions are the same (m).
    pub eps: f64,
}

/// A horizontal segment of the frame at `level` from `left` to `right` (in `u`) whose ends lie on
/// the edges `left_edge` and `right_edge`; the polygon on its far side is cut off from the cell.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Chord {
    pub level: f64,
    pub left: f64,
    pub right: f64,
    pub left_edge: usize,
    pub right_edge: usize,
    /// Whether the part cut off lies above the chord (else below).
    pub beyond_above: bool,
}

/// The cell covered by one back-and-forth: trapezoids stacked from bottom to top.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Cell {
    pub trapezoids: Vec<Trapezoid>,
}

impl Cell {
    pub fn bottom(&self) -> f64 {
        self.trapezoids.first().map_or(0.0, |t| t.bottom)
    }

    pub fn top(&self) -> f64 {
        self.trapezoids.last().map_or(0.0, |t| t.top)
    }

    /// The `u` range of the cell between levels `lo` and `hi`: the along-stripe extent a stripe
    /// whose footprint spans those levels must photograph. It includes the spec's growth of the
    /// edge by `cot(pi - gamma) L_x` where a side leans outwards.
    pub fn extent(&self, lo: f64, hi: f64) -> Option<(f64, f64)> {
        let mut range: Option<(f64, f64)> = None;
        for t in &self.trapezoids {
            let a = lo.max(t.bottom);
            let b = hi.min(t.top);
            if a > b {
                continue;
            }
            let left = t.left_at(a).min(t.left_at(b));
            let right = t.right_at(a).max(t.right_at(b));
            range = Some(match range {
                None => (left, right),
                Some((l, r)) => (l.min(left), r.max(right)),
            });
        }
        range
    }
}

impl Sweep {
    /// Decomposes the counter-clockwise simple polygon `vertices` in `frame`. Vertices listed in
    /// `on_axis` are put exactly on level 0 (the base edge).
    pub fn new(vertices: &[DVec2], frame: Frame, on_axis: &[usize], eps: f64) -> Self {
        let mut points: Vec<DVec2> = vertices.iter().map(|&p| frame.to_frame(p)).collect();
        for &i in on_axis {
            points[i].y = 0.0;
        }
        let levels = snap_levels(&mut points, eps);
        let n = points.len();
        let mut slabs = Vec::with_capacity(levels.len().saturating_sub(1));
        for j in 0..levels.len().saturating_sub(1) {
            let (lo, hi) = (levels[j], levels[j + 1]);
            let mid = 0.5 * (lo + hi);
            let mut crossing: Vec<(f64, usize)> = (0..n)
                .filter(|&i| {
                    let (a, b) = (points[i], points[(i + 1) % n]);
                    a.y.min(b.y) <= lo && a.y.max(b.y) >= hi
                })
                .map(|i| (edge_u_at(&points, i, mid), i))
                .collect();
            crossing.sort_by(|a, b| a.0.total_cmp(&b.0));
            // A closed polyline crosses a line through no vertex an even number of times, so the
            // crossings pair up into the intervals inside the polygon.
            let slab = crossing
                .chunks_exact(2)
                .map(|pair| {
                    let (left_edge, right_edge) = (pair[0].1, pair[1].1);
                    Trapezoid {
                        bottom: lo,
                        top: hi,
                        left_edge,
                        right_edge,
                        bottom_left: edge_u_at(&points, left_edge, lo),
                        bottom_right: edge_u_at(&points, right_edge, lo),
                        top_left: edge_u_at(&points, left_edge, hi),
                        top_right: edge_u_at(&points, right_edge, hi),
                    }
                })
                .collect();
            slabs.push(slab);
        }
        Self {
            frame,
            points,
            levels,
            slabs,
            eps,
        }
    }

    /// Trapezoids of slab `j + 1` sharing a stretch of level `levels[j + 1]` with `slabs[j][t]`.
    pub fn upper_neighbours(&self, j: usize, t: usize) -> Vec<usize> {
        let Some(upper) = self.slabs.get(j + 1) else {
            return Vec::new();
        };
        let below = self.slabs[j][t];
        (0..upper.len())
            .filter(|&k| {
                overlap(
                    (below.top_left, below.top_right),
                    (upper[k].bottom_left, upper[k].bottom_right),
                ) > self.eps
            })
            .collect()
    }

    /// Trapezoids of slab `j - 1` sharing a stretch of level `levels[j]` with `slabs[j][t]`.
    pub fn lower_neighbours(&self, j: usize, t: usize) -> Vec<usize> {
        if j == 0 {
            return Vec::new();
        }
        let above = self.slabs[j][t];
        let lower = &self.slabs[j - 1];
        (0..lower.len())
            .filter(|&k| {
                overlap(
                    (lower[k].top_left, lower[k].top_right),
                    (above.bottom_left, above.bottom_right),
                ) > self.eps
            })
            .collect()
    }

    /// The trapezoid just above level `base_level` whose bottom contains `base_u`.
    pub fn base_trapezoid(&self, base_level: f64, base_u: f64) -> Option<(usize, usize)> {
        let j = self.levels.iter().position(|&l| l == base_level)?;
        let slab = self.slabs.get(j)?;
        let t = slab.iter().position(|t| {
            t.bottom_left - self.eps <= base_u && base_u <= t.bottom_right + self.eps
        })?;
        Some((j, t))
    }

    /// Grows the cell from the base trapezoid `(j, t)` upwards through one-to-one joins and
    /// returns it with the chords that cut off the rest of the polygon (below its base, where the
    /// polygon also extends beyond the base edge, and above its top).
    pub fn cell_from(&self, j0: usize, t0: usize) -> (Cell, Vec<Chord>) {
        let mut chords: Vec<Chord> = self
            .lower_neighbours(j0, t0)
            .into_iter()
            .map(|k| self.chord(j0 - 1, k, t0, false))
            .collect();
        let mut trapezoids = vec![self.slabs[j0][t0]];
        let (mut j, mut t) = (j0, t0);
        loop {
            let ups = self.upper_neighbours(j, t);
            if ups.len() == 1 && self.lower_neighbours(j + 1, ups[0]).len() == 1 {
                j += 1;
                t = ups[0];
                trapezoids.push(self.slabs[j][t]);
                continue;
            }
            chords.extend(ups.into_iter().map(|k| self.chord(j, t, k, true)));
            break;
        }
        (Cell { trapezoids }, chords)
    }

    /// The chord between `slabs[j][lower]` and `slabs[j + 1][upper]`.
    fn chord(&self, j: usize, lower: usize, upper: usize, beyond_above: bool) -> Chord {
        let d = self.slabs[j][lower];
        let u = self.slabs[j + 1][upper];
        let (left, left_edge) = if d.top_left >= u.bottom_left {
            (d.top_left, d.left_edge)
        } else {
            (u.bottom_left, u.left_edge)
        };
        let (right, right_edge) = if d.top_right <= u.bottom_right {
            (d.top_right, d.right_edge)
        } else {
            (u.bottom_right, u.right_edge)
        };
        Chord {
            level: self.levels[j + 1],
            left,
            right,
            left_edge,
            right_edge,
            beyond_above,
        }
    }

    /// The polygon on the far side of `chord`, counter-clockwise, in world coordinates, cleaned of
    /// repeated and collinear vertices; `None` when nothing of positive area is left.
    pub fn cut_off(&self, vertices: &[DVec2], chord: &Chord) -> Option<Vec<DVec2>> {
        let n = vertices.len();
        let left = self.frame.to_world(DVec2::new(chord.left, chord.level));
        let right = self.frame.to_world(DVec2::new(chord.right, chord.level));
        // Counter-clockwise, the interior is on the left: above the chord the boundary runs from
        // its right end round to its left end, below it from the left end round to the right end.
        let (first, first_edge, last, last_edge) = if chord.beyond_above {
            (right, chord.right_edge, left, chord.left_edge)
        } else {
            (left, chord.left_edge, right, chord.right_edge)
        };
        let mut ring = vec![first];
        let mut k = first_edge;
        while k != last_edge {
            k = (k + 1) % n;
            ring.push(vertices[k]);
        }
        ring.push(last);
        clean_ring(ring, self.eps)
    }
}

/// `u` where edge `i` (from point `i` to `i + 1`) crosses level `w`; exact at its end points.
fn edge_u_at(points: &[DVec2], i: usize, w: f64) -> f64 {
    let a = points[i];
    let b = points[(i + 1) % points.len()];
    if w == a.y {
        a.x
    } else if w == b.y {
        b.x
    } else {
        a.x + (w - a.y) * (b.x - a.x) / (b.y - a.y)
    }
}

fn overlap(a: (f64, f64), b: (f64, f64)) -> f64 {
    a.1.min(b.1) - a.0.max(b.0)
}

/// Groups the points' `v` values that lie within `eps` of each other onto one level (the one of
/// smallest magnitude, so that level 0 stays exactly 0) and returns the distinct levels.
fn snap_levels(points: &mut [DVec2], eps: f64) -> Vec<f64> {
    let mut order: Vec<usize> = (0..points.len()).collect();
    order.sort_by(|&a, &b| points[a].y.total_cmp(&points[b].y));
    let mut levels = Vec::new();
    let mut start = 0;
    while start < order.len() {
        let first = points[order[start]].y;
        let mut end = start + 1;
        while end < order.len() && points[order[end]].y - first <= eps {
            end += 1;
        }
        let group = &order[start..end];
        let level = group
            .iter()
            .map(|&i| points[i].y)
            .min_by(|a, b| a.abs().total_cmp(&b.abs()))
            .unwrap_or(first);
        for &i in group {
            points[i].y = level;
        }
        levels.push(level);
        start = end;
    }
    levels
}

/// Removes repeated vertices and vertices within `eps` of the line through their neighbours;
/// `None` when fewer than three remain or the area vanishes.
pub(crate) fn clean_ring(mut ring: Vec<DVec2>, eps: f64) -> Option<Vec<DVec2>> {
    loop {
        let n = ring.len();
        if n < 3 {
            return None;
        }
        let redundant = (0..n).find(|&i| {
            let prev = ring[(i + n - 1) % n];
            let next = ring[(i + 1) % n];
            let p = ring[i];
            p.distance(prev) <= eps || {
                let chord = next - prev;
                let len = chord.length();
                len > eps
                    && (p - prev).perp_dot(chord).abs() / len <= eps
                    && (p - prev).dot(chord) >= 0.0
                    && (p - next).dot(-chord) >= 0.0
            }
        });
        match redundant {
            Some(i) => {
                ring.remove(i);
            }
            None => break,
        }
    }
    let scale: f64 = edges(&ring).map(|(a, b)| a.distance(b)).sum();
    (signed_area(&ring) > eps * scale).then_some(ring)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pts(points: &[(f64, f64)]) -> Vec<DVec2> {
        points.iter().map(|&(x, y)| DVec2::new(x, y)).collect()
    }

    fn u_shape() -> Vec<DVec2> {
        pts(&[
            (0.0, 0.0),
            (3.0, 0.0),
            (3.0, 3.0),
            (2.0, 3.0),
            (2.0, 1.0),
            (1.0, 1.0),
            (1.0, 3.0),
            (0.0, 3.0),
        ])
    }

    #[test]
    fn square_is_one_cell() {
        let square = pts(&[(0.0, 0.0), (2.0, 0.0), (2.0, 1.0), (0.0, 1.0)]);
        let sweep = Sweep::new(&square, Frame::new(square[0], DVec2::X), &[0, 1], 1e-9);
        assert_eq!(sweep.levels, vec![0.0, 1.0]);
        let (j, t) = sweep.base_trapezoid(0.0, 1.0).unwrap();
        let (cell, chords) = sweep.cell_from(j, t);
        assert!(chords.is_empty());
        assert_eq!((cell.bottom(), cell.top()), (0.0, 1.0));
        assert_eq!(cell.extent(0.0, 1.0), Some((0.0, 2.0)));
    }

    #[test]
    fn u_shape_splits_into_base_and_two_arms() {
        let u = u_shape();
        let sweep = Sweep::new(&u, Frame::new(u[0], DVec2::X), &[0, 1], 1e-9);
        assert_eq!(sweep.levels, vec![0.0, 1.0, 3.0]);
        let (j, t) = sweep.base_trapezoid(0.0, 1.5).unwrap();
        let (cell, chords) = sweep.cell_from(j, t);
        assert_eq!((cell.bottom(), cell.top()), (0.0, 1.0));
        assert_eq!(chords.len(), 2);
        let left = sweep.cut_off(&u, &chords[0]).unwrap();
        let right = sweep.cut_off(&u, &chords[1]).unwrap();
        assert_eq!(left, pts(&[(1.0, 1.0), (1.0, 3.0), (0.0, 3.0), (0.0, 1.0)]));
        assert_eq!(
            right,
            pts(&[(3.0, 1.0), (3.0, 3.0), (2.0, 3.0), (2.0, 1.0)])
        );
    }

    #[test]
    fn part_below_the_base_edge_is_cut_off_below() {
        // The base edge (0,0)-(4,0) has the polygon also below level 0 to its right.
        let poly = pts(&[
            (0.0, 0.0),
            (4.0, 0.0),
            (4.0, -2.0),
            (6.0, -2.0),
            (6.0, 2.0),
            (0.0, 2.0),
        ]);
        let sweep = Sweep::new(&poly, Frame::new(poly[0], DVec2::X), &[0, 1], 1e-9);
        let (j, t) = sweep.base_trapezoid(0.0, 2.0).unwrap();
        let (cell, chords) = sweep.cell_from(j, t);
        assert_eq!((cell.bottom(), cell.top()), (0.0, 2.0));
        assert_eq!(cell.extent(0.0, 2.0), Some((0.0, 6.0)));
        assert_eq!(chords.len(), 1);
        assert!(!chords[0].beyond_above);
        let below = sweep.cut_off(&poly, &chords[0]).unwrap();
        assert_eq!(
            below,
            pts(&[(4.0, 0.0), (4.0, -2.0), (6.0, -2.0), (6.0, 0.0)])
        );
    }

    #[test]
    fn leaning_sides_widen_the_extent() {
        // Trapezoid whose sides lean out by 1 m over its 2 m height.
        let poly = pts(&[(0.0, 0.0), (4.0, 0.0), (5.0, 2.0), (-1.0, 2.0)]);
        let sweep = Sweep::new(&poly, Frame::new(poly[0], DVec2::X), &[0, 1], 1e-9);
        let (cell, _) = sweep.cell_from(0, 0);
        assert_eq!(cell.extent(0.0, 1.0), Some((-0.5, 4.5)));
        assert_eq!(cell.extent(-5.0, 5.0), Some((-1.0, 5.0)));
    }

    #[test]
    fn clean_ring_drops_repeats_and_collinear_points() {
        let ring = pts(&[(0.0, 0.0), (1.0, 0.0), (2.0, 0.0), (2.0, 0.0), (2.0, 2.0)]);
        assert_eq!(
            clean_ring(ring, 1e-9),
            Some(pts(&[(0.0, 0.0), (2.0, 0.0), (2.0, 2.0)]))
        );
        assert_eq!(
            clean_ring(pts(&[(0.0, 0.0), (1.0, 0.0), (2.0, 0.0)]), 1e-9),
            None
        );
    }
}
