//! Table cells, and reading a JSON record into named cells in the record's own field order.
//!
//! `serde_json::Value` keeps object keys sorted, which would scatter a summary's fields
//! alphabetically across the table; this reader keeps them in the order `summary.json` writes
//! them (the struct's order), and flattens nested values into dotted names (`uavs.0.status`).

use serde::de::{self, Deserialize, Deserializer, MapAccess, SeqAccess, Visitor};
use std::fmt;

/// One value of a table.
#[derive(Debug, Clone, PartialEq)]
pub enum Cell {
    Null,
    Bool(bool),
    Int(i64),
    Float(f64),
    Text(String),
}

impl Cell {
    /// The value as a number, for statistics (booleans and text are not numbers).
    pub fn as_f64(&self) -> Option<f64> {
        match *self {
            Cell::Int(i) => Some(i as f64),
            Cell::Float(x) => Some(x),
            _ => None,
        }
    }

    /// The cell from a JSON value; arrays and objects become their JSON text.
    pub fn from_json(value: &serde_json::Value) -> Self {
        match value {
            serde_json::Value::Null => Cell::Null,
            serde_json::Value::Bool(b) => Cell::Bool(*b),
            serde_json::Value::Number(n) => match n.as_i64() {
                Some(i) => Cell::Int(i),
                None => Cell::Float(n.as_f64().unwrap_or(f64::NAN)),
            },
            serde_json::Value::String(s) => Cell::Text(s.clone()),
            other => Cell::Text(other.to_string()),
        }
    }

    /// The text of the cell in a CSV file: empty for null, shortest round-trip for numbers.
    pub fn to_csv(&self) -> String {
        match self {
            Cell::Null => String::new(),
            Cell::Bool(b) => b.to_string(),
            Cell::Int(i) => i.to_string(),
            Cell::Float(x) => x.to_string(),
            Cell::Text(s) => s.clone(),
        }
    }
}

/// A JSON object read with its fields in file order, flattened to `(dotted name, cell)`.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct FlatRecord(pub Vec<(String, Cell)>);

impl FlatRecord {
    pub fn from_json_text(text: &str) -> Result<Self, serde_json::Error> {
        let ordered: Ordered = serde_json::from_str(text)?;
        let mut out = Vec::new();
        ordered.flatten_into(String::new(), &mut out);
        Ok(Self(out))
    }

    pub fn get(&self, name: &str) -> Option<&Cell> {
        self.0.iter().find(|(n, _)| n == name).map(|(_, c)| c)
    }
}

/// A JSON value whose objects keep their key order.
enum Ordered {
    Leaf(Cell),
    List(Vec<Ordered>),
    Object(Vec<(String, Ordered)>),
}

impl Ordered {
    fn flatten_into(self, prefix: String, out: &mut Vec<(String, Cell)>) {
        let name = |key: &str| {
            if prefix.is_empty() {
                key.to_owned()
            } else {
                format!("{prefix}.{key}")
            }
        };
        match self {
            Ordered::Leaf(cell) => out.push((prefix, cell)),
            Ordered::List(items) => {
                for (i, item) in items.into_iter().enumerate() {
                    item.flatten_into(name(&i.to_string()), out);
                }
            }
            Ordered::Object(fields) => {
                for (key, value) in fields {
                    value.flatten_into(name(&key), out);
                }
            }
        }
    }
}

impl<'de> Deserialize<'de> for Ordered {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        deserializer.deserialize_any(OrderedVisitor)
    }
}

struct OrderedVisitor;

impl<'de> Visitor<'de> for OrderedVisitor {
    type Value = Ordered;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a JSON value")
    }
    fn visit_unit<E: de::Error>(self) -> Result<Ordered, E> {
        Ok(Ordered::Leaf(Cell::Null))
    }
    fn visit_bool<E: de::Error>(self, v: bool) -> Result<Ordered, E> {
        Ok(Ordered::Leaf(Cell::Bool(v)))
    }
    fn visit_i64<E: de::Error>(self, v: i64) -> Result<Ordered, E> {
        Ok(Ordered::Leaf(Cell::Int(v)))
    }
    fn visit_u64<E: de::Error>(self, v: u64) -> Result<Ordered, E> {
        // Counts beyond i64 (none in practice) keep their magnitude as floats.
        Ok(Ordered::Leaf(
            i64::try_from(v).map_or(Cell::Float(v as f64), Cell::Int),
        ))
    }
    fn visit_f64<E: de::Error>(self, v: f64) -> Result<Ordered, E> {
        Ok(Ordered::Leaf(Cell::Float(v)))
    }
    fn visit_str<E: de::Error>(self, v: &str) -> Result<Ordered, E> {
        Ok(Ordered::Leaf(Cell::Text(v.to_owned())))
    }
    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Ordered, A::Error> {
        let mut items = Vec::new();
        while let Some(item) = seq.next_element()? {
            items.push(item);
        }
        Ok(Ordered::List(items))
    }
    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Ordered, A::Error> {
        let mut fields = Vec::new();
        while let Some((key, value)) = map.next_entry::<String, Ordered>()? {
            fields.push((key, value));
        }
        Ok(Ordered::Object(fields))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keeps_field_order_and_flattens_lists_and_objects() {
        let record = FlatRecord::from_json_text(
            r#"{"scenario": "s", "seed": 3, "outcome": "complete", "zeta": null,
                "alpha": 1.5, "uavs": [{"name": "a", "path_length_m": 2.0}], "big": 18446744073709551615}"#,
        )
        .unwrap();
        let names: Vec<&str> = record.0.iter().map(|(n, _)| n.as_str()).collect();
        assert_eq!(
            names,
            [
                "scenario",
                "seed",
                "outcome",
                "zeta",
                "alpha",
                "uavs.0.name",
                "uavs.0.path_length_m",
                "big"
            ]
        );
        assert_eq!(record.get("seed"), Some(&Cell::Int(3)));
        assert_eq!(record.get("zeta"), Some(&Cell::Null));
        assert_eq!(record.get("alpha"), Some(&Cell::Float(1.5)));
        assert_eq!(
            record.get("big"),
            Some(&Cell::Float(18446744073709551615.0))
        );
        assert_eq!(record.get("uavs.0.name"), Some(&Cell::Text("a".into())));
    }

    #[test]
    fn csv_text_of_cells() {
        assert_eq!(Cell::Null.to_csv(), "");
        assert_eq!(Cell::Float(0.1).to_csv(), "0.1");
        assert_eq!(Cell::Int(-4).to_csv(), "-4");
        assert_eq!(Cell::Bool(true).to_csv(), "true");
        assert_eq!(
            Cell::from_json(&serde_json::json!([1, 2])),
            Cell::Text("[1,2]".into())
        );
        assert_eq!(Cell::from_json(&serde_json::json!(2.5)).as_f64(), Some(2.5));
    }
}
