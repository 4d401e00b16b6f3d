//! Non-finite numbers in a typed scenario (the loader finds them in the text; code that builds
//! or edits a `Scenario` needs the same check on the values).

use crate::scenario::diagnostic::Finding;
use crate::scenario::path::FieldPath;
use crate::scenario::schema::Scenario;

/// Every NaN or infinite number in `scenario`, by its field path in the file's terms.
///
/// The scenario is serialized (serde, with the same field names as the file) and the values
/// are walked, so every `f64` of the schema is covered, including those added later.
pub(crate) fn non_finite(scenario: &Scenario) -> Vec<Finding> {
    // TOML integers are i64: a seed above i64::MAX cannot be serialized, and is no number this
    // check is about.
    let mut copy = scenario.clone();
    copy.seed = 0;
    let mut findings = Vec::new();
    if let Ok(value) = toml::Value::try_from(&copy) {
        walk(&FieldPath::root(), &value, &mut findings);
    }
    findings
}

fn walk(path: &FieldPath, value: &toml::Value, out: &mut Vec<Finding>) {
    match value {
        toml::Value::Float(x) if !x.is_finite() => {
            out.push(Finding::must_be(
                path.clone(),
                "a finite number",
                format!("{x}"),
            ));
        }
        toml::Value::Array(items) => {
            for (i, item) in items.iter().enumerate() {
                walk(&path.index(i), item, out);
            }
        }
        toml::Value::Table(table) => {
            for (key, item) in table {
                walk(&path.key(key), item, out);
            }
        }
        _ => {}
    }
}
