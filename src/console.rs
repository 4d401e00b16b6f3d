//! What the commands print: [`outln!`] and [`out!`] for standard output, [`errln!`] for
//! standard error, in place of `println!`, `print!` and `eprintln!`, which panic when the
//! stream is gone (`uavex sweep PLAN --out DIR | head -1` ended in "failed printing to
//! stdout: Broken pipe" and exit code 101).
//!
//! A command's console is a report of its work, not the work: the files a run, sweep, merge,
//! cover or calibrate writes are the results. So a stream that cannot be written is only
//! stopped, not a reason to stop: once a write to it fails, nothing more is printed there and
//! the command goes on to its end. A sweep whose reader has gone still writes its tables and
//! plots (exiting at the closed pipe, as ripgrep does, would have left a results folder
//! without them); its runs' folders are written before anything is printed anyway.
//!
//! Exit code: a closed pipe on standard output (the reader, `head`, has all it wanted) leaves
//! the command's own code, 0 when its work succeeded. Any other failure to write standard
//! output (`> file` on a full disk) means a report was lost without anyone asking for that: it
//! is said once on standard error, and a command that would have succeeded exits 1 instead
//! ([`exit_code`]). A failure to write standard error changes nothing: there is no one left to
//! tell, and the exit code already says whether the command failed.
//!
//! The progress bar of `uavex sweep` goes to standard error through indicatif, which draws
//! nothing when standard error is not a terminal (a pipe) and ignores its write errors, so it
//! needs none of this.

use std::fmt::Arguments;
use std::io::{self, Write};
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};

/// Set at the first failed write to standard output: nothing more is printed there.
static STDOUT_STOPPED: AtomicBool = AtomicBool::new(false);
/// Set when that failure was not a closed pipe (see [`exit_code`]).
static STDOUT_LOST: AtomicBool = AtomicBool::new(false);
/// Set at the first failed write to standard error.
static STDERR_STOPPED: AtomicBool = AtomicBool::new(false);

/// `println!` that stops printing, without a panic, once standard output cannot be written.
macro_rules! outln {
    ($($arg:tt)*) => {
        $crate::console::print_out(format_args!("{}\n", format_args!($($arg)*)))
    };
}

/// `print!` that stops printing, without a panic, once standard output cannot be written.
macro_rules! out {
    ($($arg:tt)*) => {
        $crate::console::print_out(format_args!($($arg)*))
    };
}

/// `eprintln!` that stops printing, without a panic, once standard error cannot be written.
macro_rules! errln {
    ($($arg:tt)*) => {
        $crate::console::print_err(format_args!("{}\n", format_args!($($arg)*)))
    };
}

pub(crate) use {errln, out, outln};

/// Writes `text` to standard output, unless a write there has failed before. Flushed at once,
/// so that a failure shows here and not in the flush at exit, whose errors Rust ignores.
pub fn print_out(text: Arguments<'_>) {
    if STDOUT_STOPPED.load(Ordering::Relaxed) {
        return;
    }
    let mut stdout = io::stdout().lock();
    if let Err(e) = stdout.write_fmt(text).and_then(|()| stdout.flush()) {
        STDOUT_STOPPED.store(true, Ordering::Relaxed);
        if e.kind() != io::ErrorKind::BrokenPipe {
            STDOUT_LOST.store(true, Ordering::Relaxed);
            print_err(format_args!(
                "uavex: cannot write to standard output ({e}); nothing more is printed there\n"
            ));
        }
    }
}

/// Writes `text` to standard error, unless a write there has failed before.
pub fn print_err(text: Arguments<'_>) {
    if STDERR_STOPPED.load(Ordering::Relaxed) {
        return;
    }
    if io::stderr().lock().write_fmt(text).is_err() {
        STDERR_STOPPED.store(true, Ordering::Relaxed);
    }
}

/// The exit code of a command that would exit with `code`: 1 instead of success when its
/// standard output was lost for another reason than a closed pipe.
pub fn exit_code(code: ExitCode) -> ExitCode {
    if code == ExitCode::SUCCESS && STDOUT_LOST.load(Ordering::Relaxed) {
        ExitCode::FAILURE
    } else {
        code
    }
}
