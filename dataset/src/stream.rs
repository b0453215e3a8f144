//! Scene tables and files written as a build goes, so memory stays flat in the number of
//! scenes: `ParquetStream` (the final Parquet, row group by row group, byte-identical to
//! writing the whole table at once), and the small `SUMMARY_COLUMNS` projection that the
//! card, eval selection and summaries read. Re-exported by `dataset`.

use crate::table::{concat, schema, writer_props, ROW_GROUP_SIZE};
use arrow::array::RecordBatch;
use parquet::arrow::ArrowWriter;
use std::fs;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Why a streamed scene table could not be written or a projection read; the message
/// names the file.
#[derive(Debug, thiserror::Error)]
pub enum StreamError {
    /// `FILE: WHAT` (creating, writing, syncing or renaming it, or decoding its rows).
    #[error("{}: {message}", .path.display())]
    File { path: PathBuf, message: String },
    #[error("{}: no column '{column}'", .path.display())]
    NoColumn { path: PathBuf, column: String },
    #[error(transparent)]
    Read(#[from] crate::read::ReadError),
}

impl StreamError {
    fn file(path: &Path, e: impl std::fmt::Display) -> StreamError {
        StreamError::File {
            path: path.to_path_buf(),
            message: e.to_string(),
        }
    }
}

/// The message, for callers that pass errors on as text.
impl From<StreamError> for String {
    fn from(e: StreamError) -> String {
        e.to_string()
    }
}

/// A scene table written to disk as its rows arrive, one row group at a time: at most
/// `ROW_GROUP_SIZE` rows are held in memory, whatever the table's length. The rows are
/// gathered into whole row groups before they reach the Parquet writer, so the file is
/// byte-identical to `parquet_bytes` of all rows at once. Written to a temporary name and
/// renamed by `finish`, like `write_atomic`; dropped unfinished, the temporary is removed.
pub struct ParquetStream {
    path: PathBuf,
    group_rows: usize,
    tmp: PathBuf,
    writer: Option<ArrowWriter<std::io::BufWriter<fs::File>>>,
    pending: Vec<RecordBatch>,
    pending_rows: usize,
}

impl ParquetStream {
    /// A table of `ROW_GROUP_SIZE` rows per row group.
    pub fn create(path: &Path) -> Result<ParquetStream, StreamError> {
        ParquetStream::create_with(path, ROW_GROUP_SIZE)
    }

    /// A table of `group_rows` rows per row group (`frames::IMAGE_ROW_GROUP_SIZE` when
    /// the rows carry images).
    pub fn create_with(path: &Path, group_rows: usize) -> Result<ParquetStream, StreamError> {
        let fail = |e: &dyn std::fmt::Display| StreamError::file(path, e);
        fs::create_dir_all(path.parent().unwrap_or(Path::new("."))).map_err(|e| fail(&e))?;
        let tmp = rh_contract::fsio::temp_sibling(path);
        let file = fs::File::create(&tmp).map_err(|e| fail(&e))?;
        let schema = Arc::new(schema());
        let props = writer_props(&RecordBatch::new_empty(schema.clone()), group_rows);
        let writer = ArrowWriter::try_new(std::io::BufWriter::new(file), schema, Some(props))
            .map_err(|e| fail(&e))?;
        Ok(ParquetStream {
            path: path.to_path_buf(),
            group_rows,
            tmp,
            writer: Some(writer),
            pending: Vec::new(),
            pending_rows: 0,
        })
    }

    /// Appends rows (scene-table columns, any number of rows).
    pub fn write(&mut self, batch: &RecordBatch) -> Result<(), StreamError> {
        let mut offset = 0;
        while offset < batch.num_rows() {
            let take = (self.group_rows - self.pending_rows).min(batch.num_rows() - offset);
            self.pending.push(batch.slice(offset, take));
            self.pending_rows += take;
            offset += take;
            if self.pending_rows == self.group_rows {
                self.write_pending()?;
            }
        }
        Ok(())
    }

    /// Hands the gathered rows (one row group or the last, shorter one) to the writer.
    fn write_pending(&mut self) -> Result<(), StreamError> {
        if self.pending.is_empty() {
            return Ok(());
        }
        let rows = concat(&self.pending).map_err(|e| StreamError::file(&self.path, e))?;
        self.pending.clear();
        self.pending_rows = 0;
        let writer = self.writer.as_mut().expect("open until finish");
        writer
            .write(&rows)
            .map_err(|e| StreamError::file(&self.path, e))
    }

    /// Writes the last rows and the footer, syncs, and renames the file into place.
    pub fn finish(mut self) -> Result<(), StreamError> {
        self.write_pending()?;
        let fail = |e: &dyn std::fmt::Display| StreamError::file(&self.path, e);
        let writer = self.writer.take().expect("open until finish");
        let file = writer
            .into_inner()
            .map_err(|e| fail(&e))?
            .into_inner()
            .map_err(|e| fail(&e))?;
        file.sync_all().map_err(|e| fail(&e))?;
        fs::rename(&self.tmp, &self.path).map_err(|e| fail(&e))
    }
}

impl Drop for ParquetStream {
    fn drop(&mut self) {
        if self.writer.is_some() {
            let _ = fs::remove_file(&self.tmp);
        }
    }
}

/// The columns the dataset card, the eval selection and the build summary read: a few
/// bytes per scene, so a finished build's bookkeeping stays small when the table is large.
pub const SUMMARY_COLUMNS: [&str; 6] = [
    "scene_id",
    "scene_index",
    "family",
    "gt_action",
    "valid",
    "ego_file_name",
];

/// `batch` with only the named columns (in the order given).
pub fn project(batch: &RecordBatch, names: &[&str]) -> RecordBatch {
    let indices: Vec<usize> = names
        .iter()
        .map(|n| batch.schema().index_of(n).expect("a scene-table column"))
        .collect();
    batch.project(&indices).expect("columns exist")
}

/// The named columns of a scene-table Parquet file (a projection: the other columns are
/// never decoded).
pub fn read_columns(path: &Path, names: &[&str]) -> Result<RecordBatch, StreamError> {
    let fail = |e: &dyn std::fmt::Display| StreamError::file(path, e);
    let reader = crate::read::open_columns(path, 8192, |n| names.contains(&n))?;
    let schema = arrow::array::RecordBatchReader::schema(&reader);
    if let Some(n) = names.iter().find(|n| schema.index_of(n).is_err()) {
        return Err(StreamError::NoColumn {
            path: path.to_path_buf(),
            column: n.to_string(),
        });
    }
    let batches: Vec<RecordBatch> = reader.collect::<Result<_, _>>().map_err(|e| fail(&e))?;
    let batch = arrow::compute::concat_batches(&schema, &batches).map_err(|e| fail(&e))?;
    // The columns in the order asked for.
    Ok(project(&batch, names))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rows::record_batch;
    use crate::table::{parquet_bytes, string_column, take_rows};
    use rh_catalog::Catalog;
    use rh_scenes::config::Config;
    use rh_scenes::driver::produce_group;
    use rh_scenes::selection::plan_group;

    /// A table streamed in small pieces (as a build feeds its groups) is written row
    /// group by row group into the same bytes as the whole table at once, across several
    /// row groups; the summary projection reads back what was written.
    #[test]
    fn streamed_table_has_the_bytes_of_the_whole_table() {
        let catalog = Catalog::embedded().unwrap();
        let config = Config::embedded().unwrap();
        let families = vec!["object_drop".to_string(), "thrown_object".to_string()];
        let mut results = Vec::new();
        for g in 0..2u64 {
            let sel = plan_group(&catalog, &families, 3, g).unwrap();
            results.extend(produce_group(&sel, 3, g * 4, 4, &catalog, &config).unwrap());
        }
        let few = record_batch(&results, &catalog);
        let n = 2 * ROW_GROUP_SIZE + 345;
        let whole = take_rows(
            &few,
            &(0..n as u32).map(|i| (i * 5) % 8).collect::<Vec<_>>(),
        );
        let dir = tempfile::tempdir().unwrap();
        for piece in [4, 7, 1000, 1500] {
            let path = dir.path().join(format!("streamed-{piece}.parquet"));
            let mut stream = ParquetStream::create(&path).unwrap();
            let mut offset = 0;
            while offset < n {
                let len = piece.min(n - offset);
                stream.write(&whole.slice(offset, len)).unwrap();
                offset += len;
            }
            stream.finish().unwrap();
            let bytes = fs::read(&path).unwrap();
            assert!(bytes == parquet_bytes(&whole), "pieces of {piece} rows");
        }
        let path = dir.path().join("streamed-4.parquet");
        let summary = read_columns(&path, &SUMMARY_COLUMNS).unwrap();
        assert_eq!(summary.num_rows(), n);
        assert_eq!(summary.schema().field(0).name(), "scene_id");
        assert_eq!(
            string_column(&summary, "family"),
            string_column(&whole, "family")
        );
        // Nothing but the file itself is left in the folder (the temporary was renamed).
        let names: Vec<_> = fs::read_dir(dir.path()).unwrap().flatten().collect();
        assert_eq!(names.len(), 4);
    }
}
