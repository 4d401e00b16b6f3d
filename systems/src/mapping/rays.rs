//! A scan's rays as the map update takes them (common.md §1): checked, in voxel units, and
//! what every ray needs before any walks, computed for all of them in one pass each.

use super::dda::{ClippedSegment, SegmentClipper};
use super::full_bricks::FullBricks;
use glam::{DVec3, Vec3};
use std::cell::RefCell;
use uavex_components::map::MapConfig;
use uavex_components::sensor::Scan;

/// How far past a surface a hit point is moved along its ray (voxel units), so that a hit
/// exactly on a voxel face lands in the obstacle's voxel, not the free one in front of it.
pub const HIT_NUDGE: f64 = 1e-3;

/// The rays of one scan, in the world frame (see [`Scan`]).
#[derive(Debug, Clone, Copy)]
pub struct ScanRays<'a> {
    pub origin: Vec3,
    pub endpoints: &'a [Vec3],
    /// Whether ray `i` ended on a surface (else it was cut at max range).
    pub hit: &'a [bool],
}

impl<'a> ScanRays<'a> {
    pub fn of(scan: &'a Scan) -> Self {
        Self {
            origin: scan.origin,
            endpoints: &scan.endpoints,
            hit: &scan.hit,
        }
    }

    /// Refuses rays the map update cannot take (before anything is written).
    pub fn validate(&self) -> Result<(), ScanError> {
        if self.endpoints.len() != self.hit.len() {
            return Err(ScanError::LengthMismatch {
                endpoints: self.endpoints.len(),
                hits: self.hit.len(),
            });
        }
        if !self.origin.is_finite() {
            return Err(ScanError::NonFiniteOrigin(self.origin));
        }
        match self.endpoints.iter().position(|p| !p.is_finite()) {
            Some(index) => Err(ScanError::NonFiniteEndpoint {
                index,
                point: self.endpoints[index],
            }),
            None => Ok(()),
        }
    }
}

/// A scan that cannot be integrated (refused before anything is written).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ScanError {
    #[error("scan has {endpoints} endpoints but {hits} hit flags")]
    LengthMismatch { endpoints: usize, hits: usize },
    #[error("scan origin is not finite: {0}")]
    NonFiniteOrigin(Vec3),
    #[error("scan endpoint {index} is not finite: {point}")]
    NonFiniteEndpoint { index: usize, point: Vec3 },
}

/// A scan's rays in voxel units, ray by ray (in the scan's order) what the walks need.
pub(super) struct PreparedRays<'a> {
    /// The sensor's position.
    pub origin: DVec3,
    /// The end points (hits nudged, see [`end_point`]).
    pub ends: &'a [DVec3],
    /// `1 / (end - origin)` per axis, for [`super::dda::VoxelWalk::with_inverse`].
    pub inverses: &'a [DVec3],
    /// Each ray clipped to the map's key box (`None` when it misses the map).
    pub clips: &'a [Option<ClippedSegment>],
    /// Room for the scan's full bricks (`super::free_box`), kept from scan to scan.
    pub bricks: &'a mut FullBricks,
}

/// Calls `f` with the rays of `rays` (valid: [`ScanRays::validate`]) prepared for `config`'s
/// map. Each quantity is computed for all rays in a pass of its own, where the divisions and
/// square roots of successive rays overlap; computed one ray at a time between two walks,
/// right after the last walk's mispredicted exits, their latency showed ray after ray (the
/// inverses in a pass took 3 % off the map update, the clips 1-2 % more).
pub(super) fn prepare<R>(
    config: &MapConfig,
    rays: &ScanRays<'_>,
    f: impl FnOnce(PreparedRays<'_>) -> R,
) -> R {
    let origin = config.to_voxel_units(rays.origin);
    RAYS.with_borrow_mut(|scratch| {
        let RayScratch {
            ends,
            inverses,
            clips,
            bricks,
        } = scratch;
        ends.clear();
        ends.extend(
            rays.endpoints
                .iter()
                .zip(rays.hit)
                .map(|(&p, &hit)| end_point(origin, config.to_voxel_units(p), hit)),
        );
        inverses.clear();
        inverses.extend(ends.iter().map(|&end| DVec3::ONE / (end - origin)));
        let clipper = SegmentClipper::new(origin, config.key_min(), config.key_max());
        clips.clear();
        clips.extend(ends.iter().map(|&end| clipper.clip(end)));
        f(PreparedRays {
            origin,
            ends,
            inverses,
            clips,
            bricks,
        })
    })
}

/// The buffers of [`prepare`], kept on each thread from one scan to the next so that
/// integrating a scan allocates nothing.
#[derive(Default)]
struct RayScratch {
    ends: Vec<DVec3>,
    inverses: Vec<DVec3>,
    clips: Vec<Option<ClippedSegment>>,
    bricks: FullBricks,
}

thread_local! {
    static RAYS: RefCell<RayScratch> = RefCell::new(RayScratch::default());
}

/// Where a ray's end voxel is looked up: a hit point is nudged [`HIT_NUDGE`] along the ray.
#[inline]
fn end_point(origin: DVec3, end: DVec3, hit: bool) -> DVec3 {
    let d = end - origin;
    let length = d.length();
    if hit && length > 0.0 {
        end + d * (HIT_NUDGE / length)
    } else {
        end
    }
}
