//! Sweeps: deterministic on any number of jobs, resumable after an interruption, and robust to
//! failing runs (issue 5, "Must show").

mod sweep_common;

use std::collections::BTreeSet;
use sweep_common::{SPEEDS, options, plan_in, plan_text_in, results, sweep, without_column};
use uavex::engine::sweep::{expand, run_sweep};
use uavex::engine::tables::write_tables;

#[test]
fn one_and_two_jobs_give_identical_per_run_results() {
    let tmp = tempfile::tempdir().unwrap();
    let plan = plan_in(tmp.path(), SPEEDS);
    let one = tmp.path().join("one");
    let two = tmp.path().join("two");
    let report_one = sweep(&plan, &one, 1);
    let report_two = sweep(&plan, &two, 2);
    assert_eq!((report_one.ran, report_one.failed.len()), (6, 0));
    assert_eq!((report_two.ran, report_two.failed.len()), (6, 0));

    let (a, b) = (results(&one), results(&two));
    assert_eq!(a.len(), 6);
    let ids: BTreeSet<String> = expand(&plan).into_iter().map(|r| r.id).collect();
    assert_eq!(a.keys().cloned().collect::<BTreeSet<_>>(), ids);
    assert_eq!(
        a, b,
        "per-run summaries and series differ between 1 and 2 jobs"
    );
    // The runs did map something, and the seeds and speeds made a difference.
    let known: BTreeSet<u64> = a
        .values()
        .map(|(s, ..)| s["known_voxels"].as_u64().unwrap())
        .collect();
    assert!(known.iter().all(|&k| k > 500), "{known:?}");
    assert!(known.len() >= 4, "runs should differ: {known:?}");

    // Tables agree too, but for the host's wall time.
    write_tables(&one).unwrap();
    write_tables(&two).unwrap();
    let read = |dir: &std::path::Path, name: &str| std::fs::read_to_string(dir.join(name)).unwrap();
    assert_eq!(read(&one, "summary.csv"), read(&two, "summary.csv"));
    assert_eq!(read(&one, "summary.md"), read(&two, "summary.md"));
    assert_eq!(
        without_column(&read(&one, "runs.csv"), "wall_time_s"),
        without_column(&read(&two, "runs.csv"), "wall_time_s")
    );
}

#[test]
fn an_interrupted_sweep_run_again_ends_with_every_run_exactly_once() {
    let tmp = tempfile::tempdir().unwrap();
    let plan = plan_in(tmp.path(), SPEEDS);
    let out = tmp.path().join("out");
    let runs = expand(&plan);

    // The first attempt stops after two runs...
    let mut first = options(&out, 2);
    first.max_runs = Some(2);
    let report = run_sweep(&plan, &first).unwrap();
    assert_eq!(
        (report.ran, report.not_started, report.already_done),
        (2, 4, 0)
    );
    let finished = |id: &str| out.join("runs").join(id).join("summary.json").is_file();
    let done: Vec<bool> = runs.iter().map(|r| finished(&r.id)).collect();
    assert_eq!(done, [true, true, false, false, false, false], "plan order");
    let summary_of =
        |id: &str| std::fs::read(out.join("runs").join(id).join("summary.json")).unwrap();
    let before = [summary_of(&runs[0].id), summary_of(&runs[1].id)];

    // ...and the third run was killed mid-way, leaving files but no summary.
    let killed = out.join("runs").join(&runs[2].id);
    std::fs::create_dir_all(&killed).unwrap();
    std::fs::write(killed.join("series.csv"), "half a file").unwrap();

    let report = sweep(&plan, &out, 2);
    assert_eq!(
        (report.already_done, report.ran, report.not_started),
        (2, 4, 0)
    );
    // The first two runs were not run again (their summaries hold the first wall times).
    assert_eq!(summary_of(&runs[0].id), before[0]);
    assert_eq!(summary_of(&runs[1].id), before[1]);
    // The killed run was redone from scratch.
    let series = std::fs::read_to_string(killed.join("series.csv")).unwrap();
    assert!(series.starts_with("time_s,explored_fraction"), "{series}");

    // Every run of the plan exactly once, nothing else.
    let folders: BTreeSet<String> = std::fs::read_dir(out.join("runs"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    let ids: BTreeSet<String> = runs.iter().map(|r| r.id.clone()).collect();
    assert_eq!(folders, ids);
    assert!(runs.iter().all(|r| finished(&r.id)));

    // A third attempt has nothing left to do.
    let report = sweep(&plan, &out, 2);
    assert_eq!((report.already_done, report.ran), (6, 0));

    // The same runs as an uninterrupted sweep.
    let whole = tmp.path().join("whole");
    sweep(&plan, &whole, 1);
    assert_eq!(results(&out), results(&whole));
}

#[test]
fn failing_runs_are_recorded_and_the_others_go_on() {
    let tmp = tempfile::tempdir().unwrap();
    // A negative resolution is refused by the scenario checks; a missing scenario file
    // cannot be read.
    let plan = plan_text_in(
        tmp.path(),
        "seeds = 1\n\
         [grid]\n\"map.resolution\" = [0.2, -0.1, 0.25]\n\
         [[scenario]]\nfile = \"room.toml\"\n\
         [[scenario]]\nfile = \"missing.toml\"\n",
    );
    let out = tmp.path().join("out");
    let report = sweep(&plan, &out, 2);
    assert_eq!(report.ran, 6);
    let runs = expand(&plan);
    let failed: Vec<&str> = report.failed.iter().map(|(id, _)| id.as_str()).collect();
    assert_eq!(failed, [&runs[1].id, &runs[3].id, &runs[4].id, &runs[5].id]);
    let (_, refused) = &report.failed[0];
    assert!(
        refused.starts_with("the scenario was refused") && refused.contains("map.resolution"),
        "{refused}"
    );
    assert!(
        report.failed[1].1.starts_with("cannot read the scenario")
            && report.failed[1].1.contains("missing.toml"),
        "{}",
        report.failed[1].1
    );

    let all = results(&out);
    assert_eq!(all.len(), 6, "every run has its summary, failed or not");
    for (i, run) in runs.iter().enumerate() {
        let summary = &all[&run.id].0;
        let outcome = summary["outcome"].as_str().unwrap();
        if i == 0 || i == 2 {
            assert_eq!(outcome, "time_limit", "{}", run.id);
            assert!(summary["known_voxels"].as_u64().unwrap() > 0);
        } else {
            assert_eq!(outcome, "failed", "{}", run.id);
            assert!(!summary["reason"].as_str().unwrap().is_empty());
            assert!(summary.get("known_voxels").is_none(), "no made-up metrics");
        }
    }

    // The tables report the failures: the run table row by row, the summary by group.
    write_tables(&out).unwrap();
    let runs_csv = std::fs::read_to_string(out.join("runs.csv")).unwrap();
    assert_eq!(runs_csv.matches(",failed,").count(), 4, "{runs_csv}");
    let md = std::fs::read_to_string(out.join("summary.md")).unwrap();
    assert!(
        md.contains("| runs (failed) | 1 (0) | 1 (1) | 1 (0) |"),
        "{md}"
    );
    assert!(md.contains("\n## missing\n"), "{md}");
    assert!(
        md.contains("| runs (failed) | 1 (1) | 1 (1) | 1 (1) |"),
        "{md}"
    );

    // Running again does not retry failed runs: a failure is a result...
    let again = sweep(&plan, &out, 2);
    assert_eq!((again.already_done, again.ran), (6, 0));
    // ...unless asked to, once the cause is fixed.
    std::fs::write(tmp.path().join("missing.toml"), sweep_common::ROOM).unwrap();
    let mut retry = options(&out, 2);
    retry.retry_failed = true;
    let again = run_sweep(&plan, &retry).unwrap();
    assert_eq!((again.already_done, again.ran), (2, 4));
    let failed: Vec<&str> = again.failed.iter().map(|(id, _)| id.as_str()).collect();
    assert_eq!(
        failed,
        [&runs[1].id, &runs[4].id],
        "bad resolutions fail again"
    );
}

/// A run that outlives its wall-clock limit is recorded as failed with that reason and what it
/// had computed; a limit it stays within changes nothing.
#[test]
fn a_run_past_its_wall_clock_limit_fails_and_the_sweep_goes_on() {
    let tmp = tempfile::tempdir().unwrap();
    // At 1 kHz the clock is first read at 1.024 s, before any of the runs ends.
    let plan = plan_in(
        tmp.path(),
        &format!("{SPEEDS}[set]\n\"physics_rate_hz\" = 1000.0\n"),
    );
    let (tight, generous, none) = (
        tmp.path().join("tight"),
        tmp.path().join("generous"),
        tmp.path().join("none"),
    );
    let mut options_tight = options(&tight, 2);
    options_tight.run_wall_limit = Some(std::time::Duration::from_nanos(1));
    let report = run_sweep(&plan, &options_tight).unwrap();
    assert_eq!((report.ran, report.failed.len()), (6, 6));
    for (_, (summary, ..)) in results(&tight) {
        assert_eq!(summary["outcome"], "failed");
        assert_eq!(
            summary["reason"],
            "wall-clock limit of 0.000000001 s exceeded"
        );
        let stopped_at = summary["mission_time_s"].as_f64().unwrap();
        assert!((stopped_at - 1.024).abs() < 1e-9, "{stopped_at}");
        // What the run computed until then is kept.
        assert!(summary["known_voxels"].as_u64().unwrap() > 0);
    }
    let mut options_generous = options(&generous, 2);
    options_generous.run_wall_limit = Some(std::time::Duration::from_secs(3600));
    let report = run_sweep(&plan, &options_generous).unwrap();
    assert!(report.failed.is_empty());
    sweep(&plan, &none, 2);
    assert_eq!(results(&generous), results(&none));
}

#[test]
fn the_command_line_runs_shards_merges_and_plots() {
    let tmp = tempfile::tempdir().unwrap();
    plan_in(tmp.path(), SPEEDS);
    let uavex = |args: &[&str]| {
        let output = std::process::Command::new(env!("CARGO_BIN_EXE_uavex"))
            .args(args)
            .current_dir(tmp.path())
            .output()
            .unwrap();
        let text = String::from_utf8_lossy(&output.stdout).into_owned()
            + &String::from_utf8_lossy(&output.stderr);
        (output.status.code(), text)
    };
    for shard in ["1/2", "2/2"] {
        let out = format!("s{}", &shard[..1]);
        let (code, text) = uavex(&[
            "sweep",
            "plan.toml",
            "--out",
            &out,
            "--shard",
            shard,
            "--jobs",
            "2",
        ]);
        assert_eq!(code, Some(0), "{text}");
        assert!(
            text.contains(&format!(
                "sweep test (shard {shard}): 3 runs, 0 finished before, 3 ran"
            )),
            "{text}"
        );
    }
    // One shard alone: its runs are merged and tabled, and the exit code says runs are missing.
    let (code, text) = uavex(&["merge", "--out", "half", "s1"]);
    assert_eq!(code, Some(1), "{text}");
    assert!(
        text.contains("3 runs copied, 0 already there, 0 conflicting, 3 missing")
            && text.contains("3 of the plan's runs are in no folder"),
        "{text}"
    );
    assert!(tmp.path().join("half/runs.csv").is_file());
    let (code, text) = uavex(&["merge", "--out", "all", "s1", "s2"]);
    assert_eq!(code, Some(0), "{text}");
    assert!(
        text.contains("6 runs copied, 0 already there, 0 conflicting, 0 missing"),
        "{text}"
    );
    for file in [
        "runs.csv",
        "runs.parquet",
        "summary.csv",
        "summary.md",
        "plots/exploration_rate.svg",
    ] {
        assert!(tmp.path().join("all").join(file).is_file(), "{file}");
    }
    std::fs::remove_dir_all(tmp.path().join("all/plots")).unwrap();
    let (code, text) = uavex(&["plot", "all"]);
    assert_eq!(code, Some(0), "{text}");
    assert!(tmp.path().join("all/plots/exploration_rate.png").is_file());

    // A plan that cannot be read is refused with exit code 2 and the reason.
    std::fs::write(tmp.path().join("bad.toml"), "seeds = 1\n").unwrap();
    let (code, text) = uavex(&["sweep", "bad.toml", "--out", "x"]);
    assert_eq!(code, Some(2));
    assert!(
        text.contains("bad.toml: the plan names no scenario"),
        "{text}"
    );
    let (code, _) = uavex(&["sweep", "plan.toml", "--out", "x", "--shard", "3/2"]);
    assert_eq!(code, Some(2), "clap refuses a shard out of range");
}

/// A run's folder is named after its scene; scenes named like hidden or parent folders still
/// give runs that the tables, the plots and a merge see.
#[test]
fn scenes_named_like_hidden_or_parent_folders_are_in_the_tables() {
    let tmp = tempfile::tempdir().unwrap();
    let plan = plan_text_in(
        tmp.path(),
        "seeds = 1\n\
         [[scenario]]\nfile = \"room.toml\"\nname = \".hidden\"\n\
         [[scenario]]\nfile = \"room.toml\"\nname = \"../x\"\n",
    );
    let out = tmp.path().join("out");
    let report = sweep(&plan, &out, 2);
    assert_eq!((report.ran, report.failed.len()), (2, 0));
    assert_eq!(write_tables(&out).unwrap(), 2);
    let runs_csv = std::fs::read_to_string(out.join("runs.csv")).unwrap();
    assert!(
        runs_csv.contains(",.hidden,") && runs_csv.contains(",../x,"),
        "{runs_csv}"
    );
    assert!(!tmp.path().join("x").exists(), "no run outside the folder");
    let merged = uavex::engine::sweep::merge(&tmp.path().join("merged"), &[out]).unwrap();
    assert_eq!((merged.copied, merged.missing.len()), (2, 0));
}
