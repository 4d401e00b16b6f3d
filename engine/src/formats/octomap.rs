//! OctoMap's binary tree format (`.bt`), as `octomap::OcTree::writeBinary` writes it and
//! `octovis`, `octomap_server` and `OcTree::readBinary` read it.
//!
//! A text header (`# Octomap OcTree binary file`, comments, `id OcTree`, `size N`, `res R`,
//! `data`) is followed by the tree in depth-first order (`writeBinaryNode`): per inner node two
//! bytes holding a 2-bit code per child, children 0-3 in the first byte and 4-7 in the second,
//! child `i` in bits `2i` (low) and `2i + 1` (high) of its byte: `00` absent (unknown), `01` (low
//! bit set) free leaf, `10` occupied leaf, `11` inner node, whose own two bytes follow after its
//! parent's, children in index order. `N` counts every node of the tree, root included; OctoMap
//! refuses a file whose count differs.
//!
//! Keys (common.md §1): the map's voxel key is `floor(p / res)`; OctoMap's is that plus 32768
//! (`tree_max_val`) in 16 bits per axis, and a node at depth `d` picks child
//! `x + 2y + 4z` from bit `15 - d` of the three keys (`computeChildIdx`). Voxels are leaves at
//! depth 16. The binary format keeps occupancy only: log-odds `>= 0` is occupied, else free.
//! Like `writeBinary` (which prunes first), the writer replaces every node whose eight children
//! are leaves of one state by a leaf of that state, bottom-up; the root is never pruned.

use std::io::{self, Read, Write};
use std::path::Path;

use glam::IVec3;

use super::{Fault, FormatError, read_file};

/// Depth of an OctoMap tree: leaves at depth 16 are single voxels.
pub const TREE_DEPTH: u8 = 16;
/// Offset from the map's voxel key to OctoMap's key (`tree_max_val`).
pub const TREE_MAX_VAL: i32 = 32768;

const MAGIC: &str = "# Octomap OcTree binary file";

/// Writes voxels (map voxel key, log-odds) as an OctoMap `.bt` file of resolution `resolution`
/// metres. Voxels not given are unknown. When a key repeats, the last entry wins.
///
/// Errors (`InvalidInput`): a resolution that is not finite and positive, a key outside
/// OctoMap's range `-32768..=32767` per axis, a NaN log-odds.
pub fn write_bt(
    w: &mut impl Write,
    resolution: f64,
    voxels: impl IntoIterator<Item = (IVec3, f32)>,
) -> io::Result<()> {
    if !(resolution.is_finite() && resolution > 0.0) {
        return Err(invalid(format!(
            "resolution {resolution} is not a positive length"
        )));
    }
    let mut leaves = Vec::new();
    for (voxel, log_odds) in voxels {
        if log_odds.is_nan() {
            return Err(invalid(format!("voxel {voxel} has a NaN log-odds")));
        }
        leaves.push((morton_code(voxel)?, log_odds >= 0.0));
    }
    // Stable sort, then keep the last of equal keys.
    leaves.sort_by_key(|&(code, _)| code);
    leaves.dedup_by(|later, kept| {
        let same = later.0 == kept.0;
        if same {
            *kept = *later;
        }
        same
    });
    let mut data = Vec::new();
    if !leaves.is_empty() {
        write_node(&leaves, TREE_DEPTH.into(), true, &mut data);
    }
    write!(
        w,
        "{MAGIC}\n# (feel free to add / change comments, but leave the first line as it is!)\n#\n\
         id OcTree\nsize {}\nres {resolution}\ndata\n",
        node_count(&data, !leaves.is_empty())
    )?;
    w.write_all(&data)
}

fn invalid(message: String) -> io::Error {
    io::Error::new(io::ErrorKind::InvalidInput, message)
}

/// OctoMap key interleaved so that the 3-bit digit at bit `b` is that level's child index
/// (`x + 2y + 4z`, most significant level first): sorting by it is depth-first tree order.
fn morton_code(voxel: IVec3) -> io::Result<u64> {
    let key = voxel
        .to_array()
        .map(|k| u16::try_from(i64::from(k) + i64::from(TREE_MAX_VAL)));
    let [Ok(x), Ok(y), Ok(z)] = key else {
        return Err(invalid(format!(
            "voxel {voxel} is outside OctoMap's key range -32768..=32767"
        )));
    };
    Ok(spread_bits(x) | spread_bits(y) << 1 | spread_bits(z) << 2)
}

/// The 16 bits of `k` moved to every third bit (bit `b` to bit `3b`), in halving steps: the
/// bytes apart (each byte's bits to `24 (b / 8) + b % 8`), then the nibbles, the pairs and
/// the bits, each step shifting every group's upper half away and masking its old place out.
fn spread_bits(k: u16) -> u64 {
    let mut v = u64::from(k);
    v = (v | v << 16) & 0x0000_0000_ff00_00ff;
    v = (v | v << 8) & 0x0000_00f0_0f00_f00f;
    v = (v | v << 4) & 0x0000_0c30_c30c_30c3;
    v = (v | v << 2) & 0x0000_2492_4924_9249;
    v
}

/// A child as the binary format codes it.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Child {
    Absent,
    Leaf { occupied: bool },
    Inner,
}

impl Child {
    fn code(self) -> u8 {
        match self {
            Child::Absent => 0b00,
            Child::Leaf { occupied: false } => 0b01,
            Child::Leaf { occupied: true } => 0b10,
            Child::Inner => 0b11,
        }
    }

    fn from_code(code: u8) -> Self {
        match code & 0b11 {
            0b00 => Child::Absent,
            0b01 => Child::Leaf { occupied: false },
            0b10 => Child::Leaf { occupied: true },
            _ => Child::Inner,
        }
    }
}

/// Appends the node holding `leaves` (sorted, distinct codes) with `levels` key bits below it,
/// and returns what its parent must record for it. A node whose eight children are leaves of
/// one state becomes such a leaf itself (its two bytes, the last ones written, are removed).
fn write_node(leaves: &[(u64, bool)], levels: u32, is_root: bool, out: &mut Vec<u8>) -> Child {
    let flags_at = out.len();
    out.extend([0, 0]);
    let shift = 3 * (levels - 1);
    let digit = |code: u64| ((code >> shift) & 7) as usize;
    let mut children = [Child::Absent; 8];
    let mut rest = leaves;
    while let Some(&(first, occupied)) = rest.first() {
        let i = digit(first);
        let n = rest
            .iter()
            .position(|&(c, _)| digit(c) != i)
            .unwrap_or(rest.len());
        let (group, tail) = rest.split_at(n);
        rest = tail;
        children[i] = if levels == 1 {
            Child::Leaf { occupied }
        } else {
            write_node(group, levels - 1, false, out)
        };
    }
    if !is_root
        && matches!(children[0], Child::Leaf { .. })
        && children.iter().all(|c| *c == children[0])
    {
        out.truncate(flags_at);
        return children[0];
    }
    for (i, child) in children.iter().enumerate() {
        out[flags_at + i / 4] |= child.code() << (2 * (i % 4));
    }
    Child::Inner
}

/// Nodes in a written tree: the root plus every child coded in its bytes.
fn node_count(data: &[u8], has_root: bool) -> u64 {
    let children: u64 = data
        .iter()
        .map(|&b| (0..4).filter(|k| (b >> (2 * k)) & 0b11 != 0).count() as u64)
        .sum();
    children + u64::from(has_root)
}

/// A leaf of a read tree: `2^(16 - depth)` voxels per axis from `min_voxel` (map voxel keys).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct BtLeaf {
    /// The leaf's lowest corner, as a map voxel key.
    pub min_voxel: IVec3,
    /// Depth in the tree: 16 for a single voxel, less for a pruned block.
    pub depth: u8,
    /// Occupied (else free).
    pub occupied: bool,
}

impl BtLeaf {
    /// Voxels per axis covered by this leaf.
    pub fn side_voxels(&self) -> i32 {
        1 << (TREE_DEPTH - self.depth)
    }

    /// Whether the voxel `key` lies in this leaf.
    pub fn contains(&self, key: IVec3) -> bool {
        let rel = key - self.min_voxel;
        rel.min_element() >= 0 && rel.max_element() < self.side_voxels()
    }
}

/// An OctoMap tree as read from a `.bt` file.
#[derive(Debug, Clone, PartialEq)]
pub struct BtTree {
    /// Voxel edge in metres.
    pub resolution: f64,
    /// All leaves: each node's leaf children in index order, then its inner children's.
    pub leaves: Vec<BtLeaf>,
    /// Nodes in the tree (the header's `size`, checked against the data).
    pub nodes: u64,
}

impl BtTree {
    /// The state of the voxel `key`: `Some(true)` occupied, `Some(false)` free, `None` unknown.
    /// A linear search, meant for tests and inspection.
    pub fn state_of(&self, key: IVec3) -> Option<bool> {
        self.leaves
            .iter()
            .find(|l| l.contains(key))
            .map(|l| l.occupied)
    }

    /// Number of voxels the leaves cover (pruned leaves count all their voxels).
    pub fn covered_voxels(&self) -> u64 {
        self.leaves
            .iter()
            .map(|l| 1u64 << (3 * u32::from(TREE_DEPTH - l.depth)))
            .sum()
    }
}

/// Reads a `.bt` file.
pub fn load_bt(path: &Path) -> Result<BtTree, FormatError> {
    parse_bt(&read_file(path)?).map_err(|f| f.in_file(path))
}

/// Reads a `.bt` stream; `name` labels errors.
pub fn read_bt(r: &mut impl Read, name: &Path) -> Result<BtTree, FormatError> {
    let mut bytes = Vec::new();
    r.read_to_end(&mut bytes)
        .map_err(|e| Fault::problem(e.into()).in_file(name))?;
    parse_bt(&bytes).map_err(|f| f.in_file(name))
}

/// The header as `AbstractOcTree::readHeader` reads it: `#` comments, `id`, `size`, `res`,
/// other keywords skipped, up to `data`; returns (resolution, size, byte where data starts).
fn parse_header(bytes: &[u8]) -> Result<(f64, u64, usize), Fault> {
    let (mut id, mut size, mut res) = (None, None, None);
    let mut offset = 0;
    for (i, raw) in bytes.split(|&b| b == b'\n').enumerate() {
        let line = i + 1;
        offset += raw.len() + 1;
        let text = String::from_utf8_lossy(raw);
        if line == 1 {
            if !text.starts_with(MAGIC) {
                return Err(Fault::at(
                    1,
                    format!("not an OctoMap binary file (first line must be {MAGIC:?})"),
                ));
            }
            continue;
        }
        let mut words = text.split_whitespace();
        let value = |w: Option<&str>, key: &str| {
            w.ok_or_else(|| Fault::at(line, format!("{key} without a value")))
                .map(str::to_string)
        };
        match words.next() {
            Some("data") => {
                let id = id.ok_or_else(|| Fault::at(line, "no id line before data"))?;
                if id != "OcTree" {
                    return Err(Fault::at(line, format!("tree type {id:?} is not OcTree")));
                }
                let res: f64 = res.ok_or_else(|| Fault::at(line, "no res line before data"))?;
                let size = size.ok_or_else(|| Fault::at(line, "no size line before data"))?;
                return Ok((res, size, offset.min(bytes.len())));
            }
            Some("id") => id = Some(value(words.next(), "id")?),
            Some("size") => {
                let v = value(words.next(), "size")?;
                size = Some(
                    v.parse()
                        .map_err(|_| Fault::at(line, format!("size {v:?} is not a count")))?,
                );
            }
            Some("res") => {
                let v = value(words.next(), "res")?;
                let r: f64 = v
                    .parse()
                    .map_err(|_| Fault::at(line, format!("res {v:?} is not a number")))?;
                if !(r.is_finite() && r > 0.0) {
                    return Err(Fault::at(line, format!("res {v} is not a positive length")));
                }
                res = Some(r);
            }
            _ => {} // comments and unknown keywords, skipped as OctoMap does
        }
    }
    Err(Fault::bare("file ends before the data line"))
}

pub(crate) fn parse_bt(bytes: &[u8]) -> Result<BtTree, Fault> {
    let (resolution, size, start) = parse_header(bytes)?;
    let mut tree = BtTree {
        resolution,
        leaves: Vec::new(),
        nodes: 0,
    };
    if size > 0 {
        let mut data = &bytes[start..];
        tree.nodes = 1;
        read_node(&mut data, 0, [0; 3], &mut tree)?;
    }
    if tree.nodes != size {
        return Err(Fault::bare(format!(
            "header says {size} nodes, the data holds {}",
            tree.nodes
        )));
    }
    Ok(tree)
}

/// Reads the node at `depth` whose OctoMap key prefix is `key` (`readBinaryNode`).
fn read_node(data: &mut &[u8], depth: u8, key: [u32; 3], tree: &mut BtTree) -> Result<(), Fault> {
    let [a, b, rest @ ..] = *data else {
        return Err(Fault::bare(format!(
            "data ends inside a node at depth {depth} (truncated file?)"
        )));
    };
    *data = rest;
    let bit = u32::from(TREE_DEPTH - 1 - depth);
    let children: [(usize, Child); 8] =
        std::array::from_fn(|i| (i, Child::from_code([a, b][i / 4] >> (2 * (i % 4)))));
    let child_key = |i: usize| {
        let i = i as u32;
        [
            key[0] | (i & 1) << bit,
            key[1] | (i >> 1 & 1) << bit,
            key[2] | (i >> 2 & 1) << bit,
        ]
    };
    for &(i, child) in &children {
        if let Child::Leaf { occupied } = child {
            let k = child_key(i).map(|k| k as i32 - TREE_MAX_VAL);
            tree.leaves.push(BtLeaf {
                min_voxel: IVec3::from_array(k),
                depth: depth + 1,
                occupied,
            });
        }
        if child != Child::Absent {
            tree.nodes += 1;
        }
    }
    for &(i, child) in &children {
        if child == Child::Inner {
            if depth + 1 == TREE_DEPTH {
                return Err(Fault::bare(
                    "a voxel (depth 16) is marked as having children",
                ));
            }
            read_node(data, depth + 1, child_key(i), tree)?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests;
