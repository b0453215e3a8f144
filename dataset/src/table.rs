//! The scene table (specification §8) as Parquet: its Arrow schema with the `datasets` features,
//! the writer settings (the same rows always give the same bytes), and reading it back
//! (whole files, column values, the dataset's data files). Rows are built from scene
//! results by `rows` (feature `write`).

use crate::read;
use arrow::array::{ArrayRef, RecordBatch};
use arrow::datatypes::{DataType, Schema};
use parquet::arrow::ArrowWriter;
use parquet::basic::Compression;
use parquet::file::properties::WriterProperties;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Rows per Parquet row group: small enough for the Hub's dataset viewer to page.
pub const ROW_GROUP_SIZE: usize = 1000;

pub use rh_contract::fsio::write_atomic;
pub use rh_contract::layout::{data_file_name, frame_files, spec_path};

/// The Arrow schema of the scene table, in column order, with the `huggingface` metadata
/// key (the `datasets` features) attached.
pub fn schema() -> Schema {
    let plain = plain_schema();
    let features = huggingface_features(&plain);
    let metadata: std::collections::HashMap<String, String> =
        [("huggingface".to_string(), features)].into();
    plain.with_metadata(metadata)
}

/// The scene table's columns without schema metadata (`rh_contract::COLUMNS`).
fn plain_schema() -> Schema {
    rh_contract::arrow_schema::schema()
}

/// The `datasets` feature of an Arrow type (the JSON that `datasets.Features.to_dict()`
/// writes). Fixed-size lists become `Sequence` with a `length`, which every `datasets`
/// version reads (≥ 4 turns it into `List(..., length=n)`).
fn feature_of(data_type: &DataType) -> serde_json::Value {
    use serde_json::json;
    let value = |dtype: &str| json!({"dtype": dtype, "_type": "Value"});
    match data_type {
        DataType::Utf8 | DataType::LargeUtf8 => value("string"),
        DataType::Boolean => value("bool"),
        DataType::Float64 => value("float64"),
        DataType::Float32 => value("float32"),
        DataType::UInt64 => value("uint64"),
        DataType::UInt32 => value("uint32"),
        DataType::Int64 => value("int64"),
        DataType::Int32 => value("int32"),
        DataType::FixedSizeList(item, n) => {
            json!({"feature": feature_of(item.data_type()), "length": n, "_type": "Sequence"})
        }
        DataType::Struct(fields)
            if fields.len() == 2 && fields[0].name() == "bytes" && fields[1].name() == "path" =>
        {
            json!({"_type": "Image"})
        }
        DataType::List(item) | DataType::LargeList(item) => {
            json!({"feature": feature_of(item.data_type()), "_type": "Sequence"})
        }
        other => panic!("no datasets feature for Arrow type {other}"),
    }
}

/// `{"info": {"features": {...}}}`: the schema metadata `datasets` reads its features
/// from, with the columns in schema order.
pub fn huggingface_features(schema: &Schema) -> String {
    let entries: Vec<String> = schema
        .fields()
        .iter()
        .map(|f| {
            format!(
                "{}: {}",
                serde_json::Value::String(f.name().clone()),
                feature_of(f.data_type())
            )
        })
        .collect();
    format!("{{\"info\": {{\"features\": {{{}}}}}}}", entries.join(", "))
}

/// What a column means (`rh_contract::COLUMNS`; the dataset card's feature table).
pub fn column_description(name: &str) -> Option<String> {
    rh_contract::columns::column(name).map(|c| c.description.to_string())
}

/// A nullable string column by name (all null when absent).
pub fn optional_string_column(batch: &RecordBatch, name: &str) -> Vec<Option<String>> {
    match batch.column_by_name(name) {
        Some(_) => read::strings(batch, Path::new(TABLE), name).expect("a string column"),
        None => vec![None; batch.num_rows()],
    }
}

/// Why scene rows could not be read back or put together.
#[derive(Debug, thiserror::Error)]
pub enum TableError {
    #[error(transparent)]
    Read(#[from] read::ReadError),
    /// `FILE: WHAT` (its rows could not be decoded or put together).
    #[error("{}: {message}", .path.display())]
    File { path: PathBuf, message: String },
    #[error("{}: no data/*.parquet files", .dir.display())]
    NoData { dir: PathBuf },
    /// A batch whose columns are not `schema()`'s.
    #[error("its columns are not this version's scene table")]
    Columns,
    /// Arrow refused to put the batches together.
    #[error("{0}")]
    Arrow(String),
}

impl TableError {
    fn file(path: &Path, e: impl std::fmt::Display) -> TableError {
        TableError::File {
            path: path.to_path_buf(),
            message: e.to_string(),
        }
    }
}

/// The message, for callers that pass errors on as text.
impl From<TableError> for String {
    fn from(e: TableError) -> String {
        e.to_string()
    }
}

/// Reads a Parquet file of scene rows written by `parquet_bytes` back into one batch with
/// the canonical schema (`schema()`), the images of `<cam>_frames` left out (null).
pub fn read_batch(path: &Path) -> Result<RecordBatch, TableError> {
    let batches: Vec<RecordBatch> = read::open_parquet(path, 8192)?
        .map(|b| b.map(|b| with_null_images(&b)))
        .collect::<Result<_, _>>()
        .map_err(|e| TableError::file(path, e))?;
    concat(&batches).map_err(|e| TableError::file(path, e))
}

/// `batch` (read without its image columns) with null `<cam>_frames` columns in their
/// places; a batch that has them, or lacks other columns, is returned as it is.
fn with_null_images(batch: &RecordBatch) -> RecordBatch {
    let plain = plain_schema();
    let nulls = crate::frames::null_columns(batch.num_rows());
    let mut next_null = nulls.into_iter();
    let mut columns = Vec::with_capacity(plain.fields().len());
    for f in plain.fields() {
        match batch.column_by_name(f.name()) {
            Some(c) => columns.push(c.clone()),
            None if rh_contract::columns::is_frames_column(f.name()) => {
                columns.push(next_null.next().expect("one per camera"))
            }
            None => return batch.clone(),
        }
    }
    RecordBatch::try_new(Arc::new(plain), columns).unwrap_or_else(|_| batch.clone())
}

/// Concatenates scene batches into one with the canonical schema; fails if a batch's
/// columns differ from `schema()`.
pub fn concat(batches: &[RecordBatch]) -> Result<RecordBatch, TableError> {
    let schema = Arc::new(schema());
    let plain = plain_schema();
    let mut aligned = Vec::with_capacity(batches.len());
    for b in batches {
        if b.schema().fields() != plain.fields() {
            return Err(TableError::Columns);
        }
        aligned.push(
            RecordBatch::try_new(schema.clone(), b.columns().to_vec())
                .map_err(|e| TableError::Arrow(e.to_string()))?,
        );
    }
    arrow::compute::concat_batches(&schema, &aligned).map_err(|e| TableError::Arrow(e.to_string()))
}

/// The rows of `batch` at `indices`, in that order.
pub fn take_rows(batch: &RecordBatch, indices: &[u32]) -> RecordBatch {
    let idx = arrow::array::UInt32Array::from(indices.to_vec());
    let columns: Vec<ArrayRef> = batch
        .columns()
        .iter()
        .map(|c| arrow::compute::take(c, &idx, None).expect("indices are in range"))
        .collect();
    RecordBatch::try_new(batch.schema(), columns).expect("same schema")
}

/// What the in-memory accessors below name in a message: they read the rows this
/// program wrote itself, where a missing or mistyped column is a bug (they panic).
const TABLE: &str = "scene table";

/// The values of a non-null string column.
pub fn string_column(batch: &RecordBatch, name: &str) -> Vec<String> {
    read::required_strings(batch, Path::new(TABLE), name).unwrap_or_else(|e| panic!("{e}"))
}

/// The values of a UInt64 column.
pub fn u64_column(batch: &RecordBatch, name: &str) -> Vec<u64> {
    read::u64s(batch, Path::new(TABLE), name).unwrap_or_else(|e| panic!("{e}"))
}

/// The values of a Boolean column.
pub fn bool_column(batch: &RecordBatch, name: &str) -> Vec<bool> {
    read::bools(batch, Path::new(TABLE), name).unwrap_or_else(|e| panic!("{e}"))
}

/// Serialises rows to Parquet bytes (Snappy, `ROW_GROUP_SIZE`-row groups, no timestamps:
/// the same rows always give the same bytes). Rows carrying images (a finished rendered
/// build's) are written by `stream::ParquetStream` with `row_group_size`.
pub fn parquet_bytes(batch: &RecordBatch) -> Vec<u8> {
    let mut bytes = Vec::new();
    {
        let props = writer_props(batch, ROW_GROUP_SIZE);
        let mut writer =
            ArrowWriter::try_new(&mut bytes, batch.schema(), Some(props)).expect("valid schema");
        writer.write(batch).expect("in-memory write");
        writer.close().expect("in-memory close");
    }
    bytes
}

/// The writer settings of every scene table: Snappy, `group_rows` rows per row group
/// (`ROW_GROUP_SIZE`, or `frames::IMAGE_ROW_GROUP_SIZE` for rows with images), no
/// timestamps.
pub(crate) fn writer_props(batch: &RecordBatch, group_rows: usize) -> WriterProperties {
    // The `huggingface` features also as a plain key-value entry of the file, for readers
    // that do not decode the embedded Arrow schema.
    let kv = batch.schema().metadata().get("huggingface").map(|v| {
        vec![parquet::file::metadata::KeyValue::new(
            "huggingface".into(),
            v.clone(),
        )]
    });
    WriterProperties::builder()
        .set_key_value_metadata(kv)
        .set_compression(Compression::SNAPPY)
        .set_max_row_group_row_count(Some(group_rows))
        .set_created_by("rh-pipeline".to_string())
        .build()
}

/// Rows per row group of a dataset's tables: `frames::IMAGE_ROW_GROUP_SIZE` for a rendered
/// build (its rows carry images), else `ROW_GROUP_SIZE`.
pub fn row_group_size(render: bool) -> usize {
    if render {
        crate::frames::IMAGE_ROW_GROUP_SIZE
    } else {
        ROW_GROUP_SIZE
    }
}

/// Paths of the dataset's Parquet files, in name order.
pub fn data_files(dir: &Path) -> Result<Vec<PathBuf>, read::ReadError> {
    read::parquet_files(&dir.join("data"))
}

/// The (scene_id, spec_file, state_hash) of every row of a dataset, for `verify`.
pub fn read_hashes(dir: &Path) -> Result<Vec<(String, String, String)>, TableError> {
    let files = data_files(dir)?;
    if files.is_empty() {
        return Err(TableError::NoData {
            dir: dir.to_path_buf(),
        });
    }
    let mut rows = Vec::new();
    for path in files {
        for batch in read::open_parquet(&path, 8192)? {
            let batch = batch.map_err(|e| TableError::file(&path, e))?;
            let ids = read::required_strings(&batch, &path, "scene_id")?;
            let specs = read::required_strings(&batch, &path, "spec_file")?;
            let hashes = read::required_strings(&batch, &path, "state_hash")?;
            rows.extend(
                ids.into_iter()
                    .zip(specs)
                    .zip(hashes)
                    .map(|((a, b), c)| (a, b, c)),
            );
        }
    }
    Ok(rows)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_column_is_described_and_has_a_feature() {
        let schema = schema();
        let features: serde_json::Value =
            serde_json::from_str(&huggingface_features(&schema)).unwrap();
        assert!(
            huggingface_features(&schema).starts_with("{\"info\": {\"features\": {\"scene_id\": ")
        );
        for f in schema.fields() {
            assert!(
                column_description(f.name()).is_some(),
                "no description for {}",
                f.name()
            );
            assert!(features["info"]["features"][f.name()].is_object());
        }
        let meta: serde_json::Value =
            serde_json::from_str(&schema.metadata()["huggingface"]).unwrap();
        assert_eq!(
            meta["info"]["features"]["impact_point"],
            serde_json::json!({"feature": {"dtype": "float64", "_type": "Value"}, "length": 3, "_type": "Sequence"})
        );
        assert_eq!(meta["info"]["features"]["valid"]["dtype"], "bool");
        assert_eq!(meta["info"]["features"]["seed"]["dtype"], "uint64");
    }
}
