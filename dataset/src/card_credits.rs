//! The card's credit of the 3D models a rendered build drew (issue 45): CC-BY asks for
//! attribution. Which models: those of every catalog object in a rendered scene's spec
//! (its own model, or its look-alike's), each once, with name, creator, licence and
//! package as the catalog records them from the package's own catalog.

use arrow::array::{Array, RecordBatch, StringArray};
use rh_catalog::models::{credits, Credit};
use rh_catalog::Catalog;
use std::collections::BTreeSet;
use std::path::Path;

/// The catalog ids of the bodies of the rendered scenes among `rows` (their specs read
/// from `out`). A spec that cannot be read or parsed contributes nothing: the build wrote
/// each one before its row, and `verify` checks them.
pub fn drawn_objects(out: &Path, rows: &RecordBatch) -> BTreeSet<String> {
    let mut ids = BTreeSet::new();
    let (Some(scene), Some(ego)) = (
        rows.column_by_name("scene_id")
            .and_then(|c| c.as_any().downcast_ref::<StringArray>()),
        rows.column_by_name("ego_file_name"),
    ) else {
        return ids;
    };
    for i in (0..rows.num_rows()).filter(|&i| ego.is_valid(i)) {
        let path = out.join(rh_contract::layout::spec_path(scene.value(i)));
        let Ok(text) = std::fs::read_to_string(&path) else {
            continue;
        };
        let Ok(spec) = serde_json::from_str::<serde_json::Value>(&text) else {
            continue;
        };
        for body in spec["bodies"].as_array().into_iter().flatten() {
            if let Some(id) = body["catalog_id"].as_str() {
                ids.insert(id.to_string());
            }
        }
    }
    ids
}

/// The credits section of a rendered build's card ("" when it drew no model).
pub fn section(catalog: &Catalog, objects: &BTreeSet<String>) -> String {
    let list: Vec<Credit> = credits(catalog, objects.iter().map(String::as_str));
    if list.is_empty() {
        return String::new();
    }
    let objects_drawn = objects
        .iter()
        .filter(|id| {
            catalog
                .object(id)
                .is_some_and(|o| rh_catalog::models::drawn_model(catalog, o).is_some())
        })
        .count();
    let plural =
        |n: usize, one: &str, many: &str| format!("{n} {}", if n == 1 { one } else { many });
    let mut s = format!(
        "**3D models.** {} of this build {} drawn with real meshes from Debian's asset \
         packages (the colliders, and so the labels, are the catalog's primitive parts either \
         way). The {} used, with their creators and licences (CC-BY requires this \
         attribution):\n\n| model | creator | licence | package | file |\n|---|---|---|---|---|\n",
        plural(objects_drawn, "catalog object", "catalog objects"),
        if objects_drawn == 1 { "is" } else { "are" },
        plural(list.len(), "model", "models"),
    );
    for c in &list {
        s.push_str(&format!(
            "| {} | {} | {} | `{}` | `{}` |\n",
            c.name, c.creator, c.license, c.package, c.file
        ));
    }
    s.trim_end().to_string()
}
