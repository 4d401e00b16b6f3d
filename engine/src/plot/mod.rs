//! Plots of a results folder (PNG and SVG under `DIR/plots/`), redrawn from the runs alone:
//! - curves over time ([`SERIES_PLOTS`]): each group's mean and its min-max band, one panel per
//!   scene (exploration rate, map uncertainty, entropy, power);
//! - strip plots of per-run values ([`STRIP_PLOTS`]): every run a point, the mean a bar, one
//!   panel per scene (energy, mission time, ...).
//!
//! A plot whose column or field no run has is skipped, so a new metric is plotted by adding one
//! line to a list below once runs write it.

pub mod draw;
pub mod series;

use crate::tables::results::{RunRow, group_by, read_results};
use crate::tables::{Cell, TablesError};
use draw::{BandFigure, BandPanel, StripFigure, StripPanel, save};
use series::{band, read_curve};
use std::path::{Path, PathBuf};
use thiserror::Error;

/// A column of a run's time series to draw over time.
pub struct SeriesPlot {
    /// File stem of the figure.
    pub name: &'static str,
    /// The run's CSV file that holds the column (rows sharing a time are summed over UAVs).
    pub file: &'static str,
    pub column: &'static str,
    /// Factor applied to the values (fraction to percent).
    pub scale: f64,
    pub title: &'static str,
    pub y_label: &'static str,
}

/// The curves drawn for every sweep.
pub const SERIES_PLOTS: &[SeriesPlot] = &[
    SeriesPlot {
        name: "exploration_rate",
        file: "series.csv",
        column: "explored_fraction",
        scale: 100.0,
        title: "Exploration rate",
        y_label: "explored voxels (%)",
    },
    SeriesPlot {
        name: "map_uncertainty",
        file: "series.csv",
        column: "uncertainty_mean",
        scale: 1.0,
        title: "Map uncertainty",
        y_label: "mean voxel uncertainty",
    },
    SeriesPlot {
        name: "map_entropy",
        file: "series.csv",
        column: "entropy_box_bits",
        scale: 1.0,
        title: "Map entropy",
        y_label: "mean entropy over the box (bit)",
    },
    SeriesPlot {
        name: "power",
        file: "uavs.csv",
        column: "power_w",
        scale: 1.0,
        title: "Power",
        y_label: "total power (W)",
    },
];

/// A numeric summary field to show run by run.
pub struct StripPlot {
    pub name: &'static str,
    pub field: &'static str,
    pub scale: f64,
    pub title: &'static str,
    pub y_label: &'static str,
}

/// The per-run distributions drawn for every sweep.
pub const STRIP_PLOTS: &[StripPlot] = &[
    StripPlot {
        name: "energy",
        field: "energy_j",
        scale: 1.0,
        title: "Energy",
        y_label: "energy (J)",
    },
    StripPlot {
        name: "average_power",
        field: "avg_power_w",
        scale: 1.0,
        title: "Average power",
        y_label: "average power (W)",
    },
    StripPlot {
        name: "mission_time",
        field: "mission_time_s",
        scale: 1.0,
        title: "Mission time",
        y_label: "mission time (s)",
    },
    StripPlot {
        name: "explored",
        field: "explored_fraction",
        scale: 100.0,
        title: "Explored at the end",
        y_label: "explored voxels (%)",
    },
];

/// Folder of the figures in a results folder.
pub const PLOTS_DIR: &str = "plots";

#[derive(Debug, Error)]
pub enum PlotError {
    #[error(transparent)]
    Results(#[from] TablesError),
    #[error(transparent)]
    NotResults(#[from] crate::sweep::execute::NotResultsFolder),
    #[error("{path}: {source}")]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{0}")]
    Series(String),
    #[error("cannot draw: {0}")]
    Draw(String),
}

/// The groups of a scene in plan order: (label, rows), failed runs left out.
fn scene_groups<'a>(rows: &'a [RunRow], scene: &str) -> Vec<(String, Vec<&'a RunRow>)> {
    let label = |row: &&RunRow| {
        let (_, coordinates) = row.group_key();
        if coordinates.is_empty() {
            "all runs".to_owned()
        } else {
            coordinates
                .iter()
                .map(|(_, v)| v.as_str())
                .collect::<Vec<_>>()
                .join(", ")
        }
    };
    group_by(
        rows.iter().filter(|r| r.run.scene == scene && !r.failed()),
        label,
    )
}

fn scenes(rows: &[RunRow]) -> Vec<String> {
    let mut scenes: Vec<String> = Vec::new();
    for row in rows {
        if !scenes.contains(&row.run.scene) {
            scenes.push(row.run.scene.clone());
        }
    }
    scenes
}

/// Draws every plot of the results folder `dir` into `dir/plots`; returns the files written.
/// Refuses a folder no sweep wrote rather than create `plots/` in it.
pub fn plot_dir(dir: &Path) -> Result<Vec<PathBuf>, PlotError> {
    crate::sweep::execute::check_results_folder(dir)?;
    let rows = read_results(dir)?;
    let out = dir.join(PLOTS_DIR);
    std::fs::create_dir_all(&out).map_err(|source| PlotError::Io {
        path: out.clone(),
        source,
    })?;
    let scenes = scenes(&rows);
    // What the groups differ by, for titles and axes: the last key of each grid path.
    let by = rows
        .first()
        .map(|r| {
            r.run
                .coordinates
                .iter()
                .map(|c| c.path.rsplit('.').next().unwrap_or(&c.path).to_owned())
                .collect::<Vec<_>>()
                .join(", ")
        })
        .unwrap_or_default();
    let by_suffix = if by.is_empty() {
        String::new()
    } else {
        format!(", by {by}")
    };
    let mut written = Vec::new();

    for plot in SERIES_PLOTS {
        let mut panels = Vec::new();
        for scene in &scenes {
            let mut groups = Vec::new();
            for (label, members) in scene_groups(&rows, scene) {
                let mut curves = Vec::new();
                for row in members {
                    let path = row.dir.join(plot.file);
                    if path.is_file()
                        && let Some(curve) =
                            read_curve(&path, plot.column, plot.scale).map_err(PlotError::Series)?
                    {
                        curves.push(curve);
                    }
                }
                if let Some(b) = band(&curves) {
                    groups.push((label, b));
                }
            }
            if !groups.is_empty() {
                panels.push(BandPanel {
                    title: format!("{}: {scene}{by_suffix}", plot.title),
                    groups,
                });
            }
        }
        if !panels.is_empty() {
            let figure = BandFigure {
                y_label: plot.y_label.to_owned(),
                panels,
            };
            written.extend(save(&figure, &out.join(plot.name))?);
        }
    }

    for plot in STRIP_PLOTS {
        let mut panels = Vec::new();
        for scene in &scenes {
            let groups: Vec<(String, Vec<f64>)> = scene_groups(&rows, scene)
                .into_iter()
                .map(|(label, members)| {
                    let values = members
                        .iter()
                        .filter_map(|r| r.summary.get(plot.field).and_then(Cell::as_f64))
                        .map(|v| v * plot.scale)
                        .collect();
                    (label, values)
                })
                .collect();
            if groups.iter().any(|(_, v)| !v.is_empty()) {
                panels.push(StripPanel {
                    title: format!("{}: {scene}", plot.title),
                    groups,
                });
            }
        }
        if !panels.is_empty() {
            let figure = StripFigure {
                x_label: by.clone(),
                y_label: plot.y_label.to_owned(),
                panels,
            };
            written.extend(save(&figure, &out.join(plot.name))?);
        }
    }
    Ok(written)
}
