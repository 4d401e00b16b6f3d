//! Point clouds for world geometry, read from PCD or PLY files by extension.
//!
//! Non-finite points: organised clouds (depth images turned into PCD, PLY from scanners) mark
//! pixels without a return by NaN coordinates, and PCL's own filters
//! (`removeNaNFromPointCloud`) drop them. A point with any NaN or infinite coordinate (or one too
//! large for `f32`) therefore stands for "no measurement": it is skipped, never an error, and
//! counted in [`PointCloud::skipped_non_finite`] so that callers can report it. A file that
//! yields no finite point at all is an error, like an empty mesh.

use std::path::Path;

use glam::Vec3;

use super::{Fault, FormatError, Problem, load_by_extension, pcd, ply};

/// The finite points of a cloud file and how many non-finite ones were skipped.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PointCloud {
    /// Points in file order, all finite.
    pub points: Vec<Vec3>,
    /// Points dropped because a coordinate was NaN or not representable as a finite `f32`.
    pub skipped_non_finite: usize,
}

/// Extensions [`load_cloud`] accepts.
pub const CLOUD_EXTENSIONS: &str = ".pcd, .ply";

/// Loads the finite points of a `.pcd` (ascii, binary, binary_compressed) or `.ply` (ascii,
/// binary little or big endian, `vertex` element with `x y z`) file, chosen by extension
/// (case-insensitive). Non-finite points are skipped (see the module documentation); use
/// [`load_cloud_counted`] to know how many.
pub fn load_cloud(path: &Path) -> Result<Vec<Vec3>, FormatError> {
    load_cloud_counted(path).map(|cloud| cloud.points)
}

/// [`load_cloud`], also telling how many non-finite points were skipped.
pub fn load_cloud_counted(path: &Path) -> Result<PointCloud, FormatError> {
    load_by_extension(
        path,
        &[("pcd", pcd::parse_pcd), ("ply", ply::parse_ply_points)],
        CLOUD_EXTENSIONS,
    )
}

/// Collects points as a reader decodes them, skipping and counting non-finite ones.
#[derive(Debug, Default)]
pub(crate) struct CloudBuilder {
    cloud: PointCloud,
}

impl CloudBuilder {
    /// Reserves for `expected` points, capped so that a corrupt count cannot reserve gigabytes.
    pub fn with_capacity(expected: usize) -> Self {
        let mut builder = Self::default();
        builder.cloud.points.reserve(expected.min(1 << 20));
        builder
    }

    pub fn push(&mut self, x: f64, y: f64, z: f64) {
        let p = Vec3::new(x as f32, y as f32, z as f32);
        if p.is_finite() {
            self.cloud.points.push(p);
        } else {
            self.cloud.skipped_non_finite += 1;
        }
    }

    /// The cloud, or [`Problem::EmptyCloud`] when it has no finite point.
    pub fn finish(self) -> Result<PointCloud, Fault> {
        if self.cloud.points.is_empty() {
            return Err(Fault::problem(Problem::EmptyCloud {
                skipped_non_finite: self.cloud.skipped_non_finite,
            }));
        }
        Ok(self.cloud)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn data(name: &str) -> std::path::PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tests/data")
            .join(name)
    }

    /// The five points every cloud fixture holds, in order (see tests/data/make_fixtures.py).
    fn fixture_points() -> Vec<Vec3> {
        vec![
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.0, 2.0, 0.0),
            Vec3::new(0.0, 0.0, -3.5),
            Vec3::new(0.25, -0.5, 1.5),
        ]
    }

    #[test]
    fn every_cloud_fixture_loads_the_same_points() {
        for name in [
            "points_ascii.pcd",
            "points_binary.pcd",
            "points_binary_compressed.pcd",
            "points_ascii.ply",
            "points_binary_le.ply",
            "points_binary_be.ply",
        ] {
            let cloud = load_cloud_counted(&data(name)).unwrap_or_else(|e| panic!("{e}"));
            assert_eq!(cloud.points, fixture_points(), "{name}");
        }
    }

    /// The organised fixtures are 3x2 images whose 2nd pixel is NaN in all three coordinates.
    #[test]
    fn organised_fixtures_skip_and_count_their_nan_point() {
        for name in ["organised_nan_ascii.pcd", "organised_nan_binary.pcd"] {
            let cloud = load_cloud_counted(&data(name)).unwrap_or_else(|e| panic!("{e}"));
            assert_eq!(cloud.points, fixture_points(), "{name}");
            assert_eq!(cloud.skipped_non_finite, 1, "{name}");
        }
    }

    #[test]
    fn unknown_extension_is_refused() {
        let e = load_cloud(Path::new("scan.las")).unwrap_err();
        assert!(matches!(e.problem, Problem::UnsupportedExtension { .. }));
    }

    #[test]
    fn builder_skips_non_finite_and_refuses_an_empty_cloud() {
        let mut b = CloudBuilder::with_capacity(usize::MAX);
        b.push(1.0, 2.0, 3.0);
        b.push(f64::NAN, 0.0, 0.0);
        b.push(0.0, f64::INFINITY, 0.0);
        b.push(0.0, 0.0, 1e300); // finite in f64, infinite in f32
        let cloud = b.finish().unwrap();
        assert_eq!(cloud.points, vec![Vec3::new(1.0, 2.0, 3.0)]);
        assert_eq!(cloud.skipped_non_finite, 3);

        let mut b = CloudBuilder::default();
        b.push(f64::NAN, f64::NAN, f64::NAN);
        let fault = b.finish().unwrap_err();
        assert!(matches!(
            fault.problem,
            Problem::EmptyCloud {
                skipped_non_finite: 1
            }
        ));
    }
}
