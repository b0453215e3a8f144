//! Dataset writing (SPEC §8): one Parquet row per scene, `specs/<scene_id>.json`, all
//! written atomically (temporary file, then rename), so no reader sees half a file.

use crate::cameras::CAMERA_NAMES;
use crate::scene::SceneResult;
use crate::validate::VALIDATOR_COLUMNS;
use arrow::array::{
    ArrayRef, BooleanBuilder, FixedSizeListBuilder, Float32Builder, Float64Builder, ListBuilder,
    RecordBatch, StringBuilder, UInt32Builder, UInt64Builder,
};
use arrow::datatypes::{DataType, Field, Schema};
use parquet::arrow::ArrowWriter;
use parquet::basic::Compression;
use parquet::file::properties::WriterProperties;
use rh_catalog::Catalog;
use std::fs;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Rows per Parquet row group: small enough for the Hub's dataset viewer to page.
pub const ROW_GROUP_SIZE: usize = 1000;

/// Writes `bytes` to `path` atomically: a sibling temp file, fsync, then rename.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let dir = path.parent().unwrap_or(Path::new("."));
    fs::create_dir_all(dir)?;
    let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("file");
    let tmp = dir.join(format!(".{name}.{}.tmp", std::process::id()));
    let result = (|| {
        let mut f = fs::File::create(&tmp)?;
        f.write_all(bytes)?;
        f.sync_all()?;
        fs::rename(&tmp, path)
    })();
    if result.is_err() {
        let _ = fs::remove_file(&tmp);
    }
    result
}

pub fn spec_path(scene_id: &str) -> String {
    format!("specs/{scene_id}.json")
}

/// The `data/` file name of shard `i` of `n` (Hugging Face convention).
pub fn data_file_name(i: usize, n: usize) -> String {
    format!("data/test-{i:05}-of-{n:05}.parquet")
}

fn vec3_field(name: &str, nullable: bool) -> Field {
    Field::new(
        name,
        DataType::FixedSizeList(Arc::new(Field::new("item", DataType::Float64, false)), 3),
        nullable,
    )
}

/// The Arrow schema of the scene table, in column order.
pub fn schema() -> Schema {
    let utf8 = |n: &str, nullable: bool| Field::new(n, DataType::Utf8, nullable);
    let mut fields = vec![
        utf8("scene_id", false),
        utf8("group_id", false),
        Field::new("scene_index", DataType::UInt64, false),
        Field::new("seed", DataType::UInt64, false),
        Field::new("attempt", DataType::UInt32, false),
        utf8("family", false),
        utf8("speed_band", false),
        Field::new("speed_sweep", DataType::Boolean, false),
        utf8("speed_parameter", false),
        Field::new("speed_value", DataType::Float64, false),
        utf8("object_id", false),
        utf8("object_name", false),
        utf8("object_category", false),
        utf8("looks_like", true),
        Field::new("adversarial", DataType::Boolean, false),
        Field::new("object_mass_kg", DataType::Float64, false),
        Field::new(
            "hazards",
            DataType::List(Arc::new(Field::new("item", DataType::Utf8, true))),
            false,
        ),
        utf8("room", false),
        utf8("description", true),
        utf8("gt_action", false),
        Field::new("dangerous", DataType::Boolean, false),
        Field::new("danger_present", DataType::Boolean, false),
        Field::new(
            "danger_reasons",
            DataType::List(Arc::new(Field::new("item", DataType::Utf8, true))),
            false,
        ),
        vec3_field("impact_point", true),
        utf8("impact_kind", true),
        Field::new("time_to_impact", DataType::Float64, true),
        Field::new("time_to_floor", DataType::Float64, true),
        Field::new("impact_speed", DataType::Float64, true),
        Field::new("closest_approach", DataType::Float64, false),
        vec3_field("object_start", false),
        vec3_field("observer_pose", false),
        utf8("label_rule", false),
        utf8("state_hash", false),
        Field::new("sim_steps", DataType::UInt32, false),
        Field::new("valid", DataType::Boolean, false),
    ];
    for v in VALIDATOR_COLUMNS {
        fields.push(Field::new(v, DataType::Boolean, false));
    }
    fields.push(utf8("spec_file", false));
    for cam in CAMERA_NAMES {
        fields.push(utf8(&format!("{cam}_file_name"), true));
    }
    fields.push(utf8("full_event_file_name", true));
    fields.push(Field::new(
        "trajectory",
        DataType::List(Arc::new(Field::new(
            "item",
            DataType::FixedSizeList(Arc::new(Field::new("item", DataType::Float32, false)), 4),
            true,
        ))),
        false,
    ));
    Schema::new(fields)
}

/// Builds the record batch of scene rows (in the order given).
pub fn record_batch(results: &[SceneResult], catalog: &Catalog) -> RecordBatch {
    let n = results.len();
    macro_rules! strings {
        ($f:expr) => {{
            let mut b = StringBuilder::with_capacity(n, n * 8);
            for r in results {
                b.append_option($f(r));
            }
            Arc::new(b.finish()) as ArrayRef
        }};
    }
    macro_rules! prim {
        ($builder:ty, $f:expr) => {{
            let mut b = <$builder>::with_capacity(n);
            for r in results {
                b.append_option($f(r));
            }
            Arc::new(b.finish()) as ArrayRef
        }};
    }
    let bools = |f: &dyn Fn(&SceneResult) -> bool| {
        let mut b = BooleanBuilder::with_capacity(n);
        for r in results {
            b.append_value(f(r));
        }
        Arc::new(b.finish()) as ArrayRef
    };
    let vec3s = |f: &dyn Fn(&SceneResult) -> Option<[f64; 3]>| {
        let mut b = FixedSizeListBuilder::new(Float64Builder::new(), 3).with_field(Field::new(
            "item",
            DataType::Float64,
            false,
        ));
        for r in results {
            match f(r) {
                Some(v) => {
                    b.values().append_slice(&v);
                    b.append(true);
                }
                None => {
                    b.values().append_slice(&[0.0; 3]);
                    b.append(false);
                }
            }
        }
        Arc::new(b.finish()) as ArrayRef
    };
    let string_lists = |f: &dyn Fn(&SceneResult) -> Vec<String>| {
        let mut b = ListBuilder::new(StringBuilder::new());
        for r in results {
            for s in f(r) {
                b.values().append_value(s);
            }
            b.append(true);
        }
        Arc::new(b.finish()) as ArrayRef
    };
    let object = |r: &SceneResult| {
        catalog
            .object(&r.spec.selection.object_id)
            .expect("objects come from the catalog")
    };

    let mut columns: Vec<ArrayRef> = vec![
        strings!(|r: &SceneResult| Some(r.spec.scene_id.clone())),
        strings!(|r: &SceneResult| Some(r.spec.group_id.clone())),
        prim!(UInt64Builder, |r: &SceneResult| Some(r.spec.scene_index)),
        prim!(UInt64Builder, |r: &SceneResult| Some(r.spec.seed)),
        prim!(UInt32Builder, |r: &SceneResult| Some(r.spec.attempt)),
        strings!(|r: &SceneResult| Some(r.spec.family.clone())),
        strings!(|r: &SceneResult| Some(r.spec.speed_band.name().to_string())),
        bools(&|r| r.spec.speed_sweep),
        strings!(|r: &SceneResult| Some(r.spec.speed_parameter.clone())),
        prim!(Float64Builder, |r: &SceneResult| Some(r.spec.speed_value)),
        strings!(|r: &SceneResult| Some(object(r).id.clone())),
        strings!(|r: &SceneResult| Some(object(r).name.clone())),
        strings!(|r: &SceneResult| Some(object(r).category.clone())),
        strings!(|r: &SceneResult| object(r).looks_like.clone()),
        bools(&|r| object(r).is_adversarial()),
        prim!(Float64Builder, |r: &SceneResult| Some(
            r.spec.hazard_body().mass
        )),
        string_lists(&|r| r.spec.hazard_flags.clone()),
        strings!(|r: &SceneResult| Some(r.spec.room.id.clone())),
        strings!(|r: &SceneResult| r.spec.selection.description.clone()),
        strings!(|r: &SceneResult| Some(r.labels.gt_action.name().to_string())),
        bools(&|r| r.labels.dangerous),
        bools(&|r| r.labels.danger_present),
        string_lists(&|r| r.labels.danger_reasons.clone()),
        vec3s(&|r| r.labels.impact_point),
        strings!(|r: &SceneResult| r.labels.impact_kind.map(|k| match k {
            crate::label::ImpactKind::ReachPlane => "reach_plane".to_string(),
            crate::label::ImpactKind::ClosestApproach => "closest_approach".to_string(),
        })),
        prim!(Float64Builder, |r: &SceneResult| r.labels.time_to_impact),
        prim!(Float64Builder, |r: &SceneResult| r.labels.time_to_floor),
        prim!(Float64Builder, |r: &SceneResult| r.labels.impact_speed),
        prim!(Float64Builder, |r: &SceneResult| Some(
            r.labels.closest_approach
        )),
        vec3s(&|r| Some(r.spec.hazard_body().position)),
        vec3s(&|r| Some([r.spec.observer.x, r.spec.observer.y, r.spec.observer.yaw])),
        strings!(|r: &SceneResult| Some(r.spec.labels.rule_version.clone())),
        strings!(|r: &SceneResult| Some(r.state_hash.clone())),
        prim!(UInt32Builder, |r: &SceneResult| Some(r.steps)),
        bools(&|r| r.verdicts.all()),
    ];
    for i in 0..VALIDATOR_COLUMNS.len() {
        columns.push(bools(&|r| r.verdicts.as_array()[i]));
    }
    columns.push(strings!(|r: &SceneResult| Some(spec_path(
        &r.spec.scene_id
    ))));
    for _ in CAMERA_NAMES {
        // Rendering is a later stage; without it the video columns stay null.
        columns.push(strings!(|_r: &SceneResult| None::<String>));
    }
    columns.push(strings!(|_r: &SceneResult| None::<String>));
    let mut trajectories = ListBuilder::new(
        FixedSizeListBuilder::new(Float32Builder::new(), 4).with_field(Field::new(
            "item",
            DataType::Float32,
            false,
        )),
    );
    for r in results {
        for p in &r.trajectory {
            trajectories.values().values().append_slice(p);
            trajectories.values().append(true);
        }
        trajectories.append(true);
    }
    columns.push(Arc::new(trajectories.finish()));
    RecordBatch::try_new(Arc::new(schema()), columns).expect("columns match the schema")
}

/// Serialises rows to Parquet bytes (Snappy, fixed row groups, no timestamps: the same
/// rows always give the same bytes).
pub fn parquet_bytes(batch: &RecordBatch) -> Vec<u8> {
    let props = WriterProperties::builder()
        .set_compression(Compression::SNAPPY)
        .set_max_row_group_row_count(Some(ROW_GROUP_SIZE))
        .set_created_by("rh-pipeline".to_string())
        .build();
    let mut bytes = Vec::new();
    {
        let mut writer =
            ArrowWriter::try_new(&mut bytes, batch.schema(), Some(props)).expect("valid schema");
        writer.write(batch).expect("in-memory write");
        writer.close().expect("in-memory close");
    }
    bytes
}

/// Paths of the dataset's Parquet files, in name order.
pub fn data_files(dir: &Path) -> std::io::Result<Vec<PathBuf>> {
    let mut files: Vec<PathBuf> = fs::read_dir(dir.join("data"))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "parquet"))
        .collect();
    files.sort();
    Ok(files)
}

/// The (scene_id, spec_file, state_hash) of every row of a dataset, for `verify`.
pub fn read_hashes(dir: &Path) -> Result<Vec<(String, String, String)>, String> {
    use arrow::array::{Array, StringArray};
    use parquet::arrow::arrow_reader::ParquetRecordBatchReaderBuilder;
    let files =
        data_files(dir).map_err(|e| format!("{}: cannot list data/: {e}", dir.display()))?;
    if files.is_empty() {
        return Err(format!("{}: no data/*.parquet files", dir.display()));
    }
    let mut rows = Vec::new();
    for path in files {
        let file = fs::File::open(&path).map_err(|e| format!("{}: {e}", path.display()))?;
        let reader = ParquetRecordBatchReaderBuilder::try_new(file)
            .and_then(|b| b.build())
            .map_err(|e| format!("{}: not a readable Parquet file: {e}", path.display()))?;
        for batch in reader {
            let batch = batch.map_err(|e| format!("{}: {e}", path.display()))?;
            let column = |name: &str| -> Result<StringArray, String> {
                batch
                    .column_by_name(name)
                    .and_then(|c| c.as_any().downcast_ref::<StringArray>().cloned())
                    .ok_or_else(|| format!("{}: missing string column '{name}'", path.display()))
            };
            let (ids, specs, hashes) = (
                column("scene_id")?,
                column("spec_file")?,
                column("state_hash")?,
            );
            for i in 0..batch.num_rows() {
                if ids.is_null(i) || specs.is_null(i) || hashes.is_null(i) {
                    return Err(format!(
                        "{}: row {i} has a null id, spec_file or state_hash",
                        path.display()
                    ));
                }
                rows.push((
                    ids.value(i).to_string(),
                    specs.value(i).to_string(),
                    hashes.value(i).to_string(),
                ));
            }
        }
    }
    Ok(rows)
}
