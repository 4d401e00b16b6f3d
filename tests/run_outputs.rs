//! `run` says whether it wrote its results folder in its report, not only in the summary's
//! reason: the command line and the sweep tell a failed write by that field.

mod common;

use uavex::components::sim::Outcome;
use uavex::engine::run::{RunOptions, run, run_file};

const ROOM: &str = include_str!("fixtures/sweep_room.toml");

fn into(dir: &std::path::Path) -> RunOptions {
    RunOptions {
        out_dir: Some(dir.to_owned()),
        ..RunOptions::default()
    }
}

#[test]
fn a_results_folder_that_cannot_be_written_is_reported_with_the_folder() {
    let tmp = tempfile::tempdir().unwrap();
    let loaded = common::scenario(ROOM);
    // Writable, but the summary cannot replace a folder of its name.
    let blocked = tmp.path().join("blocked");
    std::fs::create_dir_all(blocked.join("summary.json")).unwrap();
    let report = run(&loaded, &into(&blocked)).unwrap();
    let error = report.write_error.expect("the write failed");
    assert_eq!(error.dir, blocked);
    // The summary still says it, for a sweep's tables.
    assert_eq!(report.summary.outcome, Outcome::Failed);
    assert_eq!(report.summary.reason, error.to_string());
    assert!(
        report.summary.reason.starts_with(&format!(
            "could not write results to {}: ",
            blocked.display()
        )),
        "{}",
        report.summary.reason
    );

    // Written: no error, the run's own ending, and its summary on disk.
    let file = tmp.path().join("room.toml");
    std::fs::write(&file, ROOM).unwrap();
    let good = tmp.path().join("good");
    let report = run_file(&file, &into(&good)).unwrap();
    assert!(report.write_error.is_none(), "{:?}", report.write_error);
    assert_eq!(report.summary.outcome, Outcome::TimeLimit);
    assert!(good.join("summary.json").is_file());
    // No folder asked for, none written, no error.
    let report = run(&loaded, &RunOptions::default()).unwrap();
    assert!(report.write_error.is_none());
}
