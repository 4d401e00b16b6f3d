//! Helpers shared by the sweep tests: a small fast scenario, plans over it, and readers of a
//! results folder.
#![allow(dead_code)]

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use uavex::engine::sweep::{Plan, SweepOptions, SweepReport, run_sweep};

/// A 6 x 6 x 2 m room with a seeded pillar field, one UAV on a scripted leg with a noisy
/// camera: every source of randomness a run has, in a run of a fraction of a second.
pub const ROOM: &str = include_str!("fixtures/sweep_room.toml");

/// Writes `room.toml` and a plan with `plan_body` followed by a `[[scenario]]` for the room
/// into `dir`; returns the loaded plan.
pub fn plan_in(dir: &Path, plan_body: &str) -> Plan {
    plan_text_in(
        dir,
        &format!("name = \"test\"\n{plan_body}\n[[scenario]]\nfile = \"room.toml\"\n"),
    )
}

/// Writes `room.toml` and the plan `text` into `dir`; returns the loaded plan.
pub fn plan_text_in(dir: &Path, text: &str) -> Plan {
    std::fs::write(dir.join("room.toml"), ROOM).unwrap();
    let path = dir.join("plan.toml");
    std::fs::write(&path, text).unwrap();
    Plan::load(&path).unwrap_or_else(|e| panic!("plan refused: {e}"))
}

/// Three speeds x two seeds.
pub const SPEEDS: &str = "seeds = [0, 1]\n[grid]\n\"uav.0.behaviour.speed\" = [0.5, 1.0, 2.0]\n";

pub fn options(out: &Path, jobs: usize) -> SweepOptions {
    let mut options = SweepOptions::new(out);
    options.jobs = jobs;
    options
}

pub fn sweep(plan: &Plan, out: &Path, jobs: usize) -> SweepReport {
    run_sweep(plan, &options(out, jobs)).unwrap()
}

/// Every finished run's files, by run id: summary (without the host's wall time) and the
/// time series, byte for byte.
pub fn results(out: &Path) -> BTreeMap<String, (serde_json::Value, String, String)> {
    let mut all = BTreeMap::new();
    for entry in std::fs::read_dir(out.join("runs")).unwrap() {
        let dir: PathBuf = entry.unwrap().path();
        let read = |name: &str| std::fs::read_to_string(dir.join(name)).unwrap_or_default();
        let mut summary: serde_json::Value = serde_json::from_str(&read("summary.json")).unwrap();
        summary.as_object_mut().unwrap().remove("wall_time_s");
        let id = dir.file_name().unwrap().to_string_lossy().into_owned();
        all.insert(id, (summary, read("series.csv"), read("uavs.csv")));
    }
    all
}

/// A CSV file's text without the named column.
pub fn without_column(csv: &str, column: &str) -> String {
    let lines: Vec<Vec<&str>> = csv.lines().map(|l| l.split(',').collect()).collect();
    let at = lines[0].iter().position(|c| *c == column).unwrap();
    lines
        .iter()
        .map(|cells| {
            let mut cells = cells.clone();
            cells.remove(at);
            cells.join(",")
        })
        .collect::<Vec<_>>()
        .join("\n")
}
