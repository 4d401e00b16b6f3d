//! 3D recordings (issue 5 item 6; needs `--features record`): a short Pillars exploration is
//! recorded and read back with rerun's own decoder. The recording holds the expected entities
//! on the simulated-time timeline only, its voxel boxes add up to the map at every log time
//! (and are the map's occupied voxels at the end), its candidates are the decision log's, each
//! coloured by its predicted energy, and recording changes no result of the run.
//!
//! `cargo test -p uavex --features record --test record`

mod common;

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use std::process::Command;
use uavex::components::sim::Outcome;
use uavex::engine::formats::cloud::load_cloud;
use uavex::engine::output::{HOST_FIELDS, RunSummary};
use uavex::engine::record::colour::{Palette, Span};
use uavex::engine::record::external::re_chunk::{Chunk, ComponentIdentifier};
use uavex::engine::record::external::re_log_encoding::DecoderApp;
use uavex::engine::record::external::re_log_types::{LogMsg, TimeType};
use uavex::engine::record::external::re_sdk_types::archetypes::{Boxes3D, LineStrips3D, Scalars};
use uavex::engine::record::external::re_sdk_types::components::{
    Color, LineStrip3D, Position3D, Scalar,
};
use uavex::engine::record::writer::SIM_TIME;
use uavex::engine::run::{RunOptions, run};
use uavex::engine::scenario::{LoadedScenario, load};

/// Seconds of the shipped Pillars exploration to fly: enough for several decisions.
const MISSION_S: f64 = 30.0;

fn short_pillars() -> LoadedScenario {
    let mut loaded = load(format!(
        "{}/scenarios/eaae_pillars.toml",
        env!("CARGO_MANIFEST_DIR")
    ))
    .unwrap_or_else(|e| panic!("{e}"));
    loaded.scenario.time_limit_s = MISSION_S;
    loaded
}

fn run_into(loaded: &LoadedScenario, dir: &Path, record: Option<PathBuf>) -> RunSummary {
    let options = RunOptions {
        out_dir: Some(dir.to_owned()),
        seed: None,
        record,
        ..RunOptions::default()
    };
    run(loaded, &options)
        .unwrap_or_else(|e| panic!("{e}"))
        .summary
}

/// A recording's data chunks, as rerun's decoder reads them back.
struct Recording(Vec<Chunk>);

impl Recording {
    fn read(path: &Path) -> Self {
        let file = std::io::BufReader::new(std::fs::File::open(path).unwrap());
        let chunks = DecoderApp::decode_eager(file)
            .unwrap()
            .filter_map(|msg| match msg.unwrap() {
                LogMsg::ArrowMsg(_, arrow) => Some(Chunk::from_arrow_msg(&arrow).unwrap()),
                _ => None,
            })
            .collect();
        Self(chunks)
    }

    fn entities(&self) -> BTreeSet<String> {
        self.0.iter().map(|c| c.entity_path().to_string()).collect()
    }

    fn of<'a>(&'a self, entity: &'a str) -> impl Iterator<Item = &'a Chunk> + 'a {
        self.0
            .iter()
            .filter(move |c| c.entity_path().to_string() == entity)
    }

    /// Times (s) of the rows of `entity`, in file order.
    fn times(&self, entity: &str) -> Vec<f64> {
        self.of(entity)
            .filter(|c| !c.is_static())
            .flat_map(|c| {
                let column = &c.timelines()[&SIM_TIME.into()];
                column
                    .times_raw()
                    .iter()
                    .map(|&ns| ns as f64 * 1e-9)
                    .collect::<Vec<_>>()
            })
            .collect()
    }

    /// Each row's values of component `C` at `entity`, with the row's time (s).
    fn rows<C: uavex::engine::record::external::re_sdk_types::Component>(
        &self,
        entity: &str,
        component: ComponentIdentifier,
    ) -> Vec<(f64, Vec<C>)> {
        self.of(entity)
            .flat_map(|c| {
                let times = c.iter_component_timepoints(component).map(|t| {
                    t.get(&SIM_TIME.into())
                        .map_or(f64::NAN, |ns| ns.get() as f64 * 1e-9)
                });
                let values = c.iter_component::<C>(component).map(|v| v.to_vec());
                times.zip(values).collect::<Vec<_>>()
            })
            .collect()
    }

    /// Each row's numbers of field `name` (logged as plain values beside an archetype).
    fn numbers(&self, entity: &str, name: &'static str) -> Vec<Vec<f64>> {
        self.of(entity)
            .flat_map(|c| {
                c.iter_slices::<f64>(name.into())
                    .map(|values| values.to_vec())
                    .collect::<Vec<_>>()
            })
            .collect()
    }
}

/// `summary.json` without the fields that measure the host (wall-clock times).
fn summary_of_the_run(dir: &Path) -> serde_json::Value {
    let text = std::fs::read_to_string(dir.join("summary.json")).unwrap();
    let mut json: serde_json::Value = serde_json::from_str(&text).unwrap();
    for host in HOST_FIELDS {
        json.as_object_mut().unwrap().remove(host);
    }
    json
}

/// Column `name` of a CSV file with a header, as text, one entry per row.
fn csv_column(path: &Path, name: &str) -> Vec<String> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let k = header.iter().position(|h| *h == name).unwrap();
    lines
        .map(|l| l.split(',').nth(k).unwrap_or_default().to_owned())
        .collect()
}

#[test]
fn a_recorded_exploration_holds_the_map_frontiers_candidates_and_paths_over_sim_time() {
    let loaded = short_pillars();
    let plain = tempfile::tempdir().unwrap();
    let recorded = tempfile::tempdir().unwrap();
    let file = recorded.path().join("pillars.rrd");
    let summary = run_into(&loaded, recorded.path(), Some(file.clone()));
    assert_eq!(summary.outcome, Outcome::TimeLimit, "{}", summary.reason);
    run_into(&loaded, plain.path(), None);

    // Recording changes no result.
    assert_eq!(
        summary_of_the_run(recorded.path()),
        summary_of_the_run(plain.path())
    );
    for name in ["series.csv", "uavs.csv", "decisions.csv"] {
        let read = |dir: &Path| std::fs::read_to_string(dir.join(name)).unwrap();
        assert_eq!(read(recorded.path()), read(plain.path()), "{name}");
    }

    let recording = Recording::read(&file);
    let entities = recording.entities();
    for expected in [
        "/world",
        "/world/map/bounds",
        "/world/frontier/clusters",
        "/world/frontier/centroids",
        "/world/uavs/kingfisher/body",
        "/world/uavs/kingfisher/candidates",
        "/world/uavs/kingfisher/chosen",
        "/world/uavs/kingfisher/path/000",
        "/world/uavs/kingfisher/path/002",
        "/plots/explored_pct",
        "/plots/occupied_voxels",
        "/plots/kingfisher/power_w",
    ] {
        assert!(
            entities.contains(expected),
            "{expected} missing: {entities:?}"
        );
    }

    // One timeline, simulated time; every entity's rows in increasing time within the run.
    for chunk in recording.0.iter().filter(|c| !c.is_static()) {
        let names: Vec<String> = chunk.timelines().keys().map(|n| n.to_string()).collect();
        assert_eq!(names, vec![SIM_TIME.to_owned()], "{}", chunk.entity_path());
        let timeline = chunk.timelines()[&SIM_TIME.into()].timeline();
        assert_eq!(timeline.typ(), TimeType::DurationNs);
    }
    for entity in &entities {
        let times = recording.times(entity);
        assert!(times.windows(2).all(|w| w[0] < w[1]), "{entity}: {times:?}");
        assert!(
            times
                .iter()
                .all(|&t| (0.0..=summary.mission_time_s + 1e-9).contains(&t)),
            "{entity}: {times:?}"
        );
    }
    // Regular logs at 2 Hz of simulated time from the start, and one at the end.
    let plot_times = recording.times("/plots/occupied_voxels");
    for k in 0..=(MISSION_S * 2.0) as usize - 1 {
        let t = k as f64 * 0.5;
        assert!(
            plot_times.iter().any(|&p| (p - t).abs() < 1e-6),
            "no log at {t} s: {plot_times:?}"
        );
    }
    assert!((plot_times.last().unwrap() - summary.mission_time_s).abs() < 1e-6);

    assert_voxels_follow_the_map(&recording, recorded.path(), &summary);
    assert_candidates_are_the_decisions_coloured_by_energy(&recording, recorded.path());
}

/// At every log time the chunks' latest boxes add up to the map's occupied voxels (as the
/// series and the recording's own plot say), and at the end they are exactly the voxels of
/// `map_occupied.ply`.
fn assert_voxels_follow_the_map(recording: &Recording, dir: &Path, summary: &RunSummary) {
    let centers = Boxes3D::descriptor_centers().component;
    let mut chunk_rows: BTreeMap<String, Vec<(f64, Vec<Position3D>)>> = BTreeMap::new();
    for entity in recording.entities() {
        if entity.starts_with("/world/map/occupied/") {
            chunk_rows.insert(
                entity.clone(),
                recording.rows::<Position3D>(&entity, centers),
            );
        }
    }
    assert!(chunk_rows.len() > 10, "{} chunks", chunk_rows.len());
    let latest_at = |t: f64| {
        chunk_rows
            .values()
            .filter_map(|rows| rows.iter().rev().find(|(time, _)| *time <= t + 1e-9))
            .flat_map(|(_, boxes)| boxes.iter().copied())
            .collect::<Vec<Position3D>>()
    };

    let plotted = recording.rows::<Scalar>(
        "/plots/occupied_voxels",
        Scalars::descriptor_scalars().component,
    );
    let series: BTreeMap<u64, u64> = csv_column(&dir.join("series.csv"), "time_s")
        .iter()
        .zip(csv_column(&dir.join("series.csv"), "occupied_voxels"))
        .map(|(t, n)| {
            (
                (t.parse::<f64>().unwrap() * 1e6).round() as u64,
                n.parse().unwrap(),
            )
        })
        .collect();
    let mut compared_with_series = 0;
    for (t, value) in &plotted {
        let boxes = latest_at(*t).len() as u64;
        assert_eq!(boxes as f64, value[0].0.0, "at {t} s");
        if let Some(&n) = series.get(&((t * 1e6).round() as u64)) {
            assert_eq!(boxes, n, "at {t} s (series.csv)");
            compared_with_series += 1;
        }
    }
    assert!(compared_with_series >= 50, "{compared_with_series}");

    let end: BTreeSet<[u32; 3]> = latest_at(summary.mission_time_s)
        .iter()
        .map(|p| p.0.0.map(f32::to_bits))
        .collect();
    let map: BTreeSet<[u32; 3]> = load_cloud(&dir.join("map_occupied.ply"))
        .unwrap()
        .iter()
        .map(|p| p.to_array().map(f32::to_bits))
        .collect();
    assert_eq!(end.len() as u64, summary.occupied_voxels);
    assert_eq!(end, map);
}

/// One row per decision of `decisions.csv`, with its candidates' predicted energies in order,
/// each strip coloured at its energy's place between the decision's cheapest and costliest,
/// and the chosen strip the one the log says was chosen.
fn assert_candidates_are_the_decisions_coloured_by_energy(recording: &Recording, dir: &Path) {
    let log = dir.join("decisions.csv");
    let mut decisions: BTreeMap<usize, Vec<(f64, bool)>> = BTreeMap::new();
    let [decision, energy, chosen] =
        ["decision", "predicted_energy_j", "chosen"].map(|c| csv_column(&log, c));
    for ((decision, energy), chosen) in decision.iter().zip(&energy).zip(&chosen) {
        let entry = decisions.entry(decision.parse().unwrap()).or_default();
        // A decision without candidates has one row with empty candidate cells.
        if !energy.is_empty() {
            entry.push((energy.parse().unwrap(), chosen == "true"));
        }
    }
    let entity = "/world/uavs/kingfisher/candidates";
    let energies = recording.numbers(entity, "predicted_energy_j");
    let colours = recording.rows::<Color>(entity, LineStrips3D::descriptor_colors().component);
    let strips = recording.rows::<LineStrip3D>(entity, LineStrips3D::descriptor_strips().component);
    let chosen = recording.rows::<LineStrip3D>(
        "/world/uavs/kingfisher/chosen",
        LineStrips3D::descriptor_strips().component,
    );
    assert!(decisions.len() >= 3, "{} decisions", decisions.len());
    // One row per decision in each, a decision without candidates as empty lists.
    for rows in [energies.len(), colours.len(), strips.len(), chosen.len()] {
        assert_eq!(rows, decisions.len());
    }
    let mut compared = 0;
    for (i, expected) in decisions.values().enumerate() {
        let (time_s, decision_strips) = &strips[i];
        let expected_energies: Vec<f64> = expected.iter().map(|c| c.0).collect();
        assert_eq!(energies[i], expected_energies, "at {time_s} s");
        assert_eq!(decision_strips.len(), expected.len(), "at {time_s} s");
        assert!(decision_strips.iter().all(|s| s.0.len() >= 2));
        let Some(span) = Span::of(expected_energies.iter().copied()) else {
            continue;
        };
        let expected_colours: Vec<Color> = expected_energies
            .iter()
            .map(|&e| Color::from(Palette::ENERGY.at(span.fraction(e))))
            .collect();
        assert_eq!(colours[i].1, expected_colours, "at {time_s} s");
        let picked: Vec<&LineStrip3D> = expected
            .iter()
            .zip(decision_strips)
            .filter(|((_, is_chosen), _)| *is_chosen)
            .map(|(_, strip)| strip)
            .collect();
        assert_eq!(
            chosen[i].1.iter().collect::<Vec<_>>(),
            picked,
            "at {time_s} s"
        );
        compared += usize::from(expected.len() >= 2 && picked.len() == 1);
    }
    // Decisions with a real choice among several candidates were compared.
    assert!(compared >= 3, "{compared}");
}

#[test]
fn a_recording_that_cannot_be_created_fails_the_run_before_it_flies() {
    let loaded = short_pillars();
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("no such folder").join("x.rrd");
    let summary = run_into(&loaded, dir.path(), Some(file));
    assert_eq!(summary.outcome, Outcome::Failed);
    assert!(
        summary.reason.contains("could not create the recording")
            && summary.reason.contains("no such folder"),
        "{}",
        summary.reason
    );
    assert_eq!(summary.mission_time_s, 0.0);
    // The failure is recorded like any other.
    let written = std::fs::read_to_string(dir.path().join("summary.json")).unwrap();
    assert!(
        written.contains("could not create the recording"),
        "{written}"
    );
}

/// A scripted flight past the room's east wall, with a UAV whose name needs escaping.
fn scripted_tour() -> String {
    format!(
        r#"name = "tour"
time_limit_s = 4.0
physics_rate_hz = 60.0
{room}
[[uav]]
name = "scout one"
start = {{ position = [0.0, 0.0, 1.0] }}
behaviour = {{ kind = "scripted", speed = 1.0, waypoints = [[2.0, 0.0, 1.0]] }}
[[uav.sensor]]
kind = "depth_camera"
"#,
        room = common::ROOM
    )
}

#[test]
fn a_recording_that_fails_while_writing_fails_the_run_with_the_reason() {
    // Linux's /dev/full opens, then refuses every write: the disk filling up mid-run.
    let full = Path::new("/dev/full");
    if !full.exists() {
        return;
    }
    let summary = run(
        &common::scenario(&scripted_tour()),
        &RunOptions {
            record: Some(full.to_owned()),
            ..RunOptions::default()
        },
    )
    .unwrap()
    .summary;
    assert_eq!(summary.outcome, Outcome::Failed);
    assert!(
        summary.reason.starts_with("could not write the recording")
            && summary
                .reason
                .contains("(the run: every UAV completed its behaviour)"),
        "{}",
        summary.reason
    );
    // The run itself went to its end.
    assert!(summary.mission_time_s > 1.0, "{}", summary.mission_time_s);
}

#[test]
fn the_cli_records_a_scripted_flight() {
    let dir = tempfile::tempdir().unwrap();
    let scenario = dir.path().join("tour.toml");
    std::fs::write(&scenario, scripted_tour()).unwrap();
    let file = dir.path().join("tour.rrd");
    let out = Command::new(env!("CARGO_BIN_EXE_uavex"))
        .args(["run", scenario.to_str().unwrap(), "--record"])
        .arg(&file)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{stdout}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(stdout.contains("recording in"), "{stdout}");
    let recording = Recording::read(&file);
    let entities = recording.entities();
    // A name with a space stays one part of the entity path.
    assert!(
        entities.contains("/world/uavs/scout\\ one/body"),
        "{entities:?}"
    );
    assert!(
        entities
            .iter()
            .any(|e| e.starts_with("/world/map/occupied/"))
    );
    // A scripted UAV flies no candidates.
    assert!(!entities.iter().any(|e| e.ends_with("/candidates")));
}
