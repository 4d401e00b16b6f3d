//! Our `.bt` files against the real OctoMap library (opt-in: `engine/tests/octomap/run.sh`
//! installs liboctomap-dev, builds the C++ checker and runs this test with `--ignored`).
//!
//! A known voxel set (occupied and free, negative keys, the extreme keys, blocks that prune at
//! depths 13, 14 and 15, a mixed block and a misaligned block that must not prune) is written
//! with `write_bt`, then:
//! 1. OctoMap's `OcTree::readBinary` loads it; every voxel's state, unknown neighbours, the tree
//!    size and the leaves (depth, state, corner) must be the expected ones;
//! 2. OctoMap builds the same voxels itself (`updateNode`) and saves them with `writeBinary`:
//!    its file must be byte for byte ours;
//! 3. our `load_bt` reads OctoMap's file back to the same leaves.

use std::collections::{BTreeMap, BTreeSet};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

use glam::IVec3;
use uavex_engine::formats::octomap::{BtLeaf, load_bt, write_bt};

const RES: f64 = 0.1;

fn checker() -> PathBuf {
    std::env::var_os("UAVEX_OCTOMAP_CHECKER")
        .map(PathBuf::from)
        .expect("set UAVEX_OCTOMAP_CHECKER (engine/tests/octomap/run.sh builds the checker)")
}

fn block(min: [i32; 3], side: i32, occupied: bool, out: &mut BTreeMap<[i32; 3], bool>) {
    for z in 0..side {
        for y in 0..side {
            for x in 0..side {
                out.insert([min[0] + x, min[1] + y, min[2] + z], occupied);
            }
        }
    }
}

/// Voxel key -> occupied.
type Voxels = BTreeMap<[i32; 3], bool>;
/// Octree leaves as (depth, occupied, min corner).
type Leaves = BTreeSet<(u8, bool, [i32; 3])>;

/// The voxel set, and the leaves OctoMap must hold for it.
fn scene() -> (Voxels, Leaves) {
    let mut voxels = BTreeMap::new();
    let mut leaves = BTreeSet::new();
    // Aligned blocks prune: side 8 -> depth 13, side 4 -> depth 14, side 2 -> depth 15.
    // (Keys + 32768 are multiples of the side, so each block is exactly one octree node.)
    for (min, side, occupied, depth) in [
        ([-16, 0, 8], 8, false, 13),
        ([-8, -8, -8], 4, true, 14),
        ([2, -4, 6], 2, false, 15),
    ] {
        block(min, side, occupied, &mut voxels);
        leaves.insert((depth, occupied, min));
    }
    // A full node of mixed states (one free voxel among occupied ones) and a block straddling
    // node borders (odd keys): neither prunes.
    let mut unpruned = BTreeMap::new();
    block([0, 0, 0], 2, true, &mut unpruned);
    unpruned.insert([1, 0, 1], false);
    block([5, 9, -1], 2, true, &mut unpruned);
    // Singles, including OctoMap's extreme keys.
    for (v, occupied) in [
        ([-1, 5, -3], true),
        ([100, -200, 50], false),
        ([-32768, -32768, -32768], true),
        ([32767, 32767, 32767], false),
    ] {
        unpruned.insert(v, occupied);
    }
    for (v, occupied) in unpruned {
        voxels.insert(v, occupied);
        leaves.insert((16, occupied, v));
    }
    (voxels, leaves)
}

/// Voxels next to the scene that were never given: OctoMap must call them unknown.
fn unknown_voxels() -> Vec<[i32; 3]> {
    vec![
        [-17, 0, 8],
        [-8, -8, -4],
        [4, -4, 6],
        [2, 0, 0],
        [7, 9, -1],
        [-1, 5, -2],
        [-32767, -32768, -32768],
        [32766, 32767, 32767],
    ]
}

fn center(v: [i32; 3]) -> String {
    let c = v.map(|k| (f64::from(k) + 0.5) * RES);
    format!("{} {} {}\n", c[0], c[1], c[2])
}

fn run(args: &[&str], stdin: &str) -> String {
    let mut child = Command::new(checker())
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .spawn()
        .expect("run the OctoMap checker");
    child
        .stdin
        .take()
        .unwrap()
        .write_all(stdin.as_bytes())
        .unwrap();
    let out = child.wait_with_output().unwrap();
    assert!(out.status.success(), "checker {args:?} failed");
    String::from_utf8(out.stdout).unwrap()
}

fn write_ours(path: &Path, voxels: &BTreeMap<[i32; 3], bool>) {
    let mut file = std::io::BufWriter::new(std::fs::File::create(path).unwrap());
    let entries = voxels
        .iter()
        .map(|(v, &occupied)| (IVec3::from_array(*v), if occupied { 0.85 } else { -0.41 }));
    write_bt(&mut file, RES, entries).unwrap();
    file.flush().unwrap();
}

#[test]
#[ignore = "needs the real OctoMap library: run engine/tests/octomap/run.sh"]
fn real_octomap_reads_what_we_write_and_writes_the_same_bytes() {
    let (voxels, expected_leaves) = scene();
    let dir = tempfile::tempdir().unwrap();
    let ours = dir.path().join("ours.bt");
    write_ours(&ours, &voxels);

    // 1. OctoMap reads our file.
    let queries: String = voxels
        .keys()
        .chain(unknown_voxels().iter())
        .map(|v| center(*v))
        .collect();
    let report = run(&["read", ours.to_str().unwrap()], &queries);
    let mut states = Vec::new();
    let mut leaves = BTreeSet::new();
    let mut size = None;
    let mut leaf_count = None;
    for line in report.lines() {
        let words: Vec<&str> = line.split_whitespace().collect();
        match words.as_slice() {
            ["query", state] => states.push(state.to_string()),
            ["size", n] => size = Some(n.parse::<u64>().unwrap()),
            ["leaves", n] => leaf_count = Some(n.parse::<usize>().unwrap()),
            ["leaf", depth, occupied, x, y, z] => {
                leaves.insert((
                    depth.parse::<u8>().unwrap(),
                    *occupied == "1",
                    [x, y, z].map(|k| k.parse::<i32>().unwrap()),
                ));
            }
            _ => {}
        }
    }
    let expected_states: Vec<String> = voxels
        .values()
        .map(|&o| if o { "occupied" } else { "free" }.to_string())
        .chain(unknown_voxels().iter().map(|_| "unknown".to_string()))
        .collect();
    assert_eq!(states, expected_states);
    assert_eq!(leaves, expected_leaves);
    assert_eq!(leaf_count, Some(expected_leaves.len()));
    let ours_read = load_bt(&ours).unwrap();
    assert_eq!(size, Some(ours_read.nodes));
    println!(
        "OctoMap read {} voxels as {} leaves, {} nodes; all {} queries match",
        voxels.len(),
        expected_leaves.len(),
        ours_read.nodes,
        expected_states.len()
    );

    // 2. OctoMap writes the same voxels: byte-identical files.
    let reference = dir.path().join("octomap.bt");
    let lines: String = voxels
        .iter()
        .map(|(v, &o)| format!("{} {} {} {}\n", v[0], v[1], v[2], u8::from(o)))
        .collect();
    run(
        &["write", reference.to_str().unwrap(), &RES.to_string()],
        &lines,
    );
    let (a, b) = (
        std::fs::read(&ours).unwrap(),
        std::fs::read(&reference).unwrap(),
    );
    assert!(
        a == b,
        "our .bt differs from OctoMap's writeBinary ({} vs {} bytes)",
        a.len(),
        b.len()
    );
    println!(
        "OctoMap's writeBinary of the same voxels is byte-identical ({} bytes)",
        a.len()
    );

    // 3. Our reader on OctoMap's file.
    let theirs = load_bt(&reference).unwrap();
    let read: BTreeSet<(u8, bool, [i32; 3])> = theirs
        .leaves
        .iter()
        .map(|l: &BtLeaf| (l.depth, l.occupied, l.min_voxel.to_array()))
        .collect();
    assert_eq!(read, expected_leaves);
}
