//! Shards of a plan cover it exactly once, and merging their folders gives the unsharded
//! sweep: the same runs, tables and plots (issue 5, "Must show").

mod sweep_common;

use std::collections::BTreeSet;
use std::path::PathBuf;
use sweep_common::{SPEEDS, options, plan_in, results, sweep, without_column};
use uavex::engine::plot::plot_dir;
use uavex::engine::sweep::{Shard, expand, merge, run_sweep};
use uavex::engine::tables::write_tables;

#[test]
fn merged_shards_equal_the_unsharded_sweep() {
    let tmp = tempfile::tempdir().unwrap();
    let plan = plan_in(tmp.path(), SPEEDS);
    let runs = expand(&plan);

    let whole = tmp.path().join("whole");
    sweep(&plan, &whole, 2);
    write_tables(&whole).unwrap();

    // Three shards, each into its own folder, as three cluster tasks would.
    let mut shard_dirs: Vec<PathBuf> = Vec::new();
    let mut seen: Vec<String> = Vec::new();
    for index in 1..=3 {
        let dir = tmp.path().join(format!("shard{index}"));
        let mut o = options(&dir, 1);
        o.shard = Some(Shard { index, count: 3 });
        let report = run_sweep(&plan, &o).unwrap();
        assert_eq!((report.planned, report.ran), (2, 2));
        let ids: Vec<String> = results(&dir).into_keys().collect();
        let expected: BTreeSet<String> = runs
            .iter()
            .filter(|r| r.index % 3 == index - 1)
            .map(|r| r.id.clone())
            .collect();
        assert_eq!(ids.iter().cloned().collect::<BTreeSet<_>>(), expected);
        seen.extend(ids);
        shard_dirs.push(dir);
    }
    // Shards 1..3 cover the plan exactly once.
    let mut sorted = seen.clone();
    sorted.sort();
    let mut all: Vec<String> = runs.iter().map(|r| r.id.clone()).collect();
    all.sort();
    assert_eq!(sorted, all);

    let merged = tmp.path().join("merged");
    let report = merge(&merged, &shard_dirs).unwrap();
    assert_eq!(report.copied, 6);
    assert_eq!(
        (
            report.already_present,
            report.conflicts.len(),
            report.missing.len()
        ),
        (0, 0, 0)
    );
    assert_eq!(results(&merged), results(&whole));

    write_tables(&merged).unwrap();
    let read = |dir: &PathBuf, name: &str| std::fs::read_to_string(dir.join(name)).unwrap();
    assert_eq!(read(&merged, "summary.csv"), read(&whole, "summary.csv"));
    assert_eq!(read(&merged, "summary.md"), read(&whole, "summary.md"));
    assert_eq!(
        without_column(&read(&merged, "runs.csv"), "wall_time_s"),
        without_column(&read(&whole, "runs.csv"), "wall_time_s")
    );
    assert_eq!(read(&merged, "plan.toml"), plan.text);

    // Merging again changes nothing.
    let again = merge(&merged, &shard_dirs).unwrap();
    assert_eq!((again.copied, again.already_present), (0, 6));
}

#[test]
fn merge_reports_missing_runs_and_conflicts() {
    let tmp = tempfile::tempdir().unwrap();
    let plan = plan_in(tmp.path(), SPEEDS);
    let runs = expand(&plan);
    let one = tmp.path().join("one");
    let mut o = options(&one, 2);
    o.shard = Some(Shard { index: 1, count: 2 });
    run_sweep(&plan, &o).unwrap();
    let copy = tmp.path().join("copy");
    sweep_common::sweep(&plan, &copy, 2);
    // Another machine's copy of a run that disagrees.
    let tampered = copy.join("runs").join(&runs[0].id).join("summary.json");
    let text = std::fs::read_to_string(&tampered).unwrap();
    let mut value: serde_json::Value = serde_json::from_str(&text).unwrap();
    value["known_voxels"] = serde_json::json!(1);
    std::fs::write(&tampered, serde_json::to_string(&value).unwrap()).unwrap();

    let merged = tmp.path().join("merged");
    let report = merge(&merged, std::slice::from_ref(&one)).unwrap();
    assert_eq!(report.copied, 3);
    let missing: Vec<&String> = runs
        .iter()
        .filter(|r| r.index % 2 == 1)
        .map(|r| &r.id)
        .collect();
    assert_eq!(report.missing.iter().collect::<Vec<_>>(), missing);

    let report = merge(&merged, &[copy]).unwrap();
    assert_eq!(report.copied, 3);
    assert_eq!(report.conflicts, [runs[0].id.clone()]);
    assert!(report.missing.is_empty());
}

#[test]
fn merge_refuses_folders_of_different_plans() {
    let tmp = tempfile::tempdir().unwrap();
    let a = tmp.path().join("a");
    let b = tmp.path().join("b");
    std::fs::create_dir_all(&a).unwrap();
    std::fs::create_dir_all(&b).unwrap();
    std::fs::write(a.join("plan.toml"), "seeds = 1").unwrap();
    std::fs::write(b.join("plan.toml"), "seeds = 2").unwrap();
    let error = merge(&tmp.path().join("m"), &[a, b])
        .unwrap_err()
        .to_string();
    assert!(error.contains("different plans"), "{error}");
}

#[test]
fn plots_are_drawn_from_a_results_folder() {
    let tmp = tempfile::tempdir().unwrap();
    let plan = plan_in(tmp.path(), SPEEDS);
    let out = tmp.path().join("out");
    sweep(&plan, &out, 2);
    let files = plot_dir(&out).unwrap();
    let names: BTreeSet<String> = files
        .iter()
        .map(|f| f.file_name().unwrap().to_string_lossy().into_owned())
        .collect();
    for stem in [
        "exploration_rate",
        "map_uncertainty",
        "map_entropy",
        "mission_time",
        "explored",
    ] {
        assert!(names.contains(&format!("{stem}.png")), "{names:?}");
        assert!(names.contains(&format!("{stem}.svg")), "{names:?}");
    }
    // No energy in scripted runs yet: its plots are skipped, not drawn empty.
    assert!(!names.contains("energy.png"));
    let png = std::fs::read(out.join("plots/exploration_rate.png")).unwrap();
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
    // 640 x 420 pixels: IHDR width and height.
    assert_eq!(&png[16..24], &[0, 0, 2, 128, 0, 0, 1, 164]);
    let svg = std::fs::read_to_string(out.join("plots/exploration_rate.svg")).unwrap();
    assert!(svg.contains("Exploration rate: room, by speed"), "title");
    assert!(
        svg.contains("\n0.5\n</text>") && svg.contains("\n2.0\n</text>"),
        "legend labels"
    );
}
