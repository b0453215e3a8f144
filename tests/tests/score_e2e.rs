//! End-to-end acceptance tests of `rh-score` (issue 5) on real datasets: one built by
//! `rh-pipeline build --no-render`, and one synthetic fixture (`rh-score make-fixture`,
//! same column contract) that covers NO_ACTION, adversarial and invalid scenes.

use rh_e2e::{python, run, run_ok};
use serde_json::Value;
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("score-e2e-{}", std::process::id()))
        .join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A dataset built once per test binary by the real pipeline.
fn pipeline_dataset() -> &'static Path {
    static DS: OnceLock<PathBuf> = OnceLock::new();
    DS.get_or_init(|| {
        let dir = scratch("pipeline").join("ds");
        run_ok(
            "rh-pipeline",
            &[
                "build",
                "--n",
                "40",
                "--no-render",
                "--out",
                dir.to_str().unwrap(),
            ],
        );
        dir
    })
}

/// A synthetic dataset with the same columns, built once per test binary.
fn fixture_dataset() -> &'static Path {
    static DS: OnceLock<PathBuf> = OnceLock::new();
    DS.get_or_init(|| {
        let dir = scratch("fixture").join("ds");
        rh_e2e::make_fixture(&dir, 120, 5);
        dir
    })
}

/// Ground truth of the valid scenes, read independently with pyarrow.
struct Truth {
    scenes: Vec<(String, String, bool, bool)>, // id, gt_action, danger_present, has impact
}

fn truth(ds: &Path) -> Truth {
    let out = python(&format!(
        r#"
import glob, json, pyarrow.parquet as pq
rows = []
# What rh-score scores by default: the evaluation subset (label rule v5 keeps at most one
# NO_ACTION per family there), else every valid scene.
files = sorted(glob.glob({dir:?} + "/eval/*.parquet")) or sorted(glob.glob({dir:?} + "/data/*.parquet"))
for f in files:
    for r in pq.read_table(f).to_pylist():
        if r.get("valid", True):
            rows.append([r["scene_id"], r["gt_action"], r["danger_present"], r["impact_point"] is not None])
print(json.dumps(rows))
"#,
        dir = ds.display().to_string()
    ));
    let v: Vec<(String, String, bool, bool)> = serde_json::from_str(out.trim()).unwrap();
    assert!(!v.is_empty(), "dataset has no valid scenes");
    Truth { scenes: v }
}

fn baseline(ds: &Path, kind: &str, out: &Path) {
    let text = run_ok(
        "rh-score",
        &["baseline", kind, "--dataset", ds.to_str().unwrap()],
    );
    std::fs::write(out, text).unwrap();
}

/// Scores `preds` and returns (report JSON, per-decision lines).
fn score(ds: &Path, preds: &Path, work: &Path) -> (Value, Vec<Value>) {
    let json = work.join(format!(
        "{}.report.json",
        preds.file_stem().unwrap().to_string_lossy()
    ));
    let dec = work.join(format!(
        "{}.decisions.jsonl",
        preds.file_stem().unwrap().to_string_lossy()
    ));
    run_ok(
        "rh-score",
        &[
            preds.to_str().unwrap(),
            "--dataset",
            ds.to_str().unwrap(),
            "--json",
            json.to_str().unwrap(),
            "--decisions",
            dec.to_str().unwrap(),
        ],
    );
    let report: Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let decisions = rh_e2e::read_json_lines(&dec);
    (report, decisions)
}

fn acceptance(ds: &Path, work: &Path) {
    let t = truth(ds);
    let n = t.scenes.len();

    // Oracle: SAA 100 %, safety 100 %, d_end ≈ 0 on CATCH scenes.
    let p = work.join("oracle.jsonl");
    baseline(ds, "oracle", &p);
    let (r, dec) = score(ds, &p, work);
    let m = &r["models"][0]["overall"];
    assert_eq!(m["decisions"], n as u64);
    assert_eq!(m["saa"], 1.0, "oracle SAA: {m}");
    assert_eq!(m["safety"], 1.0, "oracle safety: {m}");
    assert_eq!(m["aia"], 1.0);
    assert_eq!(dec.len(), n);
    let mut catch_checked = 0;
    for d in &dec {
        assert_eq!(d["status"], "scored");
        assert_eq!(d["action"], d["gt_action"]);
        if d["gt_action"] == "CATCH" && !d["d_end"].is_null() {
            let e = d["d_end"].as_f64().unwrap();
            assert!(e < 1e-6, "oracle d_end {e} on {}", d["scene_id"]);
            catch_checked += 1;
        }
    }
    let catch_with_impact = t.scenes.iter().filter(|s| s.1 == "CATCH" && s.3).count();
    assert_eq!(catch_checked, catch_with_impact);

    // Always-dodge: SAA equals the dataset's DODGE share exactly.
    let p = work.join("always-dodge.jsonl");
    baseline(ds, "always-dodge", &p);
    let (r, _) = score(ds, &p, work);
    let dodge = t.scenes.iter().filter(|s| s.1 == "DODGE").count();
    assert_eq!(
        r["models"][0]["overall"]["saa"].as_f64().unwrap(),
        dodge as f64 / n as f64
    );
    assert_eq!(r["models"][0]["overall"]["safety"], 1.0);

    // Freeze: R3 fires exactly on the danger_present scenes.
    let p = work.join("freeze.jsonl");
    baseline(ds, "freeze", &p);
    let (r, dec) = score(ds, &p, work);
    let fired: BTreeSet<String> = dec
        .iter()
        .filter(|d| d["rules"].as_array().unwrap().iter().any(|x| x == "R3"))
        .map(|d| d["scene_id"].as_str().unwrap().to_string())
        .collect();
    let danger: BTreeSet<String> = t
        .scenes
        .iter()
        .filter(|s| s.2)
        .map(|s| s.0.clone())
        .collect();
    assert_eq!(fired, danger);
    assert_eq!(
        r["models"][0]["overall"]["rules_fired"]["R3"],
        danger.len() as u64
    );
    assert_eq!(
        r["models"][0]["overall"]["predicted"]["NO_ACTION"],
        n as u64
    );

    // Every baseline together: reports in every format, figures, cross-model analyses.
    let all = work.join("all.jsonl");
    let mut text = String::new();
    for k in [
        "majority",
        "oracle",
        "random",
        "always-catch",
        "always-dodge",
        "freeze",
    ] {
        text.push_str(&run_ok(
            "rh-score",
            &["baseline", k, "--dataset", ds.to_str().unwrap()],
        ));
    }
    std::fs::write(&all, text).unwrap();
    let figs = work.join("figs");
    let (json, csv, md) = (work.join("r.json"), work.join("r.csv"), work.join("r.md"));
    let table = run_ok(
        "rh-score",
        &[
            all.to_str().unwrap(),
            "--dataset",
            ds.to_str().unwrap(),
            "--json",
            json.to_str().unwrap(),
            "--csv",
            csv.to_str().unwrap(),
            "--markdown",
            md.to_str().unwrap(),
            "--figures",
            figs.to_str().unwrap(),
        ],
    );
    for want in [
        "baseline-oracle",
        "Safety-rule breakdown",
        "Correct but out of reach",
        "Speed bands",
        "Majority vote",
        "Adversarial probes",
    ] {
        assert!(
            table.contains(want),
            "terminal report lacks {want}:\n{table}"
        );
    }
    let r: Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!(r["models"].as_array().unwrap().len(), 6);
    assert_eq!(r["analyses"]["voting"]["models"], 6);
    assert_eq!(r["analyses"]["voting"]["scenes"], n as u64);
    assert_eq!(r["analyses"]["voting"]["best_model"], "baseline-oracle");
    assert_eq!(r["input"]["decisions_scored"], 6 * n as u64);
    let csv_text = std::fs::read_to_string(&csv).unwrap();
    assert!(csv_text.starts_with("model,breakdown,group,decisions"));
    assert!(csv_text.contains("baseline-oracle,overall,all,"));
    let md_text = std::fs::read_to_string(&md).unwrap();
    assert!(md_text.contains("## Main results") && md_text.contains("| baseline-oracle |"));
    for f in [
        "disposition",
        "freeze_by_band",
        "per_family",
        "safety_rules",
    ] {
        let svg = std::fs::read_to_string(figs.join(format!("{f}.svg"))).unwrap();
        assert!(svg.contains("<svg"), "{f}.svg");
        let png = std::fs::read(figs.join(format!("{f}.png"))).unwrap();
        assert!(png.starts_with(b"\x89PNG"), "{f}.png");
    }
}

#[test]
fn acceptance_on_pipeline_dataset() {
    acceptance(pipeline_dataset(), &scratch("acc-pipeline"));
}

#[test]
fn acceptance_on_fixture_dataset() {
    let ds = fixture_dataset();
    let t = truth(ds);
    assert!(t.scenes.iter().any(|s| s.1 == "NO_ACTION"));
    assert!(
        t.scenes.iter().any(|s| !s.3),
        "fixture should have scenes without impact point"
    );
    acceptance(ds, &scratch("acc-fixture"));
}

#[test]
fn random_baseline_is_seeded() {
    let ds = fixture_dataset().to_str().unwrap();
    let a = run_ok(
        "rh-score",
        &["baseline", "random", "--dataset", ds, "--seed", "7"],
    );
    let b = run_ok(
        "rh-score",
        &["baseline", "random", "--dataset", ds, "--seed", "7"],
    );
    let c = run_ok(
        "rh-score",
        &["baseline", "random", "--dataset", ds, "--seed", "8"],
    );
    assert_eq!(a, b);
    assert_ne!(a, c);
    let named = run_ok(
        "rh-score",
        &["baseline", "majority", "--dataset", ds, "--model", "m1"],
    );
    assert!(named.lines().all(|l| l.contains("\"model\":\"m1\"")));
}

#[test]
fn dataset_from_environment_and_missing_dataset() {
    let ds = fixture_dataset();
    let work = scratch("env");
    let p = work.join("p.jsonl");
    baseline(ds, "freeze", &p);
    // No --dataset, no RH_DATASET: the project's release (configs/hub.toml). Here the Hub is a
    // closed loopback port and the HF cache is empty: exit 1 naming the repo and endpoint.
    let hf_home = scratch("env-hf-home");
    let closed = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    let endpoint = format!("http://{}", closed.local_addr().unwrap());
    drop(closed);
    let out = std::process::Command::new(rh_e2e::bin("rh-score"))
        .arg(&p)
        .env_remove("RH_DATASET")
        .env_remove("HF_HUB_OFFLINE")
        .env("HF_ENDPOINT", &endpoint)
        .env("HF_HOME", &hf_home)
        .env_remove("HF_HUB_CACHE")
        .env_remove("HF_TOKEN")
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("reacthuman/reacthuman (revision rh-release-v1)") && err.contains(&endpoint),
        "{err}"
    );
    // owner/name that is not a directory, offline with an empty cache: the same, no network.
    let out = std::process::Command::new(rh_e2e::bin("rh-score"))
        .args([p.to_str().unwrap(), "--dataset", "someone/reacthuman"])
        .env("HF_HUB_OFFLINE", "1")
        .env("HF_HOME", &hf_home)
        .env_remove("HF_HUB_CACHE")
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("someone/reacthuman") && err.contains("cache"),
        "{err}"
    );
    // A path that is neither a directory nor an owner/name id: exit 2.
    let out = run(
        "rh-score",
        &[p.to_str().unwrap(), "--dataset", "./no/such/dir"],
    );
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("does not exist"));
    // RH_DATASET is used.
    let out = std::process::Command::new(rh_e2e::bin("rh-score"))
        .arg(&p)
        .env("RH_DATASET", ds)
        .output()
        .unwrap();
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(String::from_utf8_lossy(&out.stdout).contains("baseline-freeze"));
}

#[test]
fn bad_inputs_exit_2_with_a_message() {
    let ds = fixture_dataset();
    let work = scratch("bad");
    let p = work.join("p.jsonl");
    baseline(ds, "oracle", &p);
    let d = ds.to_str().unwrap();
    // Unreadable predictions: missing file, a directory.
    for preds in [work.join("missing.jsonl"), work.clone()] {
        let out = run("rh-score", &[preds.to_str().unwrap(), "--dataset", d]);
        assert_eq!(out.status.code(), Some(2), "{preds:?}");
        assert!(String::from_utf8_lossy(&out.stderr).contains(preds.to_str().unwrap()));
    }
    // Missing dataset directory.
    let out = run(
        "rh-score",
        &[
            p.to_str().unwrap(),
            "--dataset",
            work.join("nope").to_str().unwrap(),
        ],
    );
    assert_eq!(out.status.code(), Some(2));
    // A dataset without a required column: the message names the file and the column.
    let broken = work.join("broken");
    run_ok(
        "rh-score",
        &[
            "make-fixture",
            "--out",
            broken.to_str().unwrap(),
            "--n",
            "8",
            "--drop-column",
            "impact_point",
        ],
    );
    let out = run(
        "rh-score",
        &[p.to_str().unwrap(), "--dataset", broken.to_str().unwrap()],
    );
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("impact_point") && err.contains("test-00000-of-00001.parquet"),
        "{err}"
    );
    // A bad config file.
    let cfg = work.join("bad.toml");
    std::fs::write(&cfg, "[action_rule]\nversion = 3\n").unwrap();
    let out = run(
        "rh-score",
        &[
            p.to_str().unwrap(),
            "--dataset",
            d,
            "--config",
            cfg.to_str().unwrap(),
        ],
    );
    assert_eq!(out.status.code(), Some(2));
    // Usage errors (clap): exit 2.
    assert_eq!(
        run("rh-score", &["baseline", "psychic", "--dataset", d])
            .status
            .code(),
        Some(2)
    );
    assert_eq!(run("rh-score", &["--no-such-flag"]).status.code(), Some(2));
    // --execute on a dataset without scene specs (a fixture) is an input error naming
    // the missing spec file.
    let out = run(
        "rh-score",
        &[
            p.to_str().unwrap(),
            "--dataset",
            d,
            "--execute",
            "--no-exec-cache",
        ],
    );
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("specs/"));
}

#[test]
fn help_and_explain() {
    for args in [&["--help"][..], &["baseline", "--help"]] {
        let out = run_ok("rh-score", args);
        assert!(out.contains("Usage"), "{out}");
    }
    let out = run_ok("rh-score", &["--explain"]);
    for want in [
        "ACTION RULE v2",
        "knee_bend × 0.25",
        "reach >= 0.2",
        "R1 no parseable plan",
        "R4 CATCH or NO_ACTION",
        "Negation",
        "\"do not\"",
        "AGGREGATION",
        "WARNINGS",
        "absurd_number",
        "Bare form",
    ] {
        assert!(out.contains(want), "--explain lacks {want:?}");
    }
    // A custom config changes the printed thresholds.
    let work = scratch("explain");
    let cfg_text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../configs/scoring.toml"),
    )
    .unwrap()
    .replace("reach_threshold = 0.20", "reach_threshold = 0.25");
    let cfg = work.join("c.toml");
    std::fs::write(&cfg, cfg_text).unwrap();
    let out = run_ok(
        "rh-score",
        &["--explain", "--config", cfg.to_str().unwrap()],
    );
    assert!(out.contains("reach >= 0.25"));
}

#[test]
fn lenient_inputs_and_lost_decisions() {
    let ds = fixture_dataset();
    let t = truth(ds);
    let work = scratch("lenient");
    let (a, b, c) = (&t.scenes[0].0, &t.scenes[1].0, &t.scenes[2].0);
    let lines = [
        // Raw response with a fenced block (bare keyframes), prose around.
        format!(
            r#"{{"scene_id":"{a}","model":"m","response":"Plan:\n```json\n{{\"intent\":\"catch it\",\"walking_cmd\":[0,0,0],\"walking_duration\":0,\"keyframes\":[[0.5,0,0.1]]}}\n```"}}"#
        ),
        // API error: lost, not scored.
        format!(r#"{{"scene_id":"{b}","model":"m","error":"timeout"}}"#),
        // Unparseable response: R1.
        format!(r#"{{"scene_id":"{c}","model":"m","response":"I would step back."}}"#),
        // Duplicate of the first pair: counted, ignored.
        format!(
            r#"{{"scene_id":"{a}","model":"m","plan":{{"walking_cmd":[-1,0,0],"walking_duration":1}}}}"#
        ),
        // Unknown scene.
        r#"{"scene_id":"ffffffff0","model":"m","plan":{"walking_cmd":[0,0,0]}}"#.to_string(),
        // Absurd number: R1.
        format!(
            r#"{{"scene_id":"{b}","model":"m2","plan":{{"walking_cmd":[500,0,0],"walking_duration":1}}}}"#
        ),
        // Malformed JSON.
        "{\"scene_id\": ".to_string(),
    ];
    let p = work.join("p.jsonl");
    std::fs::write(&p, lines.join("\n") + "\n").unwrap();
    let (r, dec) = score(ds, &p, &work);
    let input = &r["input"];
    assert_eq!(input["lines"], 7);
    assert_eq!(input["decisions_scored"], 3);
    assert_eq!(input["decisions_lost"], 1);
    assert_eq!(input["duplicates"], 1);
    let kinds: Vec<&str> = input["warnings"]
        .as_array()
        .unwrap()
        .iter()
        .map(|w| w["kind"].as_str().unwrap())
        .collect();
    for k in [
        "duplicate_decision",
        "unknown_scene_id",
        "absurd_number",
        "malformed_json",
        "r1_no_json_in_response",
    ] {
        assert!(kinds.contains(&k), "{k} not in {kinds:?}");
    }
    let m = r["models"]
        .as_array()
        .unwrap()
        .iter()
        .find(|m| m["model"] == "m")
        .unwrap();
    assert_eq!(m["lost"], 1);
    assert_eq!(m["overall"]["decisions"], 2);
    assert_eq!(m["overall"]["first_rule"]["R1"], 1);
    assert_eq!(dec[0]["action"], "CATCH");
    assert_eq!(dec[0]["status"], "scored");
}

/// Issue 24: coverage, intervals, `--compare` and strict inputs through the real binary.
#[test]
fn coverage_intervals_compare_and_strict_inputs() {
    let ds = pipeline_dataset();
    let d = ds.to_str().unwrap();
    let t = truth(ds);
    let n = t.scenes.len() as u64;
    let work = scratch("coverage");
    let oracle = work.join("oracle.jsonl");
    baseline(ds, "oracle", &oracle);
    // A run stopped after 4 scenes: coverage 4/n, SAA over the n expected scenes.
    let text = std::fs::read_to_string(&oracle).unwrap();
    let four: String = text.lines().take(4).map(|l| format!("{l}\n")).collect();
    let stopped = work.join("stopped.jsonl");
    std::fs::write(&stopped, four).unwrap();
    let out = run(
        "rh-score",
        &[stopped.to_str().unwrap(), "--dataset", d, "--json", "-"],
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let r: Value = serde_json::from_slice(&out.stdout).unwrap();
    let m = &r["models"][0];
    assert_eq!(
        r["coverage"]["subset"], "eval",
        "a built dataset has an eval subset"
    );
    assert_eq!(
        r["coverage"]["expected_scenes"], n,
        "small builds: eval = all valid"
    );
    assert_eq!(m["coverage"]["answered"], 4);
    assert_eq!(m["coverage"]["expected"], n);
    assert_eq!(m["coverage"]["complete"], false);
    assert_eq!(m["overall"]["unanswered"], n - 4);
    assert_eq!(m["overall"]["first_rule"]["R1"], 0);
    let saa = m["overall"]["saa"].as_f64().unwrap();
    assert!((saa - 4.0 / n as f64).abs() < 1e-12, "{saa}");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains(&format!("INCOMPLETE: baseline-oracle answered 4 of {n}")),
        "{err}"
    );
    // Every headline proportion has a 95% interval.
    for k in ["saa_ci", "safety_ci", "aia_ci", "freeze_rate_ci"] {
        let ci = m["overall"][k]
            .as_array()
            .unwrap_or_else(|| panic!("{k}: {m}"));
        assert!(ci[0].as_f64().unwrap() <= ci[1].as_f64().unwrap());
    }
    assert!(m["balanced_accuracy_ci"].is_array());
    assert_eq!(m["recall"].as_array().unwrap().len(), 3);
    // --answered-only: the old view, labelled.
    let table = run_ok(
        "rh-score",
        &[stopped.to_str().unwrap(), "--dataset", d, "--answered-only"],
    );
    assert!(
        table.contains("ANSWERED-ONLY VIEW") && table.contains(&format!("4/{n} INCOMPLETE")),
        "{table}"
    );

    // --compare on two baseline files (known answers: the oracle is right everywhere,
    // always-catch exactly on the CATCH scenes).
    let both = work.join("both.jsonl");
    let catch_file = work.join("catch.jsonl");
    baseline(ds, "always-catch", &catch_file);
    std::fs::write(
        &both,
        text.clone() + &std::fs::read_to_string(&catch_file).unwrap(),
    )
    .unwrap();
    let md = work.join("cmp.md");
    let out = run_ok(
        "rh-score",
        &[
            both.to_str().unwrap(),
            "--dataset",
            d,
            "--json",
            "-",
            "--markdown",
            md.to_str().unwrap(),
            "--compare",
            "baseline-oracle",
            "baseline-always-catch",
        ],
    );
    let r: Value = serde_json::from_str(&out).unwrap();
    let c = &r["comparisons"][0];
    let catch = t.scenes.iter().filter(|s| s.1 == "CATCH").count() as u64;
    let saa = &c["metrics"][0];
    assert_eq!(c["scenes"], n);
    assert_eq!(
        (
            saa["both"].as_u64(),
            saa["only_a"].as_u64(),
            saa["only_b"].as_u64()
        ),
        (Some(catch), Some(n - catch), Some(0))
    );
    let p = saa["mcnemar_p"].as_f64().unwrap();
    let want = (2.0 * 0.5f64.powi((n - catch) as i32)).min(1.0);
    assert!((p - want).abs() <= 1e-12 * want, "{p} vs {want}");
    let md = std::fs::read_to_string(&md).unwrap();
    assert!(
        md.contains("Paired comparison: baseline-oracle vs baseline-always-catch"),
        "{md}"
    );
    assert!(
        md.contains("SAA CI") && md.contains("Per-class recall"),
        "{md}"
    );
    let out = run(
        "rh-score",
        &[
            both.to_str().unwrap(),
            "--dataset",
            d,
            "--compare",
            "baseline-oracle",
            "nobody",
        ],
    );
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("nobody"));

    // Nothing scorable: exit 2 naming the problem.
    let id = &t.scenes[0].0;
    let plan = r#"{"walking_cmd":[0,0,0]}"#;
    let cases = [
        ("empty", String::new(), "is empty"),
        (
            "array",
            format!("[{{\"scene_id\":\"{id}\",\"model\":\"m\",\"plan\":{plan}}}]\n"),
            "JSON array",
        ),
        (
            "nomodel",
            format!("{{\"scene_id\":\"{id}\",\"plan\":{plan}}}\n"),
            "`model`",
        ),
        (
            "foreign",
            format!("{{\"scene_id\":\"00000000\",\"model\":\"m\",\"plan\":{plan}}}\n"),
            "another dataset",
        ),
    ];
    for (name, body, needle) in cases {
        let p = work.join(format!("{name}.jsonl"));
        std::fs::write(&p, body).unwrap();
        let out = run("rh-score", &[p.to_str().unwrap(), "--dataset", d]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{name}: {err}");
        assert!(err.contains(needle), "{name}: {err}");
    }
    // The fixture's predictions scored against the pipeline's dataset: foreign ids.
    let foreign = work.join("fixture-oracle.jsonl");
    baseline(fixture_dataset(), "oracle", &foreign);
    let out = run("rh-score", &[foreign.to_str().unwrap(), "--dataset", d]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("another dataset"));

    // Literal NaN / Infinity: R1 absurd_number, like the strings; dropped lines named.
    let nan = work.join("nan.jsonl");
    std::fs::write(
        &nan,
        format!(
            "{{\"scene_id\":\"{id}\",\"model\":\"m\",\"plan\":{{\"walking_cmd\":[NaN,0,0],\"walking_duration\":1}}}}\n\
             garbage\n\
             {{\"scene_id\":\"{}\",\"model\":\"m\",\"plan\":{{\"walking_cmd\":[0,0,0],\"keyframes\":[[-Infinity,0,0]]}}}}\n",
            t.scenes[1].0
        ),
    )
    .unwrap();
    let out = run(
        "rh-score",
        &[nan.to_str().unwrap(), "--dataset", d, "--json", "-"],
    );
    assert!(out.status.success());
    let r: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(r["models"][0]["overall"]["first_rule"]["R1"], 2);
    assert_eq!(r["input"]["dropped_lines"], 1);
    let w: Vec<&Value> = r["input"]["warnings"].as_array().unwrap().iter().collect();
    assert!(w
        .iter()
        .any(|w| w["kind"] == "absurd_number" && w["count"] == 2));
    assert!(w
        .iter()
        .any(|w| w["kind"] == "malformed_json" && w["lines"] == "2"));
    assert!(String::from_utf8_lossy(&out.stderr).contains("malformed_json ×1 dropped (lines 2)"));
}
