//! Field paths name a place in a scenario file the way its reader sees it:
//! `uav[0].sensor[1].range_max`, `world.obstacle[3].file` (TOML key names, not Rust field names;
//! array elements by their index in the file).

use std::fmt;

/// One step of a [`FieldPath`]: a table key or an array index.
#[derive(Debug, Clone, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Segment {
    Key(String),
    Index(usize),
}

/// A path from the top of the file to a value. The empty path is the whole file.
#[derive(Debug, Clone, Default, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct FieldPath {
    segments: Vec<Segment>,
}

impl FieldPath {
    /// The whole file.
    pub fn root() -> Self {
        Self::default()
    }

    /// Reads the display form back (`uav[0].sensor[1].range_max`). Best effort and total: text
    /// that is not a well-formed index stays part of the key, so any string gives some path
    /// (callers such as the world builder hand their paths over as strings).
    pub fn parse(text: &str) -> Self {
        let mut path = Self::root();
        if text.is_empty() {
            return path;
        }
        for part in text.split('.') {
            let (key, indices) = split_indices(part);
            if !key.is_empty() {
                path.segments.push(Segment::Key(key.to_owned()));
            }
            path.segments
                .extend(indices.into_iter().map(Segment::Index));
        }
        path
    }

    /// This path followed by a table key.
    pub fn key(&self, key: &str) -> Self {
        let mut child = self.clone();
        child.segments.push(Segment::Key(key.to_owned()));
        child
    }

    /// This path followed by an array index.
    pub fn index(&self, index: usize) -> Self {
        let mut child = self.clone();
        child.segments.push(Segment::Index(index));
        child
    }

    /// The enclosing value, or `None` for the whole file.
    pub fn parent(&self) -> Option<Self> {
        let mut parent = self.clone();
        parent.segments.pop().map(|_| parent)
    }

    pub fn segments(&self) -> &[Segment] {
        &self.segments
    }

    pub fn is_root(&self) -> bool {
        self.segments.is_empty()
    }

    /// The last key of the path, if it ends with a key.
    pub fn last_key(&self) -> Option<&str> {
        match self.segments.last() {
            Some(Segment::Key(key)) => Some(key),
            _ => None,
        }
    }

    /// Whether `self` is `other` or lies inside it.
    pub fn starts_with(&self, other: &FieldPath) -> bool {
        self.segments.starts_with(&other.segments)
    }

    /// The segments of `self` below `ancestor`, if `ancestor` is an ancestor (or `self`).
    pub fn strip_prefix(&self, ancestor: &FieldPath) -> Option<&[Segment]> {
        self.segments.strip_prefix(ancestor.segments.as_slice())
    }
}

impl fmt::Display for FieldPath {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, segment) in self.segments.iter().enumerate() {
            match segment {
                Segment::Key(key) if i == 0 => write!(f, "{key}")?,
                Segment::Key(key) => write!(f, ".{key}")?,
                Segment::Index(index) => write!(f, "[{index}]")?,
            }
        }
        Ok(())
    }
}

impl From<&str> for FieldPath {
    fn from(text: &str) -> Self {
        Self::parse(text)
    }
}

/// Splits `sensor[1][2]` into `("sensor", [1, 2])`; a malformed suffix stays in the key.
fn split_indices(part: &str) -> (&str, Vec<usize>) {
    let mut key = part;
    let mut indices = Vec::new();
    while let Some(open) = key.rfind('[') {
        let Some(inner) = key[open + 1..].strip_suffix(']') else {
            break;
        };
        let Ok(index) = inner.parse::<usize>() else {
            break;
        };
        indices.push(index);
        key = &key[..open];
    }
    indices.reverse();
    (key, indices)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn display_and_parse_round_trip() {
        let path = FieldPath::root()
            .key("uav")
            .index(0)
            .key("sensor")
            .index(1)
            .key("range_max");
        assert_eq!(path.to_string(), "uav[0].sensor[1].range_max");
        assert_eq!(FieldPath::parse("uav[0].sensor[1].range_max"), path);
        let bounds = FieldPath::parse("world.bounds.max[2]");
        assert_eq!(
            bounds.segments(),
            &[
                Segment::Key("world".into()),
                Segment::Key("bounds".into()),
                Segment::Key("max".into()),
                Segment::Index(2)
            ]
        );
    }

    #[test]
    fn parse_is_total_on_odd_text() {
        assert!(FieldPath::parse("").is_root());
        assert_eq!(
            FieldPath::parse("a[x]").segments(),
            &[Segment::Key("a[x]".into())]
        );
        assert_eq!(
            FieldPath::parse("waypoints[1][2]").segments(),
            &[
                Segment::Key("waypoints".into()),
                Segment::Index(1),
                Segment::Index(2)
            ]
        );
        // Empty parts between dots are skipped rather than refused.
        assert_eq!(FieldPath::parse("a..b").to_string(), "a.b");
    }

    #[test]
    fn parent_and_prefix() {
        let path = FieldPath::parse("world.obstacle[3].file");
        assert_eq!(path.parent().unwrap().to_string(), "world.obstacle[3]");
        assert!(path.starts_with(&FieldPath::parse("world.obstacle")));
        assert_eq!(
            path.strip_prefix(&FieldPath::parse("world.obstacle[3]")),
            Some(&[Segment::Key("file".into())][..])
        );
        assert_eq!(FieldPath::root().parent(), None);
    }
}
