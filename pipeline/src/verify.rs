//! `rh-pipeline verify DIR`: replays every spec and compares its per-step state hash
//! with the one stored in the dataset.

use crate::dataset;
use crate::simulate::{simulate, SimOptions};
use crate::spec::SceneSpec;
use rayon::prelude::*;
use serde::Serialize;
use std::path::Path;

#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct Mismatch {
    pub scene_id: String,
    pub problem: String,
}

#[derive(Debug, Clone, Serialize)]
pub struct VerifyReport {
    pub scenes: usize,
    pub matched: usize,
    pub mismatches: Vec<Mismatch>,
}

impl VerifyReport {
    pub fn ok(&self) -> bool {
        self.mismatches.is_empty()
    }
}

/// Replays every scene of the dataset in `dir`. Err only when the dataset itself cannot be read.
pub fn verify(dir: &Path) -> Result<VerifyReport, String> {
    let rows = dataset::read_hashes(dir)?;
    let mut mismatches: Vec<Mismatch> = rows
        .par_iter()
        .filter_map(|(scene_id, spec_file, stored)| {
            let path = dir.join(spec_file);
            let problem = match std::fs::read_to_string(&path) {
                Err(e) => Some(format!("cannot read {}: {e}", path.display())),
                Ok(text) => match SceneSpec::from_json(&text) {
                    Err(e) => Some(format!("{}: invalid spec: {e}", path.display())),
                    Ok(spec) if &spec.scene_id != scene_id => Some(format!(
                        "{} holds scene '{}'",
                        path.display(),
                        spec.scene_id
                    )),
                    Ok(spec) => {
                        let replayed = simulate(&spec, SimOptions::default()).state_hash;
                        (replayed != *stored)
                            .then(|| format!("state hash {replayed} differs from stored {stored}"))
                    }
                },
            };
            problem.map(|problem| Mismatch {
                scene_id: scene_id.clone(),
                problem,
            })
        })
        .collect();
    mismatches.sort_by(|a, b| a.scene_id.cmp(&b.scene_id));
    Ok(VerifyReport {
        scenes: rows.len(),
        matched: rows.len() - mismatches.len(),
        mismatches,
    })
}
