//! The model-input frames as data: the `<cam>_frames` columns (Hugging Face `datasets`'
//! `Image` feature, a list per camera in `FRAME_TIMES` order) hold the PNG bytes of
//! `frames/<scene_id>/<cam>_t….png` and their relative paths, so
//! `load_dataset(DIR)[0]["ego_frames"]` are the images the prompt carried, from any
//! working directory and in the Hub's viewer.
//!
//! One entry point each way: [`null_columns`] (the rows as the build first writes them,
//! before the files are final) and [`embed`] (at finalize: fills the columns of rendered
//! rows from the files; rows that already hold them — a merge's shards — pass through).
//! Readers that do not need the images leave them out (`read::open_parquet`).

use arrow::array::{
    Array, ArrayRef, BinaryBuilder, ListArray, ListBuilder, RecordBatch, StringBuilder,
    StructBuilder,
};
use arrow::datatypes::{DataType, Field};
use rh_contract::columns::{frames_column, video_column};
use rh_contract::layout::{frame_path, CAMERAS, FRAME_TIMES};
use std::path::Path;
use std::sync::Arc;

/// Rows per Parquet row group in a table whose rows carry images (each about 1 MB with
/// fifteen 1280×720 PNGs): memory stays bounded while the row groups are gathered.
pub const IMAGE_ROW_GROUP_SIZE: usize = 16;

fn image_fields() -> Vec<Field> {
    match rh_contract::arrow_schema::image_type() {
        DataType::Struct(fields) => fields.iter().map(|f| f.as_ref().clone()).collect(),
        _ => unreachable!("an image is a struct"),
    }
}

fn builder() -> ListBuilder<StructBuilder> {
    let fields = image_fields();
    let item = Field::new("item", rh_contract::arrow_schema::image_type(), true);
    ListBuilder::new(StructBuilder::new(
        fields,
        vec![
            Box::new(BinaryBuilder::new()),
            Box::new(StringBuilder::new()),
        ],
    ))
    .with_field(Arc::new(item))
}

/// The `<cam>_frames` columns of `rows` rows, all null (in `CAMERAS` order).
pub fn null_columns(rows: usize) -> Vec<ArrayRef> {
    CAMERAS
        .iter()
        .map(|_| {
            let mut b = builder();
            for _ in 0..rows {
                b.append(false);
            }
            Arc::new(b.finish()) as ArrayRef
        })
        .collect()
}

/// Why the frames of rendered rows could not be embedded.
#[derive(Debug, thiserror::Error)]
pub enum FramesError {
    #[error(transparent)]
    Read(#[from] crate::read::ReadError),
    #[error("the scene table has no column `{0}`")]
    NoColumn(String),
    #[error("column `{0}` is not a list")]
    NotAList(String),
    /// A frame file that cannot be read: `FILE: WHAT`.
    #[error("{}: {source}", .path.display())]
    Frame {
        path: std::path::PathBuf,
        source: std::io::Error,
    },
    /// Arrow refused the rows with their images.
    #[error("{0}")]
    Arrow(String),
}

/// The message, for callers that pass errors on as text.
impl From<FramesError> for String {
    fn from(e: FramesError) -> String {
        e.to_string()
    }
}

/// `batch` with the `<cam>_frames` of every rendered row (its `<cam>_file_name` set)
/// read from the frame files under `dir`; rows whose frames are already there, and rows
/// not rendered, are unchanged.
pub fn embed(batch: &RecordBatch, dir: &Path) -> Result<RecordBatch, FramesError> {
    let table = Path::new("scene table");
    let ids = crate::read::required_strings(batch, table, "scene_id")?;
    let mut columns = batch.columns().to_vec();
    for cam in CAMERAS {
        let name = frames_column(cam);
        let index = batch
            .schema()
            .index_of(&name)
            .map_err(|_| FramesError::NoColumn(name.clone()))?;
        let current = batch
            .column(index)
            .as_any()
            .downcast_ref::<ListArray>()
            .ok_or_else(|| FramesError::NotAList(name.clone()))?;
        let rendered = match batch.column_by_name(&video_column(cam)) {
            Some(_) => crate::read::strings(batch, table, &video_column(cam))?,
            None => vec![None; batch.num_rows()],
        };
        if (0..batch.num_rows()).all(|r| current.is_valid(r) || rendered[r].is_none()) {
            continue;
        }
        let mut b = builder();
        for (r, id) in ids.iter().enumerate() {
            if current.is_valid(r) {
                append_existing(&mut b, current, r);
            } else if rendered[r].is_some() {
                for &t in FRAME_TIMES.iter() {
                    let rel = frame_path(id, cam, t);
                    let bytes =
                        std::fs::read(dir.join(&rel)).map_err(|source| FramesError::Frame {
                            path: dir.join(&rel),
                            source,
                        })?;
                    let s = b.values();
                    s.field_builder::<BinaryBuilder>(0)
                        .expect("bytes")
                        .append_value(&bytes);
                    s.field_builder::<StringBuilder>(1)
                        .expect("path")
                        .append_value(&rel);
                    s.append(true);
                }
                b.append(true);
            } else {
                b.append(false);
            }
        }
        columns[index] = Arc::new(b.finish());
    }
    RecordBatch::try_new(batch.schema(), columns).map_err(|e| FramesError::Arrow(e.to_string()))
}

/// Copies row `r`'s list of images from `from`.
fn append_existing(b: &mut ListBuilder<StructBuilder>, from: &ListArray, r: usize) {
    let images = from.value(r);
    let images = images
        .as_any()
        .downcast_ref::<arrow::array::StructArray>()
        .expect("images are structs");
    let bytes = images
        .column(0)
        .as_any()
        .downcast_ref::<arrow::array::BinaryArray>()
        .expect("bytes are binary");
    let paths = images
        .column(1)
        .as_any()
        .downcast_ref::<arrow::array::StringArray>()
        .expect("paths are strings");
    for i in 0..images.len() {
        let s = b.values();
        let bb = s.field_builder::<BinaryBuilder>(0).expect("bytes");
        if bytes.is_valid(i) {
            bb.append_value(bytes.value(i));
        } else {
            bb.append_null();
        }
        let pb = s.field_builder::<StringBuilder>(1).expect("path");
        if paths.is_valid(i) {
            pb.append_value(paths.value(i));
        } else {
            pb.append_null();
        }
        s.append(true);
    }
    b.append(true);
}
