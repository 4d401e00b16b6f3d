//! Applying overrides to a scenario's TOML text before it is decoded.
//!
//! The text is edited as a TOML document (toml_edit) rather than re-serialised from values, so
//! everything an override does not touch keeps its line and column: when the edited scenario is
//! refused, the loader's diagnostics still point at the right places of the file, except for
//! the overridden values themselves.

use super::path::{OverridePath, Step};
use thiserror::Error;
use toml_edit::{DocumentMut, Item, Value};

/// One value to put at one place of a scenario.
#[derive(Debug, Clone, PartialEq)]
pub struct Override {
    pub path: OverridePath,
    pub value: toml::Value,
}

/// An override that cannot be applied to the scenario's text.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum OverrideError {
    #[error("the scenario is not valid TOML, so overrides cannot be applied: {0}")]
    Syntax(String),
    #[error("override `{path}`: {why}")]
    Place { path: String, why: String },
}

/// The scenario `text` with every override applied in order (a later one wins where two touch
/// the same place). Missing tables on the way are created, so `map.resolution` works on a file
/// without a `[map]` table; list elements must exist.
pub fn apply_overrides(text: &str, overrides: &[Override]) -> Result<String, OverrideError> {
    if overrides.is_empty() {
        return Ok(text.to_owned());
    }
    let mut document: DocumentMut = text
        .parse()
        .map_err(|e: toml_edit::TomlError| OverrideError::Syntax(e.message().to_owned()))?;
    for o in overrides {
        set(document.as_item_mut(), &o.path, to_edit_value(&o.value)?)?;
    }
    Ok(document.to_string())
}

/// The same value as a document value (through its TOML text, which both crates share).
fn to_edit_value(value: &toml::Value) -> Result<Value, OverrideError> {
    value
        .to_string()
        .parse::<Value>()
        .map_err(|e| OverrideError::Syntax(e.message().to_owned()))
}

/// Puts `value` at `path` under `root`.
fn set(root: &mut Item, path: &OverridePath, value: Value) -> Result<(), OverrideError> {
    let place = |why: String| OverrideError::Place {
        path: path.to_string(),
        why,
    };
    let Some((last, parents)) = path.steps().split_last() else {
        return Err(place("the path is empty".to_owned()));
    };
    let mut item = root;
    for (depth, step) in parents.iter().enumerate() {
        let walked = OverridePath::from_steps(&path.steps()[..depth]);
        item = child(item, step).map_err(|why| place(at(&walked, why)))?;
    }
    let walked = OverridePath::from_steps(parents);
    put(item, last, value).map_err(|why| place(at(&walked, why)))
}

fn at(walked: &OverridePath, why: String) -> String {
    if walked.steps().is_empty() {
        why
    } else {
        format!("at `{walked}`: {why}")
    }
}

/// The child of `item` at `step`, creating a missing table key as an empty table.
fn child<'a>(item: &'a mut Item, step: &Step) -> Result<&'a mut Item, String> {
    match step {
        Step::Key(key) => {
            if item.is_none() {
                *item = Item::Value(Value::InlineTable(Default::default()));
            }
            if item.is_array_of_tables() || item.is_array() {
                return Err(format!(
                    "a list: name one of its elements by index before `{key}`"
                ));
            }
            if !item.is_table_like() {
                return Err(format!("not a table, so it has no field `{key}`"));
            }
            item.get_mut(key.as_str())
                .ok_or_else(|| format!("no field `{key}`"))
        }
        Step::Index(index) => {
            let len = list_len(item).ok_or_else(|| "not a list".to_owned())?;
            item.get_mut(*index)
                .ok_or_else(|| out_of_range(*index, len))
        }
    }
}

fn list_len(item: &Item) -> Option<usize> {
    match item {
        Item::ArrayOfTables(list) => Some(list.len()),
        Item::Value(Value::Array(list)) => Some(list.len()),
        _ => None,
    }
}

fn out_of_range(index: usize, len: usize) -> String {
    format!("index {index} is out of range: the list has {len} element(s)")
}

/// Replaces (or adds) `parent`'s entry at `step` with `value`.
fn put(parent: &mut Item, step: &Step, value: Value) -> Result<(), String> {
    match step {
        Step::Key(key) => {
            if parent.is_none() {
                *parent = Item::Value(Value::InlineTable(Default::default()));
            }
            match parent {
                Item::Table(table) => {
                    table.insert(key, Item::Value(value));
                    Ok(())
                }
                Item::Value(Value::InlineTable(table)) => {
                    table.insert(key.as_str(), value);
                    Ok(())
                }
                Item::ArrayOfTables(_) | Item::Value(Value::Array(_)) => Err(format!(
                    "a list: name one of its elements by index before `{key}`"
                )),
                _ => Err(format!("not a table, so it has no field `{key}`")),
            }
        }
        Step::Index(index) => match parent {
            // An element of `[[uav]]` must stay a table: its value is written as one.
            Item::ArrayOfTables(list) => {
                let len = list.len();
                let table = match value {
                    Value::InlineTable(inline) => inline.into_table(),
                    other => {
                        return Err(format!(
                            "its elements are tables, so element {index} cannot become `{other}`"
                        ));
                    }
                };
                let slot = list
                    .get_mut(*index)
                    .ok_or_else(|| out_of_range(*index, len))?;
                *slot = table;
                Ok(())
            }
            Item::Value(Value::Array(list)) => {
                if *index >= list.len() {
                    return Err(out_of_range(*index, list.len()));
                }
                list.replace(*index, value);
                Ok(())
            }
            _ => Err("not a list".to_owned()),
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const SCENARIO: &str = r#"# a comment
name = "demo"
time_limit_s = 5.0

[world.bounds]
min = [0.0, 0.0, 0.0]
max = [4.0, 4.0, 2.0]

[[uav]]
name = "a"
start = { position = [1.0, 1.0, 1.0] }
behaviour = { kind = "scripted", speed = 1.0, waypoints = [[2.0, 1.0, 1.0]] }

[[uav]]
name = "b"
start = { position = [3.0, 3.0, 1.0] }
[uav.behaviour]
kind = "scripted"
speed = 0.5
waypoints = [[3.0, 2.0, 1.0], [2.0, 2.0, 1.0]]
"#;

    fn o(path: &str, value: &str) -> Override {
        Override {
            path: OverridePath::parse(path).unwrap(),
            value: value.parse().unwrap(),
        }
    }

    fn applied(overrides: &[Override]) -> toml::Table {
        apply_overrides(SCENARIO, overrides)
            .unwrap()
            .parse()
            .unwrap()
    }

    #[test]
    fn no_override_keeps_the_text_byte_for_byte() {
        assert_eq!(apply_overrides(SCENARIO, &[]).unwrap(), SCENARIO);
    }

    #[test]
    fn sets_values_in_inline_and_section_tables_of_listed_uavs() {
        let t = applied(&[
            o("uav.0.behaviour.speed", "2.5"),
            o("uav[1].behaviour.speed", "0.75"),
            o("uav.1.behaviour.waypoints.1.2", "1.5"),
            o("time_limit_s", "9.0"),
        ]);
        let uav = t["uav"].as_array().unwrap();
        assert_eq!(uav[0]["behaviour"]["speed"].as_float(), Some(2.5));
        assert_eq!(uav[1]["behaviour"]["speed"].as_float(), Some(0.75));
        assert_eq!(
            uav[1]["behaviour"]["waypoints"][1].as_array().unwrap()[2].as_float(),
            Some(1.5)
        );
        assert_eq!(t["time_limit_s"].as_float(), Some(9.0));
        // Untouched values are unchanged.
        assert_eq!(uav[0]["name"].as_str(), Some("a"));
        assert_eq!(uav[1]["behaviour"]["kind"].as_str(), Some("scripted"));
    }

    #[test]
    fn untouched_lines_keep_their_place() {
        let text = apply_overrides(SCENARIO, &[o("uav.1.behaviour.speed", "0.75")]).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        let original: Vec<&str> = SCENARIO.lines().collect();
        assert_eq!(lines.len(), original.len());
        let changed: Vec<usize> = (0..lines.len())
            .filter(|&i| lines[i] != original[i])
            .collect();
        assert_eq!(changed, vec![18], "only the speed line differs:\n{text}");
        assert_eq!(lines[18].replace(' ', ""), "speed=0.75");
    }

    #[test]
    fn creates_missing_tables_and_replaces_whole_values() {
        let t = applied(&[
            o("map.resolution", "0.2"),
            o(
                "uav.0.behaviour",
                r#"{ kind = "scripted", speed = 3.0, waypoints = [] }"#,
            ),
            o(
                "uav.1",
                r#"{ name = "c", start = { position = [1.0, 2.0, 1.0] } }"#,
            ),
        ]);
        assert_eq!(t["map"]["resolution"].as_float(), Some(0.2));
        let uav = t["uav"].as_array().unwrap();
        assert_eq!(uav[0]["behaviour"]["speed"].as_float(), Some(3.0));
        assert_eq!(
            uav[0]["behaviour"]["waypoints"].as_array().unwrap().len(),
            0
        );
        assert_eq!(uav[1]["name"].as_str(), Some("c"));
        assert!(
            uav[1].get("behaviour").is_none(),
            "the element was replaced whole"
        );
    }

    #[test]
    fn later_overrides_win() {
        let t = applied(&[o("time_limit_s", "1.0"), o("time_limit_s", "2.0")]);
        assert_eq!(t["time_limit_s"].as_float(), Some(2.0));
    }

    #[test]
    fn impossible_places_are_explained() {
        let why = |path: &str, value: &str| {
            apply_overrides(SCENARIO, &[o(path, value)])
                .unwrap_err()
                .to_string()
        };
        assert_eq!(
            why("uav.2.name", "\"x\""),
            "override `uav.2.name`: at `uav`: index 2 is out of range: the list has 2 element(s)"
        );
        assert_eq!(
            why("uav.name", "\"x\""),
            "override `uav.name`: at `uav`: a list: name one of its elements by index before `name`"
        );
        assert_eq!(
            why("name.first", "\"x\""),
            "override `name.first`: at `name`: not a table, so it has no field `first`"
        );
        assert_eq!(
            why("uav.0", "3"),
            "override `uav.0`: at `uav`: its elements are tables, so element 0 cannot become `3`"
        );
        assert_eq!(
            why("world.bounds.min.7", "1.0"),
            "override `world.bounds.min.7`: at `world.bounds.min`: index 7 is out of range: the \
             list has 3 element(s)"
        );
    }

    #[test]
    fn a_file_that_is_not_toml_is_reported() {
        let err = apply_overrides("name = ", &[o("name", "\"x\"")]).unwrap_err();
        assert!(matches!(err, OverrideError::Syntax(_)), "{err}");
    }
}
