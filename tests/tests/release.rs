//! The benchmark's canonical release (specification §8, "The release"): `rh-pipeline
//! build --release` refuses pins that differ and builds the release exactly; `rh-score`
//! without `--dataset` downloads the project's release from the Hub (the local stand-in,
//! `rh_e2e::fake_hub`, on 127.0.0.1), checks its fingerprint and scores it; a repository
//! holding the paper-style metadata only, and a tampered copy of the release, exit 2
//! saying why.

use rh_e2e::fake_hub::{hub_run, ok, Hub, Mode};
use rh_e2e::{files_under, python, run, run_ok};
use std::collections::BTreeMap;
use std::path::Path;

const PAPER_REPO: &str = "Alan123/reacthuman-benchmark-scaled";
const COPY_REPO: &str = "someone/reacthuman-copy";

fn configs(name: &str) -> String {
    std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../configs")
            .join(name),
    )
    .unwrap()
}

/// The repository part of `released_dataset` in configs/hub.toml.
fn released_repo() -> String {
    let hub: serde_json::Value = toml_value(&configs("hub.toml"));
    let id = hub["released_dataset"].as_str().unwrap().to_string();
    id.split_once('@')
        .map_or(id.clone(), |(r, _)| r.to_string())
}

/// A TOML text as JSON (through Python's tomllib: no TOML crate in this test crate).
fn toml_value(text: &str) -> serde_json::Value {
    let script = format!(
        "import json, tomllib; print(json.dumps(tomllib.loads({:?})))",
        text
    );
    serde_json::from_str(&python(&script)).unwrap()
}

fn stderr(out: &std::process::Output) -> String {
    String::from_utf8_lossy(&out.stderr).to_string()
}

/// A small release file: 8 label-only scenes of two families at seed 5, with the pins of
/// the embedded configuration and `fingerprint` (the TOML table `rh-pipeline fingerprint`
/// prints).
fn release_file(path: &Path, build_json: &serde_json::Value, fingerprint: &str, rule: &str) {
    let prompt = toml_value(&configs("prompt.toml"))["version"]
        .as_str()
        .unwrap()
        .to_string();
    let text = format!(
        "id = \"rh-release-test\"\nseed = 5\nn = 8\nfamilies = [\"object_drop\", \"shelf_slide\"]\nrender = false\n\n[pins]\nconfig_sha256 = \"{}\"\ncatalog_sha256 = \"{}\"\nlabel_rule = \"{rule}\"\nprompt_version = \"{prompt}\"\n\n{fingerprint}\n",
        build_json["config_sha256"].as_str().unwrap(),
        build_json["catalog_sha256"].as_str().unwrap(),
    );
    std::fs::write(path, text).unwrap();
}

fn build_json(dir: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(dir.join("build.json")).unwrap()).unwrap()
}

/// A plain build of the small release's scenes and its fingerprint table.
fn plain_build(dir: &Path) -> String {
    let d = dir.to_str().unwrap();
    run_ok(
        "rh-pipeline",
        &[
            "build",
            "--n",
            "8",
            "--seed",
            "5",
            "--no-render",
            "--quiet",
            "--families",
            "object_drop,shelf_slide",
            "--out",
            d,
        ],
    );
    run_ok("rh-pipeline", &["fingerprint", d])
}

/// `rh-pipeline build --release [--release-config RELEASE] --out OUT EXTRA...` (without
/// RELEASE: the embedded configs/release.toml).
fn build_release(release: Option<&Path>, out: &Path, extra: &[&str]) -> std::process::Output {
    let mut args = vec!["build", "--release", "--out", out.to_str().unwrap()];
    if let Some(r) = release {
        args.extend(["--release-config", r.to_str().unwrap()]);
    }
    args.extend_from_slice(extra);
    run("rh-pipeline", &args)
}

#[test]
fn build_release_refuses_pins_that_differ_and_builds_the_release_exactly() {
    let tmp = tempfile::tempdir().unwrap();
    let plain = tmp.path().join("plain");
    let fingerprint = plain_build(&plain);
    assert!(
        fingerprint.starts_with("[fingerprint]\nscenes_sha256 = \""),
        "{fingerprint}"
    );
    let manifest = build_json(&plain);
    let rule = manifest["config"]["labels"]["rule_version"]
        .as_str()
        .unwrap();

    // A release that pins another label rule and another configuration: exit 2 naming
    // both, before anything is written.
    let wrong = tmp.path().join("wrong.toml");
    let mut other = manifest.clone();
    other["config_sha256"] = serde_json::json!("0".repeat(64));
    release_file(&wrong, &other, &fingerprint, "v0");
    let out_dir = tmp.path().join("refused");
    let out = build_release(Some(&wrong), &out_dir, &[]);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("release rh-release-test") && err.contains("cannot be built"),
        "{err}"
    );
    assert!(
        err.contains("configuration's SHA-256") && err.contains(&"0".repeat(64)),
        "{err}"
    );
    assert!(
        err.contains("label rule") && err.contains("pins v0"),
        "{err}"
    );
    assert!(
        !err.contains("catalog's SHA-256"),
        "the catalog matches: {err}"
    );
    assert!(!out_dir.join("build.json").exists());

    // The right pins but another configuration given with --config: exit 2.
    let right = tmp.path().join("right.toml");
    release_file(&right, &manifest, &fingerprint, rule);
    let changed = tmp.path().join("changed.toml");
    std::fs::write(
        &changed,
        configs("default.toml").replacen("seed = 0", "seed = 1", 1),
    )
    .unwrap();
    std::fs::copy(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../configs/labels.toml"),
        tmp.path().join("labels.toml"),
    )
    .unwrap();
    let out = build_release(
        Some(&right),
        &out_dir,
        &["--config", changed.to_str().unwrap()],
    );
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("configuration's SHA-256") && !err.contains("label rule"),
        "{err}"
    );
    // --release takes its numbers from the release: --n beside it is a usage error.
    let out = run(
        "rh-pipeline",
        &[
            "build",
            "--release",
            "--n",
            "4",
            "--out",
            out_dir.to_str().unwrap(),
        ],
    );
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));

    // The right pins: the release is built, equal file for file to the plain build but
    // for the release it records (build.json) and names (the card).
    let released = tmp.path().join("released");
    let out = build_release(Some(&right), &released, &[]);
    let err = stderr(&out);
    assert!(out.status.success(), "{err}");
    assert!(
        err.contains("is release rh-release-test: its fingerprint matches"),
        "{err}"
    );
    assert_eq!(build_json(&released)["release"], "rh-release-test");
    let (a, b) = (files_under(&plain), files_under(&released));
    let differ: Vec<&String> = a.keys().filter(|k| a.get(*k) != b.get(*k)).collect();
    assert_eq!(differ, vec!["README.md", "build.json"], "{differ:?}");
    let card = String::from_utf8_lossy(&b["README.md"]).to_string();
    assert!(
        card.contains("release `rh-release-test` of the benchmark"),
        "{card}"
    );

    // A release whose fingerprint the build does not have: exit 1 naming the part.
    let mismatched = tmp.path().join("mismatched.toml");
    let bad: String = fingerprint
        .lines()
        .map(|l| match l.starts_with("specs_sha256") {
            true => format!("specs_sha256 = \"{}\"\n", "f".repeat(64)),
            false => format!("{l}\n"),
        })
        .collect();
    release_file(&mismatched, &manifest, &bad, rule);
    let out = build_release(Some(&mismatched), &tmp.path().join("again"), &[]);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("does not reproduce release rh-release-test"),
        "{err}"
    );
    assert!(
        err.contains("the scene specs (specs/)") && !err.contains("(data/)"),
        "{err}"
    );
}

#[test]
fn the_embedded_release_pins_the_embedded_configuration() {
    // One scene group of the canonical release (shard 0 of 170): the pins pass and the
    // shard records the release; the whole release's fingerprint is checked in
    // `the_canonical_release_reproduces_its_pinned_fingerprint`.
    let tmp = tempfile::tempdir().unwrap();
    let out = build_release(None, tmp.path(), &["--no-render", "--shard", "0/170"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let m = build_json(tmp.path());
    let release = toml_value(&configs("release.toml"));
    assert_eq!(m["release"], release["id"]);
    assert_eq!(m["n"], release["n"]);
    assert_eq!(m["seed"], release["seed"]);
    assert_eq!(m["config_sha256"], release["pins"]["config_sha256"]);
    // The release id is the revision configs/hub.toml names.
    let hub = toml_value(&configs("hub.toml"));
    let tag = hub["released_dataset"]
        .as_str()
        .unwrap()
        .split_once('@')
        .unwrap()
        .1;
    assert_eq!(release["id"].as_str(), Some(tag));
}

#[test]
fn the_canonical_release_reproduces_its_pinned_fingerprint() {
    // The label-only part of the canonical release (680 scenes): its fingerprint is the
    // one configs/release.toml pins (the rendered release has the same one).
    let tmp = tempfile::tempdir().unwrap();
    let out = build_release(None, tmp.path(), &["--no-render"]);
    let err = stderr(&out);
    assert!(out.status.success(), "{err}");
    assert!(
        err.contains("its fingerprint matches configs/release.toml"),
        "{err}"
    );
    let fp = run_ok(
        "rh-pipeline",
        &["fingerprint", tmp.path().to_str().unwrap()],
    );
    let pinned = toml_value(&configs("release.toml"));
    assert!(
        fp.contains(pinned["fingerprint"]["scenes_sha256"].as_str().unwrap()),
        "{fp}"
    );
}

/// The paper's metadata-only layout (`<family>/<family>__dN_vM/` with metadata.json and
/// spec.json, as grade's `dataset_diagnosis` knows it): a card and scene folders, no tables.
fn paper_style_repo() -> BTreeMap<String, Vec<u8>> {
    let file = |p: &str, text: &str| (p.to_string(), text.as_bytes().to_vec());
    BTreeMap::from([
        file(".gitattributes", "*.json filter=lfs\n"),
        file("README.md", "# ReactHuman (paper release)\n"),
        file("object_drop/object_drop__d1_v1/metadata.json", "{}\n"),
        file("object_drop/object_drop__d1_v1/spec.json", "{}\n"),
        file("shelf_slide/shelf_slide__d1_v1/metadata.json", "{}\n"),
    ])
}

/// The release with one scene's ground truth flipped in both tables, and `build.json`'s
/// sums made to match (so only the fingerprint can tell).
fn tampered(release: &Path, dir: &Path) -> BTreeMap<String, Vec<u8>> {
    let files = files_under(release);
    for (rel, bytes) in &files {
        let p = dir.join(rel);
        std::fs::create_dir_all(p.parent().unwrap()).unwrap();
        std::fs::write(p, bytes).unwrap();
    }
    python(&format!(
        r#"
import hashlib, json, pathlib, pyarrow.parquet as pq, pyarrow as pa
d = pathlib.Path({:?})
m = json.loads((d / "build.json").read_text())
for f in ["data/test-00000-of-00001.parquet", "eval/test-00000-of-00001.parquet"]:
    t = pq.read_table(d / f)
    a = t.column("gt_action").to_pylist()
    a[0] = "DODGE" if a[0] != "DODGE" else "CATCH"
    t = t.set_column(t.schema.get_field_index("gt_action"), "gt_action", pa.array(a))
    pq.write_table(t, d / f)
    m["files"][f] = hashlib.sha256((d / f).read_bytes()).hexdigest()
(d / "build.json").write_text(json.dumps(m, indent=2))
"#,
        dir.to_str().unwrap()
    ));
    files_under(dir)
}

#[test]
fn the_release_from_the_hub_is_checked_and_scored_and_other_repositories_are_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let plain = tmp.path().join("plain");
    let fingerprint = plain_build(&plain);
    let manifest = build_json(&plain);
    let rule = manifest["config"]["labels"]["rule_version"]
        .as_str()
        .unwrap();
    let rel = tmp.path().join("release.toml");
    release_file(&rel, &manifest, &fingerprint, rule);
    let released = tmp.path().join("released");
    let out = build_release(Some(&rel), &released, &["--quiet"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let preds = tmp.path().join("preds.jsonl");
    let text = run_ok(
        "rh-score",
        &["baseline", "oracle", "--dataset", plain.to_str().unwrap()],
    );
    std::fs::write(&preds, text).unwrap();

    let repos = BTreeMap::from([
        (released_repo(), files_under(&released)),
        (PAPER_REPO.to_string(), paper_style_repo()),
        (
            COPY_REPO.to_string(),
            tampered(&released, &tmp.path().join("tampered")),
        ),
    ]);
    let hub = Hub::serve_repos(repos, Mode::Serve);
    let hf_home = tmp.path().join("hf-home");
    let score = |args: &[&str]| {
        let mut all = vec![preds.to_str().unwrap()];
        all.extend_from_slice(args);
        let mut cmd = rh_e2e::fake_hub::hub_cmd(
            "rh-score",
            &all,
            &hub.endpoint,
            &hf_home,
            Some(rh_e2e::fake_hub::TOKEN),
        );
        cmd.env("RH_RELEASE_CONFIG", &rel).output().unwrap()
    };

    // No --dataset: the project's release, downloaded, its fingerprint checked, scored.
    let out = score(&["--json", "-"]);
    let report = ok(&out, "rh-score on the released dataset");
    let err = stderr(&out);
    assert!(
        err.contains(&format!(
            "{} is release rh-release-test: its fingerprint matches",
            released_repo()
        )),
        "{err}"
    );
    let report: serde_json::Value = serde_json::from_str(&report).unwrap();
    assert!(report.to_string().contains("baseline-oracle"), "{report}");

    // The paper's metadata-only repository: exit 2, listing what it holds and how to get
    // a dataset that scores.
    let out = score(&["--dataset", PAPER_REPO]);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains(&format!("{PAPER_REPO} holds no ReactHuman tables")),
        "{err}"
    );
    assert!(
        err.contains(
            "5 file(s): .gitattributes, README.md, object_drop/object_drop__d1_v1/metadata.json"
        ),
        "{err}"
    );
    assert!(
        err.contains("rh-pipeline build --release") && err.contains(&released_repo()),
        "{err}"
    );
    assert!(
        err.contains("2 scene folders <family>/<family>__dN_vM/: the paper's metadata-only layout"),
        "{err}"
    );
    // `rh-pipeline download` still fetches it (it is a Hub dataset like any other).
    ok(
        &hub_run(
            "rh-pipeline",
            &["download", PAPER_REPO],
            &hub.endpoint,
            &hf_home,
        ),
        "download of the paper's repository",
    );

    // A copy claiming to be the release with one label changed (its sums consistent):
    // exit 2 naming the tables that differ.
    let out = score(&["--dataset", COPY_REPO]);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains(&format!("{COPY_REPO} is not release rh-release-test")),
        "{err}"
    );
    assert!(
        err.contains("the scene table (data/)") && err.contains("the evaluation subset (eval/)"),
        "{err}"
    );
    assert!(!err.contains("specs/"), "the specs are untouched: {err}");
}
