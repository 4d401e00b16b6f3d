//! The per-run table as Parquet, for pandas, polars, DuckDB or R.
//!
//! Written with the `parquet` crate's own column writers, without Arrow (which would add
//! several large crates to the build for a table of a few thousand rows). Each column gets the
//! narrowest type that holds all of its values: BOOLEAN, INT64, DOUBLE, else UTF-8 text; every
//! column is OPTIONAL, a missing value being null. One row group, no compression. Checked
//! against pyarrow's reader (types, nulls, values) besides this module's read-back test.

use super::cells::Cell;
use super::runs::Table;
use parquet::basic::{LogicalType, Repetition, Type as PhysicalType};
use parquet::data_type::{BoolType, ByteArray, ByteArrayType, DoubleType, Int64Type};
use parquet::errors::ParquetError;
use parquet::file::properties::WriterProperties;
use parquet::file::writer::SerializedFileWriter;
use parquet::schema::types::Type;
use std::sync::Arc;

/// The storage type of a column.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ColumnKind {
    Bool,
    Int,
    Float,
    Text,
}

/// The narrowest kind holding every non-null cell. A column with no value at all is a
/// number column: such columns are metrics no run reached (a time to 99 % explored).
pub fn column_kind<'a>(cells: impl IntoIterator<Item = &'a Cell>) -> ColumnKind {
    let mut kind: Option<ColumnKind> = None;
    for cell in cells {
        let this = match cell {
            Cell::Null => continue,
            Cell::Bool(_) => ColumnKind::Bool,
            Cell::Int(_) => ColumnKind::Int,
            Cell::Float(_) => ColumnKind::Float,
            Cell::Text(_) => ColumnKind::Text,
        };
        kind = Some(match (kind, this) {
            (None, k) => k,
            (Some(a), b) if a == b => a,
            (Some(ColumnKind::Int), ColumnKind::Float)
            | (Some(ColumnKind::Float), ColumnKind::Int) => ColumnKind::Float,
            _ => ColumnKind::Text,
        });
    }
    kind.unwrap_or(ColumnKind::Float)
}

/// The table as the bytes of a Parquet file.
pub fn to_parquet(table: &Table) -> Result<Vec<u8>, ParquetError> {
    let kinds: Vec<ColumnKind> = (0..table.columns.len())
        .map(|at| column_kind(table.rows.iter().map(|row| &row[at])))
        .collect();
    let fields = table
        .columns
        .iter()
        .zip(&kinds)
        .map(|(name, kind)| {
            let physical = match kind {
                ColumnKind::Bool => PhysicalType::BOOLEAN,
                ColumnKind::Int => PhysicalType::INT64,
                ColumnKind::Float => PhysicalType::DOUBLE,
                ColumnKind::Text => PhysicalType::BYTE_ARRAY,
            };
            let logical = (*kind == ColumnKind::Text).then_some(LogicalType::String);
            Type::primitive_type_builder(name, physical)
                .with_repetition(Repetition::OPTIONAL)
                .with_logical_type(logical)
                .build()
                .map(Arc::new)
        })
        .collect::<Result<Vec<_>, _>>()?;
    let schema = Arc::new(
        Type::group_type_builder("runs")
            .with_fields(fields)
            .build()?,
    );
    let properties = Arc::new(WriterProperties::builder().build());
    let mut writer = SerializedFileWriter::new(Vec::new(), schema, properties)?;
    let mut group = writer.next_row_group()?;
    let mut at = 0;
    while let Some(mut column) = group.next_column()? {
        let cells: Vec<&Cell> = table.rows.iter().map(|row| &row[at]).collect();
        // Definition level 1: the value is present; 0: null.
        let levels: Vec<i16> = cells.iter().map(|c| i16::from(**c != Cell::Null)).collect();
        match kinds[at] {
            ColumnKind::Bool => {
                let values: Vec<bool> = cells
                    .iter()
                    .filter_map(|c| match c {
                        Cell::Bool(b) => Some(*b),
                        _ => None,
                    })
                    .collect();
                column
                    .typed::<BoolType>()
                    .write_batch(&values, Some(&levels), None)?;
            }
            ColumnKind::Int => {
                let values: Vec<i64> = cells
                    .iter()
                    .filter_map(|c| match c {
                        Cell::Int(i) => Some(*i),
                        _ => None,
                    })
                    .collect();
                column
                    .typed::<Int64Type>()
                    .write_batch(&values, Some(&levels), None)?;
            }
            ColumnKind::Float => {
                let values: Vec<f64> = cells.iter().filter_map(|c| c.as_f64()).collect();
                column
                    .typed::<DoubleType>()
                    .write_batch(&values, Some(&levels), None)?;
            }
            ColumnKind::Text => {
                let values: Vec<ByteArray> = cells
                    .iter()
                    .filter(|c| ***c != Cell::Null)
                    .map(|c| ByteArray::from(c.to_csv().into_bytes()))
                    .collect();
                column
                    .typed::<ByteArrayType>()
                    .write_batch(&values, Some(&levels), None)?;
            }
        }
        column.close()?;
        at += 1;
    }
    group.close()?;
    writer.into_inner()
}

#[cfg(test)]
mod tests {
    use super::*;
    use parquet::file::reader::{FileReader, SerializedFileReader};
    use parquet::record::{Field, RowAccessor};

    #[test]
    fn kinds_widen_to_float_then_text() {
        use Cell::*;
        assert_eq!(column_kind(&[Int(1), Null, Int(2)]), ColumnKind::Int);
        assert_eq!(column_kind(&[Int(1), Float(2.5)]), ColumnKind::Float);
        assert_eq!(column_kind(&[Bool(true), Int(1)]), ColumnKind::Text);
        assert_eq!(column_kind(&[Null, Null]), ColumnKind::Float);
        assert_eq!(column_kind(&[Bool(false)]), ColumnKind::Bool);
    }

    #[test]
    fn a_table_reads_back_with_types_and_nulls() {
        let table = Table {
            columns: vec![
                "run_id".into(),
                "uav.0.speed".into(),
                "ticks".into(),
                "ok".into(),
            ],
            rows: vec![
                vec![
                    Cell::Text("a".into()),
                    Cell::Float(1.5),
                    Cell::Int(300),
                    Cell::Bool(true),
                ],
                vec![Cell::Text("b".into()), Cell::Int(2), Cell::Null, Cell::Null],
            ],
        };
        let bytes = to_parquet(&table).unwrap();
        assert_eq!(&bytes[..4], b"PAR1");
        assert_eq!(&bytes[bytes.len() - 4..], b"PAR1");
        let file = tempfile::tempfile().unwrap();
        std::io::Write::write_all(&mut &file, &bytes).unwrap();
        let reader = SerializedFileReader::new(file).unwrap();
        let schema = reader.metadata().file_metadata().schema_descr();
        let names: Vec<String> = (0..schema.num_columns())
            .map(|i| schema.column(i).name().to_owned())
            .collect();
        assert_eq!(names, ["run_id", "uav.0.speed", "ticks", "ok"]);
        let rows: Vec<_> = reader
            .get_row_iter(None)
            .unwrap()
            .map(Result::unwrap)
            .collect();
        assert_eq!(rows.len(), 2);
        assert_eq!(rows[0].get_string(0).unwrap(), "a");
        assert_eq!(rows[0].get_double(1).unwrap(), 1.5);
        assert_eq!(rows[0].get_long(2).unwrap(), 300);
        assert!(rows[0].get_bool(3).unwrap());
        assert_eq!(rows[1].get_double(1).unwrap(), 2.0);
        let (_, ticks) = rows[1].get_column_iter().nth(2).unwrap();
        assert_eq!(*ticks, Field::Null);
    }
}
