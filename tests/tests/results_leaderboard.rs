//! Results files (`rh-score PREDS --results DIR`) and `rh-score leaderboard` (issue 28):
//! written files validate against `schemas/results.schema.json` (with and without
//! `--execute`) and carry the report's numbers; two baselines on one dataset merge; a run
//! on another dataset (another seed) is refused with exit 2 naming the difference.

use rh_e2e::{run, run_ok};
use serde_json::Value;
use std::path::{Path, PathBuf};

fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("results-{}", std::process::id()))
        .join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn build(dir: &Path, seed: u64) -> PathBuf {
    let out = dir.join(format!("ds{seed}"));
    let seed = seed.to_string();
    let args = [
        "build",
        "--n",
        "24",
        "--seed",
        &seed,
        "--no-render",
        "--out",
        out.to_str().unwrap(),
    ];
    run_ok("rh-pipeline", &args);
    out
}

/// Scores baseline `kind` on `ds` with `--results res` (and `extra` arguments); returns
/// the results file and the JSON report.
fn score(ds: &Path, kind: &str, res: &Path, extra: &[&str]) -> (PathBuf, Value) {
    let preds = res.with_extension(format!("{kind}.jsonl"));
    let text = run_ok(
        "rh-score",
        &["baseline", kind, "--dataset", ds.to_str().unwrap()],
    );
    std::fs::write(&preds, text).unwrap();
    let mut args = vec![
        preds.to_str().unwrap(),
        "--dataset",
        ds.to_str().unwrap(),
        "--results",
        res.to_str().unwrap(),
        "--json",
        "-",
    ];
    args.extend_from_slice(extra);
    let report: Value = serde_json::from_str(&run_ok("rh-score", &args)).unwrap();
    (res.join(format!("baseline-{kind}.json")), report)
}

/// Each document's errors against `schemas/results.schema.json` (JSON Schema 2020-12, the
/// schema itself checked first), by Python's `jsonschema` (installed by scripts/setup.sh),
/// as "message at /instance/path". Python's rather than a Rust crate's: the Rust one's
/// dev-dependencies changed the features of serde and others in the test build, so
/// `cargo test` after `cargo build` recompiled most of the dependency graph.
fn schema_errors(dir: &Path, docs: &[Value]) -> Vec<Vec<String>> {
    let schema = Path::new(env!("CARGO_MANIFEST_DIR")).join("../schemas/results.schema.json");
    let input = dir.join("schema-check.json");
    std::fs::write(&input, serde_json::to_vec(docs).unwrap()).unwrap();
    let out = rh_e2e::python(&format!(
        r#"
import json
from jsonschema import Draft202012Validator
schema = json.load(open({schema:?}))
Draft202012Validator.check_schema(schema)
v = Draft202012Validator(schema)
docs = json.load(open({input:?}))
print(json.dumps([[e.message + " at /" + "/".join(map(str, e.absolute_path)) for e in v.iter_errors(d)] for d in docs]))
"#,
        schema = schema.to_str().unwrap(),
        input = input.to_str().unwrap()
    ));
    let errors: Vec<Vec<String>> = serde_json::from_str(&out).unwrap();
    assert_eq!(errors.len(), docs.len(), "{out}");
    errors
}

fn read(path: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

#[test]
fn results_validate_and_leaderboard_merges_or_refuses() {
    let work = scratch("merge");
    let ds = build(&work, 7);
    let other = build(&work, 8);
    let res = work.join("res");
    let (oracle, report) = score(&ds, "oracle", &res, &["--execute", "--no-exec-cache"]);
    let (freeze, _) = score(&ds, "freeze", &res, &[]);
    let (foreign, _) = score(&other, "oracle", &work.join("res2"), &[]);

    // The schema is strict: an unknown field or a wrong type fails.
    let mut wrong_type = read(&oracle);
    wrong_type["headline"]["saa"]["value"] = Value::String("1".into());
    let mut unknown_field = read(&oracle);
    unknown_field["extra"] = Value::Bool(true);
    let files = [&oracle, &freeze, &foreign];
    let mut docs: Vec<Value> = files.iter().map(|f| read(f)).collect();
    docs.extend([wrong_type, unknown_field]);
    let errors = schema_errors(&work, &docs);
    for (f, e) in files.iter().zip(&errors) {
        assert!(e.is_empty(), "{}: {e:?}", f.display());
    }
    assert!(!errors[3].is_empty(), "a string SAA value validated");
    assert!(
        !errors[4].is_empty(),
        "an unknown top-level field validated"
    );

    // The file carries the report's numbers and the dataset's identity.
    let o = read(&oracle);
    let m = &report["models"][0];
    assert_eq!(o["headline"]["saa"]["value"], m["overall"]["saa"]);
    assert_eq!(o["headline"]["saa"]["ci"], m["overall"]["saa_ci"]);
    assert_eq!(
        o["headline"]["balanced_accuracy"]["ci"],
        m["balanced_accuracy_ci"]
    );
    assert_eq!(o["coverage"], m["coverage"]);
    assert_eq!(o["by_family"], m["by_family"]);
    assert_eq!(o["dataset"]["seed"], 7);
    assert_eq!(
        o["dataset"]["expected_scenes"],
        report["coverage"]["expected_scenes"]
    );
    let manifest = read(&ds.join("build.json"));
    assert_eq!(
        o["dataset"]["label_rule"],
        manifest["config"]["labels"]["rule_version"]
    );
    assert_eq!(o["dataset"]["config_sha256"], manifest["config_sha256"]);
    assert_eq!(
        o["prompt"]["version"],
        Value::Null,
        "baselines use no prompt"
    );
    assert_eq!(
        o["executor"]["config_version"],
        report["execution"]["config"]["version"]
    );
    assert_eq!(o["execution"]["model"], "baseline-oracle");
    assert_eq!(read(&freeze)["execution"], Value::Null);
    assert_eq!(read(&freeze)["dataset"], o["dataset"]);

    // Two baselines on one dataset merge, best SAA first.
    let md = work.join("board.md");
    let site = work.join("site");
    let out = run_ok(
        "rh-score",
        &[
            "leaderboard",
            freeze.to_str().unwrap(),
            oracle.to_str().unwrap(),
            "--json",
            "--markdown",
            md.to_str().unwrap(),
            "--html",
            site.to_str().unwrap(),
        ],
    );
    let board: Value = serde_json::from_str(&out).unwrap();
    let models: Vec<&str> = board["rows"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| r["model"].as_str().unwrap())
        .collect();
    assert_eq!(models, ["baseline-oracle", "baseline-freeze"]);
    assert_eq!(board["rows"][0]["headline"], o["headline"]);
    let md = std::fs::read_to_string(md).unwrap();
    assert!(
        md.contains("| baseline-oracle") && md.contains("seed 7"),
        "{md}"
    );
    let html = std::fs::read_to_string(site.join("index.html")).unwrap();
    assert!(html.contains("<td>baseline-freeze</td>") && site.join("assets/site.css").is_file());

    // A run on another dataset is refused, naming the field, both values and both files.
    let r = run(
        "rh-score",
        &[
            "leaderboard",
            oracle.to_str().unwrap(),
            foreign.to_str().unwrap(),
        ],
    );
    let err = String::from_utf8_lossy(&r.stderr);
    assert_eq!(r.status.code(), Some(2), "{err}");
    assert!(
        err.contains("dataset.seed: 7 (") && err.contains(") vs 8 ("),
        "{err}"
    );
    assert!(
        err.contains(oracle.to_str().unwrap()) && err.contains(foreign.to_str().unwrap()),
        "{err}"
    );
    // A file that is not a results file is an input error naming it.
    let r = run(
        "rh-score",
        &["leaderboard", ds.join("build.json").to_str().unwrap()],
    );
    assert_eq!(r.status.code(), Some(2));
    assert!(
        String::from_utf8_lossy(&r.stderr).contains("build.json is not an rh-score results file")
    );
}
