//! Reading the surveyed field from the files users' fields come in: GeoJSON (RFC 7946, longitude
//! and latitude in degrees) and WKT (no coordinate system of its own; metres unless told). A
//! geographic field is projected onto a local plane in metres for planning, and the plan is
//! projected back for writing.

use super::CoverageIoError;
use geojson::{GeoJson, GeometryValue};
use glam::DVec2;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// How a file's coordinates are to be read.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Coordinates {
    /// Longitude and latitude (degrees, WGS 84).
    Lonlat,
    /// Metres in a local plane.
    Metres,
}

/// A field's outer ring in metres, in the file's vertex order (no closing repeat), with the
/// projection back to longitude and latitude when the file was geographic.
#[derive(Debug, Clone, PartialEq)]
pub struct Field {
    pub vertices: Vec<DVec2>,
    pub projection: Option<LocalProjection>,
}

/// The local-level plane at an origin on the WGS 84 ellipsoid: `x` east and `y` north (m), from
/// the meridional and prime-vertical radii of curvature at the origin's latitude. Within a few
/// kilometres of the origin, distances are off by less than about 0.02 %, far below what a
/// coverage plan notices.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct LocalProjection {
    pub origin_lon: f64,
    pub origin_lat: f64,
}

/// WGS 84 semi-major axis (m) and first eccentricity squared.
const WGS84_A: f64 = 6_378_137.0;
const WGS84_E2: f64 = 6.694_379_990_14e-3;

impl LocalProjection {
    /// Metres per radian of latitude (meridional radius `M`) and of longitude (`N cos(lat)`).
    fn radii(&self) -> (f64, f64) {
        let phi = self.origin_lat.to_radians();
        let w = 1.0 - WGS84_E2 * phi.sin().powi(2);
        let m = WGS84_A * (1.0 - WGS84_E2) / w.powf(1.5);
        let n = WGS84_A / w.sqrt();
        (m, n * phi.cos())
    }

    /// The point at `lon`, `lat` (degrees), its longitude taken the short way round from the
    /// origin's (so a field across the antimeridian stays in one piece).
    pub fn to_metres(&self, lon: f64, lat: f64) -> DVec2 {
        let (m, n_cos) = self.radii();
        DVec2::new(
            n_cos * (nearest_turn(lon, self.origin_lon) - self.origin_lon).to_radians(),
            m * (lat - self.origin_lat).to_radians(),
        )
    }

    /// `(lon, lat)` in degrees.
    pub fn to_lonlat(&self, p: DVec2) -> (f64, f64) {
        let (m, n_cos) = self.radii();
        (
            nearest_turn(self.origin_lon + (p.x / n_cos).to_degrees(), 0.0),
            self.origin_lat + (p.y / m).to_degrees(),
        )
    }
}

/// `lon` (degrees), or the same meridian a turn nearer to `reference` when it lies half a turn
/// or more from it; unchanged, to the bit, nearer than that.
fn nearest_turn(lon: f64, reference: f64) -> f64 {
    let offset = lon - reference;
    if offset >= 180.0 {
        lon - 360.0
    } else if offset < -180.0 {
        lon + 360.0
    } else {
        lon
    }
}

/// Reads the one polygon of a `.geojson`/`.json` or `.wkt` file. `coordinates` overrides the
/// format's default (GeoJSON: longitude/latitude; WKT: metres).
pub fn read_field(path: &Path, coordinates: Option<Coordinates>) -> Result<Field, CoverageIoError> {
    let text = std::fs::read_to_string(path).map_err(|source| CoverageIoError::Io {
        path: path.to_owned(),
        source,
    })?;
    let content = |message: String| CoverageIoError::Content {
        path: path.to_owned(),
        message,
    };
    let extension = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    let (ring, default) = match extension.as_deref() {
        Some("geojson" | "json") => (geojson_ring(&text).map_err(content)?, Coordinates::Lonlat),
        Some("wkt") => (wkt_ring(&text).map_err(content)?, Coordinates::Metres),
        _ => {
            return Err(content(
                "a field file must end in .geojson, .json or .wkt".to_owned(),
            ));
        }
    };
    let ring = without_closing_vertex(ring);
    match coordinates.unwrap_or(default) {
        Coordinates::Metres => Ok(Field {
            vertices: ring,
            projection: None,
        }),
        Coordinates::Lonlat => {
            if let Some(bad) = ring
                .iter()
                .find(|p| !(-180.0..=180.0).contains(&p.x) || !(-90.0..=90.0).contains(&p.y))
            {
                return Err(content(format!(
                    "({}, {}) is not a longitude/latitude in degrees; set `coordinates = \
                     \"metres\"` if the file is in metres",
                    bad.x, bad.y
                )));
            }
            // The centre of the vertices as they lie together: a longitude more than half a
            // turn from the first vertex's is the same meridian a turn nearer (a field across
            // the antimeridian has vertices near 180 and near -180 degrees).
            let first = ring.first().map_or(0.0, |p| p.x);
            let n = ring.len().max(1) as f64;
            let centre = ring
                .iter()
                .map(|&p| DVec2::new(nearest_turn(p.x, first), p.y))
                .sum::<DVec2>()
                / n;
            let projection = LocalProjection {
                origin_lon: nearest_turn(centre.x, 0.0),
                origin_lat: centre.y,
            };
            Ok(Field {
                vertices: ring
                    .iter()
                    .map(|p| projection.to_metres(p.x, p.y))
                    .collect(),
                projection: Some(projection),
            })
        }
    }
}

fn without_closing_vertex(mut ring: Vec<DVec2>) -> Vec<DVec2> {
    if ring.len() > 1 && ring.first() == ring.last() {
        ring.pop();
    }
    ring
}

/// The outer ring of the only polygon in a GeoJSON text.
fn geojson_ring(text: &str) -> Result<Vec<DVec2>, String> {
    let geojson: GeoJson = text
        .parse()
        .map_err(|e| format!("not valid GeoJSON: {e}"))?;
    let mut polygons: Vec<Vec<Vec<DVec2>>> = Vec::new();
    let mut collect = |value: &GeometryValue| collect_geojson(value, &mut polygons);
    match &geojson {
        GeoJson::Geometry(g) => collect(&g.value),
        GeoJson::Feature(f) => {
            if let Some(g) = &f.geometry {
                collect(&g.value);
            }
        }
        GeoJson::FeatureCollection(fc) => {
            for g in fc.features.iter().filter_map(|f| f.geometry.as_ref()) {
                collect(&g.value);
            }
        }
    }
    single_outer_ring(polygons)
}

fn collect_geojson(value: &GeometryValue, polygons: &mut Vec<Vec<Vec<DVec2>>>) {
    let ring = |positions: &Vec<geojson::Position>| -> Vec<DVec2> {
        positions
            .iter()
            .map(|p| {
                let c = p.as_slice();
                DVec2::new(
                    c.first().copied().unwrap_or(f64::NAN),
                    c.get(1).copied().unwrap_or(f64::NAN),
                )
            })
            .collect()
    };
    match value {
        GeometryValue::Polygon { coordinates } => {
            polygons.push(coordinates.iter().map(ring).collect());
        }
        GeometryValue::MultiPolygon { coordinates } => {
            for polygon in coordinates {
                polygons.push(polygon.iter().map(ring).collect());
            }
        }
        GeometryValue::GeometryCollection { geometries } => {
            for g in geometries {
                collect_geojson(&g.value, polygons);
            }
        }
        _ => {}
    }
}

/// The outer ring of the only polygon in a WKT text.
fn wkt_ring(text: &str) -> Result<Vec<DVec2>, String> {
    let parsed: wkt::Wkt<f64> = text
        .trim()
        .parse()
        .map_err(|e| format!("not valid WKT: {e}"))?;
    let mut polygons = Vec::new();
    collect_wkt(&parsed, &mut polygons);
    single_outer_ring(polygons)
}

fn collect_wkt(value: &wkt::Wkt<f64>, polygons: &mut Vec<Vec<Vec<DVec2>>>) {
    let rings = |polygon: &wkt::types::Polygon<f64>| -> Vec<Vec<DVec2>> {
        polygon
            .rings()
            .iter()
            .map(|r| r.coords().iter().map(|c| DVec2::new(c.x, c.y)).collect())
            .collect()
    };
    match value {
        wkt::Wkt::Polygon(p) => polygons.push(rings(p)),
        wkt::Wkt::MultiPolygon(mp) => polygons.extend(mp.polygons().iter().map(rings)),
        wkt::Wkt::GeometryCollection(gc) => {
            for g in gc.geometries() {
                collect_wkt(g, polygons);
            }
        }
        _ => {}
    }
}

fn single_outer_ring(mut polygons: Vec<Vec<Vec<DVec2>>>) -> Result<Vec<DVec2>, String> {
    match polygons.len() {
        0 => Err("no polygon found: the file must hold exactly one Polygon".to_owned()),
        1 => {
            let mut rings = polygons.remove(0);
            if rings.len() > 1 {
                return Err(format!(
                    "the polygon has {} holes; fields with holes are not supported",
                    rings.len() - 1
                ));
            }
            rings
                .pop()
                .ok_or_else(|| "the polygon has no ring".to_owned())
        }
        n => Err(format!(
            "{n} polygons found: the file must hold exactly one (split the field per flight)"
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Write;

    fn file(dir: &tempfile::TempDir, name: &str, text: &str) -> std::path::PathBuf {
        let path = dir.path().join(name);
        std::fs::File::create(&path)
            .unwrap()
            .write_all(text.as_bytes())
            .unwrap();
        path
    }

    #[test]
    fn projection_by_hand_and_round_trip() {
        let p = LocalProjection {
            origin_lon: 11.0,
            origin_lat: 45.0,
        };
        // At 45 deg the WGS 84 meridional radius is 6 367 381.8 m: a degree of latitude is
        // 111 132 m; the prime-vertical radius is 6 388 838.3 m: a degree of longitude is
        // 6 388 838.3 * cos(45 deg) * pi / 180 = 78 847 m.
        let north = p.to_metres(11.0, 46.0);
        assert!((north.y - 111_132.0).abs() < 1.0, "{north}");
        let east = p.to_metres(12.0, 45.0);
        assert!((east.x - 78_847.0).abs() < 1.0, "{east}");
        let (lon, lat) = p.to_lonlat(DVec2::new(123.4, -56.7));
        let back = p.to_metres(lon, lat);
        assert!(back.distance(DVec2::new(123.4, -56.7)) < 1e-9);
    }

    #[test]
    fn geojson_feature_collection_in_lonlat() {
        let dir = tempfile::tempdir().unwrap();
        let path = file(
            &dir,
            "field.geojson",
            r#"{"type": "FeatureCollection", "features": [
                {"type": "Feature", "properties": {"name": "gate"},
                 "geometry": {"type": "Point", "coordinates": [11.0, 45.0]}},
                {"type": "Feature", "properties": {},
                 "geometry": {"type": "Polygon", "coordinates": [[[11.0, 45.0], [11.002, 45.0],
                   [11.002, 45.001], [11.0, 45.001], [11.0, 45.0]]]}}]}"#,
        );
        let field = read_field(&path, None).unwrap();
        assert_eq!(field.vertices.len(), 4);
        let projection = field.projection.unwrap();
        assert!((projection.origin_lon - 11.001).abs() < 1e-12);
        // 0.002 deg of longitude at 45 deg = 157.7 m; 0.001 deg of latitude = 111.1 m.
        let width = field.vertices[0].distance(field.vertices[1]);
        let height = field.vertices[1].distance(field.vertices[2]);
        assert!((width - 157.69).abs() < 0.05, "{width}");
        assert!((height - 111.13).abs() < 0.05, "{height}");
    }

    /// A field across the antimeridian (Taveuni, Fiji, lies on it) keeps its shape: its vertices
    /// in metres are those of the same field across the prime meridian, and the plan's points
    /// go back to longitudes on either side of 180 degrees.
    #[test]
    fn a_field_across_the_antimeridian_stays_in_one_piece() {
        let dir = tempfile::tempdir().unwrap();
        let polygon = |west: f64, east: f64| {
            format!(
                r#"{{"type": "Polygon", "coordinates": [[[{west}, -16.8], [{east}, -16.8],
                   [{east}, -16.799], [{west}, -16.799], [{west}, -16.8]]]}}"#
            )
        };
        let across =
            read_field(&file(&dir, "a.geojson", &polygon(179.999, -179.999)), None).unwrap();
        let at_zero = read_field(&file(&dir, "z.geojson", &polygon(-0.001, 0.001)), None).unwrap();
        for (a, z) in across.vertices.iter().zip(&at_zero.vertices) {
            assert!(a.distance(*z) < 1e-6, "{a} against {z}");
        }
        // 0.002 degrees of longitude at 16.8 degrees south: some 213 m, not a turn of the Earth.
        let width = across.vertices[0].distance(across.vertices[1]);
        assert!((width - 213.3).abs() < 0.5, "{width}");
        let projection = across.projection.unwrap();
        assert!(
            (projection.origin_lon.abs() - 180.0).abs() < 1e-9,
            "{projection:?}"
        );
        let (west, _) = projection.to_lonlat(across.vertices[0]);
        let (east, _) = projection.to_lonlat(across.vertices[1]);
        assert!(
            (west - 179.999).abs() < 1e-9 && (east + 179.999).abs() < 1e-9,
            "{west} {east}"
        );
    }

    #[test]
    fn wkt_in_metres() {
        let dir = tempfile::tempdir().unwrap();
        let path = file(
            &dir,
            "field.wkt",
            "POLYGON ((0 0, 100 0, 100 50, 0 50, 0 0))",
        );
        let field = read_field(&path, None).unwrap();
        assert_eq!(
            field.vertices,
            vec![
                DVec2::new(0.0, 0.0),
                DVec2::new(100.0, 0.0),
                DVec2::new(100.0, 50.0),
                DVec2::new(0.0, 50.0)
            ]
        );
        assert!(field.projection.is_none());
    }

    #[test]
    fn unusable_files_say_why() {
        let dir = tempfile::tempdir().unwrap();
        let message = |name: &str, text: &str, coordinates| {
            read_field(&file(&dir, name, text), coordinates)
                .unwrap_err()
                .to_string()
        };
        assert!(message("a.wkt", "POLYGON ((0 0, 1 0", None).contains("not valid WKT"));
        assert!(message("b.geojson", "{", None).contains("not valid GeoJSON"));
        assert!(message("c.wkt", "POINT (1 2)", None).contains("no polygon found"));
        assert!(
            message(
                "d.wkt",
                "POLYGON ((0 0, 10 0, 10 10, 0 10, 0 0), (2 2, 3 2, 3 3, 2 2))",
                None
            )
            .contains("1 holes")
        );
        assert!(
            message(
                "e.wkt",
                "MULTIPOLYGON (((0 0, 1 0, 1 1, 0 0)), ((5 5, 6 5, 6 6, 5 5)))",
                None
            )
            .contains("2 polygons found")
        );
        assert!(
            message(
                "f.geojson",
                r#"{"type": "Polygon", "coordinates": [[[0, 0], [500, 0], [500, 300], [0, 0]]]}"#,
                None
            )
            .contains("is not a longitude/latitude")
        );
        assert!(message("g.txt", "", None).contains(".geojson, .json or .wkt"));
        let missing = read_field(&dir.path().join("none.wkt"), None).unwrap_err();
        assert!(matches!(missing, CoverageIoError::Io { .. }));
        // Metres in GeoJSON when told so.
        let path = file(
            &dir,
            "h.geojson",
            r#"{"type": "Polygon", "coordinates": [[[0, 0], [500, 0], [500, 300], [0, 0]]]}"#,
        );
        assert_eq!(
            read_field(&path, Some(Coordinates::Metres))
                .unwrap()
                .vertices[1],
            DVec2::new(500.0, 0.0)
        );
    }
}
