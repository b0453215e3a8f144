//! A rendered scene's media in the scene table: what the renderer measured (the hazard's
//! visible pixels and unoccluded fraction per camera and observation time, from the
//! instance-id pass) and the segmentation / depth files of `build --masks` — the columns
//! `<cam>_hazard_visible_px`, `<cam>_hazard_unoccluded_fraction`, `<cam>_mask_paths` and
//! `<cam>_depth_paths` (rh-contract `COLUMNS`).
//!
//! One entry point each way: [`measured_columns`] turns scenes into those columns (the
//! dataset writer), [`media_of_row`] reads a row's media back (`verify`, which cannot
//! derive them without rendering), and [`mask_files`] lists the files a row names
//! (`rows::referenced_files`: resume, shard, merge and verify checksum them).
//! No GPU code here: label-only builds write the columns as nulls.

use arrow::array::{
    Array, ArrayRef, Float64Array, Float64Builder, ListArray, ListBuilder, RecordBatch,
    StringArray, StringBuilder, UInt32Array, UInt32Builder,
};
use rh_contract::columns::{
    depth_paths_column, mask_paths_column, unoccluded_column, visible_px_column,
};
use rh_contract::CAMERAS;
use rh_scenes::driver::{HazardVisibility, SceneMedia, SceneResult};
use std::collections::BTreeMap;
use std::sync::Arc;

/// The media columns of `results`, in `COLUMNS` order: visible px per camera, unoccluded
/// fraction per camera, mask paths per camera, depth paths per camera. Null for a scene
/// without media, and the path lists null for one rendered without `--masks`.
pub fn measured_columns(results: &[SceneResult]) -> Vec<ArrayRef> {
    fn media(r: &SceneResult) -> Option<&SceneMedia> {
        r.media.as_ref()
    }
    fn masks(m: &SceneMedia) -> &BTreeMap<String, Vec<String>> {
        &m.masks
    }
    fn depth(m: &SceneMedia) -> &BTreeMap<String, Vec<String>> {
        &m.depth
    }
    let mut columns: Vec<ArrayRef> = Vec::new();
    for cam in CAMERAS {
        let mut b = ListBuilder::new(UInt32Builder::new());
        for r in results {
            match media(r).and_then(|m| m.visibility.get(cam)) {
                Some(v) => {
                    b.values().append_slice(&v.visible_px);
                    b.append(true);
                }
                None => b.append(false),
            }
        }
        columns.push(Arc::new(b.finish()));
    }
    for cam in CAMERAS {
        let mut b = ListBuilder::new(Float64Builder::new());
        for r in results {
            match media(r).and_then(|m| m.visibility.get(cam)) {
                Some(v) => {
                    b.values().append_slice(&v.unoccluded);
                    b.append(true);
                }
                None => b.append(false),
            }
        }
        columns.push(Arc::new(b.finish()));
    }
    type Files = fn(&SceneMedia) -> &BTreeMap<String, Vec<String>>;
    for files in [masks as Files, depth as Files] {
        for cam in CAMERAS {
            let mut b = ListBuilder::new(StringBuilder::new());
            for r in results {
                match media(r).and_then(|m| files(m).get(cam)) {
                    Some(paths) => {
                        for p in paths {
                            b.values().append_value(p);
                        }
                        b.append(true);
                    }
                    None => b.append(false),
                }
            }
            columns.push(Arc::new(b.finish()));
        }
    }
    columns
}

/// The names of the list columns that hold file paths (masks, then depth, per camera).
pub fn path_columns() -> Vec<String> {
    CAMERAS
        .iter()
        .map(|c| mask_paths_column(c))
        .chain(CAMERAS.iter().map(|c| depth_paths_column(c)))
        .collect()
}

/// A list column's entries at `row` (None: the column is absent or the entry null).
fn list_at(batch: &RecordBatch, name: &str, row: usize) -> Option<ArrayRef> {
    let list = batch
        .column_by_name(name)?
        .as_any()
        .downcast_ref::<ListArray>()?;
    (!list.is_null(row)).then(|| list.value(row))
}

fn strings_at(batch: &RecordBatch, name: &str, row: usize) -> Option<Vec<String>> {
    let values = list_at(batch, name, row)?;
    let s = values.as_any().downcast_ref::<StringArray>()?;
    Some((0..s.len()).map(|i| s.value(i).to_string()).collect())
}

/// The mask and depth files row `row` names (`<cam>_mask_paths`, `<cam>_depth_paths`),
/// in column order; empty when it has none (or the columns are not in `batch`).
pub fn mask_files(batch: &RecordBatch, row: usize) -> Vec<String> {
    path_columns()
        .iter()
        .flat_map(|c| strings_at(batch, c, row).unwrap_or_default())
        .collect()
}

/// Row `row`'s media as the build recorded it (`None`: not rendered): video paths, the
/// measured visibility, and the mask/depth files.
pub fn media_of_row(batch: &RecordBatch, row: usize) -> Option<SceneMedia> {
    let full_event =
        crate::table::optional_string_column(batch, "full_event_file_name")[row].clone()?;
    let mut media = SceneMedia {
        videos: BTreeMap::new(),
        full_event,
        visibility: BTreeMap::new(),
        masks: BTreeMap::new(),
        depth: BTreeMap::new(),
    };
    for cam in CAMERAS {
        let col = rh_contract::columns::video_column(cam);
        if let Some(v) = crate::table::optional_string_column(batch, &col)[row].clone() {
            media.videos.insert(cam.to_string(), v);
        }
        let px = list_at(batch, &visible_px_column(cam), row);
        let fr = list_at(batch, &unoccluded_column(cam), row);
        if let (Some(px), Some(fr)) = (px, fr) {
            let px = px.as_any().downcast_ref::<UInt32Array>()?;
            let fr = fr.as_any().downcast_ref::<Float64Array>()?;
            media.visibility.insert(
                cam.to_string(),
                HazardVisibility {
                    visible_px: px.values().to_vec(),
                    unoccluded: fr.values().to_vec(),
                },
            );
        }
        if let Some(m) = strings_at(batch, &mask_paths_column(cam), row) {
            media.masks.insert(cam.to_string(), m);
        }
        if let Some(d) = strings_at(batch, &depth_paths_column(cam), row) {
            media.depth.insert(cam.to_string(), d);
        }
    }
    Some(media)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fractions_are_visible_over_covered_and_zero_when_nothing_is_covered() {
        let v = HazardVisibility::from_counts(&[(50, 100), (0, 0), (7, 7), (0, 40)]);
        assert_eq!(v.visible_px, vec![50, 0, 7, 0]);
        assert_eq!(v.unoccluded, vec![0.5, 0.0, 1.0, 0.0]);
    }
}
