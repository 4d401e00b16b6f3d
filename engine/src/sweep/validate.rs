//! Checking a plan without running it (`uavex validate PLAN.toml`): each scenario variant the
//! plan makes (a scenario with one grid combination, the fixed overrides applied) is loaded,
//! checked and its world built exactly as its runs would be, with the plan's first seed. A
//! plan whose every variant passes starts every run; one that does not would record the
//! variant's runs as failed with the same reasons (`execute`), after the others ran.

use super::execute::load_run;
use super::expand::{RunSpec, expand};
use super::plan::Plan;
use crate::sim::Sim;
use std::collections::BTreeMap;
use std::path::Path;

/// A variant of a plan that its runs would not get past.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RefusedVariant {
    /// The scene and its grid values, e.g. `pillars, uav.0.behaviour.strategy = "classic"`.
    pub variant: String,
    /// Why, as the failed runs' summaries would say.
    pub reason: String,
}

/// What checking a plan found.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PlanCheck {
    /// Variants checked: scenarios x grid combinations.
    pub variants: usize,
    /// Runs of the plan: variants x seeds.
    pub runs: usize,
    pub refused: Vec<RefusedVariant>,
}

/// Checks every variant of `plan` (see the module documentation).
pub fn check_plan(plan: &Plan) -> PlanCheck {
    let runs = expand(plan);
    // Runs that differ only in their seed share a variant; plan order lists them together.
    let variants: Vec<&RunSpec> = runs.iter().step_by(plan.seeds.len().max(1)).collect();
    let mut texts = BTreeMap::new();
    let refused = variants
        .iter()
        .filter_map(|run| {
            let text = texts
                .entry(run.scenario_file.as_path())
                .or_insert_with(|| read_scenario(&run.scenario_file));
            let reason = match load_run(run, text) {
                Ok(loaded) => Sim::build(&loaded, run.seed)
                    .err()
                    .map(|errors| format!("the world was refused:\n{errors}")),
                Err(reason) => Some(reason),
            }?;
            Some(RefusedVariant {
                variant: describe(run),
                reason,
            })
        })
        .collect();
    PlanCheck {
        variants: variants.len(),
        runs: runs.len(),
        refused,
    }
}

/// The text of a plan's scenario file, or why it cannot be read (the reason its runs fail).
pub(super) fn read_scenario(path: &Path) -> Result<String, String> {
    std::fs::read_to_string(path)
        .map_err(|e| format!("cannot read the scenario {}: {e}", path.display()))
}

/// `scene, path = value, ...` of `run`'s variant.
fn describe(run: &RunSpec) -> String {
    std::iter::once(run.scene.clone())
        .chain(
            run.coordinates
                .iter()
                .map(|(path, value)| format!("{path} = {value}")),
        )
        .collect::<Vec<_>>()
        .join(", ")
}

/// What a TOML file holds, told by the tables only one kind lists: a sweep plan
/// `[[scenario]]`, a scenario `[[uav]]`. A file with neither (or not TOML) is neither, even if
/// it means to be one: a scenario that misspells a table is a scenario with a problem.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FileKind {
    Plan,
    Scenario,
    Neither,
}

impl FileKind {
    pub fn of(text: &str) -> Self {
        let Ok(table) = text.parse::<toml::Table>() else {
            return Self::Neither;
        };
        let lists = |key: &str| table.get(key).is_some_and(toml::Value::is_array);
        if lists("scenario") {
            Self::Plan
        } else if lists("uav") {
            Self::Scenario
        } else {
            Self::Neither
        }
    }

    /// The kind of the file at `path` (`Neither` when it cannot be read).
    pub fn of_file(path: &Path) -> Self {
        std::fs::read_to_string(path).map_or(Self::Neither, |text| Self::of(&text))
    }
}

#[cfg(test)]
mod tests {
    use super::FileKind;

    #[test]
    fn plans_and_scenarios_are_told_apart_by_their_tables() {
        let kind = FileKind::of;
        assert_eq!(
            kind("seeds = 2\n[[scenario]]\nfile = \"a.toml\"\n"),
            FileKind::Plan
        );
        assert_eq!(
            kind(include_str!("../../../scenarios/eaae_protocol.toml")),
            FileKind::Plan
        );
        assert_eq!(
            kind(include_str!("../../../scenarios/eaae_pillars.toml")),
            FileKind::Scenario
        );
        // A file that misspells the table of its kind is that kind with a problem, not the
        // other kind: neither is told.
        assert_eq!(
            kind("name = \"x\"\n[scenario]\nfile = \"a.toml\"\n"),
            FileKind::Neither
        );
        assert_eq!(
            kind("name = \"x\"\n[uav]\nname = \"a\"\n"),
            FileKind::Neither
        );
        assert_eq!(kind("not toml ["), FileKind::Neither);
    }
}
