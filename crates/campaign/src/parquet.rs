//! `results.parquet`: the [`Table`] of `campaign collect` as an Apache Parquet file
//! (format specification: <https://parquet.apache.org/docs/file-format/>), for pandas,
//! polars, DuckDB and Spark users who would rather not parse CSV.
//!
//! Written with the `parquet` crate of the Apache Arrow Rust project (without Arrow and
//! without compression codecs, which keeps it small): one row group, one optional
//! column per table column (`BYTE_ARRAY` UTF8 text, `DOUBLE`, `INT64`, `BOOLEAN`),
//! definition level 0 where a variant has no value.

use std::sync::Arc;

use parquet::basic::{LogicalType, Repetition, Type as Physical};
use parquet::data_type::{BoolType, ByteArray, ByteArrayType, DoubleType, Int64Type};
use parquet::file::properties::WriterProperties;
use parquet::file::writer::SerializedFileWriter;
use parquet::schema::types::Type;

use crate::collect::{Table, Values};

/// The Parquet bytes of `table`.
///
/// # Errors
///
/// The writer's, as text (it fails only on a schema it cannot build, such as two
/// columns of one name).
pub fn write(table: &Table) -> Result<Vec<u8>, String> {
    let e = |x: parquet::errors::ParquetError| x.to_string();
    let fields = table
        .columns
        .iter()
        .map(|c| {
            let (physical, logical) = match c.values {
                Values::Text(_) => (Physical::BYTE_ARRAY, Some(LogicalType::String)),
                Values::Float(..) => (Physical::DOUBLE, None),
                Values::Int(_) => (Physical::INT64, None),
                Values::Bool(_) => (Physical::BOOLEAN, None),
            };
            Type::primitive_type_builder(&c.name, physical)
                .with_repetition(Repetition::OPTIONAL)
                .with_logical_type(logical)
                .build()
                .map(Arc::new)
                .map_err(e)
        })
        .collect::<Result<Vec<_>, _>>()?;
    let schema = Arc::new(Type::group_type_builder("results").with_fields(fields).build().map_err(e)?);
    let props = Arc::new(WriterProperties::builder().set_created_by("cadmorph campaign collect".into()).build());
    let mut w = SerializedFileWriter::new(Vec::new(), schema, props).map_err(e)?;
    let mut rg = w.next_row_group().map_err(e)?;
    let mut columns = table.columns.iter();
    while let Some(mut col) = rg.next_column().map_err(e)? {
        let c = columns.next().ok_or("more Parquet columns than table columns")?;
        // Definition levels: 1 where present, 0 where missing; only present values given.
        fn split<T: Clone>(v: &[Option<T>]) -> (Vec<T>, Vec<i16>) {
            (v.iter().flatten().cloned().collect(), v.iter().map(|x| i16::from(x.is_some())).collect())
        }
        match &c.values {
            Values::Text(v) => {
                let (vals, def) = split(v);
                let vals: Vec<ByteArray> = vals.into_iter().map(|s| ByteArray::from(s.into_bytes())).collect();
                col.typed::<ByteArrayType>().write_batch(&vals, Some(&def), None).map_err(e)?;
            }
            Values::Float(v, _) => {
                let (vals, def) = split(v);
                col.typed::<DoubleType>().write_batch(&vals, Some(&def), None).map_err(e)?;
            }
            Values::Int(v) => {
                let (vals, def) = split(v);
                col.typed::<Int64Type>().write_batch(&vals, Some(&def), None).map_err(e)?;
            }
            Values::Bool(v) => {
                let (vals, def) = split(v);
                col.typed::<BoolType>().write_batch(&vals, Some(&def), None).map_err(e)?;
            }
        }
        col.close().map_err(e)?;
    }
    rg.close().map_err(e)?;
    w.into_inner().map_err(e)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::collect::Column;
    use parquet::file::reader::{FileReader, SerializedFileReader};
    use parquet::record::Field;

    /// The crate's own reader gives back every value and every gap (pyarrow reads the
    /// campaign's real file in the CLI test).
    #[test]
    fn values_and_gaps_read_back() {
        let t = Table {
            columns: vec![
                Column { name: "id".into(), values: Values::Text(vec![Some("v0".into()), Some("v1".into())]) },
                Column { name: "x".into(), values: Values::Float(vec![Some(0.25), None], None) },
                Column { name: "n".into(), values: Values::Int(vec![None, Some(7)]) },
                Column { name: "ok".into(), values: Values::Bool(vec![Some(true), None]) },
            ],
            rows: 2,
        };
        let bytes = write(&t).unwrap();
        assert_eq!(&bytes[..4], b"PAR1");
        let r = SerializedFileReader::new(bytes::Bytes::from(bytes)).unwrap();
        assert_eq!(r.metadata().file_metadata().num_rows(), 2);
        let rows: Vec<Vec<Field>> = r
            .get_row_iter(None)
            .unwrap()
            .map(|row| row.unwrap().get_column_iter().map(|(_, f)| f.clone()).collect())
            .collect();
        assert_eq!(rows[0], vec![Field::Str("v0".into()), Field::Double(0.25), Field::Null, Field::Bool(true)]);
        assert_eq!(rows[1], vec![Field::Str("v1".into()), Field::Null, Field::Long(7), Field::Null]);
    }
}
