//! Recognising what a directory without `data/*.parquet` is, so `rh-score` and
//! `rh-score predict` can say what they found and what they need (exit 2) instead of a
//! generic I/O error. The paper's own Hub release is metadata only:
//! `<family>/<family>__dN_vM/{metadata.json, spec.json}`, no Parquet, no frames.

use std::path::Path;

/// What the scorer needs, in words.
const NEEDED: &str = "rh-score needs a dataset built by rh-pipeline: data/*.parquet (one row per \
    scene, with the ground-truth columns) and specs/, plus frames/ for `rh-score predict`. \
    Build one with `rh-pipeline build --n N --out DIR`, or pass a Hub dataset that has them";

/// Scene folders of the paper's metadata-only layout: `<family>/<family>__dN_vM/` holding
/// `metadata.json` or `spec.json`.
pub fn paper_scene_folders(dir: &Path) -> usize {
    let Ok(families) = std::fs::read_dir(dir) else {
        return 0;
    };
    let mut n = 0;
    for fam in families.flatten() {
        let fam_path = fam.path();
        let Some(fam_name) = fam_path
            .file_name()
            .and_then(|s| s.to_str())
            .map(str::to_string)
        else {
            continue;
        };
        let Ok(scenes) = std::fs::read_dir(&fam_path) else {
            continue;
        };
        for scene in scenes.flatten() {
            let p = scene.path();
            let name = p.file_name().and_then(|s| s.to_str()).unwrap_or("");
            if name.starts_with(&format!("{fam_name}__"))
                && (p.join("metadata.json").is_file() || p.join("spec.json").is_file())
            {
                n += 1;
            }
        }
    }
    n
}

/// The message for a dataset directory without `data/*.parquet`.
pub fn missing_parquet_message(dir: &Path) -> String {
    let paper = paper_scene_folders(dir);
    if paper > 0 {
        return format!(
            "{} is the paper's metadata-only layout ({paper} scene folders \
             <family>/<family>__dN_vM/ with metadata.json/spec.json; no Parquet tables, no \
             frames), which cannot be scored or run. {NEEDED}.",
            dir.display()
        );
    }
    let mut found: Vec<String> = std::fs::read_dir(dir)
        .map(|rd| {
            rd.flatten()
                .map(|e| {
                    let name = e.file_name().to_string_lossy().to_string();
                    if e.path().is_dir() {
                        format!("{name}/")
                    } else {
                        name
                    }
                })
                .collect()
        })
        .unwrap_or_default();
    found.sort();
    let shown = if found.is_empty() {
        "nothing".to_string()
    } else if found.len() > 8 {
        format!("{}, … ({} entries)", found[..8].join(", "), found.len())
    } else {
        found.join(", ")
    };
    format!(
        "{} has no data/*.parquet (found: {shown}). {NEEDED}.",
        dir.display()
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn recognises_the_paper_layout() {
        let d = tempfile::tempdir().unwrap();
        let s = d.path().join("object_drop/object_drop__d1_v2");
        std::fs::create_dir_all(&s).unwrap();
        std::fs::write(s.join("metadata.json"), "{}").unwrap();
        let m = missing_parquet_message(d.path());
        assert!(
            m.contains("metadata-only") && m.contains("1 scene folders"),
            "{m}"
        );
        let e = tempfile::tempdir().unwrap();
        std::fs::write(e.path().join("notes.txt"), "x").unwrap();
        let m = missing_parquet_message(e.path());
        assert!(
            m.contains("found: notes.txt") && m.contains("data/*.parquet"),
            "{m}"
        );
    }
}
