//! Ray patterns: the unit directions a sensor casts, in its own frame (x forward, y left, z up).
//!
//! A depth camera casts rays through the cell centres of a grid laid over its image plane; the
//! camera's own resolution gives one ray per pixel, the `auto` grid the coarsest grid that still
//! sees every voxel of the map (common.md §2). A lidar casts beams at even angular steps.

use super::frustum::{Frustum, RayTile};
use bevy_ecs::prelude::*;
use glam::{DVec3, Vec3};
use std::f64::consts::{PI, TAU};

/// Patterns larger than this are refused: 50 million rays per sweep is beyond any real sensor
/// (and would take seconds per sweep), so it is a configuration mistake, e.g. a tiny resolution.
pub const MAX_RAYS: u64 = 50_000_000;

/// The rays of one sensor, cast on every sweep.
#[derive(Component, Debug, Clone, PartialEq)]
pub struct RayPattern {
    /// Unit directions in the sensor frame, row-major: `directions[row * columns + column]`;
    /// row 0 is the top, column 0 the left of a camera image (the rightmost beam of a lidar).
    pub directions: Vec<Vec3>,
    pub columns: u32,
    pub rows: u32,
    /// Surfaces closer than this give no depth (the ray is dropped).
    pub range_min: f32,
    /// Rays are cut here; beyond it nothing is seen.
    pub range_max: f32,
    /// The pyramid the directions lie in, when they all look forward (a camera's): obstacles
    /// outside it are not tried ([`Frustum`]).
    pub frustum: Option<Frustum>,
    /// The rays in tiles, each with its own pyramid ([`RayTile`]); empty when there is no
    /// frustum.
    pub tiles: Vec<RayTile>,
}

/// A pinhole depth camera (common.md §2): looks along +x, square pixels, so the vertical field
/// of view follows from the aspect ratio.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PinholeCamera {
    pub width: u32,
    pub height: u32,
    /// Horizontal field of view (rad), in (0, pi).
    pub hfov: f64,
}

impl PinholeCamera {
    /// Half extents of the image plane at unit distance: (tan(hfov / 2), tan(hfov / 2) * h / w).
    pub fn half_extents(&self) -> (f64, f64) {
        let a = (0.5 * self.hfov).tan();
        (a, a * f64::from(self.height) / f64::from(self.width))
    }

    /// Vertical field of view: 2 atan(tan(hfov / 2) * height / width).
    pub fn vfov(&self) -> f64 {
        2.0 * self.half_extents().1.atan()
    }

    /// Focal length in pixels: (width / 2) / tan(hfov / 2).
    pub fn focal_px(&self) -> f64 {
        0.5 * f64::from(self.width) / self.half_extents().0
    }
}

/// Which rays a camera casts.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum RayGrid {
    /// The coarsest grid whose angular step between neighbouring rays is at most
    /// `resolution / range_max` everywhere (see [`auto_grid`]).
    Auto { resolution: f64 },
    /// `columns x rows` rays through the cell centres of a grid over the image; the camera's
    /// own `width x height` gives exactly one ray per pixel.
    Explicit { columns: u32, rows: u32 },
}

/// A lidar: `beams_h` over `hfov` centred on +x, `beams_v` over `vfov` centred on the horizontal
/// plane; planar when `beams_v == 1`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LidarBeams {
    pub hfov: f64,
    pub beams_h: u32,
    pub vfov: f64,
    pub beams_v: u32,
}

/// A pattern that cannot be built; the message names the offending parameter.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{field}: {message}")]
pub struct PatternError {
    pub field: &'static str,
    pub message: String,
}

fn refuse(field: &'static str, message: impl Into<String>) -> PatternError {
    PatternError {
        field,
        message: message.into(),
    }
}

fn check_ranges(range_min: f64, range_max: f64) -> Result<(), PatternError> {
    if !(range_min.is_finite() && range_min >= 0.0) {
        return Err(refuse(
            "range_min",
            format!("must be finite and >= 0, got {range_min}"),
        ));
    }
    if !(range_max.is_finite() && range_max > range_min) {
        return Err(refuse(
            "range_max",
            format!("must be finite and above range_min ({range_min}), got {range_max}"),
        ));
    }
    Ok(())
}

fn check_count(columns: u32, rows: u32) -> Result<(), PatternError> {
    let count = u64::from(columns) * u64::from(rows);
    if count == 0 || count > MAX_RAYS {
        return Err(refuse(
            "ray_grid",
            format!("{columns} x {rows} rays: must be between 1 and {MAX_RAYS}"),
        ));
    }
    Ok(())
}

/// The rays of a depth camera.
pub fn camera_pattern(
    camera: PinholeCamera,
    grid: RayGrid,
    range_min: f64,
    range_max: f64,
) -> Result<RayPattern, PatternError> {
    if camera.width == 0 || camera.height == 0 {
        return Err(refuse(
            "width",
            format!(
                "image size must be positive, got {} x {}",
                camera.width, camera.height
            ),
        ));
    }
    if !(camera.hfov > 0.0 && camera.hfov < PI) {
        return Err(refuse(
            "hfov",
            format!(
                "must lie in (0, pi) for a pinhole camera, got {}",
                camera.hfov
            ),
        ));
    }
    check_ranges(range_min, range_max)?;
    let (columns, rows) = match grid {
        RayGrid::Explicit { columns, rows } => (columns, rows),
        RayGrid::Auto { resolution } => auto_grid(camera, resolution, range_max)?,
    };
    check_count(columns, rows)?;
    let (a, b) = camera.half_extents();
    let (du, dv) = (2.0 * a / f64::from(columns), 2.0 * b / f64::from(rows));
    let mut directions = Vec::with_capacity(columns as usize * rows as usize);
    for row in 0..rows {
        // Row 0 is the top of the image (+z), column 0 its left (+y).
        let z = b - (f64::from(row) + 0.5) * dv;
        for column in 0..columns {
            let y = a - (f64::from(column) + 0.5) * du;
            directions.push(DVec3::new(1.0, y, z).normalize().as_vec3());
        }
    }
    Ok(RayPattern {
        frustum: Frustum::enclosing(&directions),
        tiles: RayTile::tile(&directions, columns as usize, rows as usize),
        directions,
        columns,
        rows,
        range_min: range_min as f32,
        range_max: range_max as f32,
    })
}

/// The `auto` grid (common.md §2): the fewest columns and rows such that the angle between any
/// two neighbouring rays is at most `resolution / range_max`, so that at the far end of the range
/// neighbouring rays land at most one voxel apart and the map sees the voxels one ray per pixel
/// would, at a fraction of the rays (55 x 41 = 2,255 for the EAAE camera at 0.1 m and 5 m, against
/// 307,200 pixels).
///
/// Rays are evenly spaced on the image plane, so the angle between neighbours is largest where
/// the plane is nearest, at the centre: for spacing `s` (at unit distance) the two central rays of
/// an even count lie at +-s/2, 2 atan(s/2) apart; for an odd count at 0 and s, atan(s) apart. The
/// count along each axis is the smallest whose central angle meets the bound; off the centre the
/// angles only shrink (a pinhole grid is denser in angle towards its edges).
pub fn auto_grid(
    camera: PinholeCamera,
    resolution: f64,
    range_max: f64,
) -> Result<(u32, u32), PatternError> {
    if !(resolution.is_finite() && resolution > 0.0) {
        return Err(refuse(
            "resolution",
            format!("must be finite and positive, got {resolution}"),
        ));
    }
    if !(range_max.is_finite() && range_max > 0.0) {
        return Err(refuse(
            "range_max",
            format!("must be finite and positive, got {range_max}"),
        ));
    }
    let step = resolution / range_max;
    let (a, b) = camera.half_extents();
    let columns = fewest_rays(2.0 * a, step);
    let rows = fewest_rays(2.0 * b, step);
    match (columns, rows) {
        (Some(c), Some(r)) if u64::from(c) * u64::from(r) <= MAX_RAYS => Ok((c, r)),
        _ => Err(refuse(
            "ray_grid",
            format!(
                "the auto grid for resolution {resolution} m at range {range_max} m needs more \
                 than {MAX_RAYS} rays; use a coarser resolution or an explicit grid"
            ),
        )),
    }
}

/// Largest angle between neighbouring rays of `n` rays evenly spaced across `width` of the unit
/// image plane (at the centre, see [`auto_grid`]). A single ray has no neighbour; it counts as
/// the whole field of view, as if its neighbours sat on both edges.
pub fn central_step(width: f64, n: u32) -> f64 {
    let s = width / f64::from(n);
    match n {
        0 | 1 => 2.0 * (0.5 * width).atan(),
        n if n % 2 == 0 => 2.0 * (0.5 * s).atan(),
        _ => s.atan(),
    }
}

/// Smallest `n` with `central_step(width, n) <= step`, or `None` beyond [`MAX_RAYS`].
fn fewest_rays(width: f64, step: f64) -> Option<u32> {
    if central_step(width, 1) <= step {
        return Some(1);
    }
    // Here step < the field of view < pi. Even counts need s <= 2 tan(step / 2); odd ones
    // s <= tan(step), a hair more (any odd count meets it once step >= pi / 2).
    let round_up_to = |x: f64, odd: bool| {
        let n = x.ceil().max(1.0);
        if (n % 2.0 == 1.0) == odd { n } else { n + 1.0 }
    };
    let even = round_up_to(width / (2.0 * (0.5 * step).tan()), false);
    let odd = if step < 0.5 * PI {
        round_up_to(width / step.tan(), true).max(3.0)
    } else {
        3.0
    };
    let mut n = even.min(odd);
    // Guard against rounding at the boundary: the answer must meet the bound exactly as
    // `central_step` computes it.
    while n <= MAX_RAYS as f64 && central_step(width, n as u32) > step {
        n += 1.0;
    }
    (n <= MAX_RAYS as f64).then_some(n as u32)
}

/// The beams of a lidar. Horizontal: a full circle (`hfov` >= 2 pi) has `beams_h` beams
/// `2 pi / beams_h` apart starting at -pi; a sector has its first and last beams on its edges,
/// `-hfov / 2` (right) and `+hfov / 2` (left), as a ROS `LaserScan` from angle_min to angle_max.
/// Vertical: beams on both edges of `vfov`, top row first.
pub fn lidar_pattern(
    lidar: LidarBeams,
    range_min: f64,
    range_max: f64,
) -> Result<RayPattern, PatternError> {
    if !(lidar.hfov > 0.0 && lidar.hfov <= TAU + 1e-9) {
        return Err(refuse(
            "hfov",
            format!("must lie in (0, 2 pi], got {}", lidar.hfov),
        ));
    }
    if !(lidar.vfov >= 0.0 && lidar.vfov < PI) {
        return Err(refuse(
            "vfov",
            format!("must lie in [0, pi), got {}", lidar.vfov),
        ));
    }
    if lidar.beams_v > 1 && lidar.vfov <= 0.0 {
        return Err(refuse(
            "vfov",
            format!("must be positive with {} vertical beams", lidar.beams_v),
        ));
    }
    check_ranges(range_min, range_max)?;
    check_count(lidar.beams_h, lidar.beams_v)?;
    let full_circle = lidar.hfov >= TAU - 1e-9;
    let azimuth = |i: u32| -> f64 {
        let i = f64::from(i);
        if full_circle {
            -PI + i * TAU / f64::from(lidar.beams_h)
        } else if lidar.beams_h == 1 {
            0.0
        } else {
            -0.5 * lidar.hfov + i * lidar.hfov / f64::from(lidar.beams_h - 1)
        }
    };
    let elevation = |j: u32| -> f64 {
        if lidar.beams_v == 1 {
            0.0
        } else {
            0.5 * lidar.vfov - f64::from(j) * lidar.vfov / f64::from(lidar.beams_v - 1)
        }
    };
    let mut directions = Vec::with_capacity(lidar.beams_h as usize * lidar.beams_v as usize);
    for j in 0..lidar.beams_v {
        let (sin_el, cos_el) = elevation(j).sin_cos();
        for i in 0..lidar.beams_h {
            let (sin_az, cos_az) = azimuth(i).sin_cos();
            directions.push(DVec3::new(cos_el * cos_az, cos_el * sin_az, sin_el).as_vec3());
        }
    }
    Ok(RayPattern {
        frustum: Frustum::enclosing(&directions),
        tiles: RayTile::tile(&directions, lidar.beams_h as usize, lidar.beams_v as usize),
        directions,
        columns: lidar.beams_h,
        rows: lidar.beams_v,
        range_min: range_min as f32,
        range_max: range_max as f32,
    })
}
