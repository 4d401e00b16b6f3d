//! Bad-input tests for every reader (DESIGN.md, "Bad input"): random bytes, random bytes behind a
//! plausible header, truncated and corrupted copies of the fixtures must give errors, never a
//! panic; truncating a file whose format declares its size must always be an error.

use proptest::prelude::*;

use super::{obj, octomap, pcd, ply, stl};

const CUBE_OBJ: &[u8] = include_bytes!("../../tests/data/cube.obj");
const CUBE_STL_ASCII: &[u8] = include_bytes!("../../tests/data/cube_ascii.stl");
const CUBE_STL_BINARY: &[u8] = include_bytes!("../../tests/data/cube_binary.stl");
const PCD_ASCII: &[u8] = include_bytes!("../../tests/data/points_ascii.pcd");
const PCD_BINARY: &[u8] = include_bytes!("../../tests/data/points_binary.pcd");
const PCD_COMPRESSED: &[u8] = include_bytes!("../../tests/data/points_binary_compressed.pcd");
const PLY_ASCII: &[u8] = include_bytes!("../../tests/data/points_ascii.ply");
const PLY_LE: &[u8] = include_bytes!("../../tests/data/points_binary_le.ply");
const PLY_BE: &[u8] = include_bytes!("../../tests/data/points_binary_be.ply");

/// Whether one reader accepts some bytes.
type Accepts = fn(&[u8]) -> bool;

/// Every reader on `bytes`; true for each that accepted them. Panics propagate (and fail).
fn run_all(bytes: &[u8]) -> [bool; 5] {
    [
        obj::parse_obj(bytes).is_ok(),
        stl::parse_stl(bytes).is_ok(),
        pcd::parse_pcd(bytes).is_ok(),
        ply::parse_ply_points(bytes).is_ok(),
        octomap::parse_bt(bytes).is_ok(),
    ]
}

fn bt_fixture() -> Vec<u8> {
    let mut out = Vec::new();
    let voxels = (0..40).map(|i| {
        (
            glam::IVec3::new(i % 7 - 3, i / 7 - 2, -i % 3),
            i as f32 - 20.0,
        )
    });
    octomap::write_bt(&mut out, 0.1, voxels).unwrap();
    out
}

/// Headers that get a reader past its header, so that random bytes hit the data decoders.
const HEADERS: [&[u8]; 7] = [
    b"ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty double z\nproperty list uchar int f\nend_header\n",
    b"ply\nformat binary_big_endian 1.0\nelement face 2\nproperty list uint int i\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\nend_header\n",
    b"ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\nend_header\n",
    b"FIELDS x y z\nSIZE 4 4 8\nTYPE F F F\nPOINTS 4\nDATA binary_compressed\n",
    b"FIELDS x y z i\nSIZE 4 4 4 1\nTYPE F F F U\nCOUNT 1 1 1 3\nPOINTS 3\nDATA ascii\n",
    b"# Octomap OcTree binary file\nid OcTree\nsize 9\nres 0.1\ndata\n",
    b"solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\n",
];

proptest! {
    #[test]
    fn random_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..600)) {
        run_all(&bytes);
    }

    #[test]
    fn random_data_behind_valid_headers_never_panics(
        header in 0..HEADERS.len(),
        tail in proptest::collection::vec(any::<u8>(), 0..400),
    ) {
        let mut bytes = HEADERS[header].to_vec();
        bytes.extend(tail);
        run_all(&bytes);
    }

    #[test]
    fn random_text_behind_valid_headers_never_panics(
        header in 0..HEADERS.len(),
        tail in "[-0-9 .enaif/\n]{0,300}",
    ) {
        let mut bytes = HEADERS[header].to_vec();
        bytes.extend(tail.as_bytes());
        run_all(&bytes);
    }

    #[test]
    fn corrupted_fixtures_never_panic(
        which in 0..10usize,
        edits in proptest::collection::vec((any::<prop::sample::Index>(), any::<u8>()), 1..8),
    ) {
        let bt = bt_fixture();
        let fixtures: [&[u8]; 10] = [
            CUBE_OBJ, CUBE_STL_ASCII, CUBE_STL_BINARY, PCD_ASCII, PCD_BINARY, PCD_COMPRESSED,
            PLY_ASCII, PLY_LE, PLY_BE, &bt,
        ];
        let mut bytes = fixtures[which].to_vec();
        for (at, value) in edits {
            let i = at.index(bytes.len());
            bytes[i] = value;
        }
        run_all(&bytes);
    }

    #[test]
    fn truncated_fixtures_are_errors(cut in any::<prop::sample::Index>()) {
        // Formats that declare their size: any strict prefix is an error.
        let bt = bt_fixture();
        let sized: [(&[u8], Accepts); 6] = [
            (CUBE_STL_BINARY, |b| stl::parse_stl(b).is_ok()),
            (PCD_BINARY, |b| pcd::parse_pcd(b).is_ok()),
            (PCD_COMPRESSED, |b| pcd::parse_pcd(b).is_ok()),
            (PLY_LE, |b| ply::parse_ply_points(b).is_ok()),
            (PLY_BE, |b| ply::parse_ply_points(b).is_ok()),
            (&bt, |b| octomap::parse_bt(b).is_ok()),
        ];
        for (bytes, parses) in sized {
            let n = cut.index(bytes.len());
            prop_assert!(!parses(&bytes[..n]), "prefix of {} bytes of {} accepted", n, bytes.len());
        }
        // Text formats: cutting before the last record is an error; any cut never panics.
        let text: [(&[u8], &[u8], Accepts); 4] = [
            (CUBE_STL_ASCII, b"endsolid", |b| stl::parse_stl(b).is_ok()),
            (PCD_ASCII, b"0.25 -0.5 1.5", |b| pcd::parse_pcd(b).is_ok()),
            (PLY_ASCII, b"0.25 -0.5 1.5", |b| ply::parse_ply_points(b).is_ok()),
            (CUBE_OBJ, b"", |b| obj::parse_obj(b).is_ok()),
        ];
        for (bytes, last_record, parses) in text {
            let n = cut.index(bytes.len());
            let accepted = parses(&bytes[..n]);
            let last = bytes.windows(last_record.len().max(1)).rposition(|w| w == last_record);
            if !last_record.is_empty() && last.is_some_and(|at| n <= at) {
                prop_assert!(!accepted, "prefix of {} bytes accepted", n);
            }
        }
    }
}
