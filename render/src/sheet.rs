//! The contact sheet (`rh-pipeline sheet`): one frame per family, tiled and labelled.

use super::font;
use super::RenderError;
use rh_contract::layout::frame_path;
use rh_physics::spec::SceneSpec;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// What `contact_sheet` drew.
#[derive(Debug, Clone, PartialEq)]
pub struct ContactSheet {
    /// Family and scene id per tile, in tile order.
    pub tiles: Vec<(String, String)>,
    pub width: u32,
    pub height: u32,
}

/// Tiles one frame per family (the close-up frame at t = 0.30 s of the family's first
/// scene by index; the ego frame when there is no close-up) with a label, so a person can
/// eyeball every family at once. Reads `DIR/specs/*.json` and `DIR/frames/`.
pub fn contact_sheet(dataset_dir: &Path, out_png: &Path) -> Result<ContactSheet, RenderError> {
    let specs_dir = dataset_dir.join("specs");
    let entries = std::fs::read_dir(&specs_dir)
        .map_err(|e| RenderError::Io(format!("{}: {e}", specs_dir.display())))?;
    let mut first: BTreeMap<String, (u64, String, PathBuf)> = BTreeMap::new();
    for entry in entries {
        let path = entry.map_err(|e| RenderError::Io(e.to_string()))?.path();
        if path.extension().and_then(|e| e.to_str()) != Some("json") {
            continue;
        }
        let text = std::fs::read_to_string(&path)
            .map_err(|e| RenderError::Io(format!("{}: {e}", path.display())))?;
        let spec = SceneSpec::from_json(&text)
            .map_err(|e| RenderError::Io(format!("{}: {e}", path.display())))?;
        // The close-up frame at 0.30 s, or the ego one when there is no close-up.
        let Some(frame) = ["closeup", "ego"]
            .into_iter()
            .map(|cam| dataset_dir.join(frame_path(&spec.scene_id, cam, 0.30)))
            .find(|p| p.exists())
        else {
            continue;
        };
        let e =
            first
                .entry(spec.family.clone())
                .or_insert((u64::MAX, String::new(), PathBuf::new()));
        if spec.scene_index < e.0 {
            *e = (spec.scene_index, spec.scene_id.clone(), frame);
        }
    }
    if first.is_empty() {
        return Err(RenderError::Io(format!(
            "{}: no rendered scenes (specs with frames/<id>/closeup_t0.300.png)",
            dataset_dir.display()
        )));
    }
    // Canonical family order, then any others.
    let mut order: Vec<String> = rh_contract::FAMILIES
        .iter()
        .filter(|f| first.contains_key(**f))
        .map(|f| f.to_string())
        .collect();
    for f in first.keys() {
        if !order.contains(f) {
            order.push(f.clone());
        }
    }
    // Label strip: 4 px, the 9-row font at scale 2 (descenders included), 4 px.
    let (tw, th, label) = (384u32, 216u32, 8 + 2 * font::ROWS);
    let n = order.len() as u32;
    let cols = sheet_columns(n);
    let rows = n.div_ceil(cols);
    let (w, h) = (cols * tw, rows * (th + label));
    let mut sheet = image::RgbImage::from_pixel(w, h, image::Rgb([24, 24, 28]));
    let mut tiles = Vec::new();
    for (i, family) in order.iter().enumerate() {
        let (_, id, path) = &first[family];
        let img = image::open(path)
            .map_err(|e| RenderError::Io(format!("{}: {e}", path.display())))?
            .to_rgb8();
        let tile = image::imageops::resize(&img, tw, th, image::imageops::FilterType::Triangle);
        // A short last row is centred rather than leaving empty tiles at its end.
        let (row, col) = (i as u32 / cols, i as u32 % cols);
        let in_row = if row + 1 == rows {
            n - row * cols
        } else {
            cols
        };
        let x = col * tw + (cols - in_row) * tw / 2;
        let y = row * (th + label);
        image::imageops::replace(&mut sheet, &tile, x as i64, (y + label) as i64);
        font::draw_text(
            &mut sheet,
            x + 6,
            y + 4,
            &format!("{family} {id}"),
            2,
            [235, 235, 235],
        );
        tiles.push((family.clone(), id.clone()));
    }
    let mut bytes = Vec::new();
    image::DynamicImage::ImageRgb8(sheet)
        .write_to(
            &mut std::io::Cursor::new(&mut bytes),
            image::ImageFormat::Png,
        )
        .map_err(|e| RenderError::Io(format!("{}: {e}", out_png.display())))?;
    rh_contract::fsio::write_atomic(out_png, &bytes)
        .map_err(|e| RenderError::Io(format!("{}: {e}", out_png.display())))?;
    Ok(ContactSheet {
        tiles,
        width: w,
        height: h,
    })
}

/// Columns of a contact sheet of `n` tiles: 3 to 5 (fewer when there are fewer tiles),
/// the count that leaves the fewest empty places in the last row, the most columns on a tie.
fn sheet_columns(n: u32) -> u32 {
    if n <= 3 {
        return n.max(1);
    }
    (3..=5u32)
        .min_by_key(|&c| (n.div_ceil(c) * c - n, u32::MAX - c))
        .unwrap_or(5)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn contact_sheet_columns_leave_the_fewest_gaps() {
        assert_eq!(sheet_columns(1), 1);
        assert_eq!(sheet_columns(2), 2);
        assert_eq!(sheet_columns(15), 5);
        assert_eq!(sheet_columns(16), 4);
        assert_eq!(sheet_columns(17), 3);
        assert_eq!(sheet_columns(10), 5);
    }
}
