//! The scenes a prompt is built for: those `rh-score predict --subset S [--limit N]` runs
//! (the Python package's `Dataset.scene_ids` too).

use anyhow::Result;
use rh_grade::dataset::{eval_scene_ids, Dataset, Subset};
use rh_grade::error::InputError;

/// The scene ids to run, in dataset order: valid scenes of the subset, first `limit`.
pub fn select_scenes(ds: &Dataset, subset: Subset, limit: Option<usize>) -> Result<Vec<String>> {
    let eval = match subset {
        Subset::All => None,
        Subset::Eval => Some(eval_scene_ids(&ds.dir)?.ok_or_else(|| {
            InputError(format!(
                "{} has no eval/ subset (a shard, or an old build); use --subset all",
                ds.dir.display()
            ))
        })?),
    };
    let ids: Vec<String> = ds
        .scenes
        .iter()
        .filter(|s| s.valid)
        .filter(|s| eval.as_ref().is_none_or(|e| e.contains(&s.scene_id)))
        .map(|s| s.scene_id.clone())
        .take(limit.unwrap_or(usize::MAX))
        .collect();
    if ids.is_empty() {
        return Err(InputError(format!(
            "{}: no valid scenes to run in the selected subset",
            ds.dir.display()
        ))
        .into());
    }
    Ok(ids)
}
