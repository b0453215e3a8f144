//! `rh-score baseline KIND`: reference predictions for every scene, on stdout.

use super::output::load_config;
use anyhow::Result;
use rh_grade::baseline::{write_baseline, BaselineKind};
use rh_grade::Dataset;
use std::path::Path;

/// Writes baseline `kind`'s predictions (model name `model`, default `baseline-KIND`) for
/// the dataset to stdout; a reader that went away (`| head`) is not an error.
pub fn run(
    kind: BaselineKind,
    dataset: &Path,
    seed: u64,
    model: Option<String>,
    config: Option<&Path>,
) -> Result<()> {
    let cfg = load_config(config)?;
    let ds = Dataset::load(dataset)?;
    let model = model.unwrap_or_else(|| format!("baseline-{}", kind.name()));
    let stdout = std::io::stdout();
    let mut out = std::io::BufWriter::new(stdout.lock());
    let check: Option<rh_grade::oracle::DodgeCheck> = Some(rh_execute::physics_dodges_of);
    match write_baseline(kind, &ds, seed, &model, &cfg, check, &mut out) {
        Err(e) => {
            let kind = e
                .downcast_ref::<std::io::Error>()
                .map(std::io::Error::kind)
                .or_else(|| {
                    e.downcast_ref::<serde_json::Error>()
                        .and_then(|j| j.io_error_kind())
                });
            match kind {
                Some(std::io::ErrorKind::BrokenPipe) => Ok(()),
                // A full stdout (`> /dev/full`) is an output that cannot be written (exit 3).
                Some(k) => Err(rh_contract::fsio::CannotWrite::new(
                    "",
                    Path::new("stdout"),
                    std::io::Error::new(k, format!("{e}")),
                )
                .into()),
                None => Err(e),
            }
        }
        Ok(()) => Ok(()),
    }
}
