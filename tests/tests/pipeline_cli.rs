//! End-to-end tests of the real `rh-pipeline` binary: reproducible builds, the dataset
//! layout read back by pyarrow, replay verification, and clear errors on bad input.

use rh_e2e::{files_under, python, run, run_ok};
use std::fs;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

const FOUNDATION_FAMILIES: &str =
    "object_drop,shelf_slide,ceiling_drop,sliding_object,rolling_ball,thrown_object";

/// Two builds of the same 60 scenes, with one and with two worker threads.
fn builds() -> &'static (tempfile::TempDir, PathBuf, PathBuf) {
    static BUILDS: OnceLock<(tempfile::TempDir, PathBuf, PathBuf)> = OnceLock::new();
    BUILDS.get_or_init(|| {
        let dir = tempfile::tempdir().unwrap();
        let a = dir.path().join("jobs1");
        let b = dir.path().join("jobs2");
        for (out, jobs) in [(&a, "1"), (&b, "2")] {
            run_ok(
                "rh-pipeline",
                &[
                    "build",
                    "--n",
                    "60",
                    "--no-render",
                    "--quiet",
                    "--seed",
                    "7",
                    "--jobs",
                    jobs,
                    "--families",
                    FOUNDATION_FAMILIES,
                    "--out",
                    out.to_str().unwrap(),
                ],
            );
        }
        (dir, a, b)
    })
}

#[test]
fn builds_are_identical_across_runs_and_thread_counts() {
    let (_, a, b) = builds();
    let fa = files_under(a);
    let fb = files_under(b);
    assert_eq!(fa.keys().collect::<Vec<_>>(), fb.keys().collect::<Vec<_>>());
    assert_eq!(fa.keys().filter(|k| k.starts_with("specs/")).count(), 60);
    for (name, bytes) in &fa {
        assert!(
            bytes == &fb[name],
            "{name} differs between --jobs 1 and --jobs 2"
        );
    }
    // A third build in a fresh process gives the same state hashes.
    let dir = tempfile::tempdir().unwrap();
    let c = dir.path().join("again");
    run_ok(
        "rh-pipeline",
        &[
            "build",
            "--n",
            "60",
            "--no-render",
            "--quiet",
            "--seed",
            "7",
            "--families",
            FOUNDATION_FAMILIES,
            "--out",
            c.to_str().unwrap(),
        ],
    );
    let hashes = |d: &Path| {
        python(&format!(
            "import pyarrow.parquet as pq\nprint(pq.read_table('{}/data/test-00000-of-00001.parquet').column('state_hash').to_pylist())",
            d.display()
        ))
    };
    assert_eq!(hashes(a), hashes(&c));
}

#[test]
fn sixty_scene_build_has_every_column_and_valid_rows() {
    let (_, a, _) = builds();
    let script = format!(
        r#"
import json, pyarrow.parquet as pq
t = pq.read_table('{}/data/test-00000-of-00001.parquet')
rows = t.to_pylist()
print(json.dumps({{"columns": t.column_names, "n": t.num_rows,
  "families": sorted(set(r['family'] for r in rows)),
  "all_valid": all(r['valid'] or r['twin_scene_id'] is not None for r in rows),
  "actions": sorted(set(r['gt_action'] for r in rows)),
  "bands": sorted(set(r['speed_band'] for r in rows)),
  "impact_ok": all(r['impact_point'] is None or len(r['impact_point']) == 3 for r in rows),
  "pose_ok": all(len(r['observer_pose']) == 3 for r in rows),
  "ids_ok": all(len(r['scene_id']) == 8 for r in rows),
  "groups": len(set(r['group_id'] for r in rows)),
  "specs": sorted(r['spec_file'] for r in rows)[:1]}}))
"#,
        a.display()
    );
    let report: serde_json::Value = serde_json::from_str(python(&script).trim()).unwrap();
    assert_eq!(report["n"], 60);
    assert_eq!(
        report["all_valid"], true,
        "every scene of the 60 must pass every validator (but an adversarial twin, never resampled)"
    );
    let families: Vec<&str> = report["families"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_str().unwrap())
        .collect();
    assert_eq!(families.len(), 6, "{families:?}");
    assert_eq!(report["bands"].as_array().unwrap().len(), 4);
    assert_eq!(report["groups"], 15);
    assert_eq!(report["impact_ok"], true);
    assert_eq!(report["pose_ok"], true);
    assert_eq!(report["ids_ok"], true);
    let columns: Vec<&str> = report["columns"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_str().unwrap())
        .collect();
    // specification §8 required columns.
    for required in [
        "scene_id",
        "group_id",
        "seed",
        "family",
        "speed_band",
        "speed_sweep",
        "object_id",
        "object_name",
        "looks_like",
        "adversarial",
        "room",
        "description",
        "gt_action",
        "dangerous",
        "danger_present",
        "impact_point",
        "time_to_impact",
        "time_to_floor",
        "impact_speed",
        "observer_pose",
        "label_rule",
        "state_hash",
        "valid",
        "spec_file",
        "ego_file_name",
        "closeup_file_name",
        "overhead_file_name",
        "valid_no_interpenetration",
        "valid_energy",
        "valid_no_tunnelling",
        "valid_in_frame",
        "valid_visible",
        "valid_intended_event",
    ] {
        assert!(columns.contains(&required), "missing column {required}");
    }
    // Specs parse and name their own scene.
    let spec_file = report["specs"][0].as_str().unwrap();
    let spec: serde_json::Value =
        serde_json::from_str(&fs::read_to_string(a.join(spec_file)).unwrap()).unwrap();
    assert_eq!(spec["schema_version"], 1);
    assert_eq!(spec["cameras"].as_array().unwrap().len(), 3);
}

#[test]
fn verify_replays_and_catches_a_tampered_spec() {
    let (_, a, _) = builds();
    let out = run_ok("rh-pipeline", &["verify", a.to_str().unwrap(), "--json"]);
    let report: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(report["scenes"], 60);
    assert_eq!(report["matched"], 60);

    // Copy the dataset and nudge one body in one spec: verify must fail with exit 2.
    let dir = tempfile::tempdir().unwrap();
    for (name, bytes) in files_under(a) {
        let path = dir.path().join(&name);
        fs::create_dir_all(path.parent().unwrap()).unwrap();
        fs::write(path, bytes).unwrap();
    }
    let victim = fs::read_dir(dir.path().join("specs"))
        .unwrap()
        .next()
        .unwrap()
        .unwrap()
        .path();
    let mut spec: serde_json::Value =
        serde_json::from_str(&fs::read_to_string(&victim).unwrap()).unwrap();
    let hazard = spec["hazard"].as_u64().unwrap() as usize;
    let x = spec["bodies"][hazard]["linvel"][0].as_f64().unwrap();
    spec["bodies"][hazard]["linvel"][0] = serde_json::json!(x + 0.05);
    fs::write(&victim, serde_json::to_string_pretty(&spec).unwrap()).unwrap();
    let id = victim.file_stem().unwrap().to_str().unwrap();
    // The replay-only check sees the physics change.
    let out = run(
        "rh-pipeline",
        &["verify", "--fast", dir.path().to_str().unwrap()],
    );
    assert_eq!(out.status.code(), Some(2));
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains(&format!("MISMATCH {id}: state hash")),
        "{stdout}"
    );
    assert!(stdout.contains("59 match, 1 mismatch"), "{stdout}");
    // The full check sees the altered file and the spec that no longer derives.
    let out = run("rh-pipeline", &["verify", dir.path().to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains(&format!("FILE specs/{id}.json: altered")),
        "{stdout}"
    );
    assert!(stdout.contains(&format!("MISMATCH {id}")), "{stdout}");
    assert!(stdout.contains("59 match, 1 differ"), "{stdout}");
}

fn assert_bad_input(args: &[&str], expect_in_message: &str) {
    let out = run("rh-pipeline", args);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
    assert!(
        stderr.contains(expect_in_message),
        "{args:?}: expected '{expect_in_message}' in: {stderr}"
    );
}

#[test]
fn bad_input_is_a_clear_error_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let out_s = out.to_str().unwrap();
    assert_bad_input(
        &[
            "build",
            "--n",
            "8",
            "--families",
            "object_dorp",
            "--out",
            out_s,
        ],
        "unknown family 'object_dorp'",
    );
    assert_bad_input(
        &["build", "--n", "0", "--out", out_s],
        "--n must be at least 1",
    );
    assert_bad_input(
        &["build", "--n", "4", "--shard", "3/2", "--out", out_s],
        "--shard",
    );
    assert!(
        !out.exists(),
        "a rejected build must not create its output directory"
    );

    // Unwritable --out: a path below a regular file.
    let file = dir.path().join("a-file");
    fs::write(&file, "x").unwrap();
    let below = file.join("sub");
    assert_bad_input(
        &["build", "--n", "4", "--out", below.to_str().unwrap()],
        "cannot write to --out",
    );

    // Malformed config: the message names the file and line.
    let config = dir.path().join("broken.toml");
    fs::write(
        &config,
        "labels = \"labels.toml\"\n[build]\nseed = \"zero\"\n",
    )
    .unwrap();
    assert_bad_input(
        &[
            "--config",
            config.to_str().unwrap(),
            "build",
            "--n",
            "4",
            "--out",
            out_s,
        ],
        "broken.toml:",
    );
    assert!(
        !out.exists(),
        "a malformed config must not create the output directory"
    );

    // Usage errors exit 2 as well; --help exits 0.
    assert_eq!(run("rh-pipeline", &["build"]).status.code(), Some(2));
    assert_eq!(run("rh-pipeline", &["--help"]).status.code(), Some(0));
    assert_eq!(
        run(
            "rh-pipeline",
            &["verify", dir.path().join("missing").to_str().unwrap()]
        )
        .status
        .code(),
        Some(2)
    );
}

#[test]
fn plan_maps_descriptions_and_rejects_nonsense() {
    let out = run_ok(
        "rh-pipeline",
        &[
            "plan",
            "a cast-iron pan slides off the counter in the kitchen",
        ],
    );
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["selection"]["object_id"], "cast_iron_pan");
    assert_eq!(v["selection"]["family"], "object_drop");
    assert_eq!(v["selection"]["room_id"], "kitchen");
    let out = run_ok(
        "rh-pipeline",
        &["plan", "a lamp falls from the ceiling", "--seed", "3"],
    );
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["selection"]["family"], "ceiling_drop");
    // Same text and seed, same selection.
    assert_eq!(
        out,
        run_ok(
            "rh-pipeline",
            &["plan", "a lamp falls from the ceiling", "--seed", "3"]
        )
    );
    assert_bad_input(&["plan", "zzzz qqqq"], "close catalogue names");
}

#[test]
fn all_seventeen_families_build_valid_and_replay() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("all");
    let summary = run_ok(
        "rh-pipeline",
        &[
            "build",
            "--n",
            "340",
            "--no-render",
            "--quiet",
            "--json",
            "--out",
            out.to_str().unwrap(),
        ],
    );
    let summary: serde_json::Value = serde_json::from_str(&summary).unwrap();
    assert_eq!(summary["scenes"], 340);
    // Every scene passes every validator, but a scene of an adversarial probe pair: a twin
    // is the probe's spec with the object swapped, labelled without resampling (label
    // rule v5), so a twin (and a probe band no attempt made valid) may stay invalid.
    let invalid: Vec<String> = summary["invalid_scene_ids"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_str().unwrap().to_string())
        .collect();
    let twins = twin_members(&out);
    assert!(
        invalid.len() <= 12 && invalid.iter().all(|id| twins.contains(id)),
        "invalid scenes outside probe pairs: {invalid:?}"
    );
    assert_eq!(summary["valid"], 340 - invalid.len() as u64);
    let per_family = summary["per_family"].as_object().unwrap();
    assert_eq!(per_family.len(), 17);
    assert!(per_family.values().all(|c| c == 20), "{per_family:?}");
    // How many attempts each validator rejected, per family (issue 12: visibility).
    let rejections = summary["rejections"].as_object().unwrap();
    assert_eq!(rejections.len(), 17);
    let mut attempts = 0;
    let mut visible = 0;
    for (family, r) in rejections {
        let a = r["attempts"].as_u64().unwrap();
        assert!(a >= 5, "{family}: five groups need at least five attempts");
        let v = r["rejected_by"]["valid_visible"].as_u64().unwrap();
        assert!(v < a, "{family}: {v} of {a}");
        attempts += a;
        visible += v;
    }
    // The ego pixel rule (issue 44) rejects small far balls often: bouncing_object and
    // thrown_object most (scenes/tests/visibility.rs has the figures).
    assert!(
        visible * 3 <= attempts,
        "visibility rejected {visible} of {attempts}"
    );
    let script = format!(
        "import pyarrow.parquet as pq, collections\nt = pq.read_table('{}/data/test-00000-of-00001.parquet').to_pylist()\nc = collections.Counter((r['family'], r['speed_band']) for r in t)\nprint(len(c), min(c.values()))",
        out.display()
    );
    assert_eq!(python(&script).trim(), "68 5", "every family × band pair");
    let report: serde_json::Value = serde_json::from_str(&run_ok(
        "rh-pipeline",
        &["verify", out.to_str().unwrap(), "--json"],
    ))
    .unwrap();
    assert_eq!(report["matched"], 340);
}

#[test]
fn balance_reports_counts_per_action_per_family() {
    let out = run_ok(
        "rh-pipeline",
        &[
            "balance",
            "--json",
            "--per-family",
            "8",
            "--families",
            FOUNDATION_FAMILIES,
        ],
    );
    let report: serde_json::Value = serde_json::from_str(&out).unwrap();
    let rows = report["families"].as_array().unwrap();
    assert_eq!(rows.len(), 6);
    for r in rows {
        // The subset's scenes of a family (at most 8, at most one NO_ACTION), chosen from
        // its share of the 680-scene pool, which is counted whole.
        let subset = ["catch", "dodge", "no_action"]
            .iter()
            .map(|k| r[*k].as_u64().unwrap())
            .sum::<u64>();
        // The valid scenes of the family's 40 in the pool (an adversarial twin group is
        // counted beside its probe's).
        let pool = ["pool_catch", "pool_dodge", "pool_no_action"]
            .iter()
            .map(|k| r[*k].as_u64().unwrap())
            .sum::<u64>();
        // At most one NO_ACTION, two where a twin pair's member is one
        // ([eval] twin_no_action_per_family).
        assert!(
            (1..=8).contains(&subset) && r["no_action"].as_u64().unwrap() <= 2,
            "{r}"
        );
        assert!((20..=40).contains(&pool), "{r}");
    }
    let eval = &report["eval"];
    assert_eq!(
        eval["scenes"].as_u64().unwrap(),
        rows.iter()
            .map(|r| ["catch", "dodge", "no_action"]
                .iter()
                .map(|k| r[*k].as_u64().unwrap())
                .sum::<u64>())
            .sum::<u64>()
    );
    let text = run_ok(
        "rh-pipeline",
        &["balance", "--per-family", "4", "--families", "object_drop"],
    );
    assert!(
        text.contains("object_drop") && text.contains("CATCH"),
        "{text}"
    );
    assert_eq!(
        run("rh-pipeline", &["balance", "--families", "nope"])
            .status
            .code(),
        Some(2)
    );
}

/// The label balance sentence of docs/labels.md is the output of `rh-pipeline balance`
/// (the one source): a change to the samplers or labels that moves a count fails here,
/// and the message gives the sentence to paste.
#[test]
fn docs_label_balance_matches_the_balance_command() {
    let readme =
        fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/labels.md"))
            .unwrap()
            .replace('\n', " ");
    let start = readme
        .find("Label balance of the 17 × 18 subset")
        .expect("docs/labels.md states the label balance");
    let sentence = &readme[start..start + readme[start..].find('.').unwrap()];
    let count = |label: &str| -> u64 {
        let at = sentence
            .find(&format!("{label} "))
            .unwrap_or_else(|| panic!("{label} in: {sentence}"));
        sentence[at + label.len() + 1..]
            .split(|c: char| !c.is_ascii_digit())
            .next()
            .unwrap()
            .parse()
            .unwrap()
    };
    let stated = (count("CATCH"), count("DODGE"), count("NO_ACTION"));
    let rows: serde_json::Value = serde_json::from_str(&run_ok(
        "rh-pipeline",
        &["balance", "--json", "--seed", "0"],
    ))
    .unwrap();
    let rows = rows["families"].as_array().unwrap();
    assert_eq!(rows.len(), 17);
    let sum = |k: &str| rows.iter().map(|r| r[k].as_u64().unwrap_or(0)).sum::<u64>();
    let actual = (sum("catch"), sum("dodge"), sum("no_action"));
    assert_eq!(
        stated, actual,
        "docs/labels.md says CATCH {}, DODGE {}, NO_ACTION {}; `rh-pipeline balance --seed 0` gives CATCH {}, DODGE {}, NO_ACTION {} — update docs/labels.md (its table too)",
        stated.0, stated.1, stated.2, actual.0, actual.1, actual.2
    );
}

/// Scene ids of a build's adversarial probe pairs (both members carry `twin_scene_id`).
fn twin_members(dataset: &Path) -> std::collections::BTreeSet<String> {
    let script = format!(
        r#"
import glob, json, pyarrow.parquet as pq
ids = []
for f in glob.glob("{}/data/*.parquet"):
    t = pq.read_table(f, columns=["scene_id", "twin_scene_id"]).to_pylist()
    ids += [r["scene_id"] for r in t if r["twin_scene_id"] is not None]
print(json.dumps(ids))
"#,
        dataset.display()
    );
    serde_json::from_str(python(&script).trim()).unwrap()
}
