//! `rh-score --execute` end to end (specification §12, issue 14) on a label-only build of all 17
//! families: agreement of execution with the labels (oracle plans caught on CATCH scenes
//! and never struck on DODGE scenes; the freeze plan struck exactly where the
//! counterfactual label says `danger_present`), bad plans not executed, the cache,
//! determinism across thread counts, and refusal when a spec does not replay.

use rh_e2e::{bin, run, run_ok};
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;

/// 340 scenes: five groups of four speed bands per family.
fn dataset() -> &'static (tempfile::TempDir, PathBuf) {
    static DS: OnceLock<(tempfile::TempDir, PathBuf)> = OnceLock::new();
    DS.get_or_init(|| {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("ds");
        run_ok(
            "rh-pipeline",
            &[
                "build",
                "--n",
                "340",
                "--seed",
                "14",
                "--no-render",
                "--quiet",
                "--out",
                out.to_str().unwrap(),
            ],
        );
        (dir, out)
    })
}

fn baseline(kind: &str, ds: &Path, out: &Path) {
    let text = run_ok(
        "rh-score",
        &["baseline", kind, "--dataset", ds.to_str().unwrap()],
    );
    std::fs::write(out, text).unwrap();
}

/// Runs `rh-score PREDS --dataset D --execute` and returns (report JSON, decision lines, stdout).
fn execute(
    preds: &Path,
    ds: &Path,
    work: &Path,
    extra: &[&str],
    threads: &str,
) -> (Value, Vec<Value>, String) {
    let json = work.join("r.json");
    let decisions = work.join("d.jsonl");
    let cache = work.join("cache");
    let mut args = vec![
        preds.to_str().unwrap(),
        "--dataset",
        ds.to_str().unwrap(),
        "--execute",
        "--json",
        json.to_str().unwrap(),
        "--decisions",
        decisions.to_str().unwrap(),
        "--exec-cache",
        cache.to_str().unwrap(),
        // Every valid scene of the build, not the eval subset: the figures docs/execution.md
        // quotes are over the whole 340-scene build.
        "--subset",
        "all",
    ];
    args.extend_from_slice(extra);
    let out = Command::new(bin("rh-score"))
        .args(&args)
        .env("RAYON_NUM_THREADS", threads)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "rh-score --execute failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let report: Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let lines = rh_e2e::read_json_lines(&decisions);
    (report, lines, String::from_utf8(out.stdout).unwrap())
}

/// (scene_id → row) of the dataset's labels, via the scorer's own JSON decisions.
fn outcome(d: &Value) -> &str {
    d["execution"]["outcome"].as_str().unwrap_or("not_executed")
}

fn labels(ds: &Path) -> std::collections::BTreeMap<String, (String, bool)> {
    let script = format!(
        "import pyarrow.parquet as pq, json\nt = pq.read_table('{}/data').to_pylist()\nprint(json.dumps({{r['scene_id']: [r['gt_action'], r['danger_present'], r['valid']] for r in t}}))",
        ds.display()
    );
    let v: Value = serde_json::from_str(&rh_e2e::python(&script)).unwrap();
    v.as_object()
        .unwrap()
        .iter()
        .filter(|(_, r)| r[2].as_bool().unwrap())
        .map(|(k, r)| {
            (
                k.clone(),
                (r[0].as_str().unwrap().to_string(), r[1].as_bool().unwrap()),
            )
        })
        .collect()
}

// Issue 14's acceptance targets, asserted as written. Measured on this 340-scene build with
// label rule v4 and executor exec-4: oracle CATCH caught 69/72 (96%), oracle DODGE struck
// 0/162 (174/186 and 0/464 on `--n 1020 --seed 123`). (Rule v3 labelled balls rolling to the feet and knee-high throws no step could
// reach in time CATCH: 58/146; see docs/execution.md, "How the labels got there".)
#[test]
fn oracle_plans_catch_and_never_get_struck_dodging() {
    let (_tmp, ds) = dataset();
    let work = tempfile::tempdir().unwrap();
    let preds = work.path().join("oracle.jsonl");
    baseline("oracle", ds, &preds);
    let (report, lines, stdout) = execute(&preds, ds, work.path(), &[], "2");
    let labels = labels(ds);
    let (mut catch, mut caught, mut dodge, mut dodge_struck) = (0, 0, 0, 0);
    for d in &lines {
        let (gt, _) = &labels[d["scene_id"].as_str().unwrap()];
        match gt.as_str() {
            "CATCH" => {
                catch += 1;
                caught += (outcome(d) == "caught") as u32;
            }
            "DODGE" => {
                dodge += 1;
                dodge_struck += (outcome(d) == "struck") as u32;
            }
            _ => {}
        }
    }
    eprintln!(
        "oracle: caught {caught}/{catch} CATCH scenes, struck {dodge_struck}/{dodge} DODGE scenes"
    );
    assert!(
        catch >= 20,
        "too few CATCH scenes ({catch}) for the test to mean anything"
    );
    // Issue #23's target on an unseen seed: >= 95% (measured: 131 of 137, rule v6).
    assert!(
        caught as f64 >= 0.95 * catch as f64,
        "oracle caught only {caught}/{catch}"
    );
    assert_eq!(
        dodge_struck, 0,
        "oracle struck on {dodge_struck}/{dodge} DODGE scenes"
    );
    // Outcome counts per model in the JSON report, disagreements printed.
    let m = &report["execution"]["models"][0];
    assert_eq!(m["model"], "baseline-oracle");
    assert_eq!(m["all"]["caught"].as_u64().unwrap(), caught as u64);
    assert!(stdout.contains("Disagreements with the labels"), "{stdout}");
    // The figure docs/execution.md (and so README.md, tests/tests/docs_truths.rs) and the
    // dataset card state for this build is this measurement.
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let docs = std::fs::read_to_string(root.join("docs/execution.md")).unwrap();
    let card = std::fs::read_to_string(ds.join("README.md")).unwrap();
    for (name, text, marker) in [
        (
            "docs/execution.md",
            &docs,
            "its CATCH plans are `caught` on",
        ),
        ("the dataset card", &card, "rule-v3 CATCH labels,"),
    ] {
        assert_eq!(
            rh_e2e::n_of_m_after(text, marker),
            (caught, catch),
            "{name} states another oracle catch figure than measured ({caught} of {catch}): update it"
        );
    }
}

// Label rule v3 and the executor share one standing body and one strike test, so the
// freeze plan is struck where the label says danger_present (measured on this build:
// see docs/execution.md, "Agreement with the labels"; exec-2 with rule v2 was at 115/132).
#[test]
fn freeze_is_struck_exactly_where_the_label_says_danger() {
    let (_tmp, ds) = dataset();
    let work = tempfile::tempdir().unwrap();
    let preds = work.path().join("freeze.jsonl");
    baseline("freeze", ds, &preds);
    let (report, lines, _) = execute(&preds, ds, work.path(), &["--quiet"], "2");
    let labels = labels(ds);
    let (mut danger, mut danger_struck, mut safe, mut safe_struck) = (0, 0, 0, 0);
    for d in &lines {
        let (_, dp) = labels[d["scene_id"].as_str().unwrap()];
        let struck = outcome(d) == "struck";
        if dp {
            danger += 1;
            danger_struck += struck as u32;
        } else {
            safe += 1;
            safe_struck += struck as u32;
        }
    }
    eprintln!(
        "freeze: struck {danger_struck}/{danger} danger_present, {safe_struck}/{safe} others"
    );
    assert!(danger >= 20 && safe >= 20, "{danger} / {safe} scenes");
    // Harmed on >= 95% of danger_present scenes, and on at most 1% of the others, each
    // listed below as a disagreement (measured under rule v6: 158 of 159, and 1 of 181 —
    // a touch at the harm limit that the label's fixed links and the executor's kinematic
    // ones resolve differently; docs/execution.md. Under rule v5 it was 0 of 181).
    assert!(
        danger_struck as f64 >= 0.95 * danger as f64,
        "struck {danger_struck}/{danger}"
    );
    assert!(
        safe_struck as f64 <= 0.01 * safe as f64,
        "struck {safe_struck}/{safe} safe"
    );
    let a = &report["execution"]["agreement"];
    assert_eq!(a["standing_danger"].as_u64().unwrap(), danger as u64);
    assert_eq!(
        a["standing_danger_struck"].as_u64().unwrap(),
        danger_struck as u64
    );
    // Every disagreement is listed (each is a label bug or an execution bug).
    let listed = report["execution"]["disagreements"].as_array().unwrap();
    assert_eq!(
        listed.len() as u32,
        (danger - danger_struck) + safe_struck,
        "{listed:?}"
    );
}

#[test]
fn pipe_bad_plans_cache_and_thread_count() {
    let (_tmp, ds) = dataset();
    let work = tempfile::tempdir().unwrap();
    let w = work.path();
    let d = ds.to_str().unwrap();
    // The acceptance pipe: baseline | rh-score - --execute --json.
    let json = w.join("pipe.json");
    let status = Command::new("sh")
        .arg("-c")
        .arg(format!(
            "'{}' baseline oracle --dataset '{d}' | '{}' - --dataset '{d}' --subset all --execute --json '{}' --exec-cache '{}' --quiet",
            bin("rh-score").display(),
            bin("rh-score").display(),
            json.display(),
            w.join("pipe-cache").display()
        ))
        .status()
        .unwrap();
    assert!(status.success());
    let r: Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let all = &r["execution"]["models"][0]["all"];
    let sum: u64 = ["caught", "struck", "missed", "clear"]
        .iter()
        .map(|k| all[k].as_u64().unwrap())
        .sum();
    assert!(sum > 100 && sum == all["n"].as_u64().unwrap(), "{all}");

    // Bad and absurd plans are R1 and not executed; nothing panics.
    let scene = labels(ds).keys().next().unwrap().clone();
    let bad = [
        r#"{"walking_cmd": [1e30, 0, 0], "walking_duration": 1, "keyframes": []}"#,
        r#"{"walking_cmd": [0, 0, 0], "walking_duration": 1, "keyframes": [{}]}"#,
        r#"{"walking_cmd": [0, 0, 0], "walking_duration": 1, "keyframes": [[]]}"#,
        r#"{"walking_cmd": [0, 0, 0], "walking_duration": 1, "keyframes": [{"t": 0.2, "left_hand": [1e30, 0, 0], "right_hand": [0.1, 0, 0]}]}"#,
    ];
    let mut text = String::new();
    for (i, p) in bad.iter().enumerate() {
        text += &format!("{{\"scene_id\": \"{scene}\", \"model\": \"bad{i}\", \"plan\": {p}}}\n");
    }
    text += &format!(
        "{{\"scene_id\": \"{scene}\", \"model\": \"nan\", \"response\": \"{{\\\"walking_cmd\\\": [NaN, 0, 0], \\\"keyframes\\\": []}}\"}}\n"
    );
    let preds = w.join("bad.jsonl");
    std::fs::write(&preds, text).unwrap();
    let (report, lines, _) = execute(&preds, ds, w, &["--quiet"], "2");
    assert_eq!(lines.len(), 5);
    for l in &lines {
        assert_eq!(l["rules"][0], "R1", "{l}");
        assert!(l["execution"]["outcome"].is_null(), "{l}");
    }
    assert_eq!(report["execution"]["run"]["not_executed"], 5);
    assert_eq!(report["execution"]["run"]["executed"], 0);

    // Cache: a second run executes nothing and gives the same outcomes; one thread gives
    // the same outcomes and final state hashes as two.
    let preds = w.join("oracle.jsonl");
    baseline("oracle", ds, &preds);
    let first = tempfile::tempdir().unwrap();
    let (r1, l1, _) = execute(&preds, ds, first.path(), &["--quiet"], "2");
    let (r2, l2, _) = execute(&preds, ds, first.path(), &["--quiet"], "2");
    assert!(r1["execution"]["run"]["executed"].as_u64().unwrap() > 100);
    assert_eq!(r2["execution"]["run"]["executed"], 0);
    assert_eq!(
        r2["execution"]["run"]["from_cache"],
        r1["execution"]["run"]["executed"]
    );
    assert_eq!(l1, l2);
    let other = tempfile::tempdir().unwrap();
    let (_, l3, _) = execute(&preds, ds, other.path(), &["--quiet"], "1");
    assert_eq!(l1, l3, "outcomes depend on the thread count");
    assert!(l1.iter().all(|l| l["execution"]["state_hash"]
        .as_str()
        .is_some_and(|h| h.len() == 32)));
}

#[test]
fn a_spec_that_does_not_replay_is_refused() {
    let (_tmp, ds) = dataset();
    let work = tempfile::tempdir().unwrap();
    // A copy of the dataset with one spec's hazard nudged by a micrometre.
    let copy = work.path().join("ds");
    let out = Command::new("cp")
        .arg("-r")
        .arg(ds)
        .arg(&copy)
        .status()
        .unwrap();
    assert!(out.success());
    let scene = labels(ds).keys().next().unwrap().clone();
    let path = copy.join(format!("specs/{scene}.json"));
    let mut spec: Value = serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    let h = spec["hazard"].as_u64().unwrap() as usize;
    let x = spec["bodies"][h]["position"][0].as_f64().unwrap();
    spec["bodies"][h]["position"][0] = serde_json::json!(x + 1e-6);
    std::fs::write(&path, serde_json::to_string_pretty(&spec).unwrap()).unwrap();
    let preds = work.path().join("p.jsonl");
    std::fs::write(
        &preds,
        format!("{{\"scene_id\": \"{scene}\", \"model\": \"m\", \"plan\": {{\"walking_cmd\": [0,0,0], \"keyframes\": []}}}}\n"),
    )
    .unwrap();
    let out = run(
        "rh-score",
        &[
            preds.to_str().unwrap(),
            "--dataset",
            copy.to_str().unwrap(),
            "--execute",
            "--no-exec-cache",
        ],
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains(&scene) && err.contains("refusing"), "{err}");
}
