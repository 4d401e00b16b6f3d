//! From a plan to its runs: every scenario x every grid combination x every seed, each with a
//! stable id, and the deterministic split of that list into shards.

use super::apply::Override;
use super::plan::Plan;
use serde::{Deserialize, Serialize};
use std::fmt;
use std::path::PathBuf;
use std::str::FromStr;
use thiserror::Error;

/// One run of a plan.
#[derive(Debug, Clone, PartialEq)]
pub struct RunSpec {
    /// Position in the plan's run list (scenario-major, then grid, then seed).
    pub index: usize,
    /// Stable name of the run: its folder under `runs/`. A pure function of the run's
    /// coordinates (scene, grid values, fixed overrides, seed), so the same run has the same
    /// id in a longer plan, on another machine, in another shard.
    pub id: String,
    pub scene: String,
    /// The scenario file, resolved against the plan's folder.
    pub scenario_file: PathBuf,
    /// Overrides to apply, in order: the plan's `[set]`, then this run's grid values.
    pub overrides: Vec<Override>,
    /// This run's grid values (path as the plan writes it, value).
    pub coordinates: Vec<(String, toml::Value)>,
    pub seed: u64,
}

/// `run.json`: what a run is, written into its folder before it starts, so a results folder
/// can be read without its plan.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RunCoordinates {
    pub index: usize,
    pub id: String,
    pub scene: String,
    /// The scenario file as the sweep read it.
    pub scenario: String,
    /// Grid values, in the plan's path order.
    pub coordinates: Vec<Coordinate>,
    pub seed: u64,
}

/// One grid value of a run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Coordinate {
    pub path: String,
    pub value: serde_json::Value,
}

impl RunSpec {
    pub fn record(&self) -> RunCoordinates {
        RunCoordinates {
            index: self.index,
            id: self.id.clone(),
            scene: self.scene.clone(),
            scenario: self.scenario_file.display().to_string(),
            coordinates: self
                .coordinates
                .iter()
                .map(|(path, value)| Coordinate {
                    path: path.clone(),
                    value: serde_json::to_value(value).unwrap_or(serde_json::Value::Null),
                })
                .collect(),
            seed: self.seed,
        }
    }
}

/// Every run of `plan`, in plan order: scenarios in file order, then grid combinations (the
/// last path varies fastest), then seeds.
pub fn expand(plan: &Plan) -> Vec<RunSpec> {
    let combinations = combinations(plan);
    let mut runs = Vec::with_capacity(plan.run_count());
    for scenario in &plan.scenarios {
        for combination in &combinations {
            for &seed in &plan.seeds {
                let coordinates: Vec<(String, toml::Value)> = plan
                    .grid
                    .iter()
                    .zip(combination)
                    .map(|(axis, value)| (axis.path.to_string(), (*value).clone()))
                    .collect();
                let mut overrides = plan.set.clone();
                overrides.extend(
                    plan.grid
                        .iter()
                        .zip(combination)
                        .map(|(axis, value)| Override {
                            path: axis.path.clone(),
                            value: (*value).clone(),
                        }),
                );
                runs.push(RunSpec {
                    index: runs.len(),
                    id: run_id(&scenario.name, &plan.set, &coordinates, seed),
                    scene: scenario.name.clone(),
                    scenario_file: plan.base_dir.join(&scenario.file),
                    overrides,
                    coordinates,
                    seed,
                });
            }
        }
    }
    runs
}

/// The grid's combinations, odometer order (last axis fastest); one empty combination for an
/// empty grid.
fn combinations(plan: &Plan) -> Vec<Vec<&toml::Value>> {
    let mut all: Vec<Vec<&toml::Value>> = vec![Vec::new()];
    for axis in &plan.grid {
        all = all
            .into_iter()
            .flat_map(|prefix| {
                axis.values.iter().map(move |value| {
                    let mut next = prefix.clone();
                    next.push(value);
                    next
                })
            })
            .collect();
    }
    all
}

/// Longest readable part of an id, before its hash.
const READABLE_MAX: usize = 96;

/// `pillars__speed=1.5__seed=3__9f2c1a7e`: scene, the last key and value of each grid path,
/// the seed, and a hash of the full coordinates (fixed overrides included) so that ids stay
/// distinct where the readable part is cut or ambiguous.
pub fn run_id(
    scene: &str,
    set: &[Override],
    coordinates: &[(String, toml::Value)],
    seed: u64,
) -> String {
    // Folders whose name starts with a dot are not runs (hidden files, merge's `.ID.partial`
    // copies), so a scene named `.hidden` or `../x` must not start its id with one.
    let mut readable: String = slug(scene);
    let dots = readable.len() - readable.trim_start_matches('.').len();
    readable.replace_range(..dots, &"_".repeat(dots));
    for (path, value) in coordinates {
        let key = path.rsplit('.').find(|k| k.parse::<usize>().is_err());
        let value = match value {
            toml::Value::String(s) => s.clone(),
            other => other.to_string(),
        };
        readable.push_str(&format!("__{}={}", slug(key.unwrap_or(path)), slug(&value)));
    }
    readable.push_str(&format!("__seed={seed}"));
    if readable.len() > READABLE_MAX {
        let mut cut = READABLE_MAX;
        while !readable.is_char_boundary(cut) {
            cut -= 1;
        }
        readable.truncate(cut);
    }
    // Unit separators keep the canonical text unambiguous.
    let mut canonical = format!("scene={scene}");
    for o in set {
        canonical.push_str(&format!("\u{1f}set:{}={}", o.path, o.value));
    }
    for (path, value) in coordinates {
        canonical.push_str(&format!("\u{1f}{path}={value}"));
    }
    canonical.push_str(&format!("\u{1f}seed={seed}"));
    format!("{readable}__{:08x}", fnv1a(canonical.as_bytes()) >> 32)
}

/// File-name-safe text: letters, digits, `.`, `-`, `_` and `=` stay, the rest becomes `_`.
fn slug(text: &str) -> String {
    text.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || matches!(c, '.' | '-' | '_' | '=') {
                c
            } else {
                '_'
            }
        })
        .collect()
}

/// 64-bit FNV-1a: a hash whose value is fixed by its definition (std's hasher may change
/// between Rust releases, and ids must not).
fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |hash, &byte| {
        (hash ^ u64::from(byte)).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

/// Part `index` (1-based) of `count` equal parts of a plan: `--shard 2/4`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shard {
    pub index: usize,
    pub count: usize,
}

#[derive(Debug, Clone, PartialEq, Eq, Error)]
#[error("`{0}` is not a shard: write i/N with 1 <= i <= N, e.g. 2/4")]
pub struct ShardError(pub String);

impl FromStr for Shard {
    type Err = ShardError;
    fn from_str(text: &str) -> Result<Self, ShardError> {
        let error = || ShardError(text.to_owned());
        let (i, n) = text.split_once('/').ok_or_else(error)?;
        let index: usize = i.trim().parse().map_err(|_| error())?;
        let count: usize = n.trim().parse().map_err(|_| error())?;
        if index == 0 || index > count {
            return Err(error());
        }
        Ok(Self { index, count })
    }
}

impl fmt::Display for Shard {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

impl Shard {
    /// Runs are dealt round-robin by plan index, so every shard gets a similar mix of scenes
    /// and grid values, and the shards 1..=N cover the plan exactly once.
    pub fn contains(&self, run_index: usize) -> bool {
        run_index % self.count == self.index - 1
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::BTreeSet;
    use std::path::Path;

    fn plan(text: &str) -> Plan {
        Plan::parse(text, Path::new("dir/p.toml")).unwrap()
    }

    const PLAN: &str = r#"
        seeds = [4, 9]
        [[scenario]]
        file = "a.toml"
        [[scenario]]
        file = "b.toml"
        [set]
        time_limit_s = 3.0
        [grid]
        "uav.0.behaviour.speed" = [1.0, 2.0]
        "uav.0.behaviour.strategy" = ["eaae", "nearest frontier"]
    "#;

    #[test]
    fn runs_are_scene_then_grid_then_seed() {
        let runs = expand(&plan(PLAN));
        assert_eq!(runs.len(), 16);
        let rows: Vec<String> = runs
            .iter()
            .take(5)
            .map(|r| {
                let values: Vec<String> =
                    r.coordinates.iter().map(|(_, v)| v.to_string()).collect();
                format!("{} {} {}", r.scene, values.join(" "), r.seed)
            })
            .collect();
        assert_eq!(
            rows,
            [
                "a 1.0 \"eaae\" 4",
                "a 1.0 \"eaae\" 9",
                "a 1.0 \"nearest frontier\" 4",
                "a 1.0 \"nearest frontier\" 9",
                "a 2.0 \"eaae\" 4",
            ]
        );
        assert_eq!(runs[8].scene, "b");
        assert_eq!(runs[8].scenario_file, Path::new("dir/b.toml"));
        assert!(runs.iter().enumerate().all(|(i, r)| r.index == i));
        // Fixed overrides first, then the grid's.
        let paths: Vec<String> = runs[0]
            .overrides
            .iter()
            .map(|o| o.path.to_string())
            .collect();
        assert_eq!(
            paths,
            [
                "time_limit_s",
                "uav.0.behaviour.speed",
                "uav.0.behaviour.strategy"
            ]
        );
    }

    #[test]
    fn ids_are_readable_distinct_and_stable() {
        let runs = expand(&plan(PLAN));
        let ids: BTreeSet<&str> = runs.iter().map(|r| r.id.as_str()).collect();
        assert_eq!(ids.len(), runs.len());
        assert!(
            runs[2]
                .id
                .starts_with("a__speed=1.0__strategy=nearest_frontier__seed=4__"),
            "{}",
            runs[2].id
        );
        // The hash is FNV-1a of the canonical coordinates: fixed forever.
        assert_eq!(fnv1a(b""), 0xcbf2_9ce4_8422_2325);
        assert_eq!(fnv1a(b"a"), 0xaf63_dc4c_8601_ec8c);
        // A longer plan keeps the ids of the runs it shares with a shorter one.
        let longer = PLAN.replace("[4, 9]", "[4, 9, 10]");
        let longer_ids: BTreeSet<String> =
            expand(&plan(&longer)).into_iter().map(|r| r.id).collect();
        assert!(ids.iter().all(|id| longer_ids.contains(*id)));
        // Another fixed override is another run.
        let other = PLAN.replace("time_limit_s = 3.0", "time_limit_s = 4.0");
        let other_ids: BTreeSet<String> = expand(&plan(&other)).into_iter().map(|r| r.id).collect();
        assert!(ids.iter().all(|id| !other_ids.contains(*id)));
    }

    #[test]
    fn ids_never_start_with_a_dot() {
        let set = [];
        let id = |scene: &str| run_id(scene, &set, &[], 1);
        assert!(
            id(".hidden").starts_with("_hidden__seed=1__"),
            "{}",
            id(".hidden")
        );
        assert!(id("../x").starts_with("___x__seed=1__"), "{}", id("../x"));
        assert!(id("a.b").starts_with("a.b__seed=1__"), "{}", id("a.b"));
        // The hash keeps the scene as written: `.hidden` and `_hidden` are two runs.
        assert_ne!(id(".hidden"), id("_hidden"));
    }

    #[test]
    fn no_grid_is_one_combination() {
        let runs = expand(&plan("seeds = 2\n[[scenario]]\nfile = \"a.toml\""));
        assert_eq!(runs.len(), 2);
        assert!(runs[0].coordinates.is_empty());
        assert!(runs[1].id.starts_with("a__seed=1__"));
    }

    #[test]
    fn shards_cover_the_plan_exactly_once() {
        let runs = expand(&plan(PLAN));
        for count in 1..=5 {
            let mut seen = vec![0; runs.len()];
            for index in 1..=count {
                let shard: Shard = format!("{index}/{count}").parse().unwrap();
                for run in runs.iter().filter(|r| shard.contains(r.index)) {
                    seen[run.index] += 1;
                }
            }
            assert!(seen.iter().all(|&n| n == 1), "{count} shards: {seen:?}");
        }
        let shard: Shard = "2/3".parse().unwrap();
        let picked: Vec<usize> = (0..8).filter(|&i| shard.contains(i)).collect();
        assert_eq!(picked, [1, 4, 7]);
    }

    #[test]
    fn shard_syntax() {
        assert_eq!("1/4".parse::<Shard>(), Ok(Shard { index: 1, count: 4 }));
        assert_eq!(Shard { index: 3, count: 4 }.to_string(), "3/4");
        for bad in ["0/4", "5/4", "4", "a/b", "1/0", "-1/2"] {
            assert!(bad.parse::<Shard>().is_err(), "{bad}");
        }
    }

    #[test]
    fn the_record_carries_typed_grid_values() {
        let runs = expand(&plan(PLAN));
        let record = runs[2].record();
        assert_eq!(record.coordinates[0].value, serde_json::json!(1.0));
        assert_eq!(
            record.coordinates[1].value,
            serde_json::json!("nearest frontier")
        );
        assert_eq!(record.scenario, "dir/a.toml");
        let json = serde_json::to_string(&record).unwrap();
        assert_eq!(
            serde_json::from_str::<RunCoordinates>(&json).unwrap(),
            record
        );
    }
}
