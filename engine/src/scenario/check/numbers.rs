//! Numbers no quantity of a scenario can take: NaN, infinities, and magnitudes beyond the 32-bit
//! floats the world geometry and the map use. The loader finds them in the text; code that builds
//! or edits a `Scenario` needs the same check on the values.

use crate::scenario::diagnostic::Finding;
use crate::scenario::path::FieldPath;
use crate::scenario::schema::Scenario;

/// Largest magnitude a scenario number may have: positions, sizes and radii become `f32` (parry,
/// glam), where a larger value turns infinite after loading.
pub(crate) const MAX_MAGNITUDE: f64 = f32::MAX as f64;

/// Whether some scenario quantity can take `x` (see the module).
pub(crate) fn usable(x: f64) -> bool {
    x.is_finite() && x.abs() <= MAX_MAGNITUDE
}

/// The finding for `x` at `path` if no scenario quantity can take it (see the module).
pub(crate) fn unusable_number(path: &FieldPath, x: f64) -> Option<Finding> {
    let expected = if !x.is_finite() {
        "a finite number"
    } else if x.abs() > MAX_MAGNITUDE {
        "at most 3.4e38 in magnitude (positions and sizes are 32-bit floats)"
    } else {
        return None;
    };
    // `1e39`, as a reader wrote it, not forty digits.
    let found = if x.abs() >= 1e16 {
        format!("{x:e}")
    } else {
        format!("{x}")
    };
    Some(Finding::must_be(path.clone(), expected, found))
}

/// Every NaN, infinite or too large number in `scenario` ([`unusable_number`]), by its field
/// path in the file's terms.
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
        toml::Value::Float(x) => out.extend(unusable_number(path, *x)),
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
