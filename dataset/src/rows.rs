//! Scene rows from scene results (specification §8): one Parquet row per scene, in the column
//! order of `rh_contract::COLUMNS`, and the files each row refers to.

use crate::table::{frame_files, optional_string_column, schema, spec_path, string_column};
use arrow::array::{
    ArrayRef, BooleanBuilder, FixedSizeListBuilder, Float32Builder, Float64Builder, ListBuilder,
    RecordBatch, StringBuilder, UInt32Builder, UInt64Builder,
};
use arrow::datatypes::{DataType, Field};
use rh_catalog::Catalog;
use rh_contract::{CAMERAS as CAMERA_NAMES, VALIDATOR_COLUMNS};
use rh_scenes::driver::SceneResult;
use std::sync::Arc;

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
        strings!(|r: &SceneResult| rh_scenes::twins::twin_of(&r.spec)
            .map(|i| rh_physics::seeds::scene_id(r.spec.build_seed, i))),
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
        strings!(|r: &SceneResult| r.labels.impact_kind.map(|k| k.name().to_string())),
        prim!(Float64Builder, |r: &SceneResult| r.labels.time_to_impact),
        prim!(Float64Builder, |r: &SceneResult| r.labels.time_to_floor),
        prim!(Float64Builder, |r: &SceneResult| r.labels.impact_speed),
        prim!(Float64Builder, |r: &SceneResult| Some(
            r.labels.closest_approach
        )),
        prim!(Float64Builder, |r: &SceneResult| r.labels.time_to_reach),
        prim!(Float64Builder, |r: &SceneResult| r.labels.strike_speed),
        prim!(Float64Builder, |r: &SceneResult| r.labels.strike_impulse),
        strings!(|r: &SceneResult| r.labels.harm_region.clone()),
        prim!(Float64Builder, |r: &SceneResult| r.labels.harm_energy),
        prim!(Float64Builder, |r: &SceneResult| r.labels.harm_force),
        prim!(Float64Builder, |r: &SceneResult| r.labels.harm_ratio),
        vec3s(&|r| Some(r.spec.hazard_body().position)),
        vec3s(&|r| Some([r.spec.observer.x, r.spec.observer.y, r.spec.observer.yaw])),
    ];
    columns.extend(crate::camera_columns::columns(results));
    columns.extend([
        strings!(|r: &SceneResult| Some(r.spec.labels.rule_version.clone())),
        strings!(|r: &SceneResult| Some(r.state_hash.clone())),
        strings!(|r: &SceneResult| Some(r.decision_state_hash.clone())),
        prim!(UInt32Builder, |r: &SceneResult| Some(r.steps)),
        bools(&|r| r.verdicts.all()),
    ]);
    for i in 0..VALIDATOR_COLUMNS.len() {
        columns.push(bools(&|r| r.verdicts.as_array()[i]));
    }
    columns.push(strings!(|r: &SceneResult| Some(spec_path(
        &r.spec.scene_id
    ))));
    // Null when the scene was not rendered (`--no-render`, or an invalid scene).
    for cam in CAMERA_NAMES {
        columns.push(strings!(|r: &SceneResult| r
            .media
            .as_ref()
            .and_then(|m| m.videos.get(cam).cloned())));
    }
    columns.push(strings!(|r: &SceneResult| r
        .media
        .as_ref()
        .map(|m| m.full_event.clone())));
    columns.extend(frame_and_trajectory_columns(results));
    columns.extend(crate::media_columns::measured_columns(results));
    // The frames' images are embedded when the build is finished (`frames::embed`).
    columns.extend(crate::frames::null_columns(results.len()));
    RecordBatch::try_new(Arc::new(schema()), columns).expect("columns match the schema")
}

/// The `observation_frame_steps` and `trajectory` columns (lists per scene row).
fn frame_and_trajectory_columns(results: &[SceneResult]) -> [ArrayRef; 2] {
    let mut frame_steps = ListBuilder::new(UInt32Builder::new());
    for r in results {
        frame_steps
            .values()
            .append_slice(&r.spec.observation_frame_steps(r.steps));
        frame_steps.append(true);
    }
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
    [
        Arc::new(frame_steps.finish()),
        Arc::new(trajectories.finish()),
    ]
}

/// Every file a row refers to, relative to the dataset root: its spec, its videos
/// (`<cam>_file_name`, `full_event_file_name`) and, for a rendered scene, its observation
/// frames (`frames/<scene_id>/<cam>_t….png`) and, built with `--masks`, its mask and
/// depth images (`<cam>_mask_paths`, `<cam>_depth_paths`). Row order, then the order above.
pub fn referenced_files(batch: &RecordBatch) -> Vec<String> {
    let ids = string_column(batch, "scene_id");
    let specs = string_column(batch, "spec_file");
    let mut video_columns: Vec<Vec<Option<String>>> = CAMERA_NAMES
        .iter()
        .map(|cam| optional_string_column(batch, &format!("{cam}_file_name")))
        .collect();
    video_columns.push(optional_string_column(batch, "full_event_file_name"));
    let mut files = Vec::new();
    for (row, (id, spec)) in ids.iter().zip(specs).enumerate() {
        files.push(spec);
        let mut rendered = false;
        for column in &video_columns {
            if let Some(v) = &column[row] {
                files.push(v.clone());
                rendered = true;
            }
        }
        if rendered {
            files.extend(frame_files(id));
        }
        files.extend(crate::media_columns::mask_files(batch, row));
    }
    files
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::table::{concat, parquet_bytes, read_batch, take_rows, write_atomic};
    use rh_scenes::config::Config;
    use rh_scenes::driver::produce_group;
    use rh_scenes::selection::plan_group;

    /// Rows written per group and read back concatenate to the same Parquet bytes as the
    /// rows written at once: what makes resumed and merged builds byte-identical.
    #[test]
    fn group_records_concatenate_to_the_same_bytes() {
        let catalog = Catalog::embedded().unwrap();
        let config = Config::embedded().unwrap();
        let families = vec!["object_drop".to_string(), "rolling_ball".to_string()];
        let dir = tempfile::tempdir().unwrap();
        let mut all = Vec::new();
        let mut records = Vec::new();
        for g in 0..2u64 {
            let sel = plan_group(&catalog, &families, 1, g).unwrap();
            let results = produce_group(
                &sel,
                1,
                g * 4,
                if g == 1 { 3 } else { 4 },
                &catalog,
                &config,
            )
            .unwrap();
            let path = dir.path().join(format!("{g}.parquet"));
            write_atomic(&path, &parquet_bytes(&record_batch(&results, &catalog))).unwrap();
            records.push(read_batch(&path).unwrap());
            all.extend(results);
        }
        let direct = parquet_bytes(&record_batch(&all, &catalog));
        let via_records = parquet_bytes(&concat(&records).unwrap());
        assert!(direct == via_records);
        let back = read_batch(&dir.path().join("0.parquet")).unwrap();
        let again = take_rows(&concat(&records).unwrap(), &(0..4).collect::<Vec<_>>());
        assert!(parquet_bytes(&back) == parquet_bytes(&again));
    }
}
