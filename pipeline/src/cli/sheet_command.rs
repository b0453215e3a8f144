//! `rh-pipeline sheet`: the contact sheet of a rendered dataset (feature `render`).

use super::failure::{input, Failure};
#[cfg(feature = "render")]
use super::failure::{print_json, println};
use std::path::Path;

/// `rh-pipeline sheet`: the contact sheet of a rendered dataset.
#[cfg(feature = "render")]
pub fn run(dir: &Path, out: &Path, json: bool) -> Result<(), Failure> {
    if !dir.join("specs").is_dir() {
        return Err(input(format!(
            "{}: not a dataset directory (no specs/)",
            dir.display()
        )));
    }
    let sheet = rh_render::contact_sheet(dir, out).map_err(|e| match e {
        rh_render::RenderError::Io(m) => input(m),
        other => Failure {
            code: 1,
            message: other.to_string(),
        },
    })?;
    if json {
        let tiles: Vec<serde_json::Value> = sheet
            .tiles
            .iter()
            .map(|(family, id)| serde_json::json!({ "family": family, "scene_id": id }))
            .collect();
        print_json(&serde_json::json!({
            "out": out.display().to_string(),
            "width": sheet.width,
            "height": sheet.height,
            "tiles": tiles,
        }))?;
    } else {
        println(&format!(
            "contact sheet of {} families ({}x{}) written to {}",
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
pub fn run(_dir: &Path, _out: &Path, _json: bool) -> Result<(), Failure> {
    Err(input(
        "`sheet` needs the `render` feature; this rh-pipeline was built without it \
         (cargo build --no-default-features)",
    ))
}
