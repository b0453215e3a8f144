//! `rh-score export`: a dataset's scenes as fine-tuning data (`rh_runner::export`).

use super::args::ExportArgs;
use super::dataset_arg::resolve_dataset;
use super::output::{load_config, print_out};
use anyhow::Result;
use rh_prompt::PromptConfig;
use rh_runner::export::{run as export, ExportOptions};

/// Writes the export and prints its summary (a line, or JSON with `--json`).
pub fn run(a: ExportArgs) -> Result<()> {
    let opts = ExportOptions {
        dataset: resolve_dataset(a.dataset, a.allow_incomplete)?,
        out: a.out,
        format: a.format,
        split: a.split,
        text_only: a.text_only,
        prompt: PromptConfig::load(None)?,
        config: load_config(a.config.as_deref())?,
        dodge_check: Some(rh_execute::physics_dodges_of),
    };
    let summary = export(&opts)?;
    if a.json {
        print_out(&(serde_json::to_string_pretty(&summary)? + "\n"))?;
    } else {
        print_out(&format!(
            "wrote {} {} rows ({} scenes, {}) to {}\n",
            summary.rows,
            summary.format,
            summary.split,
            if summary.images {
                "with images"
            } else {
                "text-only"
            },
            opts.out.join(&summary.file).display()
        ))?;
        if summary.no_eval_subset && summary.split == "train" {
            rh_contract::note!(
                "rh-score: note: {} has no eval/ subset, so --split train took every valid scene",
                opts.dataset.display()
            );
        }
    }
    Ok(())
}
