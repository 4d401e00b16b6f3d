//! File formats the engine reads and writes: triangle meshes and point clouds that stand for
//! the world (OBJ, STL; PCD, PLY), and the maps it exports (OctoMap `.bt`, PLY points).
//!
//! Every reader takes the whole file as bytes and returns either its content or a
//! [`FormatError`] naming the file, the line (for line-based formats) and what is wrong. No input
//! makes a reader panic or allocate more than the file could hold (DESIGN.md, "Bad input");
//! `fuzz_tests` checks that with random and truncated files.
//!
//! Crates and hand-written readers: PLY, the richest of these formats (any property layout, three
//! encodings), is read with `ply-rs-bw`, the maintained fork of `ply-rs` (its ASCII number grammar
//! refuses `nan`, so ASCII data is read in `ply`). OBJ, STL and PCD are read by small parsers here
//! because the candidate crates fail the engine's bad-input rules (checked with a scratch program
//! against the crates.io releases, debug build): `tobj` 4.0.5 panics (integer overflow) on the face
//! `f 1/-5 2/1 3/1` after one `vt`, and its errors carry no line; `pcd-rs` 0.13 panics on a
//! binary_compressed block smaller than `POINTS` needs and on a `COUNT` of 2^64 - 1; `stl_io` 0.11
//! reads well but its ASCII errors carry no line.

pub mod cloud;
mod lzf;
pub mod mesh;
pub mod obj;
pub mod octomap;
pub mod pcd;
pub mod ply;
pub mod stl;

#[cfg(test)]
mod fuzz_tests;

use std::fmt;
use std::io;
use std::path::{Path, PathBuf};

/// A file that could not be read: which file, where in it, and what is wrong.
#[derive(Debug, thiserror::Error)]
#[error("{}{}: {problem}", .path.display(), LineSuffix(*.line))]
pub struct FormatError {
    /// The file as it was named to the reader.
    pub path: PathBuf,
    /// 1-based line of the problem, for formats (or parts of files) made of text lines.
    pub line: Option<usize>,
    /// What is wrong.
    pub problem: Problem,
}

/// What is wrong with a file (see [`FormatError`]).
#[derive(Debug, thiserror::Error)]
pub enum Problem {
    /// The file could not be opened or read.
    #[error("cannot read the file: {0}")]
    Io(#[from] io::Error),
    /// The path names a directory, device, FIFO or socket, not a regular file.
    #[error("not a regular file (a directory, device or pipe)")]
    NotAFile,
    /// The file is larger than any world file this reader takes.
    #[error(
        "the file has {bytes} bytes, more than the {} this reader takes",
        MAX_FILE_BYTES
    )]
    TooLarge {
        /// Its size.
        bytes: u64,
    },
    /// The file name's extension names no format this reader knows.
    #[error("unsupported file extension {found:?}, expected one of {expected}")]
    UnsupportedExtension {
        /// The extension found (empty when there is none).
        found: String,
        /// The extensions this reader accepts.
        expected: &'static str,
    },
    /// The content does not follow the format.
    #[error("{0}")]
    Malformed(String),
    /// A mesh file that holds no triangle (a world obstacle must have a surface).
    #[error("the mesh has no triangle")]
    EmptyMesh,
    /// A cloud file that holds no finite point.
    #[error("the cloud has no finite point ({skipped_non_finite} non-finite points skipped)")]
    EmptyCloud {
        /// Points skipped because a coordinate was NaN or infinite.
        skipped_non_finite: usize,
    },
}

struct LineSuffix(Option<usize>);

impl fmt::Display for LineSuffix {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.0 {
            Some(line) => write!(f, " line {line}"),
            None => Ok(()),
        }
    }
}

/// A problem found by a parser that works on bytes and does not know the file's name yet.
#[derive(Debug)]
pub(crate) struct Fault {
    pub line: Option<usize>,
    pub problem: Problem,
}

impl Fault {
    /// A malformed content at a known line.
    pub fn at(line: usize, message: impl Into<String>) -> Self {
        Self {
            line: Some(line),
            problem: Problem::Malformed(message.into()),
        }
    }

    /// A malformed content with no line (binary parts of files).
    pub fn bare(message: impl Into<String>) -> Self {
        Self {
            line: None,
            problem: Problem::Malformed(message.into()),
        }
    }

    /// Another kind of problem, with no line.
    pub fn problem(problem: Problem) -> Self {
        Self {
            line: None,
            problem,
        }
    }

    /// Names the file this fault was found in.
    pub fn in_file(self, path: &Path) -> FormatError {
        FormatError {
            path: path.to_path_buf(),
            line: self.line,
            problem: self.problem,
        }
    }
}

/// A parser of one file format, from the file's bytes.
pub(crate) type Parser<T> = fn(&[u8]) -> Result<T, Fault>;

/// Reads `path` with the parser that `parsers` names for its extension (lowercase, without
/// the dot); an unknown extension is an error that lists the `expected` ones.
pub(crate) fn load_by_extension<T>(
    path: &Path,
    parsers: &[(&str, Parser<T>)],
    expected: &'static str,
) -> Result<T, FormatError> {
    let found = extension(path);
    let Some((_, parse)) = parsers.iter().find(|(ext, _)| *ext == found) else {
        return Err(
            Fault::problem(Problem::UnsupportedExtension { found, expected }).in_file(path),
        );
    };
    let bytes = read_file(path)?;
    parse(&bytes).map_err(|fault| fault.in_file(path))
}

/// The lowercase extension of `path`, or "" when it has none.
pub(crate) fn extension(path: &Path) -> String {
    path.extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default()
}

/// Largest world file read (bytes): 4 GB is a scanned building at millimetres, beyond what a
/// run's geometry can hold in memory twice.
pub const MAX_FILE_BYTES: u64 = 4 << 30;

/// Reads a whole file, turning an I/O failure into a [`FormatError`]. Only regular files of at
/// most [`MAX_FILE_BYTES`]: a FIFO would block the load forever, and a link to `/dev/zero`
/// read until memory ran out.
pub(crate) fn read_file(path: &Path) -> Result<Vec<u8>, FormatError> {
    let fault = |problem| Fault::problem(problem).in_file(path);
    let metadata = std::fs::metadata(path).map_err(|e| fault(Problem::Io(e)))?;
    if !metadata.is_file() {
        return Err(fault(Problem::NotAFile));
    }
    if metadata.len() > MAX_FILE_BYTES {
        return Err(fault(Problem::TooLarge {
            bytes: metadata.len(),
        }));
    }
    std::fs::read(path).map_err(|e| fault(Problem::Io(e)))
}

/// Splits text into 1-based numbered lines (without `\n` or a trailing `\r`), lossily decoded:
/// a stray non-UTF-8 byte in a comment must not make a file unreadable.
pub(crate) fn numbered_lines(
    bytes: &[u8],
) -> impl Iterator<Item = (usize, std::borrow::Cow<'_, str>)> {
    bytes.split(|&b| b == b'\n').enumerate().map(|(i, raw)| {
        let raw = raw.strip_suffix(b"\r").unwrap_or(raw);
        (i + 1, String::from_utf8_lossy(raw))
    })
}

/// Parses one decimal number as written by C's `printf` or Rust; also accepts the `nan`, `-nan`
/// and `inf` spellings that PCL, numpy and glibc write for non-finite values.
pub(crate) fn parse_real(token: &str) -> Option<f64> {
    token.parse::<f64>().ok().or_else(|| {
        let unsigned = token.trim_start_matches(['-', '+']);
        (unsigned.len() + 1 == token.len() && unsigned.eq_ignore_ascii_case("nan"))
            .then_some(f64::NAN)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn error_display_names_file_line_and_problem() {
        let e = Fault::at(12, "face index 9 is out of range").in_file(Path::new("a/b.obj"));
        assert_eq!(
            e.to_string(),
            "a/b.obj line 12: face index 9 is out of range"
        );
        let e = Fault::bare("truncated").in_file(Path::new("c.stl"));
        assert_eq!(e.to_string(), "c.stl: truncated");
    }

    #[test]
    fn only_regular_files_are_read() {
        let dir = tempfile::tempdir().unwrap();
        let error = read_file(dir.path()).unwrap_err();
        assert!(matches!(error.problem, Problem::NotAFile), "{error}");
        // A device reads forever (a world file linked to /dev/zero filled the memory).
        let zero = Path::new("/dev/zero");
        if zero.exists() {
            let error = read_file(zero).unwrap_err();
            assert!(matches!(error.problem, Problem::NotAFile), "{error}");
        }
        let file = dir.path().join("a.obj");
        std::fs::write(&file, "v 0 0 0\n").unwrap();
        assert_eq!(read_file(&file).unwrap(), b"v 0 0 0\n");
    }

    #[test]
    fn numbered_lines_strip_crlf_and_count_from_one() {
        let lines: Vec<_> = numbered_lines(b"a\r\nb\n\nc")
            .map(|(n, s)| (n, s.into_owned()))
            .collect();
        assert_eq!(
            lines,
            vec![
                (1, "a".to_string()),
                (2, "b".to_string()),
                (3, String::new()),
                (4, "c".to_string())
            ]
        );
    }

    #[test]
    fn parse_real_reads_c_spellings_of_non_finite_values() {
        assert_eq!(parse_real("1.5e-3"), Some(0.0015));
        assert_eq!(parse_real("+2"), Some(2.0));
        assert!(parse_real("nan").is_some_and(f64::is_nan));
        assert!(parse_real("-nan").is_some_and(f64::is_nan));
        assert!(parse_real("-NaN").is_some_and(f64::is_nan));
        assert_eq!(parse_real("-inf"), Some(f64::NEG_INFINITY));
        assert_eq!(parse_real("--nan"), None);
        assert_eq!(parse_real("1,5"), None);
    }
}
