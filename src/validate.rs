//! `uavex validate`: scenario files and sweep plans, every problem reported at its place,
//! nothing run.

use crate::INVALID_INPUT;
use crate::console::{errln, outln};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use uavex_engine::run::load_and_check;
use uavex_engine::sweep::{FileKind, Plan, check_plan};

/// Checks each file of `paths`: a scenario as `uavex run` would load it, a sweep plan (a file
/// with `[[scenario]]` tables) with each of its scenario variants; exit code 2 if any fails.
pub fn validate_command(paths: &[PathBuf]) -> ExitCode {
    let mut all_valid = true;
    for path in paths {
        if FileKind::of_file(path) == FileKind::Plan {
            all_valid &= validate_plan(path);
            continue;
        }
        match load_and_check(path) {
            Ok(_) => outln!("{}: ok", path.display()),
            Err(errors) => {
                all_valid = false;
                errln!("{errors}");
            }
        }
    }
    if all_valid {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(INVALID_INPUT)
    }
}

/// `uavex validate` of a sweep plan: the plan itself, then each scenario variant it makes, as
/// its runs would load them. Whether all passed.
fn validate_plan(path: &Path) -> bool {
    let plan = match Plan::load(path) {
        Ok(plan) => plan,
        Err(e) => {
            errln!("{e}");
            return false;
        }
    };
    let check = check_plan(&plan);
    for refused in &check.refused {
        errln!(
            "{}: the variant {} is refused: {}",
            path.display(),
            refused.variant,
            refused.reason
        );
    }
    if check.refused.is_empty() {
        let plural = |n: usize, what: &str| format!("{n} {what}{}", if n == 1 { "" } else { "s" });
        outln!(
            "{}: ok (a sweep plan of {}, {} checked)",
            path.display(),
            plural(check.runs, "run"),
            plural(check.variants, "scenario variant")
        );
    }
    check.refused.is_empty()
}
