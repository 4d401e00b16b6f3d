//! The map's geometry and sensor-model constants (common.md §1) and the key arithmetic shared by
//! every reader and writer of the map.

use super::chunk::{CHUNK_EDGE, ChunkCoord, local_index};
use super::grid::ChunkGrid;
use super::stats::StatTables;
use crate::sensor::SensorQuality;
use bevy_ecs::prelude::*;
use glam::{DVec3, IVec3, Vec3};

/// Largest map, in voxels of the bounding box (2^36, e.g. 1 km x 1 km x 68 m at 0.1 m; memory
/// for the touched chunks runs out long before). It keeps the fixed-point statistics far from
/// overflow (see [`super::STAT_ONE`]) and the chunk index small.
pub const MAX_BOX_VOXELS: u64 = 1 << 36;
/// Largest chunk grid (entries of the dense [`super::ChunkIndex`]: 128 MiB at 8 bytes each).
const MAX_CHUNKS: u64 = 1 << 24;
/// Largest |key| on any axis, so that key arithmetic (key + 1, chunk * 16) never overflows i32.
const MAX_KEY: f64 = (1 << 30) as f64;
/// Largest |log-odds| of a clamping bound or increment (milli units fit i16 with room to add).
const MAX_LOG_ODDS: f64 = 30.0;

/// Why a map cannot be built, or a sensor's quality cannot update it.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MapConfigError {
    #[error("map resolution must be a finite length > 0 m, got {0}")]
    InvalidResolution(f64),
    #[error("map bounds must be finite with min < max on every axis, got min {min:?} max {max:?}")]
    InvalidBounds { min: [f64; 3], max: [f64; 3] },
    #[error(
        "clamping probabilities must satisfy 0 < p_min < 0.5 < p_max < 1 \
         (|logit| <= 30), got p_min {p_min} p_max {p_max}"
    )]
    InvalidClamping { p_min: f64, p_max: f64 },
    #[error(
        "map too large: {voxels} voxels in {chunks} chunks (limits {MAX_BOX_VOXELS} voxels, \
         {MAX_CHUNKS} chunks); use a coarser resolution or smaller bounds"
    )]
    TooLarge { voxels: f64, chunks: f64 },
    #[error("sensor {which} log-odds must be finite, {sign}, and at most 30 in size, got {value}")]
    InvalidSensorQuality {
        which: &'static str,
        sign: &'static str,
        value: f32,
    },
}

/// What a map is built from (the scenario's `[map]` table and world bounds). Defaults are
/// OctoMap's (common.md §1) over a 20 m cube.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MapSettings {
    /// Voxel edge length (m).
    pub resolution: f64,
    pub bounds_min: DVec3,
    pub bounds_max: DVec3,
    /// Clamping probabilities (map-wide): log-odds stay within [logit(p_min), logit(p_max)].
    pub p_min: f64,
    pub p_max: f64,
}

impl Default for MapSettings {
    fn default() -> Self {
        Self {
            resolution: 0.1,
            bounds_min: DVec3::ZERO,
            bounds_max: DVec3::splat(20.0),
            p_min: 0.12,
            p_max: 0.97,
        }
    }
}

/// Per-sensor log-odds increments in milli units (common.md §1: l += 0.847 on a hit, -0.405 on
/// a miss by default), converted once per scan from [`SensorQuality`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LogOddsIncrements {
    pub hit: i16,
    pub miss: i16,
}

/// The map's geometry and constants. Voxel keys are `floor(p / resolution)` in world
/// coordinates (they may be negative); the map holds the keys `key_min..=key_max`, which cover
/// the scenario's bounding box, and nothing outside (common.md §1).
#[derive(Resource, Debug, Clone, PartialEq)]
pub struct MapConfig {
    resolution: f64,
    key_min: IVec3,
    key_max: IVec3,
    clamp_min: i16,
    clamp_max: i16,
    grid: ChunkGrid,
    tables: StatTables,
}

impl MapConfig {
    pub fn new(settings: &MapSettings) -> Result<Self, MapConfigError> {
        let res = settings.resolution;
        if !(res.is_finite() && res > 0.0) {
            return Err(MapConfigError::InvalidResolution(res));
        }
        let (lo, hi) = (settings.bounds_min, settings.bounds_max);
        let bad_bounds = MapConfigError::InvalidBounds {
            min: lo.to_array(),
            max: hi.to_array(),
        };
        if !(lo.is_finite() && hi.is_finite() && lo.cmplt(hi).all()) {
            return Err(bad_bounds);
        }
        let (qlo, qhi) = (lo / res, hi / res);
        if qlo.abs().max_element() > MAX_KEY || qhi.abs().max_element() > MAX_KEY {
            return Err(too_large(qlo, qhi));
        }
        let key_min = snapped(qlo, f64::floor).as_ivec3();
        let key_max = snapped(qhi, f64::ceil).as_ivec3() - IVec3::ONE;
        let extent = (key_max - key_min + IVec3::ONE).max(IVec3::ONE).as_dvec3();
        let chunk_min = ChunkCoord::of_key(key_min).0;
        let chunk_dims = ChunkCoord::of_key(key_max).0 - chunk_min + IVec3::ONE;
        let voxels = extent.x * extent.y * extent.z;
        let chunks = chunk_dims.as_dvec3().element_product();
        if voxels > MAX_BOX_VOXELS as f64 || chunks > MAX_CHUNKS as f64 {
            return Err(MapConfigError::TooLarge { voxels, chunks });
        }

        let (p_min, p_max) = (settings.p_min, settings.p_max);
        let (l_min, l_max) = (logit(p_min), logit(p_max));
        let ok = 0.0 < p_min
            && p_min < 0.5
            && 0.5 < p_max
            && p_max < 1.0
            && l_min >= -MAX_LOG_ODDS
            && l_max <= MAX_LOG_ODDS;
        if !ok {
            return Err(MapConfigError::InvalidClamping { p_min, p_max });
        }
        // Both bounds round to non-zero milli values with the right sign, since |logit| of
        // p in (0, 0.5) grows from 0: a bound rounding to 0 would make "clamped free" occupied.
        let clamp_min = (log_odds_to_milli(l_min) as i16).min(-1);
        let clamp_max = (log_odds_to_milli(l_max) as i16).max(1);
        Ok(Self {
            resolution: res,
            key_min,
            key_max,
            clamp_min,
            clamp_max,
            grid: ChunkGrid {
                min: chunk_min,
                dims: chunk_dims,
            },
            tables: StatTables::new(clamp_min, clamp_max),
        })
    }

    /// Voxel edge length (m).
    pub fn resolution(&self) -> f64 {
        self.resolution
    }

    /// Smallest voxel key of the map (inclusive).
    pub fn key_min(&self) -> IVec3 {
        self.key_min
    }

    /// Largest voxel key of the map (inclusive).
    pub fn key_max(&self) -> IVec3 {
        self.key_max
    }

    /// Lower clamping bound of the log-odds, milli units (logit(p_min)).
    pub fn clamp_min(&self) -> i16 {
        self.clamp_min
    }

    /// Upper clamping bound of the log-odds, milli units (logit(p_max)).
    pub fn clamp_max(&self) -> i16 {
        self.clamp_max
    }

    pub fn chunk_grid(&self) -> ChunkGrid {
        self.grid
    }

    /// Entropy and uncertainty per quantised log-odds (see [`StatTables`]).
    pub fn tables(&self) -> &StatTables {
        &self.tables
    }

    /// Number of voxels in the map's box (the denominator of the exploration rate, common.md §5).
    pub fn box_voxels(&self) -> u64 {
        let e = (self.key_max - self.key_min + IVec3::ONE).as_u64vec3();
        e.x * e.y * e.z
    }

    /// A world point in voxel units (`p / resolution`): the space the ray traversal works in.
    /// Every key computation goes through here so that all agree on boundary points.
    #[inline]
    pub fn to_voxel_units(&self, point: Vec3) -> DVec3 {
        point.as_dvec3() / self.resolution
    }

    /// Key of the voxel holding `point` (may lie outside the map; saturates for huge points).
    #[inline]
    pub fn raw_key_of(&self, point: Vec3) -> IVec3 {
        floor_to_key(self.to_voxel_units(point))
    }

    /// Key of the voxel holding `point`, or `None` outside the map.
    pub fn key_of(&self, point: Vec3) -> Option<IVec3> {
        let key = self.raw_key_of(point);
        self.contains_key(key).then_some(key)
    }

    #[inline]
    pub fn contains_key(&self, key: IVec3) -> bool {
        key.cmpge(self.key_min).all() && key.cmple(self.key_max).all()
    }

    /// World position of the centre of voxel `key`.
    pub fn center_of(&self, key: IVec3) -> Vec3 {
        ((key.as_dvec3() + 0.5) * self.resolution).as_vec3()
    }

    /// Chunk holding voxel `key`.
    #[inline]
    pub fn chunk_of(&self, key: IVec3) -> ChunkCoord {
        ChunkCoord::of_key(key)
    }

    /// Flat chunk index and local voxel index of `key`, or `None` outside the map.
    pub fn address_of(&self, key: IVec3) -> Option<(usize, usize)> {
        if !self.contains_key(key) {
            return None;
        }
        Some((
            self.grid.flat_unchecked(ChunkCoord::of_key(key)),
            local_index(key),
        ))
    }

    /// Number of map voxels (inside the box) in the box of keys `lo..=hi`, clipped to the map.
    pub fn voxels_in_key_box(&self, lo: IVec3, hi: IVec3) -> u64 {
        let (lo, hi) = (lo.max(self.key_min), hi.min(self.key_max));
        if lo.cmpgt(hi).any() {
            return 0;
        }
        let e = (hi - lo + IVec3::ONE).as_u64vec3();
        e.x * e.y * e.z
    }

    /// A sensor's log-odds increments in milli units; refuses non-finite values, a hit that does
    /// not raise the log-odds or a miss that does not lower them.
    pub fn increments(&self, quality: &SensorQuality) -> Result<LogOddsIncrements, MapConfigError> {
        let check = |which, value: f32, sign: &'static str, positive: bool| {
            let milli = log_odds_to_milli(f64::from(value));
            let ok = value.is_finite()
                && f64::from(value).abs() <= MAX_LOG_ODDS
                && if positive { milli >= 1 } else { milli <= -1 };
            if ok {
                Ok(milli as i16)
            } else {
                Err(MapConfigError::InvalidSensorQuality { which, sign, value })
            }
        };
        Ok(LogOddsIncrements {
            hit: check("hit", quality.log_odds_hit, "> 0", true)?,
            miss: check("miss", quality.log_odds_miss, "< 0", false)?,
        })
    }
}

/// `floor(q)` as a key, saturating at the i32 range (NaN gives 0), exactly as
/// `q.floor().as_ivec3()`. Written as truncation plus a correction because `f64::floor` is a
/// library call on the baseline x86-64 target (no SSE4.1), and keys are computed per ray.
#[inline]
pub fn floor_to_key(q: DVec3) -> IVec3 {
    let floor = |x: f64| {
        let t = x as i32;
        t.saturating_sub(i32::from(f64::from(t) > x))
    };
    IVec3::new(floor(q.x), floor(q.y), floor(q.z))
}

/// Milli-log-odds of a log-odds value, rounded to nearest (saturating for huge values).
pub fn log_odds_to_milli(log_odds: f64) -> i32 {
    (log_odds * 1000.0).round() as i32
}

/// Log-odds of a stored milli value (for exports and metrics; unknown is not a log-odds).
pub fn milli_to_log_odds(milli: i16) -> f32 {
    f32::from(milli) / 1000.0
}

fn logit(p: f64) -> f64 {
    (p / (1.0 - p)).ln()
}

/// `round(q)` where `q` is within 1e-6 voxel of an integer (a bound of 2.0 m at 0.1 m is 200
/// voxels, not 199.99999999999997), else `rounding(q)`.
fn snapped(q: DVec3, rounding: fn(f64) -> f64) -> DVec3 {
    q.map(|x| {
        let r = x.round();
        if (x - r).abs() < 1e-6 { r } else { rounding(x) }
    })
}

fn too_large(qlo: DVec3, qhi: DVec3) -> MapConfigError {
    let e = (qhi - qlo).abs();
    MapConfigError::TooLarge {
        voxels: e.element_product(),
        chunks: (e / f64::from(CHUNK_EDGE)).element_product(),
    }
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;

    /// The map of the cube `min..max` (m, on every axis) at resolution `res` (m).
    pub(in crate::map) fn config(min: f64, max: f64, res: f64) -> MapConfig {
        MapConfig::new(&MapSettings {
            resolution: res,
            bounds_min: DVec3::splat(min),
            bounds_max: DVec3::splat(max),
            ..MapSettings::default()
        })
        .unwrap()
    }

    #[test]
    fn key_box_covers_the_bounds_exactly() {
        // 0..20 m at 0.1 m: keys 0..=199, 200^3 voxels.
        let c = config(0.0, 20.0, 0.1);
        assert_eq!((c.key_min(), c.key_max()), (IVec3::ZERO, IVec3::splat(199)));
        assert_eq!(c.box_voxels(), 8_000_000);
        // -1.05..0.3 m: floor(-10.5) = -11 .. ceil(3) - 1 = 2 (0.3 / 0.1 is 2.9999999999999996
        // in f64, snapped to 3).
        let c = config(-1.05, 0.3, 0.1);
        assert_eq!(
            (c.key_min(), c.key_max()),
            (IVec3::splat(-11), IVec3::splat(2))
        );
        assert_eq!(c.box_voxels(), 14u64.pow(3));
        // Chunks: keys -11..=2 lie in chunks -1..=0.
        assert_eq!(c.chunk_grid().min, IVec3::splat(-1));
        assert_eq!(c.chunk_grid().dims, IVec3::splat(2));
    }

    #[test]
    fn keys_and_centres() {
        let c = config(-2.0, 2.0, 0.1);
        assert_eq!(
            c.key_of(Vec3::new(-0.05, 0.0, 0.15)),
            Some(IVec3::new(-1, 0, 1))
        );
        assert_eq!(c.key_of(Vec3::new(-2.01, 0.0, 0.0)), None);
        assert_eq!(c.key_of(Vec3::new(2.0, 0.0, 0.0)), None);
        assert_eq!(
            c.key_of(Vec3::new(1.99, 0.0, 0.0)),
            Some(IVec3::new(19, 0, 0))
        );
        let centre = c.center_of(IVec3::new(-1, 0, 19));
        assert!((centre - Vec3::new(-0.05, 0.05, 1.95)).abs().max_element() < 1e-6);
        // Key -1 is local 15 of chunk -1, whose flat index is 0 in a grid starting at chunk -2.
        let (flat, local) = c.address_of(IVec3::new(-1, -20, -20)).unwrap();
        assert_eq!(c.chunk_grid().min, IVec3::splat(-2));
        assert_eq!(c.chunk_grid().coord(flat).0, IVec3::new(-1, -2, -2));
        assert_eq!(local, 15 + 16 * (12 + 16 * 12));
    }

    #[test]
    fn fast_floor_equals_floor() {
        let xs = [
            0.0,
            -0.0,
            0.5,
            -0.5,
            1.0,
            -1.0,
            2.9999999999999996,
            -2.9999999999999996,
            1e-300,
            -1e-300,
            2147483647.5,
            -2147483648.0,
            -2147483648.5,
            3e9,
            -3e9,
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
        ];
        for x in xs {
            let q = DVec3::new(x, -x, x * 0.5);
            assert_eq!(floor_to_key(q), q.floor().as_ivec3(), "{x}");
        }
    }

    #[test]
    fn octomap_defaults_in_milli_units() {
        let c = MapConfig::new(&MapSettings::default()).unwrap();
        // logit(0.12) = -1.99243, logit(0.97) = 3.47610 (common.md §1).
        assert_eq!((c.clamp_min(), c.clamp_max()), (-1992, 3476));
        let q = SensorQuality::from_probabilities(0.7, 0.4, 0.0);
        // logit(0.7) = 0.847298, logit(0.4) = -0.405465.
        assert_eq!(
            c.increments(&q).unwrap(),
            LogOddsIncrements {
                hit: 847,
                miss: -405
            }
        );
        assert_eq!(milli_to_log_odds(847), 0.847);
    }

    #[test]
    fn bad_settings_are_refused() {
        let ok = MapSettings::default();
        let bad = |s: MapSettings| MapConfig::new(&s).unwrap_err();
        assert!(matches!(
            bad(MapSettings {
                resolution: 0.0,
                ..ok
            }),
            MapConfigError::InvalidResolution(_)
        ));
        assert!(matches!(
            bad(MapSettings {
                resolution: f64::NAN,
                ..ok
            }),
            MapConfigError::InvalidResolution(_)
        ));
        assert!(matches!(
            bad(MapSettings {
                bounds_max: DVec3::new(20.0, 0.0, 20.0),
                ..ok
            }),
            MapConfigError::InvalidBounds { .. }
        ));
        assert!(matches!(
            bad(MapSettings {
                bounds_min: DVec3::splat(f64::NEG_INFINITY),
                ..ok
            }),
            MapConfigError::InvalidBounds { .. }
        ));
        assert!(matches!(
            bad(MapSettings { p_min: 0.5, ..ok }),
            MapConfigError::InvalidClamping { .. }
        ));
        assert!(matches!(
            bad(MapSettings { p_max: 1.0, ..ok }),
            MapConfigError::InvalidClamping { .. }
        ));
        assert!(matches!(
            bad(MapSettings {
                resolution: 1e-4,
                ..ok
            }),
            MapConfigError::TooLarge { .. }
        ));
        assert!(matches!(
            bad(MapSettings {
                bounds_max: DVec3::splat(1e12),
                ..ok
            }),
            MapConfigError::TooLarge { .. }
        ));
        let c = MapConfig::new(&ok).unwrap();
        for q in [
            SensorQuality::from_probabilities(0.4, 0.4, 0.0),
            SensorQuality::from_probabilities(0.7, 0.6, 0.0),
            SensorQuality::from_probabilities(f32::NAN, 0.4, 0.0),
            SensorQuality::from_probabilities(1.0, 0.4, 0.0),
        ] {
            assert!(matches!(
                c.increments(&q),
                Err(MapConfigError::InvalidSensorQuality { .. })
            ));
        }
    }
}
