//! Reading the scene table: the one place that lists a dataset's Parquet files, opens
//! them, and turns columns into values. Every error names the file and the column
//! (`FILE: column `NAME` …`), so callers pass the message on as an input error.
//! Used by the dataset's own tools (`verify`, `merge`, resume) and by `rh-score`.

use arrow::array::{
    Array, ArrayRef, BooleanArray, FixedSizeListArray, Float64Array, ListArray, RecordBatch,
    StringArray, UInt32Array, UInt64Array,
};
use arrow::datatypes::DataType;
use parquet::arrow::arrow_reader::{ParquetRecordBatchReader, ParquetRecordBatchReaderBuilder};
use std::path::{Path, PathBuf};

/// Why the scene table could not be read: every message names the file (and the column).
#[derive(Debug, thiserror::Error)]
pub enum ReadError {
    #[error("cannot read {}: {source}", .folder.display())]
    Folder {
        folder: PathBuf,
        source: std::io::Error,
    },
    #[error("cannot open {}: {source}", .file.display())]
    Open {
        file: PathBuf,
        source: std::io::Error,
    },
    #[error("{} is not a readable Parquet file: {message}", .file.display())]
    NotParquet { file: PathBuf, message: String },
    /// `FILE: column `NAME` WHAT`.
    #[error("{}: column `{column}` {what}", .file.display())]
    Column {
        file: PathBuf,
        column: String,
        what: String,
    },
}

impl ReadError {
    /// The error of a column: `FILE: column `NAME` WHAT`.
    pub fn column(file: &Path, column: &str, what: impl std::fmt::Display) -> ReadError {
        ReadError::Column {
            file: file.to_path_buf(),
            column: column.to_string(),
            what: what.to_string(),
        }
    }
}

/// The message, for callers that pass errors on as text.
impl From<ReadError> for String {
    fn from(e: ReadError) -> String {
        e.to_string()
    }
}

/// The `.parquet` files of a folder, in name order.
pub fn parquet_files(folder: &Path) -> Result<Vec<PathBuf>, ReadError> {
    let rd = std::fs::read_dir(folder).map_err(|source| ReadError::Folder {
        folder: folder.to_path_buf(),
        source,
    })?;
    let mut files: Vec<PathBuf> = rd
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|x| x == "parquet"))
        .collect();
    files.sort();
    Ok(files)
}

/// A record-batch reader over one Parquet file, every column but the model-input
/// frames' images (`<cam>_frames`, about 1 MB a row: only `datasets` users and `merge`
/// read them).
pub fn open_parquet(file: &Path, batch_size: usize) -> Result<ParquetRecordBatchReader, ReadError> {
    open_columns(file, batch_size, |name| {
        !rh_contract::columns::is_frames_column(name)
    })
}

/// A record-batch reader over one Parquet file, the columns whose names `keep` accepts
/// (the others are never decoded): the one place a scene table is opened.
pub fn open_columns(
    file: &Path,
    batch_size: usize,
    keep: impl Fn(&str) -> bool,
) -> Result<ParquetRecordBatchReader, ReadError> {
    let f = std::fs::File::open(file).map_err(|source| ReadError::Open {
        file: file.to_path_buf(),
        source,
    })?;
    ParquetRecordBatchReaderBuilder::try_new(f)
        .and_then(|b| {
            let roots: Vec<usize> = b
                .schema()
                .fields()
                .iter()
                .enumerate()
                .filter(|(_, f)| keep(f.name()))
                .map(|(i, _)| i)
                .collect();
            let mask = parquet::arrow::ProjectionMask::roots(b.parquet_schema(), roots);
            b.with_projection(mask).with_batch_size(batch_size).build()
        })
        .map_err(|e| ReadError::NotParquet {
            file: file.to_path_buf(),
            message: e.to_string(),
        })
}

/// The error of a column as text: `FILE: column `NAME` WHAT` ([`ReadError::column`]).
pub fn bad(file: &Path, column: &str, what: impl std::fmt::Display) -> String {
    ReadError::column(file, column, what).to_string()
}

/// A column by name.
pub fn column<'a>(
    batch: &'a RecordBatch,
    file: &Path,
    name: &str,
) -> Result<&'a ArrayRef, ReadError> {
    batch
        .column_by_name(name)
        .ok_or_else(|| ReadError::column(file, name, "is missing"))
}

/// A string column (Utf8, LargeUtf8 or Utf8View), nulls as `None`.
pub fn strings(
    batch: &RecordBatch,
    file: &Path,
    name: &str,
) -> Result<Vec<Option<String>>, ReadError> {
    let col = column(batch, file, name)?;
    let col = match col.data_type() {
        DataType::Utf8 => col.clone(),
        DataType::LargeUtf8 | DataType::Utf8View => arrow::compute::cast(col, &DataType::Utf8)
            .map_err(|e| ReadError::column(file, name, e))?,
        other => {
            return Err(ReadError::column(
                file,
                name,
                format!("has type {other}, expected Utf8"),
            ))
        }
    };
    let arr = col
        .as_any()
        .downcast_ref::<StringArray>()
        .ok_or_else(|| ReadError::column(file, name, "is not a string array"))?;
    Ok((0..arr.len())
        .map(|i| (!arr.is_null(i)).then(|| arr.value(i).to_string()))
        .collect())
}

/// A string column without nulls.
pub fn required_strings(
    batch: &RecordBatch,
    file: &Path,
    name: &str,
) -> Result<Vec<String>, ReadError> {
    strings(batch, file, name)?
        .into_iter()
        .enumerate()
        .map(|(i, v)| v.ok_or_else(|| ReadError::column(file, name, format!("is null in row {i}"))))
        .collect()
}

/// A column of type `A` without nulls, each value taken by `value`; `expected` names the
/// Arrow type in the error.
fn non_null<A: Array + 'static, T>(
    batch: &RecordBatch,
    file: &Path,
    name: &str,
    expected: &str,
    value: impl Fn(&A, usize) -> T,
) -> Result<Vec<T>, ReadError> {
    let col = column(batch, file, name)?;
    let arr = col.as_any().downcast_ref::<A>().ok_or_else(|| {
        ReadError::column(
            file,
            name,
            format!("has type {}, expected {expected}", col.data_type()),
        )
    })?;
    (0..arr.len())
        .map(|i| match arr.is_null(i) {
            true => Err(ReadError::column(file, name, format!("is null in row {i}"))),
            false => Ok(value(arr, i)),
        })
        .collect()
}

/// A Boolean column without nulls.
pub fn bools(batch: &RecordBatch, file: &Path, name: &str) -> Result<Vec<bool>, ReadError> {
    non_null(batch, file, name, "Boolean", |a: &BooleanArray, i| {
        a.value(i)
    })
}

/// A UInt64 column without nulls.
pub fn u64s(batch: &RecordBatch, file: &Path, name: &str) -> Result<Vec<u64>, ReadError> {
    non_null(batch, file, name, "UInt64", |a: &UInt64Array, i| a.value(i))
}

/// A List<UInt32> column, nulls as `None` (the measured-visibility columns).
pub fn u32_lists(
    batch: &RecordBatch,
    file: &Path,
    name: &str,
) -> Result<Vec<Option<Vec<u32>>>, ReadError> {
    let col = column(batch, file, name)?;
    let wrong = || {
        ReadError::column(
            file,
            name,
            format!("has type {}, expected List<UInt32>", col.data_type()),
        )
    };
    let arr = col.as_any().downcast_ref::<ListArray>().ok_or_else(wrong)?;
    (0..arr.len())
        .map(|i| {
            if arr.is_null(i) {
                return Ok(None);
            }
            let v = arr.value(i);
            let v = v.as_any().downcast_ref::<UInt32Array>().ok_or_else(wrong)?;
            Ok(Some(v.values().to_vec()))
        })
        .collect()
}

/// A column of 3-vectors: FixedSizeList<Float64, 3> (or List<Float64> of length 3).
pub fn vec3s(
    batch: &RecordBatch,
    file: &Path,
    name: &str,
) -> Result<Vec<Option<[f64; 3]>>, ReadError> {
    let col = column(batch, file, name)?;
    let wrong = || {
        ReadError::column(
            file,
            name,
            format!(
                "has type {}, expected FixedSizeList<Float64, 3>",
                col.data_type()
            ),
        )
    };
    let mut out = Vec::with_capacity(col.len());
    if let Some(arr) = col.as_any().downcast_ref::<FixedSizeListArray>() {
        if arr.value_length() != 3 {
            return Err(wrong());
        }
        let values = arr
            .values()
            .as_any()
            .downcast_ref::<Float64Array>()
            .ok_or_else(wrong)?;
        for i in 0..arr.len() {
            out.push((!arr.is_null(i)).then(|| {
                let o = i * 3;
                [values.value(o), values.value(o + 1), values.value(o + 2)]
            }));
        }
    } else if let Some(arr) = col.as_any().downcast_ref::<ListArray>() {
        for i in 0..arr.len() {
            if arr.is_null(i) {
                out.push(None);
                continue;
            }
            let v = arr.value(i);
            let v = v
                .as_any()
                .downcast_ref::<Float64Array>()
                .ok_or_else(wrong)?;
            if v.len() != 3 {
                return Err(ReadError::column(
                    file,
                    name,
                    format!("row {i} has {} values, expected 3", v.len()),
                ));
            }
            out.push(Some([v.value(0), v.value(1), v.value(2)]));
        }
    } else {
        return Err(wrong());
    }
    Ok(out)
}
