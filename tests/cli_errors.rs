//! The command line refuses bad arguments and folders with a clear message and a non-zero exit
//! code, before doing any work, and never panics or reports success for results it did not
//! write.

use std::path::Path;
use std::process::Command;

const ROOM: &str = include_str!("fixtures/sweep_room.toml");

/// Runs `uavex args` in `dir`: exit code, stdout, stderr.
fn uavex(dir: &Path, args: &[&str]) -> (Option<i32>, String, String) {
    let output = Command::new(env!("CARGO_BIN_EXE_uavex"))
        .args(args)
        .current_dir(dir)
        .output()
        .unwrap();
    (
        output.status.code(),
        String::from_utf8_lossy(&output.stdout).into_owned(),
        String::from_utf8_lossy(&output.stderr).into_owned(),
    )
}

/// A folder with `room.toml` and `plan.toml` (the room, `seeds` seeds, then `extra`).
fn room_plan(seeds: usize, extra: &str) -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("room.toml"), ROOM).unwrap();
    std::fs::write(
        dir.path().join("plan.toml"),
        format!("name = \"t\"\nseeds = {seeds}\n[[scenario]]\nfile = \"room.toml\"\n{extra}"),
    )
    .unwrap();
    dir
}

#[test]
fn wall_limits_too_large_for_a_duration_are_refused_not_a_panic() {
    let dir = room_plan(1, "");
    for args in [
        ["run", "room.toml", "--wall-limit", "1e30"],
        ["sweep", "plan.toml", "--run-wall-limit", "1e30"],
    ] {
        let mut args = args.to_vec();
        args.extend(["--out", "out"]);
        let (code, _, err) = uavex(dir.path(), &args);
        assert_eq!(code, Some(2), "{args:?}: {err}");
        assert!(
            err.contains("expected a positive number of seconds up to") && err.contains("1e30"),
            "{err}"
        );
        assert!(!err.contains("panicked"), "{err}");
    }
    assert!(!dir.path().join("out").exists(), "refused before any work");
}

#[test]
fn jobs_are_between_one_and_the_limit_and_never_more_than_the_runs() {
    let dir = room_plan(2, "");
    for jobs in ["0", "10000", "x"] {
        let (code, _, err) = uavex(
            dir.path(),
            &["sweep", "plan.toml", "--out", "out", "--jobs", jobs],
        );
        assert_eq!(code, Some(2), "--jobs {jobs}: {err}");
        assert!(
            err.contains("expected a number of runs at once from 1 to 1024"),
            "{err}"
        );
    }
    // Allowed, but two runs are two workers, not a thousand threads.
    let (code, out, err) = uavex(
        dir.path(),
        &["sweep", "plan.toml", "--out", "out", "--jobs", "1000"],
    );
    assert_eq!(code, Some(0), "{out}{err}");
    assert!(
        out.contains("2 ran in") && out.contains("on 2 jobs"),
        "{out}"
    );
}

#[test]
fn merge_and_plot_refuse_folders_that_hold_no_results() {
    let dir = room_plan(1, "");
    std::fs::create_dir(dir.path().join("empty")).unwrap();
    std::fs::write(dir.path().join("afile"), "junk").unwrap();
    for shard in ["nope", "empty", "afile"] {
        let (code, out, err) = uavex(dir.path(), &["merge", "--out", "m", shard]);
        assert_eq!(code, Some(2), "{shard}: {out}{err}");
        assert!(
            err.contains(&format!("{shard} is not a results folder")),
            "{err}"
        );
        assert!(!dir.path().join("m").exists(), "nothing written");
        let (code, out, err) = uavex(dir.path(), &["plot", shard]);
        assert_eq!(code, Some(2), "{shard}: {out}{err}");
        assert!(
            err.contains(&format!("{shard} is not a results folder")),
            "{err}"
        );
    }
    assert!(!dir.path().join("nope").exists());
    assert!(!dir.path().join("empty/plots").exists());
    // A real results folder next to a missing one is still refused, before copying anything.
    let (code, ..) = uavex(dir.path(), &["sweep", "plan.toml", "--out", "s"]);
    assert_eq!(code, Some(0));
    let (code, _, err) = uavex(dir.path(), &["merge", "--out", "m", "s", "nope"]);
    assert_eq!(code, Some(2), "{err}");
    assert!(!dir.path().join("m").exists());
}

#[test]
fn the_sweep_console_shows_why_a_scenario_was_refused() {
    let dir = room_plan(1, "[grid]\n\"map.resolution\" = [-0.1]\n");
    let (code, out, err) = uavex(dir.path(), &["sweep", "plan.toml", "--out", "out"]);
    assert_eq!(code, Some(0), "{out}{err}");
    assert!(out.contains("1 failed"), "{out}");
    let after = out.split("the scenario was refused:").nth(1).unwrap_or("");
    // The located diagnostic of the edited scenario, not only its heading.
    assert!(
        after.contains("room.toml:") && after.contains("map.resolution"),
        "{out}"
    );
}

#[test]
fn run_refuses_an_output_folder_it_cannot_write_before_running() {
    let dir = room_plan(1, "");
    std::fs::write(dir.path().join("afile"), "junk").unwrap();
    for out_dir in ["afile", "afile/sub"] {
        let (code, out, err) = uavex(dir.path(), &["run", "room.toml", "--out", out_dir]);
        assert_eq!(code, Some(2), "{out_dir}: {out}{err}");
        assert!(
            err.contains(&format!("--out {out_dir}: cannot write results there")),
            "{err}"
        );
        assert!(out.is_empty(), "the run did not start: {out}");
    }
    assert_eq!(
        std::fs::read_to_string(dir.path().join("afile")).unwrap(),
        "junk"
    );
}

#[test]
fn run_fails_when_its_results_could_not_be_written() {
    let dir = room_plan(1, "");
    // Writable at the start, but the summary cannot replace a folder of its name.
    std::fs::create_dir_all(dir.path().join("out/summary.json")).unwrap();
    let (code, out, err) = uavex(dir.path(), &["run", "room.toml", "--out", "out"]);
    assert_eq!(code, Some(1), "{out}{err}");
    assert!(out.contains("could not write results to out"), "{out}");
    assert!(err.contains("no results written to out"), "{err}");
    assert!(!out.contains("results in"), "{out}");
    // The same run into a folder it can write succeeds, also over an earlier run's results.
    for _ in 0..2 {
        let (code, out, err) = uavex(dir.path(), &["run", "room.toml", "--out", "good"]);
        assert_eq!(code, Some(0), "{out}{err}");
        assert!(out.contains("results in good"), "{out}");
    }
}

#[test]
fn run_exits_non_zero_when_the_run_failed_and_zero_when_it_crashed() {
    // One kingfisher in a room with a wall whose face is at x = 2.
    let flight = |overrides: &str| {
        format!(
            r#"name = "wall"
time_limit_s = 5.0
[world.bounds]
min = [-3.0, -3.0, 0.0]
max = [3.0, 3.0, 2.0]
[[world.obstacle]]
kind = "box"
center = [2.5, 0.0, 1.0]
size = [1.0, 6.0, 2.0]
[[uav]]
name = "k"
start = {{ position = [0.0, 0.0, 1.0] }}
airframe_overrides = {{ {overrides} }}
behaviour = {{ kind = "waypoints", waypoints = [[2.4, 0.0, 1.0]], collision_check = false }}
"#
        )
    };
    let dir = tempfile::tempdir().unwrap();
    // Flown into the wall, the UAV crashes: a result of the study.
    std::fs::write(dir.path().join("crash.toml"), flight("")).unwrap();
    let (code, out, err) = uavex(dir.path(), &["run", "crash.toml"]);
    assert_eq!(code, Some(0), "{out}{err}");
    assert!(out.contains("crashed into"), "{out}");
    // A roll inertia of 1e-30 kg m^2 passes the checks but diverges within steps: `failed`,
    // no result, which a script must be able to tell.
    std::fs::write(
        dir.path().join("diverge.toml"),
        flight("inertia_xx = 1e-30"),
    )
    .unwrap();
    let (code, out, err) = uavex(dir.path(), &["run", "diverge.toml", "--out", "out"]);
    assert_eq!(code, Some(1), "{out}{err}");
    assert!(out.contains("became numerically unstable"), "{out}");
    assert!(
        dir.path().join("out/summary.json").exists(),
        "its outputs are kept"
    );
}

#[test]
fn a_refused_run_leaves_no_output_folder_it_created() {
    let dir = room_plan(1, "");
    // Read, and the `--out` folder checked, before the world builder finds no mesh file.
    std::fs::write(
        dir.path().join("bad_world.toml"),
        format!("{ROOM}\n[[world.obstacle]]\nkind = \"mesh\"\nfile = \"missing.obj\"\n"),
    )
    .unwrap();
    let refused = |out_dir: &str| {
        let (code, out, err) = uavex(dir.path(), &["run", "bad_world.toml", "--out", out_dir]);
        assert_eq!(code, Some(2), "{out_dir}: {out}{err}");
        assert!(err.contains("missing.obj: cannot read the file"), "{err}");
    };
    refused("new/deeper");
    assert!(!dir.path().join("new").exists(), "both levels removed");
    refused("up/../down");
    assert!(
        !dir.path().join("up").exists(),
        "a level named on the way up removed"
    );
    assert!(!dir.path().join("down").exists());
    // Folders that were there before stay, with what they held; only the new level goes.
    std::fs::create_dir_all(dir.path().join("old/empty")).unwrap();
    std::fs::write(dir.path().join("old/notes.txt"), "keep").unwrap();
    for out_dir in ["old", "old/empty", "old/new"] {
        refused(out_dir);
    }
    assert!(dir.path().join("old/empty").is_dir());
    assert!(!dir.path().join("old/new").exists());
    assert_eq!(
        std::fs::read_to_string(dir.path().join("old/notes.txt")).unwrap(),
        "keep"
    );
}

#[test]
fn validate_checks_every_scenario_variant_of_a_plan() {
    let dir = room_plan(3, "");
    let (code, out, err) = uavex(dir.path(), &["validate", "plan.toml", "room.toml"]);
    assert_eq!(code, Some(0), "{out}{err}");
    assert_eq!(
        out,
        "plan.toml: ok (a sweep plan of 3 runs, 1 scenario variant checked)\nroom.toml: ok\n"
    );
    // One variant the scenario checks refuse, one the world builder refuses (no room for a
    // pillar 30 m from the start), one that passes: each refused one is named with its
    // reason, and the plan fails.
    let dir = room_plan(
        3,
        "[grid]\n\"uav.0.behaviour.speed\" = [1.0, -2.0]\n\
         \"world.obstacle.0.start_clearance\" = [0.5, 30.0]\n",
    );
    let (code, out, err) = uavex(dir.path(), &["validate", "plan.toml"]);
    assert_eq!(code, Some(2), "{out}{err}");
    assert_eq!(out, "");
    let refused = |variant: &str| format!("plan.toml: the variant room, {variant} is refused: ");
    assert!(
        err.contains(&refused(
            "uav.0.behaviour.speed = -2.0, world.obstacle.0.start_clearance = 0.5"
        )) && err.contains("uav[0].behaviour.speed"),
        "{err}"
    );
    assert!(
        err.contains(&refused(
            "uav.0.behaviour.speed = 1.0, world.obstacle.0.start_clearance = 30.0"
        )) && err.contains("the world was refused")
            && err.contains("world.obstacle[0].start_clearance"),
        "{err}"
    );
    assert!(
        !err.contains("speed = 1.0, world.obstacle.0.start_clearance = 0.5"),
        "{err}"
    );
    // A plan that is itself malformed is reported as a plan.
    let dir = room_plan(3, "[grid]\nspeed = 1.0\n");
    let (code, _, err) = uavex(dir.path(), &["validate", "plan.toml"]);
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("plan.toml"), "{err}");
}

/// A plan given to `run` and a scenario given to `sweep` are named for what they are, with the
/// command that takes them, instead of every key the other kind does not know.
#[test]
fn run_and_sweep_name_a_file_of_the_other_kind() {
    let dir = room_plan(1, "");
    for (command, file, kind, advice) in [
        (
            "run",
            "plan.toml",
            "plan.toml: a sweep plan",
            "`uavex sweep plan.toml",
        ),
        (
            "sweep",
            "room.toml",
            "room.toml: a scenario",
            "`uavex run room.toml`",
        ),
    ] {
        let (code, _, err) = uavex(dir.path(), &[command, file, "--out", "out"]);
        assert_eq!(code, Some(2), "{err}");
        assert!(err.contains(kind) && err.contains(advice), "{err}");
        assert!(!err.contains("unknown field"), "{err}");
    }
    assert!(!dir.path().join("out").exists(), "refused before any work");
}
