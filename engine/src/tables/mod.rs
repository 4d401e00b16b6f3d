//! Results tables of a sweep, read from its results folder (so that `merge` and a re-run can
//! rebuild them from the runs alone):
//! - `runs.csv` and `runs.parquet`: the tidy per-run table (`runs`, `parquet`);
//! - `summary.csv` and `summary.md`: statistics per scene x grid combination (`summary`).

pub mod cells;
pub mod parquet;
pub mod results;
pub mod runs;
pub mod summary;

pub use cells::{Cell, FlatRecord};
pub use results::{RunRow, read_results};
pub use runs::{Table, runs_table};
pub use summary::{SummaryTable, summarise};

use crate::output::write_atomically;
use crate::sweep::execute::PLAN_FILE;
use std::path::{Path, PathBuf};
use thiserror::Error;

/// File names of the tables in a results folder.
pub const RUNS_CSV: &str = "runs.csv";
pub const RUNS_PARQUET: &str = "runs.parquet";
pub const SUMMARY_CSV: &str = "summary.csv";
pub const SUMMARY_MD: &str = "summary.md";

#[derive(Debug, Error)]
pub enum TablesError {
    #[error("{path}: {source}")]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{0}")]
    Read(String),
    #[error(transparent)]
    NotResults(#[from] crate::sweep::execute::NotResultsFolder),
    #[error("cannot write CSV: {0}")]
    Csv(#[from] csv::Error),
    #[error("cannot write Parquet: {0}")]
    Parquet(#[from] ::parquet::errors::ParquetError),
}

/// Writes the four tables of the results folder `dir`; returns how many runs they hold.
/// Refuses a folder no sweep wrote rather than write empty tables into it.
pub fn write_tables(dir: &Path) -> Result<usize, TablesError> {
    crate::sweep::execute::check_results_folder(dir)?;
    let rows = read_results(dir)?;
    let table = runs_table(&rows);
    let summary = summarise(&rows);
    let title = plan_name(dir);
    let write = |name: &str, bytes: &[u8]| {
        let path = dir.join(name);
        write_atomically(&path, bytes).map_err(|source| TablesError::Io { path, source })
    };
    write(RUNS_CSV, &runs::to_csv(&table)?)?;
    write(RUNS_PARQUET, &parquet::to_parquet(&table)?)?;
    write(SUMMARY_CSV, &summary::to_csv(&summary)?)?;
    write(
        SUMMARY_MD,
        summary::to_markdown(&summary, &title).as_bytes(),
    )?;
    Ok(rows.len())
}

/// The plan's name as the results folder records it (its `plan.toml`), else the folder's name.
fn plan_name(dir: &Path) -> String {
    let folder = || {
        dir.file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_else(|| "sweep".to_owned())
    };
    let path = dir.join(PLAN_FILE);
    std::fs::read_to_string(&path)
        .ok()
        .and_then(|text| crate::sweep::Plan::parse(&text, &path).ok())
        .map(|plan| plan.name)
        .filter(|name| name != "plan")
        .unwrap_or_else(folder)
}
