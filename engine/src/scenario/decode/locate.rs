//! Narrowing a decoding error down to the value it is about.

use serde::de::DeserializeOwned;

use super::try_decode;
use crate::scenario::de::{DeError, DeErrorKind};
use crate::scenario::path::{FieldPath, Segment};
use crate::scenario::tree::{Entry, Node, Value};

/// Trial decodings spent locating one problem (see `blame`); a bisection needs about
/// log2(values) per level, so this is only reached by absurd files.
const MAX_BLAME_TRIALS: usize = 256;

/// Narrows an error down to the value it is about. Errors from serde's buffered content
/// (internally tagged enums) only name the enum's table.
pub(super) fn locate<T: DeserializeOwned>(
    node: &Node,
    root: &FieldPath,
    at: &FieldPath,
    error: &DeError,
) -> FieldPath {
    let Some(target) = at.strip_prefix(root).and_then(|rel| node.get(rel)) else {
        return at.clone();
    };
    match &error.kind {
        DeErrorKind::UnknownField { field, expected } => {
            if at.last_key() == Some(field.as_str()) {
                return at.clone();
            }
            find_unknown_key(target, at, field, expected).unwrap_or_else(|| at.clone())
        }
        DeErrorKind::UnknownVariant { variant, .. } if at.last_key() != Some("kind") => {
            // The tag itself, unless the unknown name is another value of the table (such as
            // an exploration `strategy`), which serde reports at the table too.
            match target.get(&[key("kind")]).map(|tag| &tag.value) {
                Some(Value::String(tag)) if tag == variant => at.key("kind"),
                Some(_) if target.is_container() => blame::<T>(node, root, at, error),
                Some(_) => at.key("kind"),
                None => at.clone(),
            }
        }
        DeErrorKind::UnknownVariant { .. } => at.clone(),
        _ if target.is_container() => blame::<T>(node, root, at, error),
        _ => at.clone(),
    }
}

/// The table a missing field belongs to. serde names it, except inside a `kind` table, whose
/// buffered content names the `kind` table for a field missing in a table nested in it (an
/// empty `energy_budget = {}`): then the nested table that brings the problem in, if any.
///
/// `blame` may descend below that table, into its values (in `overlap = { x = 0.2 }`, keeping
/// none of them makes `x` the missing field instead of `y`, so `x` looks like the culprit), or
/// into the value before a field missing from the `kind` table itself (`camera = {...}` before a
/// missing `overlap`). So the tables from the culprit up are asked, by [`owns_field`], whether
/// the field is one of theirs; the nearest that says so is the one, else the `kind` table.
pub(super) fn locate_missing<T: DeserializeOwned>(
    node: &Node,
    root: &FieldPath,
    at: &FieldPath,
    error: &DeError,
) -> FieldPath {
    let is_kind_table = at
        .strip_prefix(root)
        .and_then(|rel| node.get(rel))
        .is_some_and(|table| table.get(&[key("kind")]).is_some());
    let DeErrorKind::MissingField { field } = &error.kind else {
        return at.clone();
    };
    if !is_kind_table {
        return at.clone();
    }
    let mut candidate = Some(blame::<T>(node, root, at, error));
    while let Some(path) = candidate {
        if path == *at || !path.starts_with(at) {
            break;
        }
        if owns_field::<T>(node, root, &path, field) {
            return path;
        }
        candidate = path.parent();
    }
    at.clone()
}

/// Key of the probe [`owns_field`] adds: no field of any table is called so.
const PROBE_KEY: &str = "\u{0}probe";

/// Whether `field` is a field of the table at `table` (lacking it): a key no table knows, added
/// to it, makes serde refuse the key with the table's valid names, whatever the place it then
/// names. Tables that take any key (maps) own no missing field.
fn owns_field<T: DeserializeOwned>(
    node: &Node,
    root: &FieldPath,
    table: &FieldPath,
    field: &str,
) -> bool {
    let Some(relative) = table.strip_prefix(root) else {
        return false;
    };
    let mut trial = node.clone();
    let Some(Node {
        span,
        value: Value::Table(entries),
    }) = trial.get_mut(relative)
    else {
        return false;
    };
    if entries.iter().any(|entry| entry.key == field) {
        return false;
    }
    entries.push(Entry {
        key: PROBE_KEY.to_owned(),
        key_span: span.end..span.end,
        node: Node {
            span: span.end..span.end,
            value: Value::Boolean(true),
        },
    });
    matches!(
        try_decode::<T>(&trial, root),
        Err(DeError {
            kind: DeErrorKind::UnknownField { field: probe, expected },
            ..
        }) if probe == PROBE_KEY && expected.contains(&field)
    )
}

fn key(name: &str) -> Segment {
    Segment::Key(name.to_owned())
}

/// The table inside `target` (found at `at`) holding the unknown key `field`; when several do,
/// the one whose other keys best fit the valid names, then the shallowest.
fn find_unknown_key(
    target: &Node,
    at: &FieldPath,
    field: &str,
    expected: &[&str],
) -> Option<FieldPath> {
    let mut best: Option<(usize, usize, FieldPath)> = None;
    target.walk(at, &mut |path, node| {
        let keys = node.keys();
        if !keys.contains(&field) {
            return;
        }
        let fit = keys.iter().filter(|k| expected.contains(k)).count();
        let depth = path.segments().len();
        let better = best.as_ref().is_none_or(|(best_fit, best_depth, _)| {
            (fit, usize::MAX - depth) > (*best_fit, usize::MAX - best_depth)
        });
        if better {
            best = Some((fit, depth, path.key(field)));
        }
    });
    best.map(|(_, _, path)| path)
}

/// The value inside `target` (found at `at`) the error is about. serde decodes a table's or an
/// array's values in order and stops at the first bad one, so keeping only the first `n`
/// values of a level reproduces the problem exactly when the culprit is among them: the
/// smallest such `n` (found by bisection) names the value to descend into. The search stops at
/// a level that reproduces the problem with none of its values (the level itself is wrong, such
/// as an array where a table belongs) or that has no values. A `kind` tag that is a string is
/// always kept, since dropping it changes every error. Trial decodings are bounded, so a huge
/// entry cannot make the loader hang; past the bound the error stays where the search got to.
fn blame<T: DeserializeOwned>(
    node: &Node,
    root: &FieldPath,
    at: &FieldPath,
    error: &DeError,
) -> FieldPath {
    let mut current = at.clone();
    let mut trials = 0;
    loop {
        let Some(relative) = current.strip_prefix(root) else {
            return current;
        };
        let Some(level) = node.get(relative) else {
            return current;
        };
        let count = level.children(&current).len();
        let reproduces = |keep: usize| {
            let mut trial = node.clone();
            if let Some(level) = trial.get_mut(relative) {
                level.keep_first(keep);
            }
            matches!(try_decode::<T>(&trial, root), Err(again) if same_problem(&again, error))
        };
        trials += 1;
        if count == 0 || reproduces(0) {
            return current;
        }
        // The problem shows with all `count` values and not with none: bisect for the first
        // value that brings it in.
        let (mut without, mut with) = (0, count);
        while with - without > 1 {
            trials += 1;
            if trials > MAX_BLAME_TRIALS {
                return current;
            }
            let middle = without + (with - without) / 2;
            if reproduces(middle) {
                with = middle;
            } else {
                without = middle;
            }
        }
        let Some((culprit, _)) = level.children(&current).into_iter().nth(with - 1) else {
            return current;
        };
        current = culprit;
    }
}

/// Whether two errors are the same problem: same place, kind and expectation. What was found
/// is left out, since cutting a value out of an array changes its length and not its fault
/// (`[1.0, 2.0]` for a point stays "not 3 numbers" when its first number is cut).
fn same_problem(a: &DeError, b: &DeError) -> bool {
    use DeErrorKind as K;
    a.path == b.path
        && match (&a.kind, &b.kind) {
            (K::InvalidType { expected: x, .. }, K::InvalidType { expected: y, .. })
            | (K::InvalidValue { expected: x, .. }, K::InvalidValue { expected: y, .. })
            | (K::InvalidLength { expected: x, .. }, K::InvalidLength { expected: y, .. }) => {
                x == y
            }
            (x, y) => x == y,
        }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::schema::{BehaviourSpec, SensorSpec};
    use crate::scenario::tree::parse_document;

    /// The path an error of a sensor table is narrowed down to (inside a `kind` table serde
    /// only knows the table, except for the tag itself).
    fn culprit(text: &str) -> String {
        let root = FieldPath::parse("uav[0].sensor[0]");
        let tree = parse_document(text).unwrap();
        let error = try_decode::<SensorSpec>(&tree, &root).unwrap_err();
        let at = error.path.clone().unwrap();
        locate::<SensorSpec>(&tree, &root, &at, &error).to_string()
    }

    #[test]
    fn errors_inside_kind_tables_are_narrowed_to_their_value() {
        let sensor = "kind = \"depth_camera\"\nwidth = 640\n";
        assert_eq!(
            culprit(&format!("{sensor}range_max = \"far\"\nrate_hz = 30.0\n")),
            "uav[0].sensor[0].range_max"
        );
        // A table where a string or an array belongs: the table, not a value inside it.
        assert_eq!(
            culprit(&format!("{sensor}ray_grid = {{ columns = 64 }}\n")),
            "uav[0].sensor[0].ray_grid"
        );
        // serde takes a struct from an array of its fields in order, so inside a `kind` table
        // `mount = [1, 2]` is read as translation = 1 (not 3 numbers): its first element.
        assert_eq!(
            culprit(&format!("{sensor}mount = [1, 2]\n")),
            "uav[0].sensor[0].mount[0]"
        );
        // A nested value: down to the element.
        assert_eq!(
            culprit(&format!("{sensor}mount = {{ rpy = [0.0, \"up\", 0.0] }}\n")),
            "uav[0].sensor[0].mount.rpy[1]"
        );
        // Unknown fields are found by name, in the table that holds them.
        assert_eq!(
            culprit(&format!(
                "{sensor}mount = {{ rpy = [0, 0, 0], shift = 1 }}\n"
            )),
            "uav[0].sensor[0].mount.shift"
        );
        // A tag that is no string is the culprit itself.
        assert_eq!(culprit("width = 640\nkind = 3\n"), "uav[0].sensor[0].kind");
    }

    #[test]
    fn errors_inside_an_exploration_behaviour_name_their_field() {
        let root = FieldPath::parse("uav[0].behaviour");
        let culprit = |text: &str| {
            let tree = parse_document(text).unwrap();
            let error = try_decode::<BehaviourSpec>(&tree, &root).unwrap_err();
            let at = error.path.clone().unwrap();
            match error.kind {
                DeErrorKind::MissingField { .. } => {
                    locate_missing::<BehaviourSpec>(&tree, &root, &at, &error).to_string()
                }
                _ => locate::<BehaviourSpec>(&tree, &root, &at, &error).to_string(),
            }
        };
        let explore = "kind = \"explore\"\n";
        // These used to blame `kind` ("unknown behaviour 'greedy'") or the behaviour table.
        assert_eq!(
            culprit(&format!("{explore}strategy = \"greedy\"\n")),
            "uav[0].behaviour.strategy"
        );
        assert_eq!(
            culprit(&format!(
                "{explore}strategy = \"eaae\"\nevaluate = \"most\"\n"
            )),
            "uav[0].behaviour.evaluate"
        );
        assert_eq!(
            culprit(&format!(
                "{explore}strategy = \"eaae\"\nenergy_budget = {{}}\n"
            )),
            "uav[0].behaviour.energy_budget"
        );
        // A field missing from a nested table is the table's, although serde only names the
        // behaviour and the search for its culprit goes down into the table's values.
        let coverage = "kind = \"coverage\"\narea = { vertices = [[0, 0], [1, 0], [0, 1]] }\n";
        assert_eq!(
            culprit(&format!("{coverage}overlap = {{ x = 0.2 }}\n")),
            "uav[0].behaviour.overlap"
        );
        // ... but a field missing after a table is not that table's.
        let camera = "camera = { angle_of_view = 1.0, width_px = 4, height_px = 3, \
                      shot_period_s = 1.0 }\n";
        assert_eq!(culprit(&format!("{coverage}{camera}")), "uav[0].behaviour");
        // A field missing from the behaviour itself, and an unknown kind, stay where they were.
        assert_eq!(culprit(explore), "uav[0].behaviour");
        assert_eq!(culprit("kind = \"hover\"\n"), "uav[0].behaviour.kind");
    }

    #[test]
    fn a_shorter_array_is_the_same_problem() {
        let error = |len| DeError {
            kind: DeErrorKind::InvalidLength {
                len,
                expected: "an array of length 3".into(),
            },
            path: Some(FieldPath::parse("b")),
        };
        assert!(same_problem(&error(2), &error(1)));
        let mut elsewhere = error(2);
        elsewhere.path = Some(FieldPath::parse("c"));
        assert!(!same_problem(&error(2), &elsewhere));
    }
}
