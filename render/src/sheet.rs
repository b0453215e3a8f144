//! The contact sheet (`rh-pipeline sheet`): frames tiled with their captions. Which
//! scene, camera and time each tile shows is the caller's choice (`rh-pipeline sheet`
//! picks one ego frame per family, with the object and the ground truth, from the scene
//! table); this module only draws.

use super::font;
use super::RenderError;
use std::path::PathBuf;

/// One tile of a contact sheet: a frame and two caption lines.
#[derive(Debug, Clone, PartialEq)]
pub struct SheetTile {
    pub family: String,
    pub scene_id: String,
    /// The frame (a PNG written by a build).
    pub frame: PathBuf,
    /// Caption lines drawn above the frame (lowercase letters, digits, `_ - . / :`
    /// and spaces; longer lines are cut to the tile's width).
    pub lines: [String; 2],
}

/// What `contact_sheet` drew: the PNG's bytes (the caller writes them, through the one
/// atomic writer) and its tiles.
#[derive(Debug, Clone, PartialEq)]
pub struct ContactSheet {
    /// Family and scene id per tile, in tile order.
    pub tiles: Vec<(String, String)>,
    pub width: u32,
    pub height: u32,
    pub png: Vec<u8>,
}

/// Tile size (16:9, as the frames) and the caption font's scale.
const TILE_W: u32 = 448;
const TILE_H: u32 = 252;
const SCALE: u32 = 2;

/// Draws `tiles` in rows of 3 to 5 under a title line, each frame with its caption, as a
/// PNG.
pub fn contact_sheet(title: &str, tiles: &[SheetTile]) -> Result<ContactSheet, RenderError> {
    if tiles.is_empty() {
        return Err(RenderError::Io(
            "nothing to draw (no rendered scene with frames)".into(),
        ));
    }
    let line_h = font::ROWS * SCALE + 4;
    let (title_h, caption_h) = (line_h + 8, 2 * line_h + 6);
    let n = tiles.len() as u32;
    let cols = sheet_columns(n);
    let rows = n.div_ceil(cols);
    let (w, h) = (cols * TILE_W, title_h + rows * (TILE_H + caption_h));
    let mut sheet = image::RgbImage::from_pixel(w, h, image::Rgb([24, 24, 28]));
    font::draw_text(
        &mut sheet,
        8,
        6,
        &fit(title, w - 16),
        SCALE,
        [255, 255, 255],
    );
    for (i, tile) in tiles.iter().enumerate() {
        let img = image::open(&tile.frame)
            .map_err(|e| RenderError::Io(format!("{}: {e}", tile.frame.display())))?
            .to_rgb8();
        let frame =
            image::imageops::resize(&img, TILE_W, TILE_H, image::imageops::FilterType::Triangle);
        // A short last row is centred rather than leaving empty tiles at its end.
        let (row, col) = (i as u32 / cols, i as u32 % cols);
        let in_row = if row + 1 == rows {
            n - row * cols
        } else {
            cols
        };
        let x = col * TILE_W + (cols - in_row) * TILE_W / 2;
        let y = title_h + row * (TILE_H + caption_h);
        image::imageops::replace(&mut sheet, &frame, x as i64, (y + caption_h) as i64);
        let colours = [[235, 235, 235], [190, 200, 215]];
        for (k, line) in tile.lines.iter().enumerate() {
            let ty = y + 3 + k as u32 * line_h;
            font::draw_text(
                &mut sheet,
                x + 6,
                ty,
                &fit(line, TILE_W - 12),
                SCALE,
                colours[k],
            );
        }
    }
    let mut png = Vec::new();
    image::DynamicImage::ImageRgb8(sheet)
        .write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
        .map_err(|e| RenderError::Io(format!("encoding the contact sheet: {e}")))?;
    Ok(ContactSheet {
        tiles: tiles
            .iter()
            .map(|t| (t.family.clone(), t.scene_id.clone()))
            .collect(),
        width: w,
        height: h,
        png,
    })
}

/// `text` cut to what fits in `width` pixels of the caption font (".." marks a cut).
fn fit(text: &str, width: u32) -> String {
    let max = (width / (6 * SCALE)) as usize;
    if text.chars().count() <= max {
        return text.to_string();
    }
    let mut cut: String = text.chars().take(max.saturating_sub(2)).collect();
    cut.push_str("..");
    cut
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
    fn captions_are_cut_to_the_tile() {
        assert_eq!(fit("ego t 0.30 s", 400), "ego t 0.30 s");
        let long = "a".repeat(60);
        let cut = fit(&long, TILE_W - 12);
        assert_eq!(cut.chars().count() as u32, (TILE_W - 12) / 12);
        assert!(cut.ends_with(".."));
    }

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
