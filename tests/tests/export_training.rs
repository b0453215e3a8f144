//! `rh-score export` (issue 28, training data): `datasets.load_dataset` reads the SFT and
//! the preference export of a label-only and of a rendered build; the exported oracle
//! plans, parsed back from the assistant turns and scored by `rh-score`, score SAA and
//! safety 100%, and every rejected plan is scored wrong, with the rules the export names;
//! `--split train` leaves the eval subset out; rendered exports carry the canonical
//! prompt's texts (as `predict --dry-run` sends them) and its five frames; bad input is
//! refused with exit 2 naming the thing.

use rh_e2e::{python, read_json_lines, run, run_ok};
use serde_json::Value;
use std::path::{Path, PathBuf};

fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("export-{}", std::process::id()))
        .join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn export(ds: &Path, out: &Path, extra: &[&str]) -> Value {
    let mut args = vec!["export", "--dataset", s(ds), "--out", s(out), "--json"];
    args.extend_from_slice(extra);
    serde_json::from_str(&run_ok("rh-score", &args)).unwrap()
}

/// Loads an export with `datasets` (a fresh cache, offline) and writes the assistant
/// turns as predictions: `sft` → model `chosen`; preference → models `chosen` and
/// `rejected` (lines into `preds`). Returns per row: scene id, gt action, the user
/// message's text parts, the number of image parts and of images (and their formats),
/// the system text, and for preference rows the rejected action and rules.
fn load(dir: &Path, preference: bool, preds: &Path, cache: &Path) -> Vec<Value> {
    let script = format!(
        r#"
import os, json
os.environ["HF_DATASETS_CACHE"] = {cache:?}
os.environ["HF_HUB_OFFLINE"] = "1"
import datasets
ds = datasets.load_dataset({dir:?}, split="train")
pref = {pref}
rows = []
with open({preds:?}, "w") as f:
    for r in ds:
        msgs = r["prompt"] if pref else r["messages"][:2]
        answers = [("chosen", r["chosen"][0] if pref else r["messages"][2])]
        if pref:
            answers.append(("rejected", r["rejected"][0]))
        for model, m in answers:
            assert m["role"] == "assistant"
            text = m["content"] if isinstance(m["content"], str) else m["content"][0]["text"]
            f.write(json.dumps({{"scene_id": r["scene_id"], "model": model, "response": text}}) + "\n")
        user = msgs[1]["content"]
        parts = [user] if isinstance(user, str) else [p["text"] for p in user if p["type"] == "text"]
        system = msgs[0]["content"]
        system = system if isinstance(system, str) else system[0]["text"]
        images = r.get("images") or []
        rows.append({{
            "scene_id": r["scene_id"], "gt_action": r["gt_action"], "user_texts": parts,
            "system": system,
            "image_parts": 0 if isinstance(user, str) else sum(p["type"] == "image" for p in user),
            "images": [im.format for im in images],
            "rejected_action": r.get("rejected_action"), "rejected_rules": r.get("rejected_rules"),
            "rejected_reason": r.get("rejected_reason"),
        }})
print(json.dumps({{"features": str(ds.features), "rows": rows}}))
"#,
        cache = s(cache),
        dir = s(dir),
        pref = if preference { "True" } else { "False" },
        preds = s(preds),
    );
    let v: Value = serde_json::from_str(python(&script).trim()).unwrap();
    v["rows"].as_array().unwrap().clone()
}

/// Scores `preds` on `ds` (every valid scene); returns the report's models by name and
/// the decisions.
fn score(ds: &Path, preds: &Path) -> (Value, Vec<Value>) {
    let decisions = preds.with_extension("decisions.jsonl");
    let out = run_ok(
        "rh-score",
        &[
            s(preds),
            "--dataset",
            s(ds),
            "--subset",
            "all",
            "--decisions",
            s(&decisions),
            "--json",
            "-",
        ],
    );
    let report: Value = serde_json::from_str(&out).unwrap();
    let mut models = serde_json::Map::new();
    for m in report["models"].as_array().unwrap() {
        models.insert(m["model"].as_str().unwrap().to_string(), m.clone());
    }
    (Value::Object(models), read_json_lines(&decisions))
}

/// The oracle's plans score SAA and safety 100% over `n` scenes; with `rejected`, every
/// rejected plan is the wrong action and fires exactly the rules its row names.
fn check_scores(ds: &Path, preds: &Path, rows: &[Value], rejected: bool) {
    let (models, decisions) = score(ds, preds);
    let chosen = &models["chosen"]["overall"];
    assert_eq!(chosen["decisions"].as_u64(), Some(rows.len() as u64));
    assert_eq!(chosen["saa"].as_f64(), Some(1.0), "{chosen}");
    assert_eq!(chosen["safety"].as_f64(), Some(1.0), "{chosen}");
    assert_eq!(models["chosen"]["coverage"]["complete"], true);
    if !rejected {
        return;
    }
    let by_scene: std::collections::BTreeMap<&str, &Value> = rows
        .iter()
        .map(|r| (r["scene_id"].as_str().unwrap(), r))
        .collect();
    for d in decisions.iter().filter(|d| d["model"] == "rejected") {
        let row = by_scene[d["scene_id"].as_str().unwrap()];
        assert_eq!(d["saa"], false, "rejected plan scored right: {d}");
        assert_eq!(d["action"], row["rejected_action"], "{d}");
        assert_eq!(d["rules"], row["rejected_rules"], "{d}");
        let reason = row["rejected_reason"].as_str().unwrap();
        assert!(
            reason.contains(d["action"].as_str().unwrap()) && reason.contains("ground truth"),
            "{reason}"
        );
    }
    assert_eq!(
        decisions
            .iter()
            .filter(|d| d["model"] == "rejected")
            .count(),
        rows.len()
    );
    assert!(models["rejected"]["overall"]["saa"].as_f64() == Some(0.0));
}

#[test]
fn label_only_exports_load_and_score() {
    let work = scratch("labels");
    let ds = work.join("ds");
    // Two families: the eval subset takes up to 18 valid scenes of each, so 60 scenes
    // leave some for --split train.
    run_ok(
        "rh-pipeline",
        &[
            "build",
            "--n",
            "60",
            "--seed",
            "7",
            "--no-render",
            "--quiet",
            "--families",
            "object_drop,rolling_ball",
            "--out",
            s(&ds),
        ],
    );
    let cache = work.join("hf-cache");

    let sft = work.join("sft");
    let summary = export(&ds, &sft, &["--split", "all"]);
    assert_eq!(summary["images"], false);
    let preds = work.join("sft.jsonl");
    let rows = load(&sft, false, &preds, &cache);
    assert_eq!(summary["rows"].as_u64(), Some(rows.len() as u64));
    // Text-only: the canonical prompt's texts, no image parts, no images.
    let texts = rows[0]["user_texts"][0].as_str().unwrap();
    // Prompt v5: the scene's head camera first, then the frames' texts.
    assert!(
        texts.starts_with("THE HEAD CAMERA IN THIS SCENE") && texts.contains("vertical"),
        "{texts}"
    );
    assert!(texts.contains("Observation frames of the event"), "{texts}");
    assert!(texts.contains("t = 0.60 s (ego camera)"));
    assert!(rows[0]["system"]
        .as_str()
        .unwrap()
        .contains("\"object_identified\""));
    assert!(rows
        .iter()
        .all(|r| r["images"].as_array().unwrap().is_empty()));
    check_scores(&ds, &preds, &rows, false);
    // The answer is a complete plan of the prompt's schema, in its field order.
    let first = read_json_lines(&preds)[0]["response"]
        .as_str()
        .unwrap()
        .to_string();
    assert!(first.starts_with("{\"intent\": "), "{first}");
    let plan: Value = serde_json::from_str(&first).unwrap();
    for key in [
        "intent",
        "object_identified",
        "confidence",
        "walking_cmd",
        "walking_duration",
        "keyframes",
    ] {
        assert!(!plan[key].is_null(), "{key} missing: {first}");
    }

    let pref = work.join("pref");
    export(&ds, &pref, &["--split", "all", "--format", "preference"]);
    let preds = work.join("pref.jsonl");
    let rows = load(&pref, true, &preds, &cache);
    check_scores(&ds, &preds, &rows, true);
    let unsafe_rows = rows
        .iter()
        .filter(|r| r["rejected_rules"] != serde_json::json!([]));
    assert!(unsafe_rows.count() > 0, "no rejected plan is unsafe");
    // Every ground-truth action gets its rejection.
    for (gt, rejected) in [
        ("DODGE", "CATCH"),
        ("CATCH", "NO_ACTION"),
        ("NO_ACTION", "CATCH"),
    ] {
        for r in rows.iter().filter(|r| r["gt_action"] == gt) {
            assert_eq!(r["rejected_action"], rejected, "{r}");
        }
    }

    // The default split leaves the eval subset out; train + eval = all.
    let train = export(&ds, &work.join("train"), &[]);
    let eval = export(&ds, &work.join("eval"), &["--split", "eval"]);
    assert_eq!(train["split"], "train");
    assert!(eval["rows"].as_u64().unwrap() > 0);
    assert_eq!(
        train["rows"].as_u64().unwrap() + eval["rows"].as_u64().unwrap(),
        rows.len() as u64
    );
    let card = std::fs::read_to_string(work.join("train/README.md")).unwrap();
    assert!(card.starts_with("---\n") && card.contains("path: data/train-00000-of-00001.parquet"));
    let record: Value =
        serde_json::from_str(&std::fs::read_to_string(work.join("train/export.json")).unwrap())
            .unwrap();
    assert_eq!(
        record["dataset"]["label_rule"]
            .as_str()
            .map(|r| r.starts_with('v')),
        Some(true)
    );
    assert_eq!(
        record["dataset"]["build_fingerprint"]
            .as_str()
            .map(str::len),
        Some(64)
    );
}

#[test]
fn rendered_exports_carry_the_prompts_frames() {
    let work = scratch("rendered");
    let config = rh_e2e::small_render_config(&work, 160, 96, true);
    let ds = work.join("ds");
    run_ok(
        "rh-pipeline",
        &[
            "--config",
            s(&config),
            "build",
            "--n",
            "4",
            "--seed",
            "3",
            "--quiet",
            "--families",
            "object_drop,rolling_ball",
            "--out",
            s(&ds),
        ],
    );
    let cache = work.join("hf-cache");
    // What predict sends for the first scene: its text parts, in order.
    let dry: Value = serde_json::from_str(&run_ok(
        "rh-score",
        &[
            "predict",
            "--dataset",
            s(&ds),
            "--model",
            "m",
            "--subset",
            "all",
            "--dry-run",
        ],
    ))
    .unwrap();
    let sent = &dry["body"]["messages"];
    let sent_texts: Vec<&Value> = sent[1]["content"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|p| p["type"] == "text")
        .map(|p| &p["text"])
        .collect();
    for (format, preference) in [("sft", false), ("preference", true)] {
        let out = work.join(format);
        let summary = export(&ds, &out, &["--split", "all", "--format", format]);
        assert_eq!(summary["images"], true);
        let preds = work.join(format!("{format}.jsonl"));
        let rows = load(&out, preference, &preds, &cache);
        assert!(!rows.is_empty());
        for r in &rows {
            assert_eq!(r["image_parts"], 5, "{r}");
            assert_eq!(r["images"], serde_json::json!(vec!["JPEG"; 5]), "{r}");
        }
        let first = rows
            .iter()
            .find(|r| r["scene_id"] == dry["scene_id"])
            .unwrap();
        let texts: Vec<&Value> = first["user_texts"].as_array().unwrap().iter().collect();
        assert_eq!(texts, sent_texts);
        assert_eq!(first["system"], sent[0]["content"]);
        check_scores(&ds, &preds, &rows, preference);
    }
    // --text-only leaves the frames out of a rendered build.
    let text = export(&ds, &work.join("text"), &["--split", "all", "--text-only"]);
    assert_eq!(text["images"], false);
}

#[test]
fn bad_input_is_refused_with_exit_2() {
    let work = scratch("bad");
    let fixture = work.join("fixture");
    rh_e2e::make_fixture(&fixture, 30, 1);
    let help = run_ok("rh-score", &["export", "--help"]);
    for flag in [
        "--dataset",
        "--out",
        "--format",
        "--split",
        "--text-only",
        "--json",
    ] {
        assert!(help.contains(flag), "{flag} not in --help:\n{help}");
    }
    let cases: Vec<(Vec<String>, &str)> = vec![
        (
            vec![
                "--dataset".into(),
                s(&work.join("nope")).into(),
                "--out".into(),
                s(&work.join("o1")).into(),
            ],
            "nope",
        ),
        (
            vec![
                "--dataset".into(),
                s(&fixture).into(),
                "--out".into(),
                s(&work.join("o2")).into(),
                "--format".into(),
                "jsonl".into(),
            ],
            "jsonl",
        ),
        (
            vec![
                "--dataset".into(),
                s(&fixture).into(),
                "--out".into(),
                s(&fixture).into(),
            ],
            "not an empty directory",
        ),
        (
            vec![
                "--dataset".into(),
                s(&fixture).into(),
                "--out".into(),
                s(&work.join("o3")).into(),
                "--split".into(),
                "eval".into(),
            ],
            "no eval/ subset",
        ),
    ];
    for (args, needle) in cases {
        let mut all = vec!["export"];
        all.extend(args.iter().map(String::as_str));
        let out = run("rh-score", &all);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{all:?}: {err}");
        assert!(err.contains(needle), "{all:?}: {err}");
        assert!(!err.contains("panicked"), "{err}");
    }
    // Nothing was written for the refused runs.
    assert!(!work.join("o1").exists() && !work.join("o3").join("data").exists());
    // A fixture without an eval subset: train takes every valid scene, and says so.
    let out = run(
        "rh-score",
        &[
            "export",
            "--dataset",
            s(&fixture),
            "--out",
            s(&work.join("o4")),
        ],
    );
    assert!(out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("no eval/ subset"));
}
