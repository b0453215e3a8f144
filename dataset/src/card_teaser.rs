//! The dataset card's picture of what the model sees: the five ego frames of the build's
//! first valid rendered scene, as images the Hub shows from the repository's own files.

use crate::manifest::Manifest;
use crate::table;
use arrow::array::RecordBatch;
use rh_contract::layout::{frame_path, FRAME_TIMES};

/// Markdown for the teaser: a row of the first valid rendered scene's ego frames with a
/// caption, or a sentence saying that this build has none.
pub fn teaser(rows: &RecordBatch) -> String {
    let ids = table::string_column(rows, "scene_id");
    let index = table::u64_column(rows, "scene_index");
    let family = table::string_column(rows, "family");
    let action = table::string_column(rows, "gt_action");
    let valid = table::bool_column(rows, "valid");
    let video = table::optional_string_column(rows, "ego_file_name");
    let first = (0..rows.num_rows())
        .filter(|&i| valid[i] && video[i].is_some())
        .min_by_key(|&i| index[i]);
    let Some(i) = first else {
        return "This build has no rendered frames (built with `--no-render`); a rendered \
                build shows its first valid scene's five ego frames here."
            .into();
    };
    let images: Vec<String> = FRAME_TIMES
        .iter()
        .map(|&t| {
            format!(
                "![ego view at t = {t:.2} s]({})",
                frame_path(&ids[i], "ego", t)
            )
        })
        .collect();
    format!(
        "{}\n\n*Scene `{}` ({}), the ego frames at t = 0, 0.15, 0.30, 0.45, 0.60 s: what a \
         model is shown before it decides. Ground truth: **{}**.*",
        images.join(" "),
        ids[i],
        family[i],
        action[i]
    )
}

/// The frames' size from the build's `[render]` configuration, as the card's sentence
/// says it; for a label-only build, that it has none.
pub fn frame_size(m: &Manifest) -> String {
    if !m.render {
        return "a label-only build has none; a rendered one writes them as PNG".into();
    }
    let dim = |k: &str| {
        m.config
            .pointer(&format!("/render/{k}"))
            .and_then(|v| v.as_u64())
            .unwrap_or(0)
    };
    format!("here {} × {} PNG images", dim("width"), dim("height"))
}

#[cfg(test)]
mod tests {
    use super::*;
    use arrow::array::{BooleanArray, StringArray, UInt64Array};
    use std::sync::Arc;

    fn rows(valid: [bool; 2], video: [Option<&str>; 2]) -> RecordBatch {
        RecordBatch::try_from_iter(vec![
            (
                "scene_id",
                Arc::new(StringArray::from(vec!["bbbb0001", "aaaa0000"])) as _,
            ),
            (
                "scene_index",
                Arc::new(UInt64Array::from(vec![1u64, 0])) as _,
            ),
            (
                "family",
                Arc::new(StringArray::from(vec!["door_swing", "object_drop"])) as _,
            ),
            (
                "gt_action",
                Arc::new(StringArray::from(vec!["DODGE", "CATCH"])) as _,
            ),
            ("valid", Arc::new(BooleanArray::from(valid.to_vec())) as _),
            (
                "ego_file_name",
                Arc::new(StringArray::from(video.to_vec())) as _,
            ),
        ])
        .unwrap()
    }

    #[test]
    fn the_teaser_shows_the_first_valid_rendered_scene() {
        let t = teaser(&rows([true, true], [Some("v"), Some("v")]));
        assert!(t.contains("(frames/aaaa0000/ego_t0.000.png)"), "{t}");
        assert!(t.contains("(frames/aaaa0000/ego_t0.600.png)"), "{t}");
        assert!(t.contains("**CATCH**"), "{t}");
        // Scene 0 invalid: scene 1.
        let t = teaser(&rows([true, false], [Some("v"), Some("v")]));
        assert!(t.contains("bbbb0001") && t.contains("**DODGE**"), "{t}");
        // Nothing rendered: no image at all.
        let t = teaser(&rows([true, true], [None, None]));
        assert!(!t.contains("!["), "{t}");
    }
}
