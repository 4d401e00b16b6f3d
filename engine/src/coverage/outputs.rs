//! Writing a coverage plan: waypoints and legs as CSV, everything as GeoJSON (longitude/latitude
//! when the field came that way, else metres), and a picture.

use super::CoverageIoError;
use super::field::LocalProjection;
use super::picture::write_picture;
use geojson::{Feature, FeatureCollection, GeoJson, Geometry, JsonObject, JsonValue};
use glam::DVec2;
use std::path::{Path, PathBuf};
use uavex_systems::coverage::MissionPlan;

/// The files [`write_plan`] wrote.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PlanFiles {
    pub waypoints_csv: PathBuf,
    pub legs_csv: PathBuf,
    pub geojson: PathBuf,
    pub png: PathBuf,
    pub svg: PathBuf,
}

/// Writes `<stem>_waypoints.csv`, `<stem>_legs.csv`, `<stem>.geojson`, `<stem>.png` and
/// `<stem>.svg` into `dir` (created if missing).
pub fn write_plan(
    polygon: &[DVec2],
    plan: &MissionPlan,
    projection: Option<&LocalProjection>,
    dir: &Path,
    stem: &str,
) -> Result<PlanFiles, CoverageIoError> {
    plain_file_stem(stem).map_err(|message| CoverageIoError::Content {
        path: dir.to_owned(),
        message,
    })?;
    std::fs::create_dir_all(dir).map_err(|source| CoverageIoError::Io {
        path: dir.to_owned(),
        source,
    })?;
    let files = PlanFiles {
        waypoints_csv: dir.join(format!("{stem}_waypoints.csv")),
        legs_csv: dir.join(format!("{stem}_legs.csv")),
        geojson: dir.join(format!("{stem}.geojson")),
        png: dir.join(format!("{stem}.png")),
        svg: dir.join(format!("{stem}.svg")),
    };
    write_waypoints_csv(plan, projection, &files.waypoints_csv)?;
    write_legs_csv(plan, &files.legs_csv)?;
    write_geojson(polygon, plan, projection, &files.geojson)?;
    write_picture(polygon, plan, &files.png)?;
    write_picture(polygon, plan, &files.svg)?;
    Ok(files)
}

/// Checks that `stem` names files inside the output folder: one plain path component, no
/// separator, no `.` or `..`, not absolute. Names are refused rather than rewritten: a rewritten
/// name would write files the user did not name, and two names could map onto one.
pub fn plain_file_stem(stem: &str) -> Result<(), String> {
    let mut components = Path::new(stem).components();
    let plain = matches!(
        (components.next(), components.next()),
        (Some(std::path::Component::Normal(c)), None) if c == stem
    ) && !stem.contains(['/', '\\', '\0', ':']);
    if plain {
        Ok(())
    } else {
        Err(format!(
            "`{stem}` cannot name output files: it must be a plain file name (no `/`, `\\`, `:`, \
             `..`, not empty), as the files are written inside the output folder"
        ))
    }
}

fn csv_error(path: &Path) -> impl Fn(csv::Error) -> CoverageIoError + '_ {
    move |e| CoverageIoError::Content {
        path: path.to_owned(),
        message: e.to_string(),
    }
}

/// One row per waypoint: position (m, and lon/lat when geographic), altitude, whether a photo is
/// taken there and the camera's along-track yaw, and the planned cruise speed of the leg that
/// leaves it (empty at the end).
pub fn write_waypoints_csv(
    plan: &MissionPlan,
    projection: Option<&LocalProjection>,
    path: &Path,
) -> Result<(), CoverageIoError> {
    let error = csv_error(path);
    let mut writer = csv::Writer::from_path(path).map_err(&error)?;
    writer
        .write_record([
            "index",
            "x_m",
            "y_m",
            "z_m",
            "lon",
            "lat",
            "shot",
            "yaw_rad",
            "leg",
            "speed_mps",
        ])
        .map_err(&error)?;
    let waypoints = &plan.path.waypoints;
    // The leg leaving waypoint i: the leg whose range holds i and does not end there.
    let mut leaving = vec![None; waypoints.len()];
    for (k, leg) in plan.legs.iter().enumerate() {
        for slot in &mut leaving[leg.waypoints[0]..leg.waypoints[1]] {
            *slot = Some(k);
        }
    }
    for (i, w) in waypoints.iter().enumerate() {
        let (lon, lat) = projection.map_or((String::new(), String::new()), |p| {
            let (lon, lat) = p.to_lonlat(w.position);
            (format!("{lon:.9}"), format!("{lat:.9}"))
        });
        let (leg, speed) = leaving[i].map_or((String::new(), String::new()), |k| {
            (k.to_string(), format!("{:.4}", plan.legs[k].speed))
        });
        writer
            .write_record([
                i.to_string(),
                format!("{:.4}", w.position.x),
                format!("{:.4}", w.position.y),
                format!("{:.4}", plan.survey.altitude_m),
                lon,
                lat,
                w.shot.is_some().to_string(),
                w.shot
                    .map_or(String::new(), |a| format!("{:.6}", a.y.atan2(a.x))),
                leg,
                speed,
            ])
            .map_err(&error)?;
    }
    writer.flush().map_err(|source| CoverageIoError::Io {
        path: path.to_owned(),
        source,
    })
}

/// One row per straight leg with its speed, energy and time, then the turn after it.
pub fn write_legs_csv(plan: &MissionPlan, path: &Path) -> Result<(), CoverageIoError> {
    let error = csv_error(path);
    let mut writer = csv::Writer::from_path(path).map_err(&error)?;
    writer
        .write_record([
            "leg",
            "start_x_m",
            "start_y_m",
            "end_x_m",
            "end_y_m",
            "length_m",
            "shots",
            "speed_limit_mps",
            "speed_mps",
            "energy_j",
            "time_s",
            "turn_after_rad",
            "turn_energy_j",
        ])
        .map_err(&error)?;
    for (k, leg) in plan.legs.iter().enumerate() {
        let turn = plan.turns.get(k);
        writer
            .write_record([
                k.to_string(),
                format!("{:.4}", leg.start.x),
                format!("{:.4}", leg.start.y),
                format!("{:.4}", leg.end.x),
                format!("{:.4}", leg.end.y),
                format!("{:.4}", leg.length_m),
                leg.shots.to_string(),
                format!("{:.4}", leg.speed_limit),
                format!("{:.4}", leg.speed),
                format!("{:.3}", leg.energy_j),
                format!("{:.4}", leg.time_s),
                turn.map_or(String::new(), |t| format!("{:.6}", t.angle_rad)),
                turn.map_or(String::new(), |t| format!("{:.3}", t.energy_j)),
            ])
            .map_err(&error)?;
    }
    writer.flush().map_err(|source| CoverageIoError::Io {
        path: path.to_owned(),
        source,
    })
}

/// The field, the path (with the plan's totals), the shots and their footprints as one
/// FeatureCollection.
pub fn write_geojson(
    polygon: &[DVec2],
    plan: &MissionPlan,
    projection: Option<&LocalProjection>,
    path: &Path,
) -> Result<(), CoverageIoError> {
    let position = |p: DVec2| -> Vec<f64> {
        match projection {
            Some(projection) => {
                let (lon, lat) = projection.to_lonlat(p);
                vec![lon, lat]
            }
            None => vec![p.x, p.y],
        }
    };
    let ring = |points: &[DVec2]| -> Vec<Vec<f64>> {
        let mut ring: Vec<Vec<f64>> = points.iter().map(|&p| position(p)).collect();
        ring.extend(ring.first().cloned());
        ring
    };
    let feature = |geometry: Geometry, properties: Vec<(&str, JsonValue)>| {
        let mut object = JsonObject::new();
        for (key, value) in properties {
            object.insert(key.to_owned(), value);
        }
        Feature {
            geometry: Some(geometry),
            properties: Some(object),
            ..Feature::default()
        }
    };
    let kind = |name: &str| ("kind", JsonValue::from(name));
    let footprints: Vec<Vec<Vec<Vec<f64>>>> = plan
        .path
        .shots()
        .map(|(p, along)| {
            let half = DVec2::new(plan.survey.footprint.l_y, plan.survey.footprint.l_x) / 2.0;
            let across = along.perp();
            vec![ring(&[
                p + along * half.x + across * half.y,
                p - along * half.x + across * half.y,
                p - along * half.x - across * half.y,
                p + along * half.x - across * half.y,
            ])]
        })
        .collect();
    let collection = FeatureCollection::new([
        feature(Geometry::new_polygon([ring(polygon)]), vec![kind("field")]),
        feature(
            Geometry::new_line_string(plan.path.waypoints.iter().map(|w| position(w.position))),
            vec![
                kind("path"),
                ("altitude_m", plan.survey.altitude_m.into()),
                (
                    "resolution_px_per_m",
                    plan.survey.resolution_px_per_m.into(),
                ),
                ("length_m", plan.length_m().into()),
                ("energy_j", plan.energy_j.into()),
                ("time_s", plan.time_s.into()),
                ("stripes", plan.path.stripes.into()),
                ("turns", plan.turns.len().into()),
            ],
        ),
        feature(
            Geometry::new_multi_point(plan.path.shots().map(|(p, _)| position(p))),
            vec![kind("shots")],
        ),
        feature(
            Geometry::new_multi_polygon(footprints),
            vec![kind("footprints")],
        ),
    ]);
    std::fs::write(path, GeoJson::from(collection).to_string()).map_err(|source| {
        CoverageIoError::Io {
            path: path.to_owned(),
            source,
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use uavex_systems::coverage::{
        Camera, CoverageProblem, Overlaps, Polygon, ScanDirection, SpeedEnergyModel, plan_mission,
    };

    fn plan() -> (Vec<DVec2>, MissionPlan) {
        let field = vec![
            DVec2::new(0.0, 0.0),
            DVec2::new(120.0, 0.0),
            DVec2::new(120.0, 60.0),
            DVec2::new(60.0, 30.0),
            DVec2::new(0.0, 60.0),
        ];
        let problem = CoverageProblem {
            polygon: Polygon::new(field.clone()).unwrap(),
            start_vertex: 0,
            camera: Camera {
                angle_of_view: std::f64::consts::FRAC_PI_2,
                width_px: 4000,
                height_px: 3000,
                shot_period_s: 1.0,
            },
            overlaps: Overlaps { x: 0.2, y: 0.3 },
            required_resolution_px_per_m: 200.0,
            direction: ScanDirection::LongestEdge,
        };
        let plan = plan_mission(&problem, 10.0, &SpeedEnergyModel::iris()).unwrap();
        (field, plan)
    }

    #[test]
    fn files_hold_the_plan() {
        let dir = tempfile::tempdir().unwrap();
        let (field, plan) = plan();
        let files = write_plan(&field, &plan, None, dir.path(), "cover").unwrap();
        let waypoints = std::fs::read_to_string(&files.waypoints_csv).unwrap();
        let lines: Vec<&str> = waypoints.lines().collect();
        assert_eq!(lines.len(), plan.path.waypoints.len() + 1);
        assert!(lines[1].starts_with("0,0.0000,0.0000,10.0000,,,false,,0,"));
        let shots = lines.iter().filter(|l| l.contains(",true,")).count();
        assert_eq!(shots, plan.path.shots().count());
        let legs = std::fs::read_to_string(&files.legs_csv).unwrap();
        assert_eq!(legs.lines().count(), plan.legs.len() + 1);
        let geojson: GeoJson = std::fs::read_to_string(&files.geojson)
            .unwrap()
            .parse()
            .unwrap();
        let GeoJson::FeatureCollection(fc) = geojson else {
            panic!("not a collection")
        };
        assert_eq!(fc.features.len(), 4);
        let path = &fc.features[1];
        let energy = path.properties.as_ref().unwrap()["energy_j"]
            .as_f64()
            .unwrap();
        assert_eq!(energy, plan.energy_j);
        let png = std::fs::read(&files.png).unwrap();
        assert_eq!(&png[1..4], b"PNG");
        let svg = std::fs::read_to_string(&files.svg).unwrap();
        assert!(svg.contains("<svg") && svg.contains("<polygon"));
    }

    #[test]
    fn a_stem_with_a_path_in_it_writes_nothing() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("out");
        let (field, plan) = plan();
        let absolute = dir.path().join("abs").display().to_string();
        for stem in ["../escape", absolute.as_str(), "a/b", "..", ""] {
            let err = write_plan(&field, &plan, None, &out, stem)
                .unwrap_err()
                .to_string();
            assert!(err.contains("plain file name"), "{stem}: {err}");
        }
        // Nothing was written anywhere, not even the output folder.
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
        assert_eq!(plain_file_stem("field_2.v1"), Ok(()));
    }

    #[test]
    fn geographic_fields_are_written_back_in_lonlat() {
        let dir = tempfile::tempdir().unwrap();
        let (field, plan) = plan();
        let projection = LocalProjection {
            origin_lon: 11.0,
            origin_lat: 45.0,
        };
        write_geojson(
            &field,
            &plan,
            Some(&projection),
            &dir.path().join("p.geojson"),
        )
        .unwrap();
        let text = std::fs::read_to_string(dir.path().join("p.geojson")).unwrap();
        // The field's first vertex is the projection's origin.
        assert!(text.contains("[11.0,45.0]"), "{}", &text[..200]);
        write_waypoints_csv(&plan, Some(&projection), &dir.path().join("w.csv")).unwrap();
        let csv = std::fs::read_to_string(dir.path().join("w.csv")).unwrap();
        assert!(
            csv.lines()
                .nth(1)
                .unwrap()
                .contains(",11.000000000,45.000000000,")
        );
    }
}
