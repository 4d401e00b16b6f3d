//! A command whose console is gone (`uavex sweep PLAN --out DIR | head -1`) stops printing and
//! finishes its work, without a panic (src/console.rs).

use std::io::{BufRead, BufReader};
use std::path::Path;
use std::process::{Command, Stdio};

const ROOM: &str = include_str!("fixtures/sweep_room.toml");

/// A folder with `room.toml` and `plan.toml` (the room, two seeds).
fn room_plan() -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("room.toml"), ROOM).unwrap();
    std::fs::write(
        dir.path().join("plan.toml"),
        "name = \"t\"\nseeds = 2\n[[scenario]]\nfile = \"room.toml\"\n",
    )
    .unwrap();
    dir
}

/// Runs `uavex args` in `dir` with standard output a pipe whose reader closed before the
/// command started, so its first write there fails (with standard error too when
/// `stderr_closed`, as `2>&1 | head -0`): exit code and standard error.
fn uavex_unread(dir: &Path, args: &[&str], stderr_closed: bool) -> (Option<i32>, String) {
    let (reader, writer) = std::io::pipe().unwrap();
    drop(reader);
    let stderr = if stderr_closed {
        Stdio::from(writer.try_clone().unwrap())
    } else {
        Stdio::piped()
    };
    let output = Command::new(env!("CARGO_BIN_EXE_uavex"))
        .args(args)
        .current_dir(dir)
        .stdout(writer)
        .stderr(stderr)
        .output()
        .unwrap();
    (
        output.status.code(),
        String::from_utf8_lossy(&output.stderr).into_owned(),
    )
}

#[test]
fn a_closed_standard_output_stops_the_printing_not_the_command() {
    let dir = room_plan();
    for args in [
        vec!["validate", "room.toml"],
        vec!["energy", "iris", "--distance", "50"],
        vec!["run", "room.toml", "--out", "run"],
        vec!["sweep", "plan.toml", "--out", "sweep"],
        vec!["plot", "sweep"],
    ] {
        let (code, err) = uavex_unread(dir.path(), &args, false);
        assert!(!err.contains("panicked"), "{args:?}: {err}");
        assert_eq!(code, Some(0), "{args:?}: {err}");
    }
    // The results were written to the end, after the console had gone.
    assert!(dir.path().join("run/summary.json").is_file());
    for file in ["runs.csv", "summary.md", "plots/explored.svg"] {
        assert!(dir.path().join("sweep").join(file).is_file(), "{file}");
    }
}

#[test]
fn a_closed_standard_error_keeps_the_exit_code_of_a_refusal() {
    let dir = room_plan();
    std::fs::write(dir.path().join("afile"), "junk").unwrap();
    for args in [
        vec!["validate", "nope.toml"],
        vec!["run", "room.toml", "--out", "afile/sub"],
        vec!["merge", "--out", "m", "nope"],
    ] {
        let (code, _) = uavex_unread(dir.path(), &args, true);
        assert_eq!(code, Some(2), "{args:?}");
    }
}

#[test]
fn a_sweep_read_by_head_writes_its_tables_and_plots() {
    let dir = room_plan();
    let mut child = Command::new(env!("CARGO_BIN_EXE_uavex"))
        .args(["sweep", "plan.toml", "--out", "out"])
        .current_dir(dir.path())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // `| head -1`: one line read, then the reader is gone.
    let mut first = String::new();
    BufReader::new(child.stdout.take().unwrap())
        .read_line(&mut first)
        .unwrap();
    let output = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&output.stderr);
    assert!(first.starts_with("sweep t: 2 runs"), "{first}");
    assert!(!err.contains("panicked"), "{err}");
    assert_eq!(output.status.code(), Some(0), "{err}");
    assert!(dir.path().join("out/runs.csv").is_file());
    assert!(dir.path().join("out/plots/explored.svg").is_file());
}

/// Linux's /dev/full refuses every write: a report lost without anyone asking for that is
/// said on standard error, and the command exits 1, its work done.
#[test]
fn a_standard_output_that_cannot_be_written_fails_the_command() {
    let full = Path::new("/dev/full");
    if !full.exists() {
        return;
    }
    let dir = room_plan();
    let output = Command::new(env!("CARGO_BIN_EXE_uavex"))
        .args(["run", "room.toml", "--out", "out"])
        .current_dir(dir.path())
        .stdout(std::fs::File::create(full).unwrap())
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&output.stderr);
    assert!(!err.contains("panicked"), "{err}");
    assert_eq!(output.status.code(), Some(1), "{err}");
    assert!(
        err.contains("cannot write to standard output (No space left on device"),
        "{err}"
    );
    assert!(dir.path().join("out/summary.json").is_file());
}
