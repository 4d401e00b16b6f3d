//! Typed decoding of the tree that reports every problem it can find, not just the first.
//!
//! The file is decoded in units: the top level (without its UAVs and obstacles), each
//! `[[world.obstacle]]`, each `[[uav]]` (without its sensors) and each `[[uav.sensor]]`, so a bad
//! entry never hides the others. Inside a unit, each error is reported and the offending value
//! cut out of the tree, and the unit is decoded again, until it decodes or nothing more can be
//! cut (a missing required field ends its unit: nothing can be assumed in its place).

mod locate;
mod messages;

use serde::de::DeserializeOwned;

use super::de::{DeError, DeErrorKind, NodeDeserializer};
use super::diagnostic::Finding;
use super::path::{FieldPath, Segment};
use super::schema::{BoundsSpec, MapSpec, ObstacleSpec, Scenario, SensorSpec, UavSpec};
use super::source_map::Anchor;
use super::suggest::closest;
use super::tree::{Element, Node, Value};

use locate::{locate, locate_missing};
use messages::{finding, missing_field};

/// Problems reported per unit (an entry); past this, the entry is only said to have more. Each
/// problem costs a few decodings of its entry, so this also bounds the time a hostile file
/// can take.
const MAX_FINDINGS_PER_UNIT: usize = 50;

/// The decoded pieces of a file, with their indices in the file; `None` where a piece had
/// problems (already reported).
#[derive(Debug, Default)]
pub(crate) struct Decoded {
    /// The top level with empty `uav` and `world.obstacle` lists.
    pub root: Option<Scenario>,
    /// `[map]` and `[world.bounds]`: from the top level, or, when it had problems, decoded on
    /// their own (quietly: their problems are the top level's findings) so that the checks
    /// that need them still run.
    pub map: Option<MapSpec>,
    pub bounds: Option<BoundsSpec>,
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

    let quiet_map = quiet::<MapSpec>(&root, "map").or_else(|| {
        root.get(&[Segment::Key("map".to_owned())])
            .is_none()
            .then(MapSpec::default)
    });
    let quiet_bounds = quiet::<BoundsSpec>(&root, "world.bounds");
    let root = decode_unit::<Scenario>(root, &FieldPath::root(), findings);
    let mut decoded = Decoded {
        map: root.as_ref().map(|r| r.map.clone()).or(quiet_map),
        bounds: root.as_ref().map(|r| r.world.bounds).or(quiet_bounds),
        root,
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

/// The value at `path` in `node` if it decodes without any problem.
fn quiet<T: DeserializeOwned>(node: &Node, path: &str) -> Option<T> {
    let path = FieldPath::parse(path);
    try_decode::<T>(node.get(path.segments())?, &path).ok()
}

/// One decoding attempt of a unit; errors without a place are the unit's own.
pub(super) fn try_decode<T: DeserializeOwned>(node: &Node, root: &FieldPath) -> Result<T, DeError> {
    T::deserialize(NodeDeserializer::new(node, root.clone())).map_err(|error| error.at(root))
}

/// Decodes one unit (`node`, found at `root`), reporting every problem it can.
pub(super) fn decode_unit<T: DeserializeOwned>(
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
            let at = locate_missing::<T>(&node, root, &at, &error);
            // A value we cut out earlier is not missing a second time.
            if !removed.contains(&at.key(field)) {
                findings.push(missing_field(&at, field));
            }
            at
        } else {
            let culprit = locate::<T>(&node, root, &at, &error);
            findings.push(finding(&error.kind, &culprit, &node, root));
            // A misspelt field that was matched to a valid name is not reported again as that
            // name missing.
            if let DeErrorKind::UnknownField { field, expected } = &error.kind
                && let (Some(near), Some(table)) = (closest(field, expected), culprit.parent())
            {
                removed.push(table.key(near));
            }
            culprit
        };
        let relative = cut.strip_prefix(root)?;
        if relative.is_empty() || !node.remove(relative) {
            return None;
        }
        removed.push(cut);
    }
}

/// Every number in the file that no quantity of a scenario can take (`nan`, `inf`, a literal too
/// large for 64 bits, or one beyond the 32-bit floats of the geometry:
/// [`crate::scenario::check::unusable_number`]) in `node`, found at `at`.
pub(crate) fn non_finite(node: &Node, at: &FieldPath) -> Vec<Finding> {
    let mut findings = Vec::new();
    node.walk(at, &mut |path, node| {
        if let Value::Float(x) = node.value {
            findings.extend(crate::scenario::check::unusable_number(path, x));
        }
    });
    findings
}
