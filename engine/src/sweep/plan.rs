//! Sweep plans: which scenarios, which overrides and which seeds (TOML).
//!
//! ```toml
//! name = "speeds"                       # optional; the plan file's stem by default
//! seeds = 5                             # seeds 0..5, or a list: seeds = [1, 7, 9]
//!
//! [[scenario]]
//! file = "pillars_scripted.toml"        # relative to this plan file
//! name = "pillars"                      # optional label; the file stem by default
//!
//! [set]                                 # fixed overrides, applied to every run
//! "outputs.export_map" = false
//!
//! [grid]                                # one run per combination of these values
//! "uav.0.behaviour.speed" = [1.0, 1.5]
//! "uav.0.behaviour.strategy" = ["eaae", "classic", "nearest"]
//! ```
//!
//! Keys of `[set]` and `[grid]` are field paths of the scenario (`uav.0.behaviour.speed` or
//! `uav[0].behaviour.speed`). Tables nest: `[grid.uav.0.behaviour]` with `speed = [...]` names
//! the same path. A grid value is always a list of values, and each element, whatever its type
//! (a number, a string, a whole table), replaces the value at the path. Grid paths are taken in
//! alphabetical order (TOML tables do not keep their order); the run set does not depend on it.

use super::apply::Override;
use super::path::{OverridePath, Step};
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use thiserror::Error;

/// Most runs a plan may have. A sweep expands its plan into runs before starting any (their
/// ids say which are finished): a million runs of two grid paths took 1.2 GB and 11 s before
/// the first run started (2026-12-05, release build), and a million runs of even a second each
/// are eleven days of one core. A bigger plan is a mistake, or several plans.
pub const MAX_RUNS: usize = 1_000_000;

/// A plan that parsed and makes sense.
#[derive(Debug, Clone, PartialEq)]
pub struct Plan {
    pub name: String,
    /// The folder scenario files are resolved against (the plan file's folder).
    pub base_dir: PathBuf,
    pub scenarios: Vec<PlanScenario>,
    /// Overrides applied to every run, before the grid's.
    pub set: Vec<Override>,
    /// The varied paths, each with its values.
    pub grid: Vec<Axis>,
    pub seeds: Vec<u64>,
    /// The plan file as written; kept with the results as their record.
    pub text: String,
}

/// One scenario of a plan.
#[derive(Debug, Clone, PartialEq)]
pub struct PlanScenario {
    /// The label of the scenario in run names and tables (the `scene` column).
    pub name: String,
    /// The file as the plan writes it.
    pub file: PathBuf,
}

/// One varied path and the values it takes.
#[derive(Debug, Clone, PartialEq)]
pub struct Axis {
    pub path: OverridePath,
    pub values: Vec<toml::Value>,
}

/// Why a plan is refused.
#[derive(Debug, Error)]
pub enum PlanError {
    #[error("cannot read the plan {path}: {source}")]
    Read {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{path}: {message}")]
    Invalid { path: PathBuf, message: String },
}

/// The plan file's shape, before its meaning is checked.
#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct PlanFile {
    name: Option<String>,
    #[serde(rename = "scenario", default)]
    scenarios: Vec<ScenarioEntry>,
    seeds: Option<toml::Value>,
    #[serde(default)]
    set: toml::Table,
    #[serde(default)]
    grid: toml::Table,
}

#[derive(serde::Deserialize)]
#[serde(
    deny_unknown_fields,
    expecting = "a [[scenario]] table: `file = \"path/to/scenario.toml\"` and an optional `name`"
)]
struct ScenarioEntry {
    file: PathBuf,
    name: Option<String>,
}

impl Plan {
    /// Reads and checks the plan file at `path`.
    pub fn load(path: &Path) -> Result<Self, PlanError> {
        let text = std::fs::read_to_string(path).map_err(|source| PlanError::Read {
            path: path.to_owned(),
            source,
        })?;
        Self::parse(&text, path)
    }

    /// Checks plan `text`; `path` names it in messages and gives the base folder and the
    /// default name.
    pub fn parse(text: &str, path: &Path) -> Result<Self, PlanError> {
        let invalid = |message: String| PlanError::Invalid {
            path: path.to_owned(),
            message,
        };
        let file: PlanFile =
            toml::from_str(text).map_err(|e| invalid(e.to_string().trim_end().to_owned()))?;
        let stem = |p: &Path| {
            p.file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_default()
        };
        let name = file.name.unwrap_or_else(|| stem(path));

        if file.scenarios.is_empty() {
            return Err(invalid(
                "the plan names no scenario: add a [[scenario]] with a `file`".to_owned(),
            ));
        }
        let mut scenarios = Vec::new();
        let mut labels = BTreeSet::new();
        for entry in file.scenarios {
            let label = entry.name.unwrap_or_else(|| stem(&entry.file));
            if label.is_empty() {
                return Err(invalid("a [[scenario]] has an empty name".to_owned()));
            }
            if !labels.insert(label.clone()) {
                return Err(invalid(format!(
                    "two scenarios are named `{label}`: give one a different `name`"
                )));
            }
            scenarios.push(PlanScenario {
                name: label,
                file: entry.file,
            });
        }

        let seeds = seeds(file.seeds).map_err(invalid)?;

        let mut set = Vec::new();
        flatten(
            &file.set,
            &OverridePath::from_steps(&[]),
            &mut |path, value| {
                set.push(Override {
                    path,
                    value: value.clone(),
                });
                Ok(())
            },
        )
        .map_err(|e| invalid(format!("[set]: {e}")))?;

        let mut grid = Vec::new();
        flatten(
            &file.grid,
            &OverridePath::from_steps(&[]),
            &mut |path, value| {
                let toml::Value::Array(values) = value else {
                    return Err(format!(
                        "`{path}` must be a list of the values to try, e.g. `[{value}]`"
                    ));
                };
                if values.is_empty() {
                    return Err(format!("`{path}` has no value to try"));
                }
                let mut seen = BTreeSet::new();
                for v in values {
                    if !seen.insert(v.to_string()) {
                        return Err(format!("`{path}` lists {v} twice"));
                    }
                }
                grid.push(Axis {
                    path,
                    values: values.clone(),
                });
                Ok(())
            },
        )
        .map_err(|e| invalid(format!("[grid]: {e}")))?;
        one_override_per_place(&set, &grid).map_err(invalid)?;

        check_size(scenarios.len(), &grid, seeds.len()).map_err(invalid)?;

        let base_dir = match path.parent() {
            Some(parent) if !parent.as_os_str().is_empty() => parent.to_owned(),
            _ => PathBuf::from("."),
        };
        Ok(Self {
            name,
            base_dir,
            scenarios,
            set,
            grid,
            seeds,
            text: text.to_owned(),
        })
    }

    /// How many runs the whole plan has.
    pub fn run_count(&self) -> usize {
        self.scenarios.len()
            * self.grid.iter().map(|a| a.values.len()).product::<usize>()
            * self.seeds.len()
    }
}

/// Refuses overrides of one place twice: a path written twice in a table (once dotted, once
/// nested), in both `[set]` and `[grid]`, or inside another path (`uav.0.behaviour.speed`
/// inside `uav.0.behaviour`). Applied in turn, one would overwrite the other, and the runs'
/// recorded coordinates would name a value some of them never flew.
fn one_override_per_place(set: &[Override], grid: &[Axis]) -> Result<(), String> {
    let mut paths: Vec<(&OverridePath, &str)> = set
        .iter()
        .map(|o| (&o.path, "[set]"))
        .chain(grid.iter().map(|a| (&a.path, "[grid]")))
        .collect();
    // In lexicographic order a path comes right before the paths inside it, and every path
    // between the two lies inside it too: comparing neighbours finds any overlap.
    paths.sort();
    for pair in paths.windows(2) {
        let [(outer, outer_table), (inner, inner_table)] = pair else {
            continue;
        };
        if !inner.steps().starts_with(outer.steps()) {
            continue;
        }
        return Err(if outer == inner && outer_table == inner_table {
            format!("{outer_table}: `{outer}` is written twice (once dotted, once nested?)")
        } else if outer == inner {
            format!(
                "`{outer}` is in both [set] and [grid]: a run takes one value for it; \
                 keep it in one of them"
            )
        } else {
            format!(
                "{inner_table} `{inner}` lies inside {outer_table} `{outer}`: one would \
                 overwrite the other; override each place once (the fields of `{outer}` \
                 one by one, or `{outer}` whole)"
            )
        });
    }
    Ok(())
}

/// Refuses a plan of more than [`MAX_RUNS`] runs, naming what multiplies up to its size (the
/// count saturates: 20 axes of 100 values overflow any integer).
fn check_size(scenarios: usize, grid: &[Axis], seeds: usize) -> Result<(), String> {
    let plural = |n: usize, what: &str| format!("{n} {what}{}", if n == 1 { "" } else { "s" });
    let mut factors = vec![plural(scenarios, "scenario")];
    factors.extend(
        grid.iter()
            .map(|axis| format!("{} of `{}`", plural(axis.values.len(), "value"), axis.path)),
    );
    factors.push(plural(seeds, "seed"));
    let count = grid
        .iter()
        .map(|axis| axis.values.len())
        .chain([scenarios, seeds])
        .try_fold(1usize, usize::checked_mul);
    match count {
        Some(count) if count <= MAX_RUNS => Ok(()),
        _ => Err(format!(
            "the plan has {} runs ({}), more than the {MAX_RUNS} a plan may have: \
             use fewer seeds or grid values, or split it into several plans",
            count.map_or_else(|| format!("more than {}", usize::MAX), |c| c.to_string()),
            factors.join(" x "),
        )),
    }
}

/// `seeds = N` (seeds 0..N) or `seeds = [..]` (distinct, non-negative).
fn seeds(value: Option<toml::Value>) -> Result<Vec<u64>, String> {
    let expected = "`seeds` must be a count (seeds = 5 runs seeds 0 to 4) or a list of seeds";
    let seed = |v: &toml::Value| {
        v.as_integer()
            .and_then(|i| u64::try_from(i).ok())
            .ok_or_else(|| format!("{expected}; a seed is a whole number >= 0, not {v}"))
    };
    let list = match value {
        None => return Err(format!("the plan has no seeds: {expected}")),
        Some(toml::Value::Array(items)) => items.iter().map(seed).collect::<Result<Vec<_>, _>>()?,
        Some(count @ toml::Value::Integer(_)) => {
            // Checked before the list is made: `seeds = 1000000000` would take 8 GB.
            let count = seed(&count)?;
            if count > MAX_RUNS as u64 {
                return Err(format!(
                    "`seeds = {count}` is more runs than a plan may have ({MAX_RUNS})"
                ));
            }
            (0..count).collect()
        }
        Some(other) => return Err(format!("{expected}, not {other}")),
    };
    if list.is_empty() {
        return Err(format!("the plan runs no seed: {expected}"));
    }
    let distinct: BTreeSet<u64> = list.iter().copied().collect();
    if distinct.len() != list.len() {
        return Err("`seeds` lists a seed twice".to_owned());
    }
    Ok(list)
}

/// Calls `leaf` with every non-table value of `table` and its full path; keys are paths
/// themselves (`"uav.0.speed"`), and nested tables extend them.
fn flatten(
    table: &toml::Table,
    prefix: &OverridePath,
    leaf: &mut dyn FnMut(OverridePath, &toml::Value) -> Result<(), String>,
) -> Result<(), String> {
    for (key, value) in table {
        let path = prefix.join(&OverridePath::parse(key).map_err(|e| e.to_string())?);
        if let Some(first) = path.steps().first()
            && matches!(first, Step::Index(_))
        {
            return Err(format!("`{path}` starts with a list index"));
        }
        match value {
            toml::Value::Table(inner) => flatten(inner, &path, leaf)?,
            other => leaf(path, other)?,
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<Plan, String> {
        Plan::parse(text, Path::new("plans/speeds.toml")).map_err(|e| e.to_string())
    }

    #[test]
    fn reads_scenarios_set_grid_and_seed_count() {
        let plan = parse(
            r#"
            seeds = 3
            [[scenario]]
            file = "../scenarios/pillars_scripted.toml"
            [[scenario]]
            file = "room.toml"
            name = "room"
            [set]
            "outputs.export_map" = false
            [grid]
            "uav.0.behaviour.speed" = [1.0, 1.5]
            map = { resolution = [0.1, 0.2] }
            "#,
        )
        .unwrap();
        assert_eq!(plan.name, "speeds");
        assert_eq!(plan.base_dir, Path::new("plans"));
        let names: Vec<&str> = plan.scenarios.iter().map(|s| s.name.as_str()).collect();
        assert_eq!(names, ["pillars_scripted", "room"]);
        assert_eq!(plan.seeds, [0, 1, 2]);
        assert_eq!(plan.set.len(), 1);
        assert_eq!(plan.set[0].path.to_string(), "outputs.export_map");
        assert_eq!(plan.set[0].value, toml::Value::Boolean(false));
        let axes: Vec<(String, usize)> = plan
            .grid
            .iter()
            .map(|a| (a.path.to_string(), a.values.len()))
            .collect();
        // Alphabetical: `map` before `uav.0...`.
        assert_eq!(
            axes,
            [
                ("map.resolution".to_owned(), 2),
                ("uav.0.behaviour.speed".to_owned(), 2)
            ]
        );
        assert_eq!(plan.run_count(), 2 * 2 * 2 * 3);
    }

    #[test]
    fn seed_lists_and_whole_table_values() {
        let plan = parse(
            r#"
            seeds = [7, 3]
            [[scenario]]
            file = "a.toml"
            [grid]
            "uav[0].behaviour" = [{ kind = "scripted", speed = 1.0, waypoints = [] }]
            "#,
        )
        .unwrap();
        assert_eq!(plan.seeds, [7, 3]);
        assert_eq!(plan.grid[0].path.to_string(), "uav.0.behaviour");
        assert!(plan.grid[0].values[0].is_table());
        assert_eq!(plan.run_count(), 2);
    }

    #[test]
    fn refusals_say_what_is_wrong() {
        let cases = [
            ("seeds = 2", "names no scenario"),
            ("[[scenario]]\nfile = \"a.toml\"", "has no seeds"),
            ("seeds = -1\n[[scenario]]\nfile = \"a.toml\"", "not -1"),
            ("seeds = [1, 1]\n[[scenario]]\nfile = \"a.toml\"", "twice"),
            ("seeds = 0\n[[scenario]]\nfile = \"a.toml\"", "runs no seed"),
            (
                "seeds = 1\n[[scenario]]\nfile = \"a.toml\"\n[[scenario]]\nfile = \"x/a.toml\"",
                "two scenarios are named `a`",
            ),
            (
                "seeds = 1\n[[scenario]]\nfile = \"a.toml\"\n[grid]\n\"uav.0.speed\" = 2.0",
                "must be a list of the values to try, e.g. `[2.0]`",
            ),
            (
                "seeds = 1\n[[scenario]]\nfile = \"a.toml\"\n[grid]\n\"x\" = []",
                "`x` has no value to try",
            ),
            (
                "seeds = 1\n[[scenario]]\nfile = \"a.toml\"\n[grid]\n\"x\" = [1, 1]",
                "`x` lists 1 twice",
            ),
            (
                "seeds = 1\n[[scenario]]\nfile = \"a.toml\"\n[grid]\n\"a[\" = [1]",
                "is not a field path",
            ),
            ("seeds = 1\nscenarios = []", "unknown field `scenarios`"),
            (
                "seeds = 1\nscenario = [\"a.toml\"]",
                "expected a [[scenario]] table: `file = \"path/to/scenario.toml\"`",
            ),
        ];
        for (text, expected) in cases {
            let error = parse(text).expect_err(text);
            assert!(
                error.starts_with("plans/speeds.toml: ") && error.contains(expected),
                "{text:?}: {error}"
            );
        }
    }

    /// A grid of `axes` paths of `values` values each.
    fn grid(axes: usize, values: usize) -> String {
        let list: Vec<String> = (0..values).map(|v| v.to_string()).collect();
        (0..axes)
            .map(|a| format!("\"x{a}\" = [{}]\n", list.join(", ")))
            .collect()
    }

    #[test]
    fn plans_beyond_the_run_limit_are_refused_before_they_are_expanded() {
        // Seeds first: the list itself would be 8 GB.
        let error = parse("seeds = 1000000000\n[[scenario]]\nfile = \"a.toml\"").unwrap_err();
        assert!(
            error.contains("`seeds = 1000000000` is more runs than a plan may have (1000000)"),
            "{error}"
        );
        let error = parse(&format!(
            "seeds = 2\n[[scenario]]\nfile = \"a.toml\"\n[grid]\n{}",
            grid(4, 100)
        ))
        .unwrap_err();
        assert!(
            error.starts_with(
                "plans/speeds.toml: the plan has 200000000 runs (1 scenario x \
                               100 values of `x0` x 100 values of `x1` x 100 values of `x2` x \
                               100 values of `x3` x 2 seeds), more than the 1000000"
            ),
            "{error}"
        );
        // A count beyond any integer is still refused, not wrapped around.
        let error = parse(&format!(
            "seeds = 1\n[[scenario]]\nfile = \"a.toml\"\n[grid]\n{}",
            grid(12, 100)
        ))
        .unwrap_err();
        assert!(error.contains("the plan has more than "), "{error}");
        // The limit itself is allowed.
        let plan = parse(&format!(
            "seeds = 100\n[[scenario]]\nfile = \"a.toml\"\n[grid]\n{}",
            grid(2, 100)
        ))
        .unwrap();
        assert_eq!(plan.run_count(), MAX_RUNS);
    }

    #[test]
    fn the_same_path_twice_is_refused() {
        let error = parse(
            "seeds = 1\n[[scenario]]\nfile = \"a.toml\"\n[grid]\n\"map.resolution\" = [1]\n\
             map = { resolution = [2] }",
        )
        .unwrap_err();
        assert!(
            error.contains("[grid]: `map.resolution` is written twice"),
            "{error}"
        );
    }

    #[test]
    fn a_place_overridden_twice_is_refused() {
        let plan = |set: &str, grid: &str| {
            parse(&format!(
                "seeds = 1\n[[scenario]]\nfile = \"a.toml\"\n[set]\n{set}\n[grid]\n{grid}"
            ))
        };
        let cases = [
            (
                "\"map.resolution\" = 1\nmap = { resolution = 2 }",
                "",
                "[set]: `map.resolution` is written twice",
            ),
            (
                "\"uav.0.behaviour.strategy\" = \"tour\"",
                "\"uav[0].behaviour.strategy\" = [\"eaae\"]",
                "`uav.0.behaviour.strategy` is in both [set] and [grid]",
            ),
            (
                // A table in [set] sets its fields one by one.
                "\"uav.0.behaviour\" = { strategy = \"tour\" }",
                "\"uav.0.behaviour.strategy\" = [\"eaae\"]",
                "`uav.0.behaviour.strategy` is in both [set] and [grid]",
            ),
            (
                "\"uav.0.behaviour.speed\" = 2.0",
                "\"uav.0.behaviour\" = [{ kind = \"explore\" }]",
                "[set] `uav.0.behaviour.speed` lies inside [grid] `uav.0.behaviour`",
            ),
            (
                "",
                "\"uav.0\" = [{ name = \"a\" }]\n\"uav.0.name\" = [\"b\"]\n\"uav.1\" = [{}]",
                "[grid] `uav.0.name` lies inside [grid] `uav.0`",
            ),
        ];
        for (set, grid, expected) in cases {
            let error = plan(set, grid).expect_err(expected);
            assert!(error.contains(expected), "{expected}: {error}");
        }
        // Neighbours that only share a beginning are different places, and so are the
        // other fields of a table in [set].
        let accepted = plan(
            "\"uav.0.behaviour.speed\" = 2.0\n\"uav.0.behaviour.speeds\" = 1.0\n\
             \"uav.0.behaviour\" = { kind = \"explore\" }",
            "\"uav.0.behaviour.strategy\" = [\"eaae\"]\n\"uav.1.behaviour\" = [{}]",
        );
        assert!(accepted.is_ok(), "{accepted:?}");
    }
}
