//! Tests of the `.bt` writer and reader: byte layouts derived by hand from
//! `OccupancyOcTreeBase::writeBinaryNode`, pruning, errors, and round trips.

use std::collections::BTreeMap;

use proptest::prelude::*;

use super::*;

const OCCUPIED: f32 = 0.85;
const FREE: f32 = -0.4;

fn write(voxels: &[(IVec3, f32)]) -> Vec<u8> {
    let mut out = Vec::new();
    write_bt(&mut out, 0.1, voxels.iter().copied()).unwrap();
    out
}

/// Splits a written file into its header text and its data bytes.
fn split(bytes: &[u8]) -> (String, &[u8]) {
    let end = bytes.windows(5).position(|w| w == b"data\n").unwrap() + 5;
    (
        String::from_utf8(bytes[..end].to_vec()).unwrap(),
        &bytes[end..],
    )
}

fn read(bytes: &[u8]) -> BtTree {
    parse_bt(bytes).unwrap()
}

#[test]
fn header_is_octomaps() {
    let (header, _) = split(&write(&[(IVec3::ZERO, OCCUPIED)]));
    assert_eq!(
        header,
        "# Octomap OcTree binary file\n\
         # (feel free to add / change comments, but leave the first line as it is!)\n#\n\
         id OcTree\nsize 17\nres 0.1\ndata\n"
    );
}

/// Every key's bits land where the interleaving puts them: bit `b` at bit `3b`, for all 2^16
/// keys, against the definition bit by bit.
#[test]
fn spread_bits_moves_bit_b_to_bit_3b() {
    for k in 0..=u16::MAX {
        let by_bit: u64 = (0..16).map(|b| u64::from((k >> b) & 1) << (3 * b)).sum();
        assert_eq!(spread_bits(k), by_bit, "key {k:#06x}");
    }
}

/// Voxel (0,0,0) has OctoMap key 32768 = 0b1000_0000_0000_0000 on each axis: child 7 at the
/// root (bit 15 set on x, y, z), then child 0 for 15 levels. Root: child 7 inner -> second byte
/// bits 6-7 = 0b11 -> 0xC0. Depths 1-14: child 0 inner -> 0x03. Depth 15: child 0 occupied
/// (high bit) -> 0x02. 16 inner nodes + 1 leaf = 17 nodes.
#[test]
fn single_occupied_voxel_at_the_origin() {
    let bytes = write(&[(IVec3::ZERO, OCCUPIED)]);
    let (_, data) = split(&bytes);
    let mut expected = vec![0x00, 0xC0];
    for _ in 1..15 {
        expected.extend([0x03, 0x00]);
    }
    expected.extend([0x02, 0x00]);
    assert_eq!(data, expected.as_slice());
    let tree = read(&bytes);
    assert_eq!(tree.nodes, 17);
    assert_eq!(
        tree.leaves,
        vec![BtLeaf {
            min_voxel: IVec3::ZERO,
            depth: 16,
            occupied: true
        }]
    );
}

/// Voxel (-1,-1,-1) has key 32767 = 0b0111_1111_1111_1111: child 0 at the root, then child 7
/// for 15 levels; free is the low bit of child 7's pair -> 0x40.
#[test]
fn single_free_voxel_below_the_origin() {
    let bytes = write(&[(IVec3::NEG_ONE, FREE)]);
    let (_, data) = split(&bytes);
    let mut expected = vec![0x03, 0x00];
    for _ in 1..15 {
        expected.extend([0x00, 0xC0]);
    }
    expected.extend([0x00, 0x40]);
    assert_eq!(data, expected.as_slice());
    assert_eq!(read(&bytes).state_of(IVec3::NEG_ONE), Some(false));
    assert_eq!(read(&bytes).state_of(IVec3::ZERO), None);
}

fn cube(min: IVec3, side: i32, log_odds: f32) -> Vec<(IVec3, f32)> {
    let mut out = Vec::new();
    for z in 0..side {
        for y in 0..side {
            for x in 0..side {
                out.push((min + IVec3::new(x, y, z), log_odds));
            }
        }
    }
    out
}

/// Eight occupied voxels filling the depth-15 node of (0,0,0) collapse into one occupied leaf
/// at depth 15, child 0 of the depth-14 node: 15 inner nodes + 1 leaf = 16 nodes, 30 bytes.
#[test]
fn full_octant_of_one_state_is_pruned() {
    let bytes = write(&cube(IVec3::ZERO, 2, OCCUPIED));
    let (header, data) = split(&bytes);
    assert!(header.contains("size 16\n"));
    let mut expected = vec![0x00, 0xC0];
    for _ in 1..14 {
        expected.extend([0x03, 0x00]);
    }
    expected.extend([0x02, 0x00]);
    assert_eq!(data, expected.as_slice());
    let tree = read(&bytes);
    assert_eq!(
        tree.leaves,
        vec![BtLeaf {
            min_voxel: IVec3::ZERO,
            depth: 15,
            occupied: true
        }]
    );
    assert_eq!(tree.covered_voxels(), 8);
}

/// 4x4x4 free voxels prune twice (to one leaf at depth 14); with one voxel occupied instead,
/// only the seven untouched depth-15 octants prune, and the touched one keeps 8 leaves.
#[test]
fn pruning_cascades_and_stops_at_mixed_nodes() {
    let tree = read(&write(&cube(IVec3::ZERO, 4, FREE)));
    assert_eq!(tree.leaves.len(), 1);
    assert_eq!(tree.leaves[0].depth, 14);
    assert!(!tree.leaves[0].occupied);
    // Nodes: root + 13 inner (depths 1-13) + 1 leaf.
    assert_eq!(tree.nodes, 15);

    let mut voxels = cube(IVec3::ZERO, 4, FREE);
    voxels.push((IVec3::new(1, 1, 1), OCCUPIED)); // last entry wins
    let bytes = write(&voxels);
    let tree = read(&bytes);
    assert_eq!(tree.leaves.len(), 7 + 8);
    assert_eq!(tree.leaves.iter().filter(|l| l.depth == 15).count(), 7);
    assert_eq!(tree.state_of(IVec3::new(1, 1, 1)), Some(true));
    assert_eq!(tree.state_of(IVec3::new(1, 1, 0)), Some(false));
    assert_eq!(tree.covered_voxels(), 64);
    // The depth-15 node of (0..2)^3: children 0-6 free (0b01), child 7 occupied (0b10):
    // bytes 0b01_01_01_01 = 0x55 and 0b10_01_01_01 = 0x95, the last two of the file.
    assert_eq!(&bytes[bytes.len() - 2..], &[0x55, 0x95]);
}

#[test]
fn empty_map_is_a_tree_of_size_zero() {
    let bytes = write(&[]);
    let (header, data) = split(&bytes);
    assert!(header.contains("size 0\n"));
    assert!(data.is_empty());
    assert_eq!(read(&bytes).leaves, vec![]);
}

#[test]
fn writer_refuses_bad_input() {
    let mut out = Vec::new();
    let kind = |r: io::Result<()>| r.unwrap_err().kind();
    assert_eq!(
        kind(write_bt(&mut out, 0.0, [])),
        io::ErrorKind::InvalidInput
    );
    assert_eq!(
        kind(write_bt(&mut out, f64::NAN, [])),
        io::ErrorKind::InvalidInput
    );
    let far = [(IVec3::new(0, 32768, 0), 1.0)];
    assert_eq!(
        kind(write_bt(&mut out, 0.1, far)),
        io::ErrorKind::InvalidInput
    );
    let nan = [(IVec3::ZERO, f32::NAN)];
    assert_eq!(
        kind(write_bt(&mut out, 0.1, nan)),
        io::ErrorKind::InvalidInput
    );
    // The extreme keys fit.
    let corners = [(IVec3::splat(-32768), 1.0), (IVec3::splat(32767), -1.0)];
    assert!(write_bt(&mut out, 0.1, corners).is_ok());
}

#[test]
fn reader_refuses_corrupt_files() {
    let good = write(&[(IVec3::ZERO, OCCUPIED)]);
    let msg = |bytes: &[u8]| parse_bt(bytes).unwrap_err().problem.to_string();
    assert!(msg(&good[..good.len() - 1]).contains("truncated"));
    let (header, data) = split(&good);
    let edit = |from: &str, to: &str| [header.replace(from, to).as_bytes(), data].concat();
    assert!(msg(&edit("size 17", "size 18")).contains("header says 18 nodes, the data holds 17"));
    assert_eq!(
        parse_bt(b"# Octomap OcTree text\n").unwrap_err().line,
        Some(1)
    );
    let color = edit("id OcTree", "id ColorOcTree");
    assert!(msg(&color).contains("ColorOcTree"));
    assert_eq!(parse_bt(&color).unwrap_err().line, Some(7));
    assert_eq!(
        parse_bt(&edit("res 0.1", "res -1")).unwrap_err().line,
        Some(6)
    );
    // A chain of 16 inner nodes claims children below the voxels.
    let mut deep = header.into_bytes();
    deep.extend([0x03, 0x00].repeat(17));
    assert!(msg(&deep).contains("depth 16"));
}

#[test]
fn reader_accepts_crlf_comments_and_unknown_keywords() {
    let good = write(&[(IVec3::ZERO, OCCUPIED)]);
    let (header, data) = split(&good);
    let mut edited = header
        .replace("id OcTree\n", "id OcTree\r\n# note\nfoo bar\n")
        .into_bytes();
    edited.extend(data);
    assert_eq!(read(&edited), read(&good));
}

/// Expands a read tree back into voxels (small trees only).
fn expand(tree: &BtTree) -> BTreeMap<[i32; 3], bool> {
    let mut out = BTreeMap::new();
    for leaf in &tree.leaves {
        let s = leaf.side_voxels();
        for (v, _) in cube(leaf.min_voxel, s, 0.0) {
            out.insert(v.to_array(), leaf.occupied);
        }
    }
    out
}

proptest! {
    /// Any voxel set (with whole blocks, to exercise pruning) reads back as exactly the same
    /// voxels and states, and writing the read tree again gives the same bytes (the pruned form
    /// is canonical).
    #[test]
    fn round_trip(
        singles in proptest::collection::vec(((-40i32..40, -40i32..40, -40i32..40), -2.0f32..2.0), 0..60),
        blocks in proptest::collection::vec(((-5i32..5, -5i32..5, -5i32..5), 1u32..3, any::<bool>()), 0..4),
    ) {
        let mut voxels = Vec::new();
        for ((x, y, z), level, occupied) in blocks {
            let side = 1 << level;
            voxels.extend(cube(IVec3::new(x, y, z) * side, side, if occupied { 1.0 } else { -1.0 }));
        }
        voxels.extend(singles.into_iter().map(|((x, y, z), l)| (IVec3::new(x, y, z), l)));
        let mut expected = BTreeMap::new();
        for (v, l) in &voxels {
            expected.insert(v.to_array(), *l >= 0.0);
        }
        let bytes = write(&voxels);
        let tree = read(&bytes);
        prop_assert_eq!(tree.covered_voxels(), expected.len() as u64);
        prop_assert_eq!(&expand(&tree), &expected);
        let again: Vec<(IVec3, f32)> = expected
            .iter()
            .map(|(v, &o)| (IVec3::from_array(*v), if o { 1.0 } else { -1.0 }))
            .collect();
        prop_assert_eq!(write(&again), bytes);
    }
}
