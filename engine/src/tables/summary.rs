//! The summary table: per scene x grid combination (in the EAAE protocol, scene x strategy),
//! the mean, standard deviation, minimum and maximum of every numeric summary field over the
//! runs that did not fail.
//!
//! The Markdown form is laid out the way the EAAE thesis compares its methods (Table 6.3): one
//! table per scene, the compared combinations side by side as columns, one metric per row,
//! each cell `mean ± std [min, max]` over the seeds. The CSV form is tidy: one row per group,
//! `<field>_mean`, `_std`, `_min`, `_max` and `_n` columns per field.
//!
//! The standard deviation is the sample one (divisor n - 1), as a spread over a handful of
//! seeds is reported; it is empty for fewer than two values. Failed runs are counted but left
//! out of the statistics (their metrics are missing or cut short). `wall_time_s` is left out;
//! the decision times (`decision_ms_p50`, `decision_ms_p95`) are kept, as the thesis reports
//! them (Table 6.2), and are the only statistics that are not a pure function of the plan.

use super::cells::Cell;
use super::results::{RunRow, group_by};
use std::fmt::Write as _;

/// Summary fields that are not statistics of a run's results.
const NOT_METRICS: [&str; 2] = ["seed", "wall_time_s"];

/// How metrics are named in the Markdown table; a field without a label keeps its name.
/// A new metric gets its label with one line here.
pub const METRIC_LABELS: &[(&str, &str)] = &[
    ("mission_time_s", "Mission time (s)"),
    ("energy_j", "Energy (J)"),
    ("avg_power_w", "Average power (W)"),
    ("power_std_w", "Power std (W)"),
    ("peak_power_w", "Peak power (W)"),
    ("explored_fraction", "Explored fraction"),
    ("entropy_known_bits", "Entropy, known voxels (bit)"),
    ("entropy_box_bits", "Entropy, whole box (bit)"),
    ("uncertainty_mean", "Mean uncertainty"),
    ("map_accuracy", "Map accuracy"),
    ("path_length_m", "Path length (m)"),
    ("time_to_explored_90_s", "Time to 90 % explored (s)"),
    ("time_to_explored_99_s", "Time to 99 % explored (s)"),
];

/// Statistics of one field over one group's runs.
#[derive(Debug, Clone, PartialEq)]
pub struct FieldStats {
    pub field: String,
    /// Runs that have a value for the field.
    pub n: usize,
    pub mean: f64,
    pub std: Option<f64>,
    pub min: f64,
    pub max: f64,
}

impl FieldStats {
    /// `None` for no values.
    pub fn of(field: &str, values: &[f64]) -> Option<Self> {
        let n = values.len();
        if n == 0 {
            return None;
        }
        // Shifted by the first value: equal values give exactly zero spread, and large
        // offsets (voxel counts) lose no precision.
        let shift = values[0];
        let sum: f64 = values.iter().map(|v| v - shift).sum();
        let mean = shift + sum / n as f64;
        let std = (n >= 2).then(|| {
            let squares: f64 = values.iter().map(|v| (v - shift).powi(2)).sum();
            ((squares - sum * sum / n as f64).max(0.0) / (n - 1) as f64).sqrt()
        });
        Some(Self {
            field: field.to_owned(),
            n,
            mean,
            std,
            min: values.iter().copied().fold(f64::INFINITY, f64::min),
            max: values.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        })
    }
}

/// One group of runs: a scene and one combination of grid values.
#[derive(Debug, Clone, PartialEq)]
pub struct GroupSummary {
    pub scene: String,
    /// Grid values (path, value as text), in plan order.
    pub coordinates: Vec<(String, String)>,
    pub runs: usize,
    pub failed: usize,
    /// One entry per metric of the table (`None`: no run of the group has the field).
    pub stats: Vec<Option<FieldStats>>,
}

/// The summary of a sweep: the metric fields and one entry per group.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SummaryTable {
    pub metrics: Vec<String>,
    pub groups: Vec<GroupSummary>,
}

/// Groups `rows` (in plan order, so groups come in plan order) and computes the statistics.
pub fn summarise(rows: &[RunRow]) -> SummaryTable {
    // Fields in summary order (first appearance), kept if any run has a number there.
    let mut fields: Vec<&str> = Vec::new();
    for row in rows {
        for (name, _) in &row.summary.0 {
            if !fields.contains(&name.as_str()) {
                fields.push(name);
            }
        }
    }
    let metrics: Vec<String> = fields
        .into_iter()
        .filter(|name| !NOT_METRICS.contains(name))
        .filter(|name| {
            rows.iter()
                .any(|r| r.summary.get(name).and_then(Cell::as_f64).is_some())
        })
        .map(str::to_owned)
        .collect();
    let groups = group_by(rows, |r| r.group_key())
        .into_iter()
        .map(|((scene, coordinates), members)| {
            let good: Vec<&&RunRow> = members.iter().filter(|r| !r.failed()).collect();
            let stats = metrics
                .iter()
                .map(|field| {
                    let values: Vec<f64> = good
                        .iter()
                        .filter_map(|r| r.summary.get(field).and_then(Cell::as_f64))
                        .collect();
                    FieldStats::of(field, &values)
                })
                .collect();
            GroupSummary {
                scene,
                coordinates,
                runs: members.len(),
                failed: members.len() - good.len(),
                stats,
            }
        })
        .collect();
    SummaryTable { metrics, groups }
}

/// The summary as CSV: `scene`, the grid paths, `runs`, `failed`, then per metric
/// `_n`, `_mean`, `_std`, `_min`, `_max`.
pub fn to_csv(table: &SummaryTable) -> Result<Vec<u8>, csv::Error> {
    let paths: Vec<String> = table
        .groups
        .first()
        .map(|g| g.coordinates.iter().map(|(p, _)| p.clone()).collect())
        .unwrap_or_default();
    let mut header = vec!["scene".to_owned()];
    header.extend(paths.iter().cloned());
    header.extend(["runs".to_owned(), "failed".to_owned()]);
    for m in &table.metrics {
        for stat in ["n", "mean", "std", "min", "max"] {
            header.push(format!("{m}_{stat}"));
        }
    }
    let mut writer = csv::Writer::from_writer(Vec::new());
    writer.write_record(&header)?;
    for g in &table.groups {
        let mut record = vec![g.scene.clone()];
        record.extend(paths.iter().map(|p| {
            g.coordinates
                .iter()
                .find(|(q, _)| q == p)
                .map(|(_, v)| v.clone())
                .unwrap_or_default()
        }));
        record.extend([g.runs.to_string(), g.failed.to_string()]);
        for stats in &g.stats {
            match stats {
                Some(s) => record.extend([
                    s.n.to_string(),
                    s.mean.to_string(),
                    s.std.map(|v| v.to_string()).unwrap_or_default(),
                    s.min.to_string(),
                    s.max.to_string(),
                ]),
                None => record.extend([
                    "0".to_owned(),
                    String::new(),
                    String::new(),
                    String::new(),
                    String::new(),
                ]),
            }
        }
        writer.write_record(&record)?;
    }
    writer
        .into_inner()
        .map_err(|e| csv::Error::from(std::io::Error::other(e.to_string())))
}

/// A number with four significant digits, all integer digits kept up to 1e9 (voxel counts),
/// scientific beyond or below 1e-3.
pub fn format_number(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    let magnitude = x.abs().log10().floor() as i32;
    if !(-3..9).contains(&magnitude) {
        return format!("{x:.3e}");
    }
    let decimals = (3 - magnitude).max(0) as usize;
    format!("{x:.decimals$}")
}

/// `mean ± std [min, max]`, with `(n = k)` when not every counted run has the field.
fn cell_text(stats: &Option<FieldStats>, counted: usize) -> String {
    let Some(s) = stats else {
        return "–".to_owned();
    };
    let mut text = format_number(s.mean);
    if let Some(std) = s.std {
        let _ = write!(text, " ± {}", format_number(std));
    }
    if s.n >= 2 {
        let _ = write!(
            text,
            " [{}, {}]",
            format_number(s.min),
            format_number(s.max)
        );
    }
    if s.n < counted {
        let _ = write!(text, " (n = {})", s.n);
    }
    text
}

fn label(field: &str) -> String {
    METRIC_LABELS
        .iter()
        .find(|(f, _)| *f == field)
        .map_or_else(|| format!("`{field}`"), |(_, l)| (*l).to_owned())
}

/// The summary as Markdown: a section per scene, combinations as columns, metrics as rows.
pub fn to_markdown(table: &SummaryTable, title: &str) -> String {
    let mut out = format!(
        "# {title}\n\nEach cell: mean ± sample std [min, max] over the runs that did not fail.\n"
    );
    let mut scenes: Vec<&str> = Vec::new();
    for g in &table.groups {
        if !scenes.contains(&g.scene.as_str()) {
            scenes.push(&g.scene);
        }
    }
    for scene in scenes {
        let groups: Vec<&GroupSummary> = table.groups.iter().filter(|g| g.scene == scene).collect();
        let keys: Vec<String> = groups[0]
            .coordinates
            .iter()
            .map(|(p, _)| p.rsplit('.').next().unwrap_or(p).to_owned())
            .collect();
        let corner = if keys.is_empty() {
            "metric".to_owned()
        } else {
            format!("metric \\ {}", keys.join(", "))
        };
        let heads: Vec<String> = groups
            .iter()
            .map(|g| {
                if g.coordinates.is_empty() {
                    "all runs".to_owned()
                } else {
                    g.coordinates
                        .iter()
                        .map(|(_, v)| v.as_str())
                        .collect::<Vec<_>>()
                        .join(", ")
                }
            })
            .collect();
        let _ = write!(
            out,
            "\n## {scene}\n\n| {corner} | {} |\n|---|",
            heads.join(" | ")
        );
        out.push_str(&"---|".repeat(groups.len()));
        out.push('\n');
        let counts: Vec<String> = groups
            .iter()
            .map(|g| format!("{} ({})", g.runs, g.failed))
            .collect();
        let _ = writeln!(out, "| runs (failed) | {} |", counts.join(" | "));
        for (i, field) in table.metrics.iter().enumerate() {
            if groups.iter().all(|g| g.stats[i].is_none()) {
                continue;
            }
            let cells: Vec<String> = groups
                .iter()
                .map(|g| cell_text(&g.stats[i], g.runs - g.failed))
                .collect();
            let _ = writeln!(out, "| {} | {} |", label(field), cells.join(" | "));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tables::runs::tests::row;

    fn rows() -> Vec<RunRow> {
        let s = |time: f64, acc: &str, outcome: &str| {
            format!(
                r#"{{"scenario": "x", "seed": 1, "outcome": "{outcome}", "mission_time_s": {time}, "map_accuracy": {acc}, "wall_time_s": 9.0}}"#
            )
        };
        vec![
            row(0, "room", 1.0, 0, &s(10.0, "0.5", "complete")),
            row(1, "room", 1.0, 1, &s(12.0, "null", "time_limit")),
            row(2, "room", 1.0, 2, &s(14.0, "0.7", "complete")),
            row(3, "room", 2.0, 0, &s(6.0, "0.9", "complete")),
            row(
                4,
                "room",
                2.0,
                1,
                r#"{"scenario": "room", "seed": 1, "outcome": "failed", "reason": "refused"}"#,
            ),
            row(5, "hall", 1.0, 0, &s(20.0, "0.8", "complete")),
        ]
    }

    #[test]
    fn statistics_per_scene_and_combination() {
        let table = summarise(&rows());
        assert_eq!(table.metrics, ["mission_time_s", "map_accuracy"]);
        let keys: Vec<(String, String, usize, usize)> = table
            .groups
            .iter()
            .map(|g| {
                (
                    g.scene.clone(),
                    g.coordinates[0].1.clone(),
                    g.runs,
                    g.failed,
                )
            })
            .collect();
        assert_eq!(
            keys,
            [
                ("room".into(), "1.0".into(), 3, 0),
                ("room".into(), "2.0".into(), 2, 1),
                ("hall".into(), "1.0".into(), 1, 0)
            ]
        );
        // 10, 12, 14: mean 12, sample std sqrt(((-2)^2 + 0 + 2^2) / 2) = 2.
        let time = table.groups[0].stats[0].clone().unwrap();
        assert_eq!(
            (time.n, time.mean, time.std, time.min, time.max),
            (3, 12.0, Some(2.0), 10.0, 14.0)
        );
        // A field some runs lack: counted over those that have it.
        let accuracy = table.groups[0].stats[1].clone().unwrap();
        assert_eq!(accuracy.n, 2);
        assert!((accuracy.mean - 0.6).abs() < 1e-12);
        assert!((accuracy.std.unwrap() - 0.02f64.sqrt()).abs() < 1e-12);
        // The failed run is left out; one value has no spread.
        let lone = table.groups[1].stats[0].clone().unwrap();
        assert_eq!((lone.n, lone.mean, lone.std), (1, 6.0, None));
    }

    #[test]
    fn equal_values_have_no_spread() {
        let s = FieldStats::of("x", &[56.233333333333334; 3]).unwrap();
        assert_eq!((s.mean, s.std), (56.233333333333334, Some(0.0)));
        let big = FieldStats::of("x", &[1e9 + 1.0, 1e9 + 3.0]).unwrap();
        assert_eq!((big.mean, big.std), (1e9 + 2.0, Some(2f64.sqrt())));
    }

    #[test]
    fn csv_has_one_row_per_group() {
        let csv = String::from_utf8(to_csv(&summarise(&rows())).unwrap()).unwrap();
        let lines: Vec<&str> = csv.lines().collect();
        assert_eq!(
            lines[0],
            "scene,uav.0.behaviour.speed,runs,failed,mission_time_s_n,mission_time_s_mean,\
             mission_time_s_std,mission_time_s_min,mission_time_s_max,map_accuracy_n,\
             map_accuracy_mean,map_accuracy_std,map_accuracy_min,map_accuracy_max"
        );
        let fields: Vec<&str> = lines[1].split(',').collect();
        assert_eq!(fields[..10].join(","), "room,1.0,3,0,3,12,2,10,14,2");
        let number = |i: usize| fields[i].parse::<f64>().unwrap();
        assert!((number(10) - 0.6).abs() < 1e-12);
        assert!((number(11) - 0.02f64.sqrt()).abs() < 1e-12);
        assert_eq!(fields[12..], ["0.5", "0.7"]);
        assert_eq!(lines[2], "room,2.0,2,1,1,6,,6,6,1,0.9,,0.9,0.9");
        assert_eq!(lines.len(), 4);
    }

    #[test]
    fn markdown_puts_combinations_side_by_side_per_scene() {
        let md = to_markdown(&summarise(&rows()), "demo");
        let expected = "\n## room\n\n\
            | metric \\ speed | 1.0 | 2.0 |\n\
            |---|---|---|\n\
            | runs (failed) | 3 (0) | 2 (1) |\n\
            | Mission time (s) | 12.00 ± 2.000 [10.00, 14.00] | 6.000 |\n\
            | Map accuracy | 0.6000 ± 0.1414 [0.5000, 0.7000] (n = 2) | 0.9000 |\n";
        assert!(md.contains(expected), "{md}");
        assert!(md.contains("\n## hall\n"), "{md}");
    }

    #[test]
    fn numbers_keep_four_significant_digits() {
        assert_eq!(format_number(12.346), "12.35");
        assert_eq!(format_number(0.92346), "0.9235");
        assert_eq!(format_number(143.25), "143.2");
        assert_eq!(format_number(12345.0), "12345");
        assert_eq!(format_number(644419.4), "644419");
        assert_eq!(format_number(1234567890.0), "1.235e9");
        assert_eq!(format_number(0.0001234), "1.234e-4");
        assert_eq!(format_number(0.0), "0");
    }
}
