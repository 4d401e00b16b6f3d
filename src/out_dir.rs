//! The `--out` folder of `uavex run`: checked before the run (a run of minutes whose results
//! cannot be written is lost work), and taken away again, with every level the check created,
//! when the run is refused after all.

use std::path::{Path, PathBuf};

/// Makes sure run results can be written into `dir` before the run, not after it: creates
/// the folder and writes and removes a file in it. Returns the folders it created, deepest
/// first, for [`remove_created`] should the run be refused after all.
pub fn check_out_dir(dir: &Path) -> Result<Vec<PathBuf>, String> {
    // `a/../b` names `a/..` among its ancestors, which is no folder of its own (it is `a`'s
    // parent), so only ancestors that end in a name are listed.
    let created: Vec<PathBuf> = dir
        .ancestors()
        .take_while(|d| !d.as_os_str().is_empty() && d.symlink_metadata().is_err())
        .filter(|d| d.file_name().is_some())
        .map(PathBuf::from)
        .collect();
    let probe = dir.join(format!(".uavex-write-check-{}", std::process::id()));
    let checked = std::fs::create_dir_all(dir)
        .and_then(|()| std::fs::write(&probe, b""))
        .and_then(|()| std::fs::remove_file(&probe));
    match checked {
        Ok(()) => Ok(created),
        Err(e) => {
            remove_created(&created);
            Err(format!(
                "--out {}: cannot write results there: {e}",
                dir.display()
            ))
        }
    }
}

/// Removes the folders [`check_out_dir`] created (deepest first), each only while it is empty:
/// a refused run leaves no folder of its own behind (an empty `--out` folder looked like a run
/// that wrote nothing), and never takes anything that was put there meanwhile. Folders that
/// were there before the check are not in `created`, and stay as they were.
pub fn remove_created(created: &[PathBuf]) {
    for dir in created {
        if std::fs::remove_dir(dir).is_err() {
            break;
        }
    }
}
