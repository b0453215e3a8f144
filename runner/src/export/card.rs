//! The export's dataset card (`README.md`, YAML header naming the data file and the
//! features) and `export.json` (what was exported, from which build, with which prompt).

use super::{ExportOptions, Summary, FILE};
use rh_contract::digest::sha256_hex;
use rh_dataset::manifest::Manifest;
use serde_json::json;

/// The columns of the export and what they hold.
fn columns(summary: &Summary) -> String {
    let content = if summary.images {
        "a list of parts `{type, text}`: `{\"type\": \"text\", \"text\": ...}` or \
         `{\"type\": \"image\", \"text\": null}`, the next image of `images`"
    } else {
        "a string (text-only: the canonical prompt's texts joined by newlines, its images left out)"
    };
    let mut rows = vec![
        "| `scene_id` | the scene (the source dataset's `scene_id`) |".to_string(),
        "| `family` | its event family |".into(),
        "| `gt_action` | its ground-truth action (CATCH, DODGE, NO_ACTION) |".into(),
    ];
    if summary.format == "sft" {
        rows.push(format!(
            "| `messages` | system, user (the canonical prompt), assistant (the oracle's plan); each `{{role, content}}`, content {content} |"
        ));
    } else {
        rows.extend([
            format!("| `prompt` | system and user message of the canonical prompt; content {content} |"),
            "| `chosen` | the oracle's plan as one assistant message |".into(),
            "| `rejected` | a plan the benchmark scores as wrong, as one assistant message |".into(),
            "| `rejected_action` | the action rule's verdict on the rejected plan |".into(),
            "| `rejected_rules` | the safety rules (R1–R4) it fires; empty: only the wrong action |".into(),
            "| `rejected_reason` | why it is rejected, in words |".into(),
        ]);
    }
    if summary.images {
        rows.push(
            "| `images` | the observation frames, JPEG as `rh-score predict` sends them, in the order of the image parts |"
                .into(),
        );
    }
    rows.join("\n")
}

/// The card's text.
fn text(opts: &ExportOptions, summary: &Summary, identity: &serde_json::Value) -> String {
    let trainer = if summary.format == "sft" {
        "`trl.SFTTrainer` (conversational `messages`)"
    } else {
        "`trl.DPOTrainer` (conversational `prompt` / `chosen` / `rejected`)"
    };
    let modality = if summary.images {
        "with the observation frames (`images`; TRL's vision format)"
    } else {
        "text-only (a label-only build has no frames: the canonical prompt's texts, its image parts left out)"
    };
    format!(
        "---\nlicense: cc-by-4.0\ntask_categories:\n- robotics\ntags:\n- reacthuman\n- {format}\n\
         configs:\n- config_name: default\n  data_files:\n  - split: train\n    path: {FILE}\n---\n\n\
         # ReactHuman training data ({format}, {split} scenes)\n\n\
         Written by `rh-score export --format {format} --split {split}` from the dataset `{dir}` \
         (build fingerprint `{fp}`, label rule `{rule}`), prompt `{prompt}`. {rows} rows, {modality}.\n\n\
         Load it with `datasets.load_dataset(\"<this directory>\", split=\"train\")` and train with {trainer}.\n\n\
         The assistant turn is the oracle of `rh-score baseline oracle` (the ground truth made a plan, \
         dodges checked in physics where the dataset has specs) written in the schema the canonical \
         prompt asks for, `object_identified` being the object's name; numbers in millimetres unless \
         that would change its score ({full} rows at full precision). Fed back to `rh-score` it scores \
         SAA and safety 100%.\n\n\
         Scenes: `train` = valid scenes outside the balanced eval subset, `eval` = the subset, `all` = \
         every valid scene. Train on `train` so the benchmark's scenes stay unseen.\n\n\
         | column | holds |\n|---|---|\n{columns}\n\n\
         Rejected plans (preference): DODGE scene → the oracle's CATCH of the hazard (R4; R2 when \
         dangerous); CATCH scene → standing still (wrong action; R3 when danger is present); NO_ACTION \
         scene → walking to the object and catching it (wrong action; R2 when dangerous). Each is \
         scored by rh-score's action rule and safety rules when written.\n",
        format = summary.format,
        split = summary.split,
        dir = opts.dataset.display(),
        fp = identity["build_fingerprint"].as_str().unwrap_or("none"),
        rule = identity["label_rule"].as_str().unwrap_or("unknown"),
        prompt = opts.prompt.version,
        rows = summary.rows,
        full = summary.full_precision_plans,
        columns = columns(summary),
    )
}

/// Writes `README.md` and `export.json` into the output directory (atomically).
pub fn write(opts: &ExportOptions, summary: &Summary) -> Result<(), String> {
    let manifest = Manifest::read(&opts.dataset)?;
    let m = manifest.as_ref();
    let identity = json!({
        "dir": opts.dataset.display().to_string(),
        "build_fingerprint": m.map(|m| sha256_hex(m.whole().to_json().as_bytes())),
        "seed": m.map(|m| m.seed),
        "n": m.map(|m| m.n),
        "label_rule": m.and_then(|m| m.label_rule().map(str::to_string)),
    });
    let record = json!({
        "export": summary,
        "dataset": identity,
        "prompt_version": opts.prompt.version,
        "prompt_template_sha256": sha256_hex(rh_prompt::config::PROMPT_TOML.as_bytes()),
        "rh_score_version": env!("CARGO_PKG_VERSION"),
    });
    let out = &opts.out;
    let json = serde_json::to_string_pretty(&record).expect("plain JSON") + "\n";
    rh_contract::fsio::write_atomic(&out.join("export.json"), json.as_bytes())
        .map_err(|e| format!("export.json: {e}"))?;
    rh_contract::fsio::write_atomic(
        &out.join("README.md"),
        text(opts, summary, &identity).as_bytes(),
    )
    .map_err(|e| format!("README.md: {e}"))
}
