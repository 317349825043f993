//! The batch's two tidy tables, built from the series' records: `images` (one row per image of
//! every series: the columns of `areas.csv`, whether the contact touches the border, the
//! metadata) and `series` (one row per series: status, error, threshold, pixel size and its
//! source, fits, flags, warnings, folders, the metadata). Each is written as Parquet (typed
//! columns: Apache Parquet's DOUBLE, INT64, BOOLEAN and UTF-8 strings, zstd pages, one row
//! group; the `parquet` crate, Apache Arrow's Rust implementation) and as CSV with the same
//! column names, units in the names as everywhere (`docs/outputs.md`).
//!
//! The tables hold nothing that depends on when or where they were made, so two runs over the
//! same inputs (the command line, Python, a Dask cluster) write the same bytes.

use std::sync::Arc;

use parquet::basic::{Compression, LogicalType, Repetition, Type as PhysicalType, ZstdLevel};
use parquet::data_type::{BoolType, ByteArray, ByteArrayType, DoubleType, Int64Type};
use parquet::file::metadata::KeyValue;
use parquet::file::properties::WriterProperties;
use parquet::file::writer::SerializedFileWriter;
use parquet::schema::types::Type;

use crate::error::{Error, Result};

/// A column's values; `None` is a null (an empty CSV cell).
#[derive(Debug, Clone, PartialEq)]
pub enum Values {
    /// Floating-point numbers.
    Float(Vec<Option<f64>>),
    /// Integers.
    Int(Vec<Option<i64>>),
    /// Text.
    Text(Vec<Option<String>>),
    /// true / false.
    Bool(Vec<Option<bool>>),
}

impl Values {
    fn len(&self) -> usize {
        match self {
            Values::Float(v) => v.len(),
            Values::Int(v) => v.len(),
            Values::Text(v) => v.len(),
            Values::Bool(v) => v.len(),
        }
    }

    fn cell(&self, row: usize) -> String {
        match self {
            Values::Float(v) => v[row].map(|x| format!("{x}")).unwrap_or_default(),
            Values::Int(v) => v[row].map(|x| x.to_string()).unwrap_or_default(),
            Values::Text(v) => v[row].clone().unwrap_or_default(),
            Values::Bool(v) => v[row].map(|x| x.to_string()).unwrap_or_default(),
        }
    }

    /// The values as text, for pages (null as empty).
    pub fn text(&self, row: usize) -> String {
        self.cell(row)
    }
}

/// One named column.
#[derive(Debug, Clone, PartialEq)]
pub struct Column {
    /// Name, with its unit.
    pub name: String,
    /// Values, one per row.
    pub values: Values,
}

/// A table: columns of equal length.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Table {
    /// Columns in order.
    pub columns: Vec<Column>,
    /// Rows.
    pub rows: usize,
}

impl Table {
    /// An empty table of `rows` rows.
    pub fn new(rows: usize) -> Self {
        Table {
            columns: Vec::new(),
            rows,
        }
    }

    /// Add a column (its length must be the table's).
    pub fn push(&mut self, name: impl Into<String>, values: Values) {
        debug_assert_eq!(values.len(), self.rows);
        self.columns.push(Column {
            name: name.into(),
            values,
        });
    }

    /// Add a float column.
    pub fn float(&mut self, name: &str, values: impl IntoIterator<Item = Option<f64>>) {
        self.push(name, Values::Float(values.into_iter().collect()));
    }

    /// Add an integer column.
    pub fn int(&mut self, name: &str, values: impl IntoIterator<Item = Option<i64>>) {
        self.push(name, Values::Int(values.into_iter().collect()));
    }

    /// Add a text column.
    pub fn text(&mut self, name: &str, values: impl IntoIterator<Item = Option<String>>) {
        self.push(name, Values::Text(values.into_iter().collect()));
    }

    /// Add a boolean column.
    pub fn bool(&mut self, name: &str, values: impl IntoIterator<Item = Option<bool>>) {
        self.push(name, Values::Bool(values.into_iter().collect()));
    }

    /// The column named `name`.
    pub fn column(&self, name: &str) -> Option<&Values> {
        self.columns
            .iter()
            .find(|c| c.name == name)
            .map(|c| &c.values)
    }

    /// The table as CSV: a header of the column names, one line per row, nulls empty; floats in
    /// the shortest form that reads back to the same number.
    pub fn to_csv(&self) -> Result<Vec<u8>> {
        let mut w = csv::Writer::from_writer(Vec::new());
        let err = |e: csv::Error| Error::InvalidArgument(format!("table: {e}"));
        w.write_record(self.columns.iter().map(|c| c.name.as_str()))
            .map_err(err)?;
        for row in 0..self.rows {
            w.write_record(self.columns.iter().map(|c| c.values.cell(row)))
                .map_err(err)?;
        }
        w.into_inner()
            .map_err(|e| Error::InvalidArgument(format!("table: {e}")))
    }

    /// The table as a Parquet file named `name` in its schema, with `metadata` as key–value
    /// pairs of the file.
    pub fn to_parquet(&self, name: &str, metadata: &[(&str, String)]) -> Result<Vec<u8>> {
        let err =
            |e: parquet::errors::ParquetError| Error::InvalidArgument(format!("Parquet: {e}"));
        let fields = self
            .columns
            .iter()
            .map(|c| {
                let (physical, logical) = match c.values {
                    Values::Float(_) => (PhysicalType::DOUBLE, None),
                    Values::Int(_) => (PhysicalType::INT64, None),
                    Values::Text(_) => (PhysicalType::BYTE_ARRAY, Some(LogicalType::String)),
                    Values::Bool(_) => (PhysicalType::BOOLEAN, None),
                };
                Type::primitive_type_builder(&c.name, physical)
                    .with_repetition(Repetition::OPTIONAL)
                    .with_logical_type(logical)
                    .build()
                    .map(Arc::new)
                    .map_err(err)
            })
            .collect::<Result<Vec<_>>>()?;
        let schema = Type::group_type_builder(name)
            .with_fields(fields)
            .build()
            .map_err(err)?;
        let properties = WriterProperties::builder()
            .set_compression(Compression::ZSTD(ZstdLevel::default()))
            .set_key_value_metadata(Some(
                metadata
                    .iter()
                    .map(|(k, v)| KeyValue::new(k.to_string(), v.clone()))
                    .collect(),
            ))
            .build();
        let mut bytes = Vec::new();
        let mut writer =
            SerializedFileWriter::new(&mut bytes, Arc::new(schema), Arc::new(properties))
                .map_err(err)?;
        let mut group = writer.next_row_group().map_err(err)?;
        for column in &self.columns {
            let mut out = group
                .next_column()
                .map_err(err)?
                .ok_or_else(|| Error::InvalidArgument("Parquet: a column too few".into()))?;
            fn split<T: Clone>(v: &[Option<T>]) -> (Vec<T>, Vec<i16>) {
                let levels = v.iter().map(|x| i16::from(x.is_some())).collect();
                (v.iter().flatten().cloned().collect(), levels)
            }
            match &column.values {
                Values::Float(v) => {
                    let (values, levels) = split(v);
                    out.typed::<DoubleType>()
                        .write_batch(&values, Some(&levels), None)
                        .map_err(err)?;
                }
                Values::Int(v) => {
                    let (values, levels) = split(v);
                    out.typed::<Int64Type>()
                        .write_batch(&values, Some(&levels), None)
                        .map_err(err)?;
                }
                Values::Bool(v) => {
                    let (values, levels) = split(v);
                    out.typed::<BoolType>()
                        .write_batch(&values, Some(&levels), None)
                        .map_err(err)?;
                }
                Values::Text(v) => {
                    let (values, levels) = split(v);
                    let values: Vec<ByteArray> =
                        values.iter().map(|s| ByteArray::from(s.as_str())).collect();
                    out.typed::<ByteArrayType>()
                        .write_batch(&values, Some(&levels), None)
                        .map_err(err)?;
                }
            }
            out.close().map_err(err)?;
        }
        group.close().map_err(err)?;
        writer.close().map_err(err)?;
        Ok(bytes)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use parquet::file::reader::{FileReader, SerializedFileReader};
    use parquet::record::Field;

    fn table() -> Table {
        let mut t = Table::new(3);
        t.text("series_id", ["a", "a", "b"].map(|s| Some(s.to_string())));
        t.float("area_um2", [Some(0.1 + 0.2), None, Some(2e-7)]);
        t.int("patches", [Some(3), Some(-1), None]);
        t.bool("edge_contact", [Some(true), None, Some(false)]);
        t.text(
            "sample",
            [Some("x,y".to_string()), None, Some("é".to_string())],
        );
        t
    }

    #[test]
    fn csv_has_nulls_empty_and_floats_that_read_back() {
        let csv = String::from_utf8(table().to_csv().unwrap()).unwrap();
        assert_eq!(
            csv,
            "series_id,area_um2,patches,edge_contact,sample\n\
             a,0.30000000000000004,3,true,\"x,y\"\n\
             a,,-1,,\n\
             b,0.0000002,,false,é\n"
        );
        assert_eq!("0.30000000000000004".parse::<f64>().unwrap(), 0.1 + 0.2);
    }

    #[test]
    fn parquet_reads_back_with_types_and_nulls() {
        let bytes = table()
            .to_parquet("images", &[("contactscope_version", "0.1.0".into())])
            .unwrap();
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("t.parquet");
        std::fs::write(&path, &bytes).unwrap();
        let reader = SerializedFileReader::new(std::fs::File::open(&path).unwrap()).unwrap();
        let meta = reader.metadata().file_metadata();
        assert_eq!(meta.num_rows(), 3);
        let kv = meta.key_value_metadata().unwrap();
        assert_eq!(kv[0].key, "contactscope_version");
        let rows: Vec<Vec<Field>> = reader
            .get_row_iter(None)
            .unwrap()
            .map(|r| {
                r.unwrap()
                    .get_column_iter()
                    .map(|(_, f)| f.clone())
                    .collect()
            })
            .collect();
        assert_eq!(rows[0][1], Field::Double(0.1 + 0.2));
        assert_eq!(rows[1][1], Field::Null);
        assert_eq!(rows[1][2], Field::Long(-1));
        assert_eq!(rows[0][3], Field::Bool(true));
        assert_eq!(rows[2][4], Field::Str("é".into()));
        // The same table, the same bytes.
        assert_eq!(
            table()
                .to_parquet("images", &[("contactscope_version", "0.1.0".into())])
                .unwrap(),
            bytes
        );
    }
}
