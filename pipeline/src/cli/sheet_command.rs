//! `rh-pipeline sheet`: the contact sheet of a rendered dataset (feature `render`).

use super::failure::{input, Failure};
#[cfg(feature = "render")]
use super::failure::{print_json, println};
use std::path::Path;

/// `rh-pipeline sheet`: the contact sheet of a rendered dataset.
#[cfg(feature = "render")]
pub fn run(dir: &Path, out: &Path, camera: &str, json: bool) -> Result<(), Failure> {
    if !dir.join("specs").is_dir() {
        return Err(input(format!(
            "{}: not a dataset directory (no specs/)",
            dir.display()
        )));
    }
    let tiles = crate::sheet::sheet_tiles(dir, camera).map_err(input)?;
    if tiles.is_empty() {
        return Err(input(format!(
            "{}: no rendered scenes (no valid scene with {camera} frames; a build without --no-render makes them)",
            dir.display()
        )));
    }
    let title =
        format!(
        "{camera} frames{}: per family the first valid scene, at the time the hazard shows most",
        if camera == "ego" { " - what the model sees" } else { "" }
    );
    let sheet = rh_render::contact_sheet(&title, &tiles).map_err(|e| match e {
        rh_render::RenderError::Io(m) => input(m),
        other => Failure {
            code: 1,
            message: other.to_string(),
        },
    })?;
    rh_contract::fsio::write_file(out, "the contact sheet", &sheet.png)?;
    if json {
        let tiles: Vec<serde_json::Value> = tiles
            .iter()
            .map(|t| {
                let frame = t.frame.strip_prefix(dir).unwrap_or(&t.frame);
                serde_json::json!({
                    "family": t.family,
                    "scene_id": t.scene_id,
                    "frame": frame.display().to_string(),
                    "caption": t.lines,
                })
            })
            .collect();
        print_json(&serde_json::json!({
            "out": out.display().to_string(),
            "camera": camera,
            "width": sheet.width,
            "height": sheet.height,
            "tiles": tiles,
        }))?;
    } else {
        println(&format!(
            "contact sheet of {} families ({camera} frames, {}x{}) written to {}",
            sheet.tiles.len(),
            sheet.width,
            sheet.height,
            out.display()
        ))?;
    }
    Ok(())
}

/// `rh-pipeline sheet` in a program built without the `render` feature.
#[cfg(not(feature = "render"))]
pub fn run(_dir: &Path, _out: &Path, _camera: &str, _json: bool) -> Result<(), Failure> {
    Err(input(
        "`sheet` needs the `render` feature; this rh-pipeline was built without it \
         (cargo build --no-default-features)",
    ))
}
