//! PCL's PCD point clouds (format versions 0.5-0.7): a text header (`FIELDS`, `SIZE`, `TYPE`,
//! `COUNT`, `WIDTH`, `HEIGHT`, `VIEWPOINT`, `POINTS`, `DATA`), then the points as text lines
//! (`ascii`), as packed little-endian records (`binary`), or as LZF-compressed columns
//! (`binary_compressed`: `u32` compressed size, `u32` uncompressed size, then the data with each
//! field's values for all points stored together).
//!
//! Only `x`, `y`, `z` are read (TYPE F, SIZE 4 or 8, COUNT 1); other fields are skipped.
//! `VIEWPOINT` (the sensor pose) is not applied, as in PCL: the points are already in the
//! cloud's frame.

use super::cloud::{CloudBuilder, PointCloud};
use super::lzf::lzf_decompress;
use super::{Fault, parse_real};

#[derive(Debug, Clone, Copy, PartialEq)]
enum Data {
    Ascii,
    Binary,
    BinaryCompressed,
}

/// One field of the header: `SIZE` bytes per value, `TYPE` F/I/U, `COUNT` values per point.
#[derive(Debug)]
struct Field {
    name: String,
    size: usize,
    kind: char,
    count: usize,
}

#[derive(Debug)]
struct Header {
    fields: Vec<Field>,
    points: usize,
    data: Data,
    /// Line of `DATA`, and the byte where the points start.
    data_line: usize,
    data_start: usize,
}

/// Where one coordinate lives: its field index and whether it is stored as `f64`.
#[derive(Debug, Clone, Copy)]
struct Coordinate {
    field: usize,
    double: bool,
}

pub(crate) fn parse_pcd(bytes: &[u8]) -> Result<PointCloud, Fault> {
    let header = parse_header(bytes)?;
    let xyz = coordinates(&header)?;
    let body = &bytes[header.data_start..];
    match header.data {
        Data::Ascii => read_ascii(body, &header, xyz),
        Data::Binary => read_binary(body, &header, xyz),
        Data::BinaryCompressed => read_compressed(body, &header, xyz),
    }
}

/// Finds `x`, `y`, `z` among the fields and checks that each is one float.
fn coordinates(header: &Header) -> Result<[Coordinate; 3], Fault> {
    let find = |name: &str| {
        let field = header
            .fields
            .iter()
            .position(|f| f.name == name)
            .ok_or_else(|| Fault::at(header.data_line, format!("no field {name:?} in FIELDS")))?;
        let f = &header.fields[field];
        if f.kind != 'F' || !matches!(f.size, 4 | 8) || f.count != 1 {
            return Err(Fault::at(
                header.data_line,
                format!(
                    "field {name:?} must be a single float (TYPE F, SIZE 4 or 8, COUNT 1), found TYPE {} SIZE {} COUNT {}",
                    f.kind, f.size, f.count
                ),
            ));
        }
        Ok(Coordinate {
            field,
            double: f.size == 8,
        })
    };
    Ok([find("x")?, find("y")?, find("z")?])
}

fn parse_header(bytes: &[u8]) -> Result<Header, Fault> {
    let (mut names, mut sizes, mut kinds, mut counts) = (None, None, None, None);
    let (mut width, mut height, mut points) = (None, None, None);
    let mut pos = 0;
    let mut line = 0;
    let data = loop {
        if pos >= bytes.len() {
            return Err(Fault::at(line.max(1), "file ends before the DATA line"));
        }
        line += 1;
        let end = bytes[pos..]
            .iter()
            .position(|&b| b == b'\n')
            .map_or(bytes.len(), |i| pos + i);
        let text = String::from_utf8_lossy(&bytes[pos..end]);
        pos = (end + 1).min(bytes.len());
        let text = text.split('#').next().unwrap_or_default();
        let mut words = text.split_whitespace();
        let Some(key) = words.next() else { continue };
        let values: Vec<&str> = words.collect();
        match key.to_ascii_uppercase().as_str() {
            "VERSION" | "VIEWPOINT" => {}
            "FIELDS" | "COLUMNS" => names = Some(values.iter().map(|s| s.to_string()).collect()),
            "SIZE" => sizes = Some(numbers(&values, line, "SIZE")?),
            "COUNT" => counts = Some(numbers(&values, line, "COUNT")?),
            "TYPE" => kinds = Some(type_letters(&values, line)?),
            "WIDTH" => width = Some(single_number(&values, line, "WIDTH")?),
            "HEIGHT" => height = Some(single_number(&values, line, "HEIGHT")?),
            "POINTS" => points = Some(single_number(&values, line, "POINTS")?),
            "DATA" => {
                break match values.as_slice() {
                    ["ascii"] => Data::Ascii,
                    ["binary"] => Data::Binary,
                    ["binary_compressed"] => Data::BinaryCompressed,
                    _ => {
                        return Err(Fault::at(
                            line,
                            format!(
                                "DATA must be ascii, binary or binary_compressed, found {:?}",
                                values.join(" ")
                            ),
                        ));
                    }
                };
            }
            other => {
                return Err(Fault::at(line, format!("unknown header entry {other:?}")));
            }
        }
    };
    let fields = assemble_fields(names, sizes, kinds, counts, line)?;
    let points = match (points, width, height) {
        (Some(p), Some(w), Some(h)) if w.checked_mul(h) != Some(p) => {
            return Err(Fault::at(
                line,
                format!("POINTS {p} differs from WIDTH x HEIGHT = {w} x {h}"),
            ));
        }
        (Some(p), _, _) => p,
        (None, Some(w), Some(h)) => w
            .checked_mul(h)
            .ok_or_else(|| Fault::at(line, "WIDTH x HEIGHT overflows"))?,
        _ => {
            return Err(Fault::at(
                line,
                "neither POINTS nor WIDTH and HEIGHT in the header",
            ));
        }
    };
    Ok(Header {
        fields,
        points,
        data,
        data_line: line,
        data_start: pos,
    })
}

fn numbers(values: &[&str], line: usize, key: &str) -> Result<Vec<usize>, Fault> {
    values
        .iter()
        .map(|v| {
            v.parse()
                .map_err(|_| Fault::at(line, format!("{key} value {v:?} is not a whole number")))
        })
        .collect()
}

fn single_number(values: &[&str], line: usize, key: &str) -> Result<usize, Fault> {
    match numbers(values, line, key)?.as_slice() {
        [n] => Ok(*n),
        _ => Err(Fault::at(line, format!("{key} takes one number"))),
    }
}

fn type_letters(values: &[&str], line: usize) -> Result<Vec<char>, Fault> {
    values
        .iter()
        .map(|v| match *v {
            "F" | "I" | "U" => Ok(v.chars().next().unwrap_or('F')),
            _ => Err(Fault::at(line, format!("TYPE {v:?} is not F, I or U"))),
        })
        .collect()
}

fn assemble_fields(
    names: Option<Vec<String>>,
    sizes: Option<Vec<usize>>,
    kinds: Option<Vec<char>>,
    counts: Option<Vec<usize>>,
    line: usize,
) -> Result<Vec<Field>, Fault> {
    let missing = |key: &str| Fault::at(line, format!("no {key} line before DATA"));
    let names = names.ok_or_else(|| missing("FIELDS"))?;
    let sizes = sizes.ok_or_else(|| missing("SIZE"))?;
    let kinds = kinds.ok_or_else(|| missing("TYPE"))?;
    let counts = counts.unwrap_or_else(|| vec![1; names.len()]);
    if names.is_empty() {
        return Err(Fault::at(line, "FIELDS names no field"));
    }
    for (key, n) in [
        ("SIZE", sizes.len()),
        ("TYPE", kinds.len()),
        ("COUNT", counts.len()),
    ] {
        if n != names.len() {
            return Err(Fault::at(
                line,
                format!("{key} has {n} entries for {} FIELDS", names.len()),
            ));
        }
    }
    let fields: Vec<Field> = names
        .into_iter()
        .zip(sizes)
        .zip(kinds)
        .zip(counts)
        .map(|(((name, size), kind), count)| Field {
            name,
            size,
            kind,
            count,
        })
        .collect();
    for f in &fields {
        if !matches!(f.size, 1 | 2 | 4 | 8) || f.count == 0 {
            return Err(Fault::at(
                line,
                format!(
                    "field {:?} has SIZE {} COUNT {} (sizes are 1, 2, 4 or 8, counts at least 1)",
                    f.name, f.size, f.count
                ),
            ));
        }
    }
    // Bound the record so that every later size computation fits `usize`.
    let total: Option<usize> = fields.iter().try_fold(0usize, |acc, f| {
        acc.checked_add(f.size.checked_mul(f.count)?)
    });
    if total.is_none_or(|t| t > 1 << 24) {
        return Err(Fault::at(line, "a point record larger than 16 MiB"));
    }
    Ok(fields)
}

impl Header {
    /// Bytes per point (bounded by `assemble_fields`).
    fn record_bytes(&self) -> usize {
        self.fields.iter().map(|f| f.size * f.count).sum()
    }

    /// Bytes of all points, or an error when that overflows (a corrupt POINTS).
    fn data_bytes(&self) -> Result<usize, Fault> {
        self.points.checked_mul(self.record_bytes()).ok_or_else(|| {
            Fault::at(
                self.data_line,
                format!("POINTS {} is too large", self.points),
            )
        })
    }
}

fn read_ascii(body: &[u8], header: &Header, xyz: [Coordinate; 3]) -> Result<PointCloud, Fault> {
    let tokens_per_point: usize = header.fields.iter().map(|f| f.count).sum();
    // Token position of each coordinate: values of the fields before it.
    let token_of = xyz.map(|c| {
        header.fields[..c.field]
            .iter()
            .map(|f| f.count)
            .sum::<usize>()
    });
    let mut cloud = CloudBuilder::with_capacity(header.points.min(body.len() / 2));
    let mut read = 0usize;
    let mut last_line = header.data_line;
    for (i, text) in super::numbered_lines(body) {
        let line = header.data_line + i;
        let tokens: Vec<&str> = text.split_whitespace().collect();
        if tokens.is_empty() {
            continue;
        }
        last_line = line;
        if read == header.points {
            return Err(Fault::at(
                line,
                format!("more points than POINTS {}", header.points),
            ));
        }
        if tokens.len() != tokens_per_point {
            return Err(Fault::at(
                line,
                format!(
                    "{} values where the fields need {tokens_per_point}",
                    tokens.len()
                ),
            ));
        }
        let [x, y, z] = token_of.map(|t| {
            parse_real(tokens[t]).ok_or_else(|| {
                Fault::at(line, format!("coordinate {:?} is not a number", tokens[t]))
            })
        });
        cloud.push(x?, y?, z?);
        read += 1;
    }
    if read < header.points {
        return Err(Fault::at(
            last_line,
            format!("file ends after {read} of {} points", header.points),
        ));
    }
    cloud.finish()
}

/// Reads the coordinates of `points` points laid out at `start[c] + i * stride[c]`.
fn read_laid_out(
    data: &[u8],
    points: usize,
    xyz: [Coordinate; 3],
    start: [usize; 3],
    stride: [usize; 3],
) -> Result<PointCloud, Fault> {
    let value = |c: usize, i: usize| {
        let at = start[c] + i * stride[c];
        if xyz[c].double {
            f64::from_le_bytes(data[at..at + 8].try_into().unwrap_or_default())
        } else {
            f64::from(f32::from_le_bytes(
                data[at..at + 4].try_into().unwrap_or_default(),
            ))
        }
    };
    let mut cloud = CloudBuilder::with_capacity(points);
    for i in 0..points {
        cloud.push(value(0, i), value(1, i), value(2, i));
    }
    cloud.finish()
}

fn read_binary(body: &[u8], header: &Header, xyz: [Coordinate; 3]) -> Result<PointCloud, Fault> {
    let needed = header.data_bytes()?;
    if body.len() < needed {
        return Err(Fault::bare(format!(
            "binary data holds {} bytes, {} points of {} bytes need {needed} (truncated file?)",
            body.len(),
            header.points,
            header.record_bytes()
        )));
    }
    let offset = xyz.map(|c| {
        header.fields[..c.field]
            .iter()
            .map(|f| f.size * f.count)
            .sum()
    });
    let record = header.record_bytes();
    read_laid_out(body, header.points, xyz, offset, [record; 3])
}

fn read_compressed(
    body: &[u8],
    header: &Header,
    xyz: [Coordinate; 3],
) -> Result<PointCloud, Fault> {
    let size = |at: usize| {
        body.get(at..at + 4)
            .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize)
            .ok_or_else(|| Fault::bare("binary_compressed data ends inside its size words"))
    };
    let (compressed, uncompressed) = (size(0)?, size(4)?);
    let needed = header.data_bytes()?;
    if uncompressed != needed {
        return Err(Fault::bare(format!(
            "binary_compressed data unpacks to {uncompressed} bytes, {} points need {needed}",
            header.points
        )));
    }
    let packed = body.get(8..8 + compressed).ok_or_else(|| {
        Fault::bare(format!(
            "binary_compressed data declares {compressed} bytes, {} remain (truncated file?)",
            body.len() - 8
        ))
    })?;
    let data = lzf_decompress(packed, uncompressed)?;
    // Field f's column starts after all values of the fields before it.
    let column = |field: usize| -> usize {
        header.fields[..field]
            .iter()
            .map(|f| f.size * f.count * header.points)
            .sum()
    };
    let start = xyz.map(|c| column(c.field));
    let stride = xyz.map(|c| header.fields[c.field].size);
    read_laid_out(&data, header.points, xyz, start, stride)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    const HEAD: &str = "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z rgb\nSIZE 4 4 4 4\nTYPE F F F U\nCOUNT 1 1 1 1\nWIDTH 2\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 2\n";

    #[test]
    fn ascii_reads_xyz_among_other_fields() {
        let src = format!("{HEAD}DATA ascii\n1 2 3 4278190080\n-0.5 nan 7 0\n");
        let cloud = parse_pcd(src.as_bytes()).unwrap();
        assert_eq!(cloud.points, vec![Vec3::new(1.0, 2.0, 3.0)]);
        assert_eq!(cloud.skipped_non_finite, 1);
    }

    #[test]
    fn binary_reads_f64_coordinates_at_their_offsets() {
        let head = "FIELDS i z y x\nSIZE 2 8 4 4\nTYPE U F F F\nPOINTS 1\nDATA binary\n";
        let mut bytes = head.as_bytes().to_vec();
        bytes.extend(7u16.to_le_bytes());
        bytes.extend(3.25f64.to_le_bytes());
        bytes.extend(2.0f32.to_le_bytes());
        bytes.extend(1.5f32.to_le_bytes());
        let cloud = parse_pcd(&bytes).unwrap();
        assert_eq!(cloud.points, vec![Vec3::new(1.5, 2.0, 3.25)]);
        bytes.pop();
        let fault = parse_pcd(&bytes).unwrap_err();
        assert!(fault.problem.to_string().contains("truncated"));
    }

    #[test]
    fn compressed_reads_columns() {
        let head = "VERSION .7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 2\nHEIGHT 1\nPOINTS 2\nDATA binary_compressed\n";
        let columns: Vec<u8> = [1.0f32, 4.0, 2.0, 5.0, 3.0, 6.0]
            .iter()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        let mut bytes = head.as_bytes().to_vec();
        bytes.extend(25u32.to_le_bytes());
        bytes.extend(24u32.to_le_bytes());
        bytes.push(23); // one literal run of 24 bytes
        bytes.extend(&columns);
        let cloud = parse_pcd(&bytes).unwrap();
        assert_eq!(
            cloud.points,
            vec![Vec3::new(1.0, 2.0, 3.0), Vec3::new(4.0, 5.0, 6.0)]
        );
    }

    #[test]
    fn header_errors_name_their_line() {
        let fault = |src: &str| parse_pcd(src.as_bytes()).unwrap_err();
        let f = fault(&HEAD.replace("TYPE F F F U", "TYPE F F F Q"));
        assert_eq!(f.line, Some(5));
        let f = fault(&format!(
            "{}DATA ascii\n",
            HEAD.replace("POINTS 2", "POINTS 3")
        ));
        assert_eq!(f.line, Some(11));
        assert!(f.problem.to_string().contains("WIDTH x HEIGHT"));
        let f = fault(&format!("{}DATA lz4\n", HEAD));
        assert_eq!(f.line, Some(11));
        let f = fault(&format!("{}DATA ascii\n1 2 3 4\n5 6 7\n", HEAD));
        assert_eq!(f.line, Some(13));
        let f = fault(&format!("{}DATA ascii\n1 2 3 4\n", HEAD));
        assert_eq!(f.line, Some(12));
        assert!(f.problem.to_string().contains("after 1 of 2 points"));
        let f = fault(&format!("{}DATA ascii\n1 2 3 4\n1 2 3 4\n1 2 3 4\n", HEAD));
        assert_eq!(f.line, Some(14));
        let f = fault("FIELDS x y\nSIZE 4 4\nTYPE F F\nPOINTS 0\nDATA ascii\n");
        assert!(f.problem.to_string().contains("\"z\""));
        let f = fault("FIELDS x y z\nSIZE 4 4 4\nTYPE F F I\nPOINTS 0\nDATA ascii\n");
        assert!(f.problem.to_string().contains("single float"));
        let f = fault(
            "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 18446744073709551615\nPOINTS 1\nDATA binary\n",
        );
        assert_eq!(f.line, Some(6));
        assert!(fault("FIELDS x y z\n").problem.to_string().contains("DATA"));
    }
}
