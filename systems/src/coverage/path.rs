//! The three-part back-and-forth path over a simple polygon (coverage.md, "Path"; Di Franco and
//! Buttazzo 2015).
//!
//! For an area entered at a vertex:
//! 1. **Part 1**: from the entry vertex along the border to the nearer end of the base edge (the
//!    longest edge), with shots along each border edge (first at `(L_y/2, L_x/2)` from the border,
//!    then `Delta_y = (d - L_y)/(m - 1)` apart, `m = ceil(d / d_y)`; an edge grows by
//!    `cot(pi - gamma) L_x` at inner angles `gamma` above `pi/2`).
//! 2. **Part 2**: an even number `n_s = ceil(d_max / d_x)` of stripes parallel to the base edge,
//!    `Delta_x = (d_max - L_x)/(n_s - 1)` apart, shots along each as in part 1 over the stretch of
//!    the cell its footprint spans. When the next stripe would meet a side not contiguous with the
//!    current one, the stripe is finished and the whole procedure runs on the part cut off
//!    (the `sweep` module); the parts beside the base edge are visited after the first stripe, those
//!    beyond the top after the last one.
//! 3. **Part 3**: back along the border to the entry vertex, with shots.
//!
//! Every point of the area lies in the footprint of a stripe shot: the footprints of consecutive
//! stripes overlap across (`Delta_x <= d_x <= L_x`) and along (`Delta_y <= d_y <= L_y`) and each
//! stripe spans the whole cross-section of the cell within its footprint; the parts cut off are
//! covered by their own runs. The border shots of parts 1 and 3 are the paper's and add overlap.

use super::camera::SurveyGeometry;
use super::polygon::{Polygon, longest_edge};
use super::spacing::{shot_count, shot_offsets, stripe_count, stripe_levels};
use super::sweep::{Chord, Frame, Sweep, clean_ring};
use glam::DVec2;
use serde::{Deserialize, Serialize};
use thiserror::Error;

/// Which way the stripes run in each (sub-)area.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ScanDirection {
    /// Parallel to the area's longest edge (the paper's choice).
    #[default]
    LongestEdge,
    /// Perpendicular to the longest edge, sweeping from the lowest vertex (for comparison).
    AcrossLongestEdge,
}

#[derive(Debug, Clone, PartialEq, Error)]
pub enum PathError {
    #[error("start vertex {index} does not exist: the polygon has {len} vertices")]
    StartVertex { index: usize, len: usize },
    #[error("the sweep found no cell above its base in a sub-area of {vertices} vertices")]
    NoBaseCell { vertices: usize },
    /// Bounded work: the counts come from the inputs (area size against footprint and
    /// overlaps), so they are checked before anything is allocated.
    #[error(
        "covering the area at {altitude_m:.2} m takes more than {limit} photos and stripes, the \
         planner's limit: the footprint is {l_x:.3e} m x {l_y:.3e} m, stripes come {d_x:.3e} m \
         apart and photos along a stripe {d_y:.3e} m apart (a smaller area, less overlap or an \
         image closer to square needs fewer)"
    )]
    TooManyShots {
        limit: usize,
        altitude_m: f64,
        l_x: f64,
        l_y: f64,
        d_x: f64,
        d_y: f64,
    },
    #[error(
        "the area is thinner than the planner's tolerance ({tolerance:.3e} m) yet does not fit \
         in one footprint ({l_x:.3e} m x {l_y:.3e} m): there is nothing of positive area to sweep"
    )]
    TooThin { tolerance: f64, l_x: f64, l_y: f64 },
    #[error(
        "the area nests concavities more than {limit} deep; the planner recurses once per level"
    )]
    TooDeep { limit: usize },
}

/// A point of the path; `shot` holds the along-track direction of the image taken there (the
/// footprint's `L_y` side), if one is.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Waypoint {
    pub position: DVec2,
    pub shot: Option<DVec2>,
}

/// A straight run of the path, flown from rest to rest.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Leg {
    pub start: DVec2,
    pub end: DVec2,
    /// Indices of its first and last waypoint in [`CoveragePath::waypoints`].
    pub waypoints: [usize; 2],
    /// Shots taken along it, ends included.
    pub shots: usize,
    /// Shortest distance between consecutive shots along it (m), when it has two or more.
    pub min_shot_spacing: Option<f64>,
}

impl Leg {
    pub fn length(&self) -> f64 {
        self.start.distance(self.end)
    }
}

/// The planned path at one altitude: a closed tour from the start vertex back to it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CoveragePath {
    pub waypoints: Vec<Waypoint>,
    /// Stripes flown, over all (sub-)areas.
    pub stripes: usize,
    /// Areas the procedure ran on: 1 plus one per part cut off at a concavity.
    pub areas: usize,
}

/// Beyond this depth sub-areas keep their parent's stripe direction, so that the recursion
/// provably ends (it then walks the parent's finite set of trapezoids).
const MAX_REORIENT_DEPTH: usize = 16;

/// Most photos plus stripes one path may plan. A survey of 100 km^2 at 2 cm/px takes about
/// 10^5 photos; the limit bounds the memory and time of one plan (and of every re-plan of the
/// altitude search) whatever the area, camera and overlaps say.
pub const MAX_SHOTS: usize = 1_000_000;

/// Deepest nesting of sub-areas cut off at concavities: each level is a recursive call, so the
/// limit keeps the stack bounded (real fields nest a few levels).
pub const MAX_AREA_DEPTH: usize = 256;

/// Plans the coverage path of `polygon` for the camera geometry of `survey`, starting and ending
/// at vertex `start_vertex` (an index into [`Polygon::vertices`]).
pub fn plan_path(
    polygon: &Polygon,
    start_vertex: usize,
    survey: &SurveyGeometry,
    direction: ScanDirection,
) -> Result<CoveragePath, PathError> {
    let vertices = polygon.vertices();
    let start = *vertices.get(start_vertex).ok_or(PathError::StartVertex {
        index: start_vertex,
        len: vertices.len(),
    })?;
    let (lo, hi) = vertices
        .iter()
        .fold((vertices[0], vertices[0]), |(lo, hi), &p| {
            (lo.min(p), hi.max(p))
        });
    let eps = 1e-9 * (hi - lo).max_element().max(survey.footprint.l_x);
    let mut planner = Planner {
        survey,
        direction,
        eps,
        waypoints: Vec::new(),
        stripes: 0,
        areas: 0,
        budget: MAX_SHOTS,
    };
    planner.go(start, None);
    // The validated polygon may still hold collinear vertices; they would split edges.
    match clean_ring(vertices.to_vec(), eps) {
        Some(area) => {
            let entry = nearest(&area, start);
            planner.go(area[entry], None);
            planner.cover(area, entry, 0, None)?;
        }
        // Thinner than the tolerance: one shot covers it if one footprint does (whichever way
        // the image lies), else there is no area to sweep and no honest plan.
        None => {
            let l = survey.footprint;
            if (hi - lo).max_element() > l.l_x.min(l.l_y) {
                return Err(PathError::TooThin {
                    tolerance: eps,
                    l_x: l.l_x,
                    l_y: l.l_y,
                });
            }
            let longest = longest_edge(vertices);
            let along = (vertices[(longest + 1) % vertices.len()] - vertices[longest]).normalize();
            planner.go((lo + hi) / 2.0, Some(along));
        }
    }
    planner.go(start, None);
    Ok(CoveragePath {
        waypoints: planner.waypoints,
        stripes: planner.stripes,
        areas: planner.areas,
    })
}

struct Planner<'a> {
    survey: &'a SurveyGeometry,
    direction: ScanDirection,
    eps: f64,
    waypoints: Vec<Waypoint>,
    stripes: usize,
    areas: usize,
    /// Photos and stripes still allowed ([`MAX_SHOTS`]).
    budget: usize,
}

impl Planner<'_> {
    /// Takes `count` from the budget, checked before the caller allocates or loops `count` times.
    fn spend(&mut self, count: usize) -> Result<(), PathError> {
        self.budget = self.budget.checked_sub(count).ok_or_else(|| {
            let l = self.survey.footprint;
            PathError::TooManyShots {
                limit: MAX_SHOTS,
                altitude_m: self.survey.altitude_m,
                l_x: l.l_x,
                l_y: l.l_y,
                d_x: self.survey.d_x,
                d_y: self.survey.d_y,
            }
        })?;
        Ok(())
    }

    /// Shot offsets along a stretch of `length`, paid for from the budget.
    fn shots_along(&mut self, length: f64) -> Result<Vec<f64>, PathError> {
        let l_y = self.survey.footprint.l_y;
        let count = shot_count(length, l_y, self.survey.d_y).unwrap_or(usize::MAX);
        self.spend(count)?;
        Ok(shot_offsets(length, l_y, count))
    }

    fn here(&self) -> DVec2 {
        self.waypoints.last().map_or(DVec2::ZERO, |w| w.position)
    }

    /// Appends a waypoint, merging it into the last one when they coincide.
    fn go(&mut self, position: DVec2, shot: Option<DVec2>) {
        if let Some(last) = self.waypoints.last_mut()
            && last.position.distance(position) <= self.eps
        {
            last.shot = last.shot.or(shot);
            last.position = position;
            return;
        }
        self.waypoints.push(Waypoint { position, shot });
    }

    /// Runs the whole procedure on the counter-clockwise simple polygon `area`, entered at (and
    /// left from) vertex `entry`. `parent_u` is the parent's stripe direction, kept beyond
    /// [`MAX_REORIENT_DEPTH`].
    fn cover(
        &mut self,
        area: Vec<DVec2>,
        entry: usize,
        depth: usize,
        parent_u: Option<DVec2>,
    ) -> Result<(), PathError> {
        if depth > MAX_AREA_DEPTH {
            return Err(PathError::TooDeep {
                limit: MAX_AREA_DEPTH,
            });
        }
        self.areas += 1;
        let l = self.survey.footprint;
        let (sweep, base) = self.sweep(&area, depth, parent_u);
        let (j, t) = sweep
            .base_trapezoid(base.level, base.u)
            .ok_or(PathError::NoBaseCell {
                vertices: area.len(),
            })?;
        let (cell, chords) = sweep.cell_from(j, t);
        let frame = sweep.frame;

        // An area that fits in one footprint takes one shot at its centre.
        let (lo, hi) = bounds(&sweep.points);
        if hi.x - lo.x <= l.l_y && hi.y - lo.y <= l.l_x {
            self.spend(1)?;
            self.go(frame.to_world((lo + hi) / 2.0), Some(frame.u));
            self.go(area[entry], None);
            return Ok(());
        }

        let count =
            stripe_count(cell.top() - cell.bottom(), l.l_x, self.survey.d_x).unwrap_or(usize::MAX);
        self.spend(count)?;
        let stripes = stripe_levels(&cell, l.l_x, count);
        self.stripes += stripes.len();
        let first = cell
            .extent(stripes[0] - l.l_x / 2.0, stripes[0] + l.l_x / 2.0)
            .unwrap_or((base.u, base.u));

        // Part 1: along the border to the corner the first stripe starts from.
        let route = self.approach(&area, entry, &base, first);
        self.border(&area, &route)?;
        let mut forward = route.forward;

        // Part 2: the stripes, with the parts cut off at concavities.
        let (below, above): (Vec<Chord>, Vec<Chord>) =
            chords.into_iter().partition(|c| !c.beyond_above);
        for (k, &level) in stripes.iter().enumerate() {
            let band = (level - l.l_x / 2.0, level + l.l_x / 2.0);
            if let Some((u0, u1)) = cell.extent(band.0, band.1) {
                let from = if forward { u0 } else { u1 };
                let along = if forward { frame.u } else { -frame.u };
                for s in self.shots_along(u1 - u0)? {
                    let u = if forward { from + s } else { from - s };
                    self.go(frame.to_world(DVec2::new(u, level)), Some(along));
                }
            }
            forward = !forward;
            if k == 0 {
                self.cut_offs(&sweep, &area, &below, depth, frame.u)?;
            }
        }
        self.cut_offs(&sweep, &area, &above, depth, frame.u)?;

        // Part 3: back along the border to the entry vertex.
        let from = nearest(&area, self.here());
        let route = shorter_route(&area, from, entry);
        self.border(&area, &route)?;
        self.go(area[entry], None);
        Ok(())
    }

    /// The sweep of `area` in the frame its stripes use, with the base the cell grows from.
    fn sweep(&self, area: &[DVec2], depth: usize, parent_u: Option<DVec2>) -> (Sweep, Base) {
        let longest = longest_edge(area);
        let n = area.len();
        let (a, b) = (area[longest], area[(longest + 1) % n]);
        let direction = match parent_u {
            Some(u) if depth >= MAX_REORIENT_DEPTH => Some(u),
            _ => match self.direction {
                ScanDirection::LongestEdge => None,
                ScanDirection::AcrossLongestEdge => Some((b - a).perp()),
            },
        };
        match direction {
            None => {
                // Frame on the longest edge: the interior lies above it (counter-clockwise).
                let frame = Frame::new(a, b - a);
                let sweep = Sweep::new(area, frame, &[longest, (longest + 1) % n], self.eps);
                let base = Base {
                    level: 0.0,
                    u: a.distance(b) / 2.0,
                    corners: [(longest, 0.0), ((longest + 1) % n, a.distance(b))],
                };
                (sweep, base)
            }
            Some(u) => {
                // Sweep from the lowest vertex.
                let frame = Frame::new(a, u);
                let sweep = Sweep::new(area, frame, &[], self.eps);
                let low = (0..n)
                    .min_by(|&i, &j| sweep.points[i].y.total_cmp(&sweep.points[j].y))
                    .unwrap_or(0);
                let p = sweep.points[low];
                let base = Base {
                    level: p.y,
                    u: p.x,
                    corners: [(low, p.x), (low, p.x)],
                };
                (sweep, base)
            }
        }
    }

    /// Part 1's route: to whichever end of the base the border reaches sooner from the entry;
    /// `forward` tells whether the first stripe then runs towards `+u`.
    fn approach(&self, area: &[DVec2], entry: usize, base: &Base, first: (f64, f64)) -> Route {
        let [(c0, u0), (c1, u1)] = base.corners;
        let r0 = shorter_route(area, entry, c0);
        let r1 = shorter_route(area, entry, c1);
        let (mut route, corner_u) = if r1.length < r0.length - self.eps {
            (r1, u1)
        } else {
            (r0, u0)
        };
        route.forward = corner_u - first.0 <= first.1 - corner_u;
        route
    }

    /// Shots along each border edge of `route` (parts 1 and 3).
    fn border(&mut self, area: &[DVec2], route: &Route) -> Result<(), PathError> {
        let n = area.len();
        let l = self.survey.footprint;
        for &(from, to) in &route.edges {
            let (a, b) = (area[from], area[to]);
            // The edge's interior normal, from its counter-clockwise direction.
            let (ccw_start, ccw_end) = if (from + 1) % n == to { (a, b) } else { (b, a) };
            let inward = (ccw_end - ccw_start).normalize().perp();
            let along = (b - a).normalize();
            let grow_a = corner_growth(area, from, to, l.l_x);
            let grow_b = corner_growth(area, to, from, l.l_x);
            let length = a.distance(b) + grow_a + grow_b;
            for s in self.shots_along(length)? {
                self.go(
                    a + along * (s - grow_a) + inward * (l.l_x / 2.0),
                    Some(along),
                );
            }
        }
        Ok(())
    }

    /// Covers each part cut off beyond `chords`, nearest first, entering each at its vertex
    /// nearest to the current position.
    fn cut_offs(
        &mut self,
        sweep: &Sweep,
        area: &[DVec2],
        chords: &[Chord],
        depth: usize,
        u: DVec2,
    ) -> Result<(), PathError> {
        let mut parts: Vec<Vec<DVec2>> = chords
            .iter()
            .filter_map(|c| sweep.cut_off(area, c))
            .collect();
        while !parts.is_empty() {
            let here = self.here();
            let (k, entry) = parts
                .iter()
                .enumerate()
                .map(|(k, p)| (k, nearest(p, here)))
                .min_by(|a, b| {
                    here.distance(parts[a.0][a.1])
                        .total_cmp(&here.distance(parts[b.0][b.1]))
                })
                .unwrap_or((0, 0));
            let part = parts.swap_remove(k);
            self.go(part[entry], None);
            self.cover(part, entry, depth + 1, Some(u))?;
        }
        Ok(())
    }
}

/// Where the cell grows from: a level, a `u` on it, and the two corners (vertex index, `u`) from
/// which the first stripe may start.
struct Base {
    level: f64,
    u: f64,
    corners: [(usize, f64); 2],
}

/// A walk along the border: edges as (from vertex, to vertex), its length, and the direction the
/// first stripe takes after it.
struct Route {
    edges: Vec<(usize, usize)>,
    length: f64,
    forward: bool,
}

/// The shorter way round the border from vertex `from` to vertex `to`.
fn shorter_route(area: &[DVec2], from: usize, to: usize) -> Route {
    let n = area.len();
    let walk = |step: usize| {
        let mut edges = Vec::new();
        let mut length = 0.0;
        let mut k = from;
        while k != to {
            let next = (k + step) % n;
            edges.push((k, next));
            length += area[k].distance(area[next]);
            k = next;
        }
        Route {
            edges,
            length,
            forward: true,
        }
    };
    let ccw = walk(1);
    let cw = walk(n - 1);
    if cw.length < ccw.length { cw } else { ccw }
}

/// How far the footprint band along the edge from `vertex` towards `other` reaches past
/// `vertex`: where the inner angle `gamma` there exceeds `pi/2` (and the corner is convex) the
/// next edge leans outwards and the band meets it `cot(pi - gamma) L_x` further on, or at the
/// next edge's far end if that comes first.
fn corner_growth(area: &[DVec2], vertex: usize, other: usize, l_x: f64) -> f64 {
    let n = area.len();
    let neighbour = if (vertex + 1) % n == other {
        (vertex + n - 1) % n
    } else {
        (vertex + 1) % n
    };
    let p = area[vertex];
    let (prev, next) = (area[(vertex + n - 1) % n], area[(vertex + 1) % n]);
    // Exterior turn at the vertex; pi - gamma for a convex corner.
    let turn = (p - prev).angle_to(next - p);
    if !(turn > 0.0 && turn < std::f64::consts::FRAC_PI_2) {
        return 0.0;
    }
    let adjacent = p.distance(area[neighbour]);
    (l_x / turn.tan()).min(adjacent * turn.cos())
}

fn nearest(points: &[DVec2], p: DVec2) -> usize {
    (0..points.len())
        .min_by(|&i, &j| points[i].distance(p).total_cmp(&points[j].distance(p)))
        .unwrap_or(0)
}

fn bounds(points: &[DVec2]) -> (DVec2, DVec2) {
    points
        .iter()
        .fold((DVec2::INFINITY, DVec2::NEG_INFINITY), |(lo, hi), &p| {
            (lo.min(p), hi.max(p))
        })
}

impl CoveragePath {
    /// Total length (m).
    pub fn length(&self) -> f64 {
        self.waypoints
            .windows(2)
            .map(|w| w[0].position.distance(w[1].position))
            .sum()
    }

    /// Shot positions with their along-track direction.
    pub fn shots(&self) -> impl Iterator<Item = (DVec2, DVec2)> + '_ {
        self.waypoints
            .iter()
            .filter_map(|w| w.shot.map(|along| (w.position, along)))
    }

    /// The straight runs of the path: consecutive segments in the same direction form one leg.
    pub fn legs(&self) -> Vec<Leg> {
        let mut legs: Vec<Leg> = Vec::new();
        let mut start = 0;
        for i in 1..self.waypoints.len() {
            let last = i + 1 == self.waypoints.len();
            let straight_on = !last && {
                let a = self.waypoints[i].position - self.waypoints[start].position;
                let b = self.waypoints[i + 1].position - self.waypoints[i].position;
                a.perp_dot(b).abs() <= 1e-9 * a.length() * b.length() && a.dot(b) > 0.0
            };
            if !straight_on {
                legs.push(self.leg(start, i));
                start = i;
            }
        }
        legs
    }

    fn leg(&self, from: usize, to: usize) -> Leg {
        let shots: Vec<DVec2> = self.waypoints[from..=to]
            .iter()
            .filter(|w| w.shot.is_some())
            .map(|w| w.position)
            .collect();
        let min_shot_spacing = shots
            .windows(2)
            .map(|w| w[0].distance(w[1]))
            .min_by(f64::total_cmp);
        Leg {
            start: self.waypoints[from].position,
            end: self.waypoints[to].position,
            waypoints: [from, to],
            shots: shots.len(),
            min_shot_spacing,
        }
    }

    /// Heading change at each junction of two legs (rad, in `(0, pi]`).
    pub fn turn_angles(&self) -> Vec<f64> {
        self.legs()
            .windows(2)
            .map(|w| {
                (w[0].end - w[0].start)
                    .angle_to(w[1].end - w[1].start)
                    .abs()
            })
            .collect()
    }
}
