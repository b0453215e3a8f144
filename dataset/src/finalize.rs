//! A dataset's final files from its rows: the data Parquet, the eval subset, the card
//! and the finished `build.json` with every file's SHA-256. Shared by `build` (rows from
//! the group records) and `merge` (rows from the shards).

use crate::integrity::FileSums;
use crate::manifest::{Manifest, MANIFEST_FILE};
use crate::{card, frames, stream, table};
use arrow::array::RecordBatch;
use std::path::Path;

#[derive(Debug, thiserror::Error)]
pub enum BuildError {
    /// Bad arguments or unusable output directory (exit 2).
    #[error("{0}")]
    Input(String),
    /// A failure of this program (exit 1).
    #[error("internal error: {0}")]
    Internal(String),
}

pub(crate) fn internal(path: &Path, e: impl std::fmt::Display) -> BuildError {
    BuildError::Internal(format!("{}: {e}", path.display()))
}

/// Receives a dataset's rows, a batch at a time.
pub type RowSink<'a> = dyn FnMut(RecordBatch) -> Result<(), BuildError> + 'a;

/// Feeds every row of a dataset, in scene-index order, to the sink; may be called more
/// than once and must give the same rows each time.
pub type RowSource<'a> = dyn Fn(&mut RowSink) -> Result<(), BuildError> + 'a;

/// Writes the dataset's final files from its rows (in scene-index order, streamed from
/// `rows`): the data Parquet (row group by row group), the eval subset (whole builds; a
/// second pass over the rows picks it), and the card. Memory stays flat in the number of
/// rows but for `stream::SUMMARY_COLUMNS`, which it returns (every row, those columns)
/// with the eval subset's size. Then it writes `build.json` again, now with the SHA-256
/// of every file (`sums`: the groups' specs and media, plus the files written here).
pub fn finalize(
    out: &Path,
    manifest: &Manifest,
    rows: &RowSource,
    mut sums: FileSums,
) -> Result<(RecordBatch, Option<usize>), BuildError> {
    let data_file = table::data_file_name(manifest.shard[0] as usize, manifest.shard[1] as usize);
    let data_path = out.join(&data_file);
    // Rendered rows carry their frames' images (`frames::embed`), read from `out`.
    let group_rows = table::row_group_size(manifest.render);
    let source = rows;
    let rows = move |sink: &mut RowSink| -> Result<(), BuildError> {
        source(&mut |batch| {
            let batch = frames::embed(&batch, out).map_err(|e| BuildError::Internal(e.into()))?;
            sink(batch)
        })
    };
    let mut data = stream::ParquetStream::create_with(&data_path, group_rows)
        .map_err(|e| BuildError::Internal(e.into()))?;
    let summary_schema = stream::project(
        &RecordBatch::new_empty(std::sync::Arc::new(table::schema())),
        &stream::SUMMARY_COLUMNS,
    )
    .schema();
    let compact = |parts: &[RecordBatch]| {
        arrow::compute::concat_batches(&summary_schema, parts)
            .map_err(|e| BuildError::Internal(e.to_string()))
    };
    let mut summary: Vec<RecordBatch> = Vec::new();
    rows(&mut |batch| {
        data.write(&batch)
            .map_err(|e| BuildError::Internal(e.into()))?;
        summary.push(stream::project(&batch, &stream::SUMMARY_COLUMNS));
        if summary.len() >= 256 {
            summary = vec![compact(&summary)?];
        }
        Ok(())
    })?;
    data.finish().map_err(|e| BuildError::Internal(e.into()))?;
    let data_sum =
        rh_contract::digest::sha256_file(&data_path).map_err(|e| internal(&data_path, e))?;
    sums.insert(data_file.clone(), data_sum);
    let summary = compact(&summary)?;
    let eval = if manifest.is_whole() {
        let (indices, counts) = card::manifest_eval_selection(&summary, manifest);
        let path = out.join(card::EVAL_FILE);
        let mut eval = stream::ParquetStream::create_with(&path, group_rows)
            .map_err(|e| BuildError::Internal(e.into()))?;
        write_streamed(&rows, &indices, &mut eval)?;
        eval.finish().map_err(|e| BuildError::Internal(e.into()))?;
        let sum = rh_contract::digest::sha256_file(&path).map_err(|e| internal(&path, e))?;
        sums.insert(card::EVAL_FILE.to_string(), sum);
        Some(counts)
    } else {
        None
    };
    let credits = match (manifest.render, rh_catalog::Catalog::embedded()) {
        (true, Ok(catalog)) => crate::card_credits::section(
            &catalog,
            &crate::card_credits::drawn_objects(out, &summary),
        ),
        _ => String::new(),
    };
    let readme = card::text(&card::CardInput {
        manifest,
        rows: &summary,
        data_files: std::slice::from_ref(&data_file),
        eval: eval.as_ref(),
        credits: &credits,
    });
    let path = out.join("README.md");
    table::write_atomic(&path, readme.as_bytes()).map_err(|e| internal(&path, e))?;
    sums.insert(
        "README.md".to_string(),
        rh_contract::digest::sha256_hex(readme.as_bytes()),
    );
    let finished = Manifest {
        files: Some(sums),
        ..manifest.clone()
    };
    let path = out.join(MANIFEST_FILE);
    table::write_atomic(&path, finished.to_json().as_bytes()).map_err(|e| internal(&path, e))?;
    Ok((summary, eval.map(|c| c.values().sum())))
}

/// Writes the rows at `indices` (ascending positions in the whole table) of a streamed
/// table to `to`.
fn write_streamed(
    rows: &RowSource,
    indices: &[u32],
    to: &mut stream::ParquetStream,
) -> Result<(), BuildError> {
    let (mut offset, mut next) = (0usize, 0usize);
    rows(&mut |batch| {
        let end = offset + batch.num_rows();
        let local: Vec<u32> = indices[next..]
            .iter()
            .take_while(|&&i| (i as usize) < end)
            .map(|&i| i - offset as u32)
            .collect();
        next += local.len();
        if !local.is_empty() {
            to.write(&table::take_rows(&batch, &local))
                .map_err(|e| BuildError::Internal(e.into()))?;
        }
        offset = end;
        Ok(())
    })
}
