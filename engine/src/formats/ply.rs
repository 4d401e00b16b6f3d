//! PLY (Stanford polygon format) points: reading the `vertex` element's `x y z` of any PLY file,
//! and writing points as a binary little-endian PLY that CloudCompare, MeshLab, Open3D and
//! [`load_cloud`](super::cloud::load_cloud) read.
//!
//! Reading uses `ply-rs-bw` for the header and the binary encodings (any property layout, list
//! properties) and a few lines here for ASCII data (see `read_ascii`).

use std::io::{self, Cursor, Write};

use glam::Vec3;
use ply_rs_bw::parser::{ParseError, Parser, Reader};
use ply_rs_bw::ply::{
    Encoding, Header, Property, PropertyAccess, PropertyAccessResult, PropertyType,
};

use super::cloud::{CloudBuilder, PointCloud};
use super::{Fault, numbered_lines, parse_real};

/// One element's coordinates; elements that lack one keep NaN (never the case for `vertex`,
/// whose `x y z` are checked in the header).
#[derive(Debug, Clone, Copy)]
struct Coordinates([f64; 3]);

fn axis(name: &str) -> Option<usize> {
    match name {
        "x" => Some(0),
        "y" => Some(1),
        "z" => Some(2),
        _ => None,
    }
}

impl PropertyAccess for Coordinates {
    fn new() -> Self {
        Self([f64::NAN; 3])
    }

    fn set_property(&mut self, name: &str, property: Property) -> PropertyAccessResult {
        let value = match property {
            Property::Char(v) => f64::from(v),
            Property::UChar(v) => f64::from(v),
            Property::Short(v) => f64::from(v),
            Property::UShort(v) => f64::from(v),
            Property::Int(v) => f64::from(v),
            Property::UInt(v) => f64::from(v),
            Property::Float(v) => f64::from(v),
            Property::Double(v) => v,
            _ => return PropertyAccessResult::Ignored,
        };
        match axis(name) {
            Some(a) => {
                self.0[a] = value;
                PropertyAccessResult::Set
            }
            None => PropertyAccessResult::Ignored,
        }
    }
}

/// Reads the `vertex` element's `x y z` (scalar properties of any numeric type) as points.
/// Elements before `vertex` are read and dropped; elements after it (faces) are not read.
pub(crate) fn parse_ply_points(bytes: &[u8]) -> Result<PointCloud, Fault> {
    let parser = Parser::<Coordinates>::new();
    let mut reader = Reader::new(Cursor::new(bytes));
    let header = parser
        .read_header(&mut reader)
        .map_err(|e| fault(e, true))?;
    let body_start = (reader.get_ref().position() as usize).min(bytes.len());
    let header_lines = bytes[..body_start].iter().filter(|&&b| b == b'\n').count();
    let vertex = header
        .elements
        .get("vertex")
        .ok_or_else(|| Fault::at(header_lines, "no \"vertex\" element in the header"))?;
    let mut axes = [usize::MAX; 3];
    for (slot, name) in axes.iter_mut().zip(["x", "y", "z"]) {
        match vertex.properties.get_full(name) {
            Some((i, _, p)) if matches!(p.data_type, PropertyType::Scalar(_)) => *slot = i,
            Some(_) => {
                return Err(Fault::at(
                    header_lines,
                    format!("vertex property {name:?} is a list, not a number"),
                ));
            }
            None => {
                return Err(Fault::at(
                    header_lines,
                    format!("the vertex element has no {name:?} property"),
                ));
            }
        }
    }
    // An element without properties takes no bytes: a corrupt count of billions would spin
    // (and allocate) without reading anything. No writer produces one.
    if let Some((name, _)) = header
        .elements
        .iter()
        .find(|(_, e)| e.count > 0 && e.properties.is_empty())
    {
        return Err(Fault::at(
            header_lines,
            format!("element {name:?} has no properties"),
        ));
    }
    if header.encoding == Encoding::Ascii {
        return read_ascii(&bytes[body_start..], header_lines, &header, axes);
    }
    for (name, element) in &header.elements {
        let values = parser
            .read_payload_for_element(&mut reader, element, &header)
            .map_err(|e| fault(e, false))?;
        if name == "vertex" {
            let mut cloud = CloudBuilder::with_capacity(values.len());
            for Coordinates([x, y, z]) in values {
                cloud.push(x, y, z);
            }
            return cloud.finish();
        }
    }
    // Not reached: the header has a `vertex` element, and the loop returns there.
    Err(Fault::bare("the vertex element was not read"))
}

/// ASCII payload, read here rather than by `ply-rs-bw`, whose number grammar refuses the `nan`
/// that organised clouds hold: one element per line, a scalar property is one number, a list
/// property its length then its items. `axes` are the positions of `x y z` among the vertex
/// properties; `header_lines` the lines before the payload.
fn read_ascii(
    body: &[u8],
    header_lines: usize,
    header: &Header,
    axes: [usize; 3],
) -> Result<PointCloud, Fault> {
    let mut lines = numbered_lines(body)
        .map(|(i, text)| (header_lines + i, text))
        .filter(|(_, text)| !text.trim().is_empty());
    let mut last_line = header_lines;
    for (name, element) in &header.elements {
        let is_vertex = name == "vertex";
        let mut cloud = CloudBuilder::with_capacity(if is_vertex { element.count } else { 0 });
        for read in 0..element.count {
            let (line, text) = lines.next().ok_or_else(|| {
                Fault::at(
                    last_line,
                    format!(
                        "file ends after {read} of {} {name:?} elements",
                        element.count
                    ),
                )
            })?;
            last_line = line;
            let mut words = text.split_whitespace();
            let mut next = |what: &str| {
                let word = words
                    .next()
                    .ok_or_else(|| Fault::at(line, format!("{what} missing")))?;
                parse_real(word)
                    .ok_or_else(|| Fault::at(line, format!("{what} {word:?} is not a number")))
            };
            let mut xyz = [f64::NAN; 3];
            for (i, (property, def)) in element.properties.iter().enumerate() {
                let value = next(&format!("property {property:?}"))?;
                if let PropertyType::List(..) = def.data_type {
                    if !(value >= 0.0 && value.fract() == 0.0) {
                        return Err(Fault::at(
                            line,
                            format!("list length {value} of {property:?}"),
                        ));
                    }
                    for _ in 0..value as u64 {
                        next(&format!("item of list {property:?}"))?;
                    }
                } else if let Some(axis) = axes.iter().position(|&a| a == i).filter(|_| is_vertex) {
                    xyz[axis] = value;
                }
            }
            if words.next().is_some() {
                return Err(Fault::at(
                    line,
                    format!("more values than the {name:?} properties"),
                ));
            }
            if is_vertex {
                cloud.push(xyz[0], xyz[1], xyz[2]);
            }
        }
        if is_vertex {
            return cloud.finish();
        }
    }
    Err(Fault::bare("the vertex element was not read"))
}

/// Turns a `ply-rs-bw` error into a fault, keeping its line only where the file is text there
/// (its line counter also runs over binary elements, where it means nothing to a user).
fn fault(error: ParseError, text: bool) -> Fault {
    let mut message = error.to_string();
    if let Some(line) = error.line() {
        let prefix = format!("Line {line}: ");
        if let Some(rest) = message.strip_prefix(&prefix) {
            message = rest.to_string();
        }
    }
    // Messages quote the offending input, which in a binary file can be long garbage.
    if let Some((cut, _)) = message.char_indices().nth(300) {
        message.truncate(cut);
        message.push_str("...");
    }
    let message = message.replace("\n\t", "; ");
    match error.line().filter(|_| text) {
        Some(line) => Fault::at(line, message),
        None => Fault::bare(message),
    }
}

/// Writes `points` as a binary little-endian PLY with one `vertex` element of `float x y z`.
pub fn write_points(w: &mut impl Write, points: impl IntoIterator<Item = Vec3>) -> io::Result<()> {
    // The header needs the count first: encode the body, then write both.
    let mut body = Vec::new();
    let mut count = 0usize;
    for p in points {
        for c in p.to_array() {
            body.extend_from_slice(&c.to_le_bytes());
        }
        count += 1;
    }
    write!(
        w,
        "ply\nformat binary_little_endian 1.0\ncomment written by uavex\n\
         element vertex {count}\nproperty float x\nproperty float y\nproperty float z\nend_header\n"
    )?;
    w.write_all(&body)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn write_then_read_round_trips_exactly() {
        let points = vec![
            Vec3::new(0.1, -2.5, 3.0),
            Vec3::new(1e-7, 1e7, -0.0),
            Vec3::new(f32::MAX, f32::MIN_POSITIVE, 42.0),
        ];
        let mut bytes = Vec::new();
        write_points(&mut bytes, points.iter().copied()).unwrap();
        // Header (8 lines) then 3 points of 12 bytes.
        let header_len = bytes.len() - 36;
        assert!(bytes[..header_len].ends_with(b"end_header\n"));
        assert_eq!(&bytes[header_len..header_len + 4], &0.1f32.to_le_bytes());
        let cloud = parse_ply_points(&bytes).unwrap();
        assert_eq!(cloud.points, points);
        assert_eq!(cloud.skipped_non_finite, 0);
    }

    #[test]
    fn ascii_with_integer_coordinates_extra_properties_and_faces() {
        let src = "ply\nformat ascii 1.0\nelement camera 1\nproperty float f\nelement vertex 3\n\
                   property int x\nproperty uchar red\nproperty short y\nproperty double z\n\
                   element face 1\nproperty list uchar int vertex_indices\nend_header\n\
                   500\n1 255 2 3.5\n-1 0 -2 nan\n4 0 5 6\n3 0 1 2\n";
        let cloud = parse_ply_points(src.as_bytes()).unwrap();
        assert_eq!(
            cloud.points,
            vec![Vec3::new(1.0, 2.0, 3.5), Vec3::new(4.0, 5.0, 6.0)]
        );
        assert_eq!(cloud.skipped_non_finite, 1);
    }

    #[test]
    fn errors_keep_text_lines_only() {
        let src = "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\nend_header\n1 2 3\n4 5\n";
        let f = parse_ply_points(src.as_bytes()).unwrap_err();
        assert_eq!(f.line, Some(9));
        let f =
            parse_ply_points(b"ply\nformat ascii 1.0\nelemnt vertex 1\nend_header\n").unwrap_err();
        assert_eq!(f.line, Some(3));
        let src = "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nend_header\n1 2\n";
        let f = parse_ply_points(src.as_bytes()).unwrap_err();
        assert!(f.problem.to_string().contains("no \"z\""), "{}", f.problem);
        let mut bytes = Vec::new();
        write_points(&mut bytes, [Vec3::ONE, Vec3::ONE]).unwrap();
        bytes.truncate(bytes.len() - 1);
        let f = parse_ply_points(&bytes).unwrap_err();
        assert_eq!(f.line, None);
        let src = "ply\nformat binary_little_endian 1.0\nelement camera 4000000000\n\
                   element vertex 1\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
        let f = parse_ply_points(src.as_bytes()).unwrap_err();
        assert_eq!(f.line, Some(8));
        assert!(
            f.problem
                .to_string()
                .contains("\"camera\" has no properties")
        );
    }
}
