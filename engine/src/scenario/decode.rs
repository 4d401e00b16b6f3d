//! Typed decoding of the tree that reports every problem it can find, not just the first.
//!
//! The file is decoded in units: the top level (without its UAVs and obstacles), each
//! `[[world.obstacle]]`, each `[[uav]]` (without its sensors) and each `[[uav.sensor]]`, so a bad
//! entry never hides the others. Inside a unit, each error is reported and the offending value
//! cut out of the tree, and the unit is decoded again, until it decodes or nothing more can be
//! cut (a missing required field ends its unit: nothing can be assumed in its place).

use serde::de::DeserializeOwned;

use super::de::{DeError, DeErrorKind, NodeDeserializer};
use super::diagnostic::Finding;
use super::path::{FieldPath, Segment};
use super::schema::{BehaviourSpec, ObstacleSpec, Scenario, SensorSpec, UavSpec};
use super::source_map::Anchor;
use super::suggest::{closest, list, plain_list};
use super::tree::{Element, Entry, Node, Value};

/// Problems reported per unit (an entry); past this, the entry is only said to have more. Each
/// problem costs a few decodings of its entry, so this also bounds the time a hostile file
/// can take.
const MAX_FINDINGS_PER_UNIT: usize = 50;
/// Trial decodings spent locating one problem (see `blame`).
const MAX_BLAME_TRIALS: usize = 256;

/// The decoded pieces of a file, with their indices in the file; `None` where a piece had
/// problems (already reported).
#[derive(Debug, Default)]
pub(crate) struct Decoded {
    /// The top level with empty `uav` and `world.obstacle` lists.
    pub root: Option<Scenario>,
    pub obstacles: Vec<(usize, Option<ObstacleSpec>)>,
    pub uavs: Vec<DecodedUav>,
    /// `uav` is written but is not an array of tables (its type error is reported; it is not
    /// also "no UAV").
    pub uav_misshapen: bool,
}

#[derive(Debug)]
pub(crate) struct DecodedUav {
    pub index: usize,
    /// The UAV with an empty sensor list.
    pub spec: Option<UavSpec>,
    pub sensors: Vec<(usize, Option<SensorSpec>)>,
}

impl Decoded {
    /// The whole scenario, if every piece decoded.
    pub fn into_scenario(self) -> Option<Scenario> {
        let mut scenario = self.root?;
        scenario.world.obstacles = self
            .obstacles
            .into_iter()
            .map(|(_, obstacle)| obstacle)
            .collect::<Option<Vec<_>>>()?;
        scenario.uavs = self
            .uavs
            .into_iter()
            .map(|uav| {
                let mut spec = uav.spec?;
                spec.sensors = uav
                    .sensors
                    .into_iter()
                    .map(|(_, sensor)| sensor)
                    .collect::<Option<Vec<_>>>()?;
                Some(spec)
            })
            .collect::<Option<Vec<_>>>()?;
        Some(scenario)
    }
}

/// Decodes every unit of `tree`, adding a finding per problem.
pub(crate) fn decode(tree: &Node, findings: &mut Vec<Finding>) -> Decoded {
    let mut root = tree.clone();
    let obstacle_path = FieldPath::parse("world.obstacle");
    let uav_path = FieldPath::root().key("uav");
    let obstacle_nodes = take_array(&mut root, &obstacle_path);
    let uav_nodes = take_array(&mut root, &uav_path);
    let uav_misshapen = root.get(uav_path.segments()).is_some();

    let mut decoded = Decoded {
        root: decode_unit::<Scenario>(root, &FieldPath::root(), findings),
        uav_misshapen,
        ..Decoded::default()
    };
    for element in obstacle_nodes {
        let path = obstacle_path.index(element.index);
        let obstacle = decode_unit::<ObstacleSpec>(element.node, &path, findings);
        decoded.obstacles.push((element.index, obstacle));
    }
    for element in uav_nodes {
        let path = uav_path.index(element.index);
        let mut node = element.node;
        let sensor_nodes = take_array(&mut node, &FieldPath::root().key("sensor"));
        let spec = decode_unit::<UavSpec>(node, &path, findings);
        let sensors = sensor_nodes
            .into_iter()
            .map(|sensor| {
                let sensor_path = path.key("sensor").index(sensor.index);
                let spec = decode_unit::<SensorSpec>(sensor.node, &sensor_path, findings);
                (sensor.index, spec)
            })
            .collect();
        decoded.uavs.push(DecodedUav {
            index: element.index,
            spec,
            sensors,
        });
    }
    decoded
}

/// Cuts out the array at `path` (relative to `node`) if it is one; anything else stays for the
/// type check of its unit to refuse.
fn take_array(node: &mut Node, path: &FieldPath) -> Vec<Element> {
    let is_array = matches!(
        node.get(path.segments()),
        Some(Node {
            value: Value::Array(_),
            ..
        })
    );
    if !is_array {
        return Vec::new();
    }
    match node.take(path.segments()) {
        Some(Node {
            value: Value::Array(elements),
            ..
        }) => elements,
        _ => Vec::new(),
    }
}

fn try_decode<T: DeserializeOwned>(node: &Node, root: &FieldPath) -> Result<T, DeError> {
    T::deserialize(NodeDeserializer::new(node, root.clone())).map_err(|error| error.at(root))
}

/// Decodes one unit (`node`, found at `root`), reporting every problem it can.
fn decode_unit<T: DeserializeOwned>(
    mut node: Node,
    root: &FieldPath,
    findings: &mut Vec<Finding>,
) -> Option<T> {
    let mut removed: Vec<FieldPath> = Vec::new();
    let first = findings.len();
    loop {
        let error = match try_decode::<T>(&node, root) {
            Ok(value) => return (findings.len() == first).then_some(value),
            Err(error) => error,
        };
        if findings.len() - first >= MAX_FINDINGS_PER_UNIT {
            findings.push(
                Finding::new(
                    root.clone(),
                    Anchor::Key,
                    format!(
                        "more problems in this entry are not shown (the first {MAX_FINDINGS_PER_UNIT} are)"
                    ),
                )
                .expected("an entry with fewer problems"),
            );
            return None;
        }
        let at = error.path.clone().unwrap_or_else(|| root.clone());
        let cut = if let DeErrorKind::MissingField { field } = &error.kind {
            // A value we cut out earlier is not missing a second time.
            if !removed.contains(&at.key(field)) {
                findings.push(missing_field(&at, field));
            }
            at
        } else {
            let culprit = locate::<T>(&node, root, &at, &error);
            findings.push(finding(&error.kind, &culprit, &node, root));
            culprit
        };
        let Some(relative) = cut.strip_prefix(root) else {
            return None;
        };
        if relative.is_empty() || !node.remove(relative) {
            return None;
        }
        removed.push(cut);
    }
}

/// Narrows an error down to the value it is about. Errors from serde's buffered content
/// (internally tagged enums) only name the enum's table.
fn locate<T: DeserializeOwned>(
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
        DeErrorKind::UnknownVariant { .. } => {
            if at.last_key() != Some("kind") && target.get(&[key("kind")]).is_some() {
                at.key("kind")
            } else {
                at.clone()
            }
        }
        _ if target.is_container() => blame::<T>(node, root, at, target, error),
        _ => at.clone(),
    }
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

/// The value inside `target` (found at `at`) the error is about. serde decodes a table's values
/// in order and stops at the first bad one, so cutting out any other value leaves the same
/// problem, while cutting out the value that holds the culprit makes it go away or become a
/// different one. Starting at `at`, each level's values are tried in order and the search goes
/// down into the first that matters, until no value below explains the error. The `kind` tag
/// is only tried when it is not a string, since cutting it out always changes the error. The
/// number of trial decodings is bounded, so a huge entry cannot make the loader hang; past the
/// bound the error stays where it is.
fn blame<T: DeserializeOwned>(
    node: &Node,
    root: &FieldPath,
    at: &FieldPath,
    target: &Node,
    error: &DeError,
) -> FieldPath {
    let mut current = at.clone();
    let mut level = target;
    let mut trials = 0;
    'descend: loop {
        let mut candidates = level.children(&current);
        let tag = current.key("kind");
        if let Some(position) = candidates.iter().position(|(path, _)| *path == tag) {
            let (path, kind) = candidates.remove(position);
            if !matches!(kind.value, Value::String(_)) {
                candidates.push((path, kind));
            }
        }
        for (candidate, child) in candidates {
            trials += 1;
            if trials > MAX_BLAME_TRIALS {
                return current;
            }
            let Some(relative) = candidate.strip_prefix(root) else {
                continue;
            };
            let mut trial = node.clone();
            if !trial.remove(relative) {
                continue;
            }
            match try_decode::<T>(&trial, root) {
                Err(again) if same_problem(&again, error) => {}
                _ => {
                    current = candidate;
                    level = child;
                    continue 'descend;
                }
            }
        }
        return current;
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

/// The internally tagged tables of the schema, by where they sit.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Tagged {
    Behaviour,
    Sensor,
    Obstacle,
}

impl Tagged {
    /// Which tagged table `path` names, if any.
    fn at(path: &FieldPath) -> Option<Self> {
        match path.segments() {
            [.., Segment::Key(k)] if k == "behaviour" => Some(Self::Behaviour),
            [.., Segment::Key(k), Segment::Index(_)] if k == "sensor" => Some(Self::Sensor),
            [Segment::Key(w), Segment::Key(o), Segment::Index(_)]
                if w == "world" && o == "obstacle" =>
            {
                Some(Self::Obstacle)
            }
            _ => None,
        }
    }

    fn kinds(self) -> &'static [&'static str] {
        match self {
            Self::Behaviour => kinds_of::<BehaviourSpec>(),
            Self::Sensor => kinds_of::<SensorSpec>(),
            Self::Obstacle => kinds_of::<ObstacleSpec>(),
        }
    }
}

/// The `kind`s an internally tagged enum knows, read from serde itself (by asking it to decode
/// a kind no enum has), so that adding a variant needs no edit here.
pub(crate) fn kinds_of<T: DeserializeOwned>() -> &'static [&'static str] {
    let probe = Node {
        span: 0..0,
        value: Value::Table(vec![Entry {
            key: "kind".to_owned(),
            key_span: 0..0,
            node: Node {
                span: 0..0,
                value: Value::String("\u{0}".to_owned()),
            },
        }]),
    };
    match try_decode::<T>(&probe, &FieldPath::root()) {
        Err(DeError {
            kind: DeErrorKind::UnknownVariant { expected, .. },
            ..
        }) => expected,
        _ => &[],
    }
}

fn missing_field(table: &FieldPath, field: &str) -> Finding {
    let path = table.key(field);
    let mut finding = Finding::new(path, Anchor::Key, "required field is missing");
    let tagged = (field == "kind").then(|| Tagged::at(table)).flatten();
    finding = match tagged {
        Some(tagged) => {
            let kinds = plain_list(tagged.kinds());
            finding.message = format!("required field is missing; this build knows: {kinds}");
            finding.expected(format!("one of: {kinds}"))
        }
        None => finding.expected(format!("a value for `{field}`")),
    };
    finding
}

/// The finding for an error located at `culprit`.
fn finding(kind: &DeErrorKind, culprit: &FieldPath, node: &Node, root: &FieldPath) -> Finding {
    match kind {
        DeErrorKind::UnknownField { field, expected } => {
            let valid = if expected.is_empty() {
                "no fields here".to_owned()
            } else {
                format!("one of {}", list(expected))
            };
            let message = match closest(field, expected) {
                Some(near) => format!("unknown field `{field}`, did you mean `{near}`?"),
                None => format!("unknown field `{field}`, expected {valid}"),
            };
            Finding::new(culprit.clone(), Anchor::Key, message).expected(valid)
        }
        DeErrorKind::UnknownVariant { variant, expected } => {
            unknown_kind(culprit, variant, expected)
        }
        DeErrorKind::MissingField { field } => missing_field(culprit, field),
        DeErrorKind::DuplicateField { field } => Finding::new(
            culprit.clone(),
            Anchor::Key,
            format!("`{field}` is given twice"),
        )
        .expected(format!("one `{field}`")),
        DeErrorKind::InvalidType { found, expected }
        | DeErrorKind::InvalidValue { found, expected } => {
            let expected = plain_expected(expected);
            Finding::new(
                culprit.clone(),
                Anchor::Value,
                format!("expected {expected}"),
            )
            .expected(expected)
            .found(plain_found(found))
        }
        DeErrorKind::InvalidLength { len, expected } => {
            let expected = plain_expected(expected);
            Finding::new(
                culprit.clone(),
                Anchor::Value,
                format!("expected {expected}"),
            )
            .expected(expected)
            .found(format!("{len} elements"))
        }
        DeErrorKind::Custom(message) if message.contains("untagged enum RayGridSpec") => {
            let expected = "\"auto\" or [columns, rows]";
            let found = culprit
                .strip_prefix(root)
                .and_then(|rel| node.get(rel))
                .map(describe)
                .unwrap_or_else(|| "something else".to_owned());
            Finding::new(
                culprit.clone(),
                Anchor::Value,
                format!("expected {expected}"),
            )
            .expected(expected)
            .found(found)
        }
        DeErrorKind::Custom(message) => {
            Finding::new(culprit.clone(), Anchor::Value, message.clone())
        }
    }
}

fn unknown_kind(culprit: &FieldPath, variant: &str, expected: &'static [&'static str]) -> Finding {
    let kinds = plain_list(expected);
    let table = culprit.parent().unwrap_or_default();
    let mut message = match Tagged::at(&table).filter(|_| culprit.last_key() == Some("kind")) {
        Some(Tagged::Behaviour) => {
            let owner = table.parent().unwrap_or_default();
            format!("unknown behaviour '{variant}' for {owner}: this build knows: {kinds}")
        }
        Some(Tagged::Sensor) => {
            format!("unknown sensor kind '{variant}': this build knows: {kinds}")
        }
        Some(Tagged::Obstacle) => {
            format!("unknown obstacle kind '{variant}': this build knows: {kinds}")
        }
        None => format!("unknown value '{variant}', expected one of: {kinds}"),
    };
    if let Some(near) = closest(variant, expected) {
        message.push_str(&format!(" (did you mean '{near}'?)"));
    }
    Finding::new(culprit.clone(), Anchor::Value, message).expected(format!("one of: {kinds}"))
}

/// serde's names of what it wanted, in the words of a TOML file.
fn plain_expected(expected: &str) -> String {
    match expected {
        "f64" | "f32" => "a number".to_owned(),
        "u32" => "a whole number from 0 to 4294967295".to_owned(),
        "u64" => "a whole number from 0 up".to_owned(),
        "a sequence" => "an array".to_owned(),
        "a map" => "a table".to_owned(),
        "path string" => "a file path (a string)".to_owned(),
        "variant identifier" => "a kind name (a string)".to_owned(),
        // Values buffered for a `kind` table: only a datetime is refused there.
        "any value" => "a number, string, boolean, array or table".to_owned(),
        other if other.starts_with("struct ") => "a table".to_owned(),
        other if other.starts_with("internally tagged enum ") => "a table with a `kind`".to_owned(),
        other => other.to_owned(),
    }
}

/// serde's names of what it saw, in the words of a TOML file.
fn plain_found(found: &str) -> String {
    match found {
        "map" => "a table".to_owned(),
        "sequence" => "an array".to_owned(),
        other => other.to_owned(),
    }
}

fn describe(node: &Node) -> String {
    match &node.value {
        Value::String(text) => format!("string {text:?}"),
        Value::Integer(v) => format!("integer `{v}`"),
        Value::Float(v) => format!("floating point `{v:?}`"),
        Value::Boolean(v) => format!("boolean `{v}`"),
        Value::Datetime(text) => format!("datetime `{text}`"),
        Value::OutOfRange(text) => format!("number `{text}`"),
        Value::Array(elements) => format!("an array of {} elements", elements.len()),
        Value::Table(_) => "a table".to_owned(),
    }
}

/// Every non-finite number in the file (`nan`, `inf`, or a literal too large for 64 bits):
/// none of the scenario's quantities can take one.
pub(crate) fn non_finite(tree: &Node) -> Vec<Finding> {
    let mut findings = Vec::new();
    tree.walk(&FieldPath::root(), &mut |path, node| {
        if let Value::Float(x) = node.value
            && !x.is_finite()
        {
            findings.push(Finding::must_be(
                path.clone(),
                "a finite number",
                format!("{x}"),
            ));
        }
    });
    findings
}
