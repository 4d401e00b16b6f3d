//! The coverage behaviour's settings as they appear in a scenario file, under
//! `[uav.behaviour] kind = "coverage"` (units as everywhere in scenarios: metres, seconds,
//! radians; energy in joules):
//!
//! ```toml
//! [uav.behaviour]
//! kind = "coverage"
//! area = { file = "fields/vineyard.geojson" }    # or { vertices = [[0, 0], [300, 0], ...] }
//! camera = { angle_of_view = 1.6476, width_px = 4000, height_px = 3000, shot_period_s = 1.0 }
//! overlap = { x = 0.2, y = 0.6 }
//! resolution_px_per_m = 100.0                     # required ground resolution R_d
//! available_energy_j = 150000.0                   # E_available
//! energy_model = "iris"                           # preset, or a fitted-model file
//! start_vertex = 0                                # take-off and landing, in the file's order
//! direction = "longest_edge"                      # or "across_longest_edge"
//! altitude = { step_m = 1.0, tolerance_j = 1000.0, min_altitude_m = 5.0, max_altitude_m = 120.0 }
//! ```

use super::CoverageIoError;
use super::field::{Coordinates, LocalProjection, read_field};
use super::model_io::load_energy_model;
use super::outputs::{PlanFiles, write_plan};
use super::report::cover_report;
use glam::DVec2;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use uavex_systems::coverage::MAX_SHOTS;
use uavex_systems::coverage::{
    AltitudeOutcome, AltitudeSearch, Camera, CameraError, CoverageProblem, Footprint, MissionError,
    Overlaps, PathError, Polygon, PolygonError, ScanDirection, SpeedEnergyModel, search_altitude,
};

/// What a coverage mission surveys, with what, and on how much energy.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CoverageSpec {
    pub area: AreaSpec,
    pub camera: Camera,
    pub overlap: Overlaps,
    /// Required ground resolution `R_d` (px/m).
    pub resolution_px_per_m: f64,
    /// Energy the battery makes available to the mission, `E_available` (J).
    pub available_energy_j: f64,
    /// A preset name (`iris`) or a model file (JSON/TOML, relative to the scenario file).
    #[serde(default = "default_energy_model")]
    pub energy_model: String,
    /// The vertex where the UAV takes off and lands, as numbered in the input.
    #[serde(default)]
    pub start_vertex: usize,
    #[serde(default)]
    pub direction: ScanDirection,
    #[serde(default)]
    pub altitude: AltitudeSearch,
}

/// The field: vertices in metres, or a GeoJSON/WKT file (exactly one of the two).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AreaSpec {
    #[serde(default)]
    pub vertices: Option<Vec<[f64; 2]>>,
    /// Relative to the scenario file.
    #[serde(default)]
    pub file: Option<PathBuf>,
    /// Overrides the file format's own convention (GeoJSON: lon/lat; WKT: metres).
    #[serde(default)]
    pub coordinates: Option<Coordinates>,
}

fn default_energy_model() -> String {
    "iris".to_owned()
}

/// A resolved coverage spec: the planner's problem, the energy model and the battery.
#[derive(Debug, Clone, PartialEq)]
pub struct CoverageSetup {
    pub problem: CoverageProblem,
    pub model: SpeedEnergyModel,
    pub available_energy_j: f64,
    pub search: AltitudeSearch,
    /// Set when the field came in longitude/latitude: outputs are written back in it.
    pub projection: Option<LocalProjection>,
}

impl CoverageSpec {
    /// Reads the field and the energy model (paths relative to `base_dir`) and validates
    /// everything the planner relies on. `source` names the scenario file in errors.
    pub fn resolve(
        &self,
        base_dir: &Path,
        source: &Path,
    ) -> Result<CoverageSetup, CoverageIoError> {
        let spec_error = |field: &str, message: String| CoverageIoError::Spec {
            path: source.to_owned(),
            field: field.to_owned(),
            message,
        };
        let (vertices, projection) = match (&self.area.vertices, &self.area.file) {
            (Some(vertices), None) => {
                if self.area.coordinates == Some(Coordinates::Lonlat) {
                    return Err(spec_error(
                        "area.coordinates",
                        "inline vertices are in metres; `lonlat` applies to files".to_owned(),
                    ));
                }
                let points = vertices.iter().map(|&[x, y]| DVec2::new(x, y)).collect();
                (points, None)
            }
            (None, Some(file)) => {
                let path = base_dir.join(file);
                let field = read_field(&path, self.area.coordinates)
                    .map_err(|e| spec_error("area.file", e.to_string()))?;
                (field.vertices, field.projection)
            }
            _ => {
                return Err(spec_error(
                    "area",
                    "give exactly one of `vertices` (metres) and `file` (GeoJSON or WKT)"
                        .to_owned(),
                ));
            }
        };
        let count = vertices.len();
        let polygon = Polygon::new(vertices).map_err(|e| match &self.area.file {
            // The file's problem, with the file named.
            Some(file) => spec_error(
                "area.file",
                format!("{}: {e}", base_dir.join(file).display()),
            ),
            None => spec_error(&polygon_field(&e), e.to_string()),
        })?;
        let start_vertex = polygon.index_of_input(self.start_vertex).ok_or_else(|| {
            spec_error(
                "start_vertex",
                format!(
                    "{} does not exist: the field has {count} vertices (0 to {})",
                    self.start_vertex,
                    polygon.len() - 1
                ),
            )
        })?;
        self.camera
            .validate()
            .and_then(|()| self.overlap.validate())
            .map_err(|e| spec_error(camera_field(&e, &self.camera), e.to_string()))?;
        if !(self.resolution_px_per_m > 0.0 && self.resolution_px_per_m.is_finite()) {
            return Err(spec_error(
                "resolution_px_per_m",
                format!("must be positive, got {}", self.resolution_px_per_m),
            ));
        }
        if !(self.available_energy_j > 0.0 && self.available_energy_j.is_finite()) {
            return Err(spec_error(
                "available_energy_j",
                format!("must be positive, got {}", self.available_energy_j),
            ));
        }
        if self.energy_model.trim().is_empty() {
            return Err(spec_error(
                "energy_model",
                format!(
                    "must name a preset ({}) or a model file (.json or .toml), got `{}`",
                    SpeedEnergyModel::PRESETS.join(", "),
                    self.energy_model
                ),
            ));
        }
        let model = load_energy_model(&self.energy_model, base_dir)
            .map_err(|e| spec_error("energy_model", e.to_string()))?;
        Ok(CoverageSetup {
            problem: CoverageProblem {
                polygon,
                start_vertex,
                camera: self.camera,
                overlaps: self.overlap,
                required_resolution_px_per_m: self.resolution_px_per_m,
                direction: self.direction,
            },
            model,
            available_energy_j: self.available_energy_j,
            search: self.altitude,
            projection,
        })
    }
}

impl CoverageSetup {
    /// The altitude search of coverage.md: the plan at the best feasible altitude, or the
    /// verdict that the battery does not suffice.
    pub fn plan(&self) -> Result<AltitudeOutcome, CoverageIoError> {
        search_altitude(
            &self.problem,
            &self.model,
            self.available_energy_j,
            &self.search,
        )
        .map_err(|source| CoverageIoError::Plan {
            field: mission_field(&source, &self.problem).to_owned(),
            source,
        })
    }

    /// The text `uavex cover` prints.
    pub fn report(&self, outcome: &AltitudeOutcome) -> String {
        cover_report(
            &self.problem.polygon,
            self.problem.required_resolution_px_per_m,
            outcome,
        )
    }

    /// Writes the plan as `<stem>_waypoints.csv`, `<stem>_legs.csv`, `<stem>.geojson`,
    /// `<stem>.png` and `<stem>.svg` into `dir`, in the field's own coordinates.
    pub fn write(
        &self,
        outcome: &AltitudeOutcome,
        dir: &Path,
        stem: &str,
    ) -> Result<PlanFiles, CoverageIoError> {
        write_plan(
            self.problem.polygon.vertices(),
            &outcome.plan,
            self.projection.as_ref(),
            dir,
            stem,
        )
    }
}

/// The spec field (below the behaviour) an inline polygon's problem is about.
fn polygon_field(error: &PolygonError) -> String {
    match error {
        PolygonError::NonFinite { index, .. } | PolygonError::TooFar { index, .. } => {
            format!("area.vertices[{index}]")
        }
        PolygonError::RepeatedVertex { second, .. } => format!("area.vertices[{second}]"),
        _ => "area.vertices".to_owned(),
    }
}

/// The spec field a camera or overlap problem is about.
fn camera_field(error: &CameraError, camera: &Camera) -> &'static str {
    match error {
        CameraError::AngleOfView(_) => "camera.angle_of_view",
        CameraError::ImageSize { .. } if camera.width_px == 0 => "camera.width_px",
        CameraError::ImageSize { .. } => "camera.height_px",
        CameraError::ShotPeriod(_) => "camera.shot_period_s",
        CameraError::Overlap { axis: 'x', .. } => "overlap.x",
        CameraError::Overlap { .. } => "overlap.y",
        CameraError::Altitude(_) => "altitude",
        CameraError::Resolution(_) => "resolution_px_per_m",
    }
}

/// The spec field a planning problem is about. A plan of too many photos is blamed on its cause
/// ([`too_many_shots_field`]); the path's other problems (an area thinner than the tolerance,
/// concavities nested too deep) are the area's.
fn mission_field(error: &MissionError, problem: &CoverageProblem) -> &'static str {
    match error {
        MissionError::Camera(e) => camera_field(e, &problem.camera),
        MissionError::Path(PathError::StartVertex { .. }) => "start_vertex",
        &MissionError::Path(PathError::TooManyShots {
            l_x, l_y, d_x, d_y, ..
        }) => too_many_shots_field(problem, Footprint { l_x, l_y }, d_x, d_y),
        MissionError::Path(_) => "area",
        MissionError::EnergyModel(_) | MissionError::LegEnergy { .. } => "energy_model",
        MissionError::AvailableEnergy(_) | MissionError::FarBeyondBattery { .. } => {
            "available_energy_j"
        }
        MissionError::Search { .. } => "altitude",
        MissionError::StepTooSmall { .. } | MissionError::TooManySteps { .. } => "altitude.step_m",
        MissionError::ResolutionUnreachable { .. } => "resolution_px_per_m",
    }
}

/// The spec field to blame for a plan of more than [`MAX_SHOTS`] photos and stripes, with
/// footprint `l`, stripes `d_x` and photos `d_y` apart (the error's figures).
///
/// The planner's count is about `N(d_x, d_y) = A / (d_x d_y) + P / min(d_x, d_y)`: the photos
/// over the area `A`, plus those along its border `P` and at the ends of the stripes. Besides
/// the area itself, four settings shrink a spacing, each by a factor that is 1 at its plain
/// value:
/// - `overlap.x`: stripes `1 - overlap.x` of the footprint's width apart (plain: no overlap);
/// - `overlap.y`: photos `1 - overlap.y` of the footprint's length apart (plain: no overlap);
/// - the image's short side: `camera.height_px` for an image wider than tall (a footprint short
///   along the track), else `camera.width_px` (narrow across it); its spacing shrinks by the
///   aspect ratio (plain: a square image);
///
/// (The altitude is never to blame: the limit is met at `h_max`, the altitude of the required
/// resolution, or the search ends there; lowering to spend spare energy stops at the limit,
/// keeping the lowest plan above it.)
///
/// The setting blamed is one whose plain value alone brings `N` within the limit, of several
/// the one that brings it lowest. When none alone does (or `N` itself stays within the limit:
/// a shape the estimate misses), the area is too large for the footprint the required
/// resolution allows, and `area` is blamed.
fn too_many_shots_field(
    problem: &CoverageProblem,
    l: Footprint,
    d_x: f64,
    d_y: f64,
) -> &'static str {
    let area = problem.polygon.area();
    let border = problem.polygon.perimeter();
    let count = |d_x: f64, d_y: f64| area / (d_x * d_y) + border / d_x.min(d_y);
    let limit = MAX_SHOTS as f64;
    let estimate = count(d_x, d_y);
    if estimate.is_nan() || estimate <= limit {
        return "area";
    }
    let mut plain = vec![("overlap.x", l.l_x, d_y), ("overlap.y", d_x, l.l_y)];
    if l.l_y < l.l_x {
        plain.push(("camera.height_px", d_x, d_y * l.l_x / l.l_y));
    } else if l.l_x < l.l_y {
        plain.push(("camera.width_px", d_x * l.l_y / l.l_x, d_y));
    }
    plain
        .into_iter()
        .map(|(field, d_x, d_y)| (field, count(d_x, d_y)))
        .filter(|&(_, n)| n <= limit)
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map_or("area", |(field, _)| field)
}

#[cfg(test)]
mod tests {
    use super::*;

    const SPEC: &str = r#"
        area = { vertices = [[0, 0], [0, 150], [300, 150], [300, 0]] }
        camera = { angle_of_view = 1.5707963267948966, width_px = 4000, height_px = 3000, shot_period_s = 1.0 }
        overlap = { x = 0.2, y = 0.3 }
        resolution_px_per_m = 100.0
        available_energy_j = 200000.0
        start_vertex = 2
        altitude = { step_m = 0.5 }
    "#;

    #[test]
    fn inline_spec_resolves_and_plans() {
        let spec: CoverageSpec = toml::from_str(SPEC).unwrap();
        assert_eq!(spec.energy_model, "iris");
        assert_eq!(spec.altitude.step_m, 0.5);
        assert_eq!(spec.altitude.max_altitude_m, 120.0);
        let setup = spec
            .resolve(Path::new("."), Path::new("test.toml"))
            .unwrap();
        // The clockwise input is stored counter-clockwise; input vertex 2 is (300, 150).
        let start = setup.problem.polygon.vertices()[setup.problem.start_vertex];
        assert_eq!(start, DVec2::new(300.0, 150.0));
        let outcome = setup.plan().unwrap();
        assert_eq!(outcome.plan.path.waypoints[0].position, start);
        assert!(outcome.plan.energy_j < 200000.0);
    }

    #[test]
    fn geojson_field_in_lonlat_end_to_end() {
        let dir = tempfile::tempdir().unwrap();
        // About 157 m x 111 m with a notch, in longitude/latitude.
        std::fs::write(
            dir.path().join("field.geojson"),
            r#"{"type": "Feature", "properties": {}, "geometry": {"type": "Polygon",
                "coordinates": [[[11.0, 45.0], [11.002, 45.0], [11.002, 45.001],
                [11.0012, 45.001], [11.001, 45.0004], [11.0008, 45.001], [11.0, 45.001],
                [11.0, 45.0]]]}}"#,
        )
        .unwrap();
        let text = SPEC.replace(
            "area = { vertices = [[0, 0], [0, 150], [300, 150], [300, 0]] }",
            "area = { file = \"field.geojson\" }",
        );
        let spec: CoverageSpec = toml::from_str(&text).unwrap();
        let setup = spec
            .resolve(dir.path(), &dir.path().join("s.toml"))
            .unwrap();
        assert!(setup.projection.is_some());
        let outcome = setup.plan().unwrap();
        assert_eq!(outcome.plan.path.areas, 3);
        let report = setup.report(&outcome);
        assert!(report.contains("7 vertices"), "{report}");
        let files = setup
            .write(&outcome, &dir.path().join("out"), "vineyard")
            .unwrap();
        let geojson: geojson::GeoJson = std::fs::read_to_string(&files.geojson)
            .unwrap()
            .parse()
            .unwrap();
        let geojson::GeoJson::FeatureCollection(fc) = geojson else {
            panic!("not a collection")
        };
        let geometry = fc.features[0].geometry.as_ref().unwrap();
        let geojson::GeometryValue::Polygon { coordinates } = &geometry.value else {
            panic!("the field is not a polygon")
        };
        // The field comes back where it was, in degrees.
        let first = coordinates[0][0].as_slice();
        assert!((first[0] - 11.0).abs() < 1e-12 && (first[1] - 45.0).abs() < 1e-12);
        assert!(files.png.exists() && files.svg.exists());
    }

    #[test]
    fn embeds_in_an_internally_tagged_behaviour() {
        // As the scenario schema embeds it: `[uav.behaviour] kind = "coverage"`.
        #[derive(Deserialize)]
        #[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
        enum Behaviour {
            Coverage(CoverageSpec),
        }
        let text = format!("kind = \"coverage\"\n{SPEC}");
        let Behaviour::Coverage(spec) = toml::from_str(&text).unwrap();
        assert_eq!(spec.start_vertex, 2);
        let typo = format!("kind = \"coverage\"\nstart_vertx = 1\n{SPEC}");
        let err = toml::from_str::<Behaviour>(&typo)
            .err()
            .unwrap()
            .to_string();
        assert!(err.contains("unknown field `start_vertx`"), "{err}");
    }

    #[test]
    fn bad_specs_name_the_field() {
        let resolve = |text: &str| {
            toml::from_str::<CoverageSpec>(text)
                .unwrap()
                .resolve(Path::new("."), Path::new("s.toml"))
                .unwrap_err()
                .to_string()
        };
        let err = resolve(&SPEC.replace("start_vertex = 2", "start_vertex = 9"));
        assert!(
            err.contains("start_vertex: 9 does not exist: the field has 4 vertices"),
            "{err}"
        );
        let err = resolve(&SPEC.replace("[300, 150], [300, 0]", "[300, 0], [300, 150]"));
        assert!(err.contains("intersects itself"), "{err}");
        let err =
            resolve(&SPEC.replace("available_energy_j = 200000.0", "available_energy_j = -5"));
        assert!(
            err.contains("available_energy_j: must be positive"),
            "{err}"
        );
        let err = resolve(&SPEC.replace("x = 0.2", "x = 1.5"));
        assert!(
            err.contains("coverage overlap.x: overlap along x must lie in [0, 1)"),
            "{err}"
        );
        let err = resolve(&SPEC.replace(
            "area = { vertices",
            "energy_model = \"nope\"\narea = { vertices",
        ));
        assert!(err.contains("not a preset energy model"), "{err}");
        let err = resolve(&SPEC.replace(
            "area = { vertices = [[0, 0], [0, 150], [300, 150], [300, 0]] }",
            "area = {}",
        ));
        assert!(err.contains("give exactly one of `vertices`"), "{err}");
        // An empty model name names the scenario and the field, not a blank path.
        let err = resolve(&SPEC.replace(
            "area = { vertices",
            "energy_model = \"\"\narea = { vertices",
        ));
        assert!(
            err.starts_with("s.toml: coverage energy_model: must name a preset (iris)"),
            "{err}"
        );
        let err = resolve(&SPEC.replace("[300, 150]", "[300, 1e30]"));
        assert!(
            err.starts_with("s.toml: coverage area.vertices[2]: vertex 2"),
            "{err}"
        );
    }

    #[test]
    fn a_negative_power_model_file_is_refused_with_its_field() {
        let dir = tempfile::tempdir().unwrap();
        let mut negative = SpeedEnergyModel::iris();
        negative.level.coefficients = vec![0.0, 0.0, 0.0, 0.0, -123.0];
        std::fs::write(
            dir.path().join("neg.json"),
            serde_json::to_string(&negative).unwrap(),
        )
        .unwrap();
        let text = SPEC.replace(
            "area = { vertices",
            "energy_model = \"neg.json\"\narea = { vertices",
        );
        let err = toml::from_str::<CoverageSpec>(&text)
            .unwrap()
            .resolve(dir.path(), Path::new("s.toml"))
            .unwrap_err()
            .to_string();
        assert!(err.starts_with("s.toml: coverage energy_model: "), "{err}");
        assert!(
            err.contains("neg.json") && err.contains("level.coefficients give -123"),
            "{err}"
        );
    }

    /// The spec `text`, resolved (its files beside it): its set-up for planning.
    fn setup(text: &str) -> CoverageSetup {
        toml::from_str::<CoverageSpec>(text)
            .unwrap()
            .resolve(Path::new("."), Path::new("s.toml"))
            .unwrap()
    }

    /// Why the spec `text` cannot be planned.
    fn plan_error(text: &str) -> String {
        setup(text).plan().unwrap_err().to_string()
    }

    #[test]
    fn planning_problems_name_the_field() {
        let err = plan_error(&SPEC.replace(
            "altitude = { step_m = 0.5 }",
            "altitude = { step_m = 1e-30, min_altitude_m = 10.0, max_altitude_m = 10.0 }",
        ));
        assert!(err.starts_with("coverage altitude.step_m: "), "{err}");
    }

    /// A plan of more than `MAX_SHOTS` photos blames the setting that alone makes it so (see
    /// `too_many_shots_field`), and the message keeps the spacings.
    #[test]
    fn too_many_photos_blame_their_cause() {
        let blamed = |err: &str, field: &str| {
            assert!(
                err.starts_with(&format!("coverage {field}: covering the area at ")),
                "{field}: {err}"
            );
            assert!(
                err.contains("stripes come") && err.contains("photos along a stripe"),
                "{err}"
            );
        };
        // Photos 3e-8 m apart along the stripes: the overlap along the track.
        blamed(
            &plan_error(&SPEC.replace("y = 0.3", "y = 0.999999999")),
            "overlap.y",
        );
        // Stripes 4e-5 m apart.
        blamed(
            &plan_error(&SPEC.replace("x = 0.2", "x = 0.999999")),
            "overlap.x",
        );
        // A 4000 x 1 px image at 400 px/m: a footprint 10 m wide and 2.5 mm long.
        let wide = SPEC
            .replace("height_px = 3000", "height_px = 1")
            .replace("resolution_px_per_m = 100.0", "resolution_px_per_m = 400.0")
            .replace("step_m = 0.5", "step_m = 0.5, min_altitude_m = 1.0");
        blamed(&plan_error(&wide), "camera.height_px");
        // A 1 x 3000 px image at 200 px/m: 5 mm wide, 15 m long.
        let tall = SPEC
            .replace("width_px = 4000", "width_px = 1")
            .replace("resolution_px_per_m = 100.0", "resolution_px_per_m = 200.0")
            .replace("step_m = 0.5", "step_m = 0.5, min_altitude_m = 0.001");
        blamed(&plan_error(&tall), "camera.width_px");
        // Plain settings over 300 km x 150 km: the area itself.
        let huge = SPEC.replace(
            "[[0, 0], [0, 150], [300, 150], [300, 0]]",
            "[[0, 0], [0, 150000], [300000, 150000], [300000, 0]]",
        );
        blamed(&plan_error(&huge), "area");
        // Feasible at h_max = 20 m with energy to spare, the search would go down to 0.1 m,
        // where the footprint is 200 times smaller on each side: it stops at the limit instead,
        // and keeps the plan at 20 m.
        let low = SPEC
            .replace("available_energy_j = 200000.0", "available_energy_j = 1e12")
            .replace("step_m = 0.5", "step_m = 19.9, min_altitude_m = 0.1");
        let setup = setup(&low);
        let outcome = setup.plan().unwrap();
        assert_eq!(outcome.plan.survey.altitude_m, outcome.required_altitude_m);
        assert!(outcome.photo_limit_at_m.is_some());
        let report = setup.report(&outcome);
        assert!(
            report.contains("altitude search 1 re-plans from 20.00 m to 20.00 m, stopped at 0.10 m: more than 1000000 photos"),
            "{report}"
        );
    }
}
