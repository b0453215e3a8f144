//! Which frames a contact sheet shows (`rh-pipeline sheet`): per family, the first valid
//! rendered scene by index, seen from one camera (the model's `ego` view by default) at
//! the observation time where the hazard shows most pixels in that camera, captioned
//! with the object, the ground truth and the time. The drawing is `rh_render::contact_sheet`.

use rh_contract::columns::{col, visible_px_column};
use rh_contract::layout::{frame_path, CAMERAS, FRAME_TIMES};
use rh_dataset::read;
use rh_render::SheetTile;
use std::collections::BTreeMap;
use std::path::Path;

/// One candidate scene row.
struct Row {
    index: u64,
    id: String,
    object: String,
    gt: String,
    visible_px: Vec<u32>,
}

/// The sheet's tiles for `camera`, in the canonical family order. Errors name the file
/// or the camera.
pub fn sheet_tiles(dir: &Path, camera: &str) -> Result<Vec<SheetTile>, String> {
    if !CAMERAS.contains(&camera) {
        return Err(format!(
            "--camera {camera}: not a camera (one of {})",
            CAMERAS.join(", ")
        ));
    }
    let mut first: BTreeMap<String, Row> = BTreeMap::new();
    for file in rh_dataset::table::data_files(dir)? {
        let px_col = visible_px_column(camera);
        let wanted = [
            col::SCENE_ID,
            col::SCENE_INDEX,
            col::FAMILY,
            col::OBJECT_NAME,
            col::GT_ACTION,
            col::VALID,
            px_col.as_str(),
        ];
        for batch in read::open_columns(&file, 1024, |n| wanted.contains(&n))? {
            let batch = batch.map_err(|e| format!("{}: {e}", file.display()))?;
            collect_rows(&batch, &file, &px_col, &mut first)?;
        }
    }
    let mut tiles = Vec::new();
    for family in rh_contract::FAMILIES {
        let Some(row) = first.remove(family) else {
            continue;
        };
        // The time the hazard shows most (the first such time on a tie).
        let best = (0..FRAME_TIMES.len())
            .max_by_key(|&k| (row.visible_px.get(k).copied().unwrap_or(0), usize::MAX - k))
            .unwrap_or(2);
        let t = FRAME_TIMES[best];
        let frame = dir.join(frame_path(&row.id, camera, t));
        if !frame.is_file() {
            continue;
        }
        tiles.push(SheetTile {
            family: family.to_string(),
            scene_id: row.id.clone(),
            frame,
            lines: [
                format!("{family}: {}", row.object.to_lowercase()),
                format!(
                    "gt {}  {camera} t {t:.2} s  {}",
                    row.gt.to_lowercase(),
                    row.id
                ),
            ],
        });
    }
    Ok(tiles)
}

/// Keeps, per family, the valid rendered row with the lowest scene index.
fn collect_rows(
    batch: &arrow::record_batch::RecordBatch,
    file: &Path,
    px_col: &str,
    first: &mut BTreeMap<String, Row>,
) -> Result<(), String> {
    let ids = read::required_strings(batch, file, col::SCENE_ID)?;
    let index = read::u64s(batch, file, col::SCENE_INDEX)?;
    let family = read::required_strings(batch, file, col::FAMILY)?;
    let object = read::required_strings(batch, file, col::OBJECT_NAME)?;
    let gt = read::required_strings(batch, file, col::GT_ACTION)?;
    let valid = read::bools(batch, file, col::VALID)?;
    let px = read::u32_lists(batch, file, px_col)?;
    for i in 0..batch.num_rows() {
        let Some(visible_px) = px[i].clone() else {
            continue; // not rendered
        };
        if !valid[i] || first.get(&family[i]).is_some_and(|r| r.index <= index[i]) {
            continue;
        }
        let row = Row {
            index: index[i],
            id: ids[i].clone(),
            object: object[i].clone(),
            gt: gt[i].clone(),
            visible_px,
        };
        first.insert(family[i].clone(), row);
    }
    Ok(())
}
