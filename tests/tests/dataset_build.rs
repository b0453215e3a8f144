//! End-to-end tests of the dataset as a Hugging Face dataset (specification §8, §13): sharded
//! builds merged equal a single build byte for byte, a build killed with SIGKILL and
//! restarted equals an uninterrupted one, and pyarrow and `datasets` load the card's
//! configs.

use rh_e2e::{bin, files_under, python, run, run_ok};
use std::fs;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::OnceLock;
use std::time::{Duration, Instant};

const FAMILIES: &str =
    "object_drop,shelf_slide,ceiling_drop,sliding_object,rolling_ball,thrown_object";

fn build_args<'a>(n: &'a str, seed: &'a str, out: &'a Path) -> Vec<&'a str> {
    vec![
        "build",
        "--n",
        n,
        "--seed",
        seed,
        "--no-render",
        "--quiet",
        "--families",
        FAMILIES,
        "--out",
        out.to_str().unwrap(),
    ]
}

/// A single 40-scene build (seed 11), shared by the tests that only read it.
fn single() -> &'static (tempfile::TempDir, PathBuf) {
    static SINGLE: OnceLock<(tempfile::TempDir, PathBuf)> = OnceLock::new();
    SINGLE.get_or_init(|| {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("single");
        run_ok("rh-pipeline", &build_args("40", "11", &out));
        (dir, out)
    })
}

fn assert_same_tree(a: &Path, b: &Path) {
    let (fa, fb) = (files_under(a), files_under(b));
    assert_eq!(
        fa.keys().collect::<Vec<_>>(),
        fb.keys().collect::<Vec<_>>(),
        "{} and {} hold different files",
        a.display(),
        b.display()
    );
    for (name, bytes) in &fa {
        assert!(bytes == &fb[name], "{name} differs");
    }
}

fn assert_exit2(args: &[&str], needle: &str) {
    let out = run("rh-pipeline", args);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
    assert!(
        err.contains(needle),
        "{args:?}: expected '{needle}' in: {err}"
    );
}

#[test]
fn dataset_build_layout_card_and_manifest() {
    let (_, dir) = single();
    let files = files_under(dir);
    for f in [
        "README.md",
        "build.json",
        "data/test-00000-of-00001.parquet",
        "eval/test-00000-of-00001.parquet",
    ] {
        assert!(files.contains_key(f), "missing {f}");
    }
    assert_eq!(files.keys().filter(|k| k.starts_with("specs/")).count(), 40);
    assert!(
        !files
            .keys()
            .any(|k| k.starts_with(".rh-build") || k.ends_with(".tmp")),
        "work files left: {:?}",
        files.keys().collect::<Vec<_>>()
    );
    let card = String::from_utf8(files["README.md"].clone()).unwrap();
    for needle in [
        "license: cc-by-4.0",
        "config_name: default",
        "path: data/test-*.parquet",
        "config_name: eval",
        "path: eval/test-*.parquet",
        "n<1K",
        "| `impact_point` | `float64[3]`, nullable |",
        "Label rule `v6`",
        "the articulated humanoid the executor moves",
        "where the hands can hold it",
        "`valid_escapable`",
        "before Δ + 0.2 s",
        "reach envelope",
        "≥ 2 kg",
        "≤ 7 m/s",
        "≤ 30 J",
        "| object_drop |",
        "@misc{li2027reacthuman",
        "## Limitations",
        "## What the model sees",
        "### Predictions",
        "### Metrics",
        "**SAA**",
        "Bang",
        "| build seed | 11 |",
        "takes up to 18 valid scenes per family",
        "stratified by label: up to 18 valid scenes per family",
        "over the whole simulation",
        "cast_column",
    ] {
        assert!(card.contains(needle), "card lacks {needle:?}:\n{card}");
    }
    // The card describes this build: its scope line counts the families that have scenes,
    // and its example code loads this folder, not the released dataset.
    let families_built: std::collections::BTreeSet<&str> = FAMILIES.split(',').collect();
    assert!(
        card.contains(&format!("of {} families", families_built.len())),
        "{card}"
    );
    assert!(!card.contains("load_dataset(\"Alan123"), "{card}");
    assert!(!card.contains("released build is"), "{card}");

    // A build smaller than one group per family says which families got no scene and
    // leaves them out of its tables.
    let tmp = tempfile::tempdir().unwrap();
    let small = tmp.path().join("small");
    run_ok(
        "rh-pipeline",
        &[
            "build",
            "--n",
            "4",
            "--no-render",
            "--quiet",
            "--families",
            "object_drop,rolling_ball",
            "--out",
            small.to_str().unwrap(),
        ],
    );
    let card = std::fs::read_to_string(small.join("README.md")).unwrap();
    assert!(card.contains("of 1 family in 1 scene group "), "{card}");
    assert!(
        card.contains("got no scene group") && card.contains("`rolling_ball`"),
        "{card}"
    );
    assert!(
        card.contains("| object_drop |") && !card.contains("| rolling_ball |"),
        "{card}"
    );
    let manifest: serde_json::Value = serde_json::from_slice(&files["build.json"]).unwrap();
    assert_eq!(manifest["seed"], 11);
    assert_eq!(manifest["n"], 40);
    assert!(
        manifest["render_adapter"].is_null(),
        "a label-only build records no adapter"
    );
    assert_eq!(manifest["shard"], serde_json::json!([0, 1]));
    assert_eq!(manifest["config"]["labels"]["rule_version"], "v6");
}

#[test]
fn dataset_sharded_build_merges_to_the_single_build() {
    let (_, single) = single();
    let tmp = tempfile::tempdir().unwrap();
    let shard = |i: u32| tmp.path().join(format!("shard{i}"));
    for i in 0..3 {
        let out = shard(i);
        let s = format!("{i}/3");
        let mut args = build_args("40", "11", &out);
        args.extend(["--shard", &s]);
        run_ok("rh-pipeline", &args);
        assert!(out
            .join(format!("data/test-0000{i}-of-00003.parquet"))
            .exists());
        assert!(!out.join("eval").exists(), "a shard has no eval subset");
    }
    let merged = tmp.path().join("merged");
    let (s0, s1, s2) = (shard(0), shard(1), shard(2));
    let (s0, s1, s2) = (
        s0.to_str().unwrap(),
        s1.to_str().unwrap(),
        s2.to_str().unwrap(),
    );
    // Any order of shard directories.
    let summary = run_ok(
        "rh-pipeline",
        &["merge", merged.to_str().unwrap(), s2, s0, s1, "--json"],
    );
    let summary: serde_json::Value = serde_json::from_str(&summary).unwrap();
    assert_eq!(summary["scenes"], 40);
    assert_same_tree(single, &merged);

    // Problems are usage errors that name them.
    let m2 = tmp.path().join("m2");
    let m2 = m2.to_str().unwrap();
    assert_exit2(&["merge", m2, s0, s1], "missing shard(s) 2/3");
    assert_exit2(&["merge", m2, s0, s1, s1], "given twice");
    assert_exit2(
        &["merge", merged.to_str().unwrap(), s0, s1, s2],
        "not empty",
    );
    let other = tmp.path().join("other-seed");
    let mut args = build_args("40", "12", &other);
    args.extend(["--shard", "2/3"]);
    run_ok("rh-pipeline", &args);
    assert_exit2(
        &["merge", m2, s0, s1, other.to_str().unwrap()],
        "different builds (seed 11 vs 12)",
    );
    assert_exit2(&["merge", m2, s0, s1, single.to_str().unwrap()], "shard");
    assert!(!Path::new(m2).exists(), "a failed merge leaves no output");
}

#[test]
fn dataset_killed_build_resumes_to_the_same_bytes() {
    let tmp = tempfile::tempdir().unwrap();
    let reference = tmp.path().join("reference");
    run_ok("rh-pipeline", &build_args("120", "5", &reference));

    let killed = tmp.path().join("killed");
    let records = killed.join(".rh-build/groups");
    let mut args = build_args("120", "5", &killed);
    args.extend(["--jobs", "1"]);
    let mut child = Command::new(bin("rh-pipeline"))
        .args(&args)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    // Kill it (SIGKILL) once a few of its 30 groups are finished.
    let deadline = Instant::now() + Duration::from_secs(60);
    loop {
        let done = fs::read_dir(&records)
            .map(|d| {
                d.flatten()
                    .filter(|e| e.file_name().to_string_lossy().ends_with(".parquet"))
                    .count()
            })
            .unwrap_or(0);
        if done >= 3 || Instant::now() > deadline {
            break;
        }
        std::thread::sleep(Duration::from_millis(2));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    assert!(
        killed.join(".rh-build").exists(),
        "the build finished before it could be killed"
    );
    assert!(!killed.join("README.md").exists());

    // Another build into the same directory with other arguments is refused.
    assert_exit2(&build_args("120", "6", &killed), "holds a different build");

    let summary = run_ok("rh-pipeline", &[&args[..], &["--json"]].concat());
    let summary: serde_json::Value = serde_json::from_str(&summary).unwrap();
    let resumed = summary["resumed_groups"].as_u64().unwrap();
    let computed = summary["computed_groups"].as_u64().unwrap();
    assert!(resumed >= 3, "{summary}");
    assert_eq!(resumed + computed, 30, "{summary}");
    assert_same_tree(&reference, &killed);

    // Once complete, the same command does nothing and changes nothing.
    let again = run_ok("rh-pipeline", &[&args[..], &["--json"]].concat());
    let again: serde_json::Value = serde_json::from_str(&again).unwrap();
    assert_eq!(again["computed_groups"], 0);
    assert_same_tree(&reference, &killed);
}

#[test]
fn dataset_loads_with_pyarrow_and_datasets_through_the_card() {
    let (_, dir) = single();
    let hf_home = tempfile::tempdir().unwrap();
    let script = format!(
        r#"
import os, json
os.environ["HF_HOME"] = {home:?}
os.environ["HF_DATASETS_OFFLINE"] = "1"
os.environ["HF_HUB_OFFLINE"] = "1"
import pyarrow.parquet as pq
import datasets
d = {dir:?}
t = pq.read_table(d + "/data/test-00000-of-00001.parquet")
e = pq.read_table(d + "/eval/test-00000-of-00001.parquet")
hf = json.loads(pq.read_schema(d + "/data/test-00000-of-00001.parquet").metadata[b"huggingface"])
pf = pq.ParquetFile(d + "/data/test-00000-of-00001.parquet")
# The card's first Python example, run from another folder with DIR given as it says.
card = open(d + "/README.md").read()
example = card.split("```python\n")[1].split("```")[0]
os.environ["RH_DATASET"] = d
os.chdir("/")
ns = {{}}
exec(example, ns)
default = datasets.load_dataset(d, "default", split="test")
ev = datasets.load_dataset(d, "eval", split="test")
print(json.dumps({{
  "rows": t.num_rows, "eval_rows": e.num_rows,
  "columns": t.column_names,
  "hf_columns": list(hf["info"]["features"].keys()),
  "ds_rows": default.num_rows, "ds_columns": default.column_names,
  "ds_eval_rows": ev.num_rows,
  "impact_point": str(default.features["impact_point"]),
  "trajectory": str(default.features["trajectory"]),
  "valid": str(default.features["valid"]),
  "row_group_rows": pf.metadata.row_group(0).num_rows,
  "eval_all_valid": all(ev["valid"]),
  "first": default[0]["scene_id"] == t.column("scene_id")[0].as_py(),
  "card_example_rows": [ns["scenes"].num_rows, ns["subset"].num_rows],
}}))
"#,
        home = hf_home.path().to_str().unwrap(),
        dir = dir.to_str().unwrap()
    );
    let out: serde_json::Value = serde_json::from_str(python(&script).trim()).unwrap();
    assert_eq!(out["rows"], 40, "{out}");
    assert_eq!(out["ds_rows"], 40, "{out}");
    assert_eq!(out["columns"], out["hf_columns"], "{out}");
    assert_eq!(out["columns"], out["ds_columns"], "{out}");
    assert!(out["eval_rows"].as_u64().unwrap() > 0, "{out}");
    assert_eq!(out["ds_eval_rows"], out["eval_rows"], "{out}");
    assert_eq!(
        out["card_example_rows"],
        serde_json::json!([out["rows"], out["eval_rows"]]),
        "the card's example code loads this dataset: {out}"
    );
    assert_eq!(out["eval_all_valid"], true, "{out}");
    assert_eq!(out["first"], true, "{out}");
    assert_eq!(out["row_group_rows"], 40, "{out}");
    assert!(
        out["impact_point"].as_str().unwrap().contains("length=3"),
        "{out}"
    );
    assert!(
        out["trajectory"].as_str().unwrap().contains("float32"),
        "{out}"
    );
    assert!(out["valid"].as_str().unwrap().contains("bool"), "{out}");
}

/// Label rule v5 re-derived from the stored columns alone (and the build's label config
/// in `build.json`): `harm_ratio` is the larger of `harm_energy` and `harm_force` over
/// the limits of `harm_region` (ISO/TS 15066 Annex A, `configs/labels.toml`);
/// `danger_present` holds exactly when that ratio is ≥ 1 or a sharp or hot hazard pressed
/// on the body (`strike_impulse` > 0); no DODGE scene's hazard leaves the standing body untouched, and every DODGE
/// scene has danger present.
#[test]
fn dataset_labels_rederive_from_the_stored_harm_columns() {
    let (_, dir) = single();
    let script = format!(
        r#"
import json
import pyarrow.parquet as pq
d = {dir:?}
t = pq.read_table(d + "/data/test-00000-of-00001.parquet").to_pylist()
labels = json.load(open(d + "/build.json"))["config"]["labels"]
f = labels["harm_transient_factor"]
bad, touched, dodge, harm = [], 0, 0, 0
for r in t:
    region = r["harm_region"]
    sharp = any(h in ("sharp", "hot") for h in r["hazards"])
    if region is None:
        ratio, hit = 0.0, False
        if r["harm_energy"] is not None or r["harm_ratio"] is not None:
            bad.append((r["scene_id"], "harm numbers without a region"))
    else:
        touched += 1
        lim = labels["harm"][region]
        e_max = (f * lim["force_n"]) ** 2 / (2 * lim["spring_n_per_mm"] * 1000)
        ratio = max(r["harm_energy"] / e_max, r["harm_force"] / lim["force_n"])
        if abs(ratio - r["harm_ratio"]) > 1e-9 * max(1.0, ratio):
            bad.append((r["scene_id"], "ratio", ratio, r["harm_ratio"]))
        hit = (r["strike_impulse"] or 0.0) > 0.0
    present = ratio >= 1.0 or (hit and sharp)
    if present != r["danger_present"]:
        bad.append((r["scene_id"], "danger_present", r["danger_present"], region, ratio))
    if r["gt_action"] == "DODGE":
        dodge += 1
        if region is None or not r["danger_present"]:
            bad.append((r["scene_id"], "DODGE without harm", region))
    harm += r["danger_present"]
print(json.dumps({{"bad": bad, "rows": len(t), "touched": touched, "dodge": dodge, "harm": harm,
  "rule": sorted(set(r["label_rule"] for r in t))}}))
"#,
        dir = dir.to_str().unwrap()
    );
    let out: serde_json::Value = serde_json::from_str(python(&script).trim()).unwrap();
    assert_eq!(out["bad"], serde_json::json!([]), "{out}");
    assert_eq!(out["rule"], serde_json::json!(["v6"]), "{out}");
    assert!(out["touched"].as_u64().unwrap() >= 5, "{out}");
    assert!(out["dodge"].as_u64().unwrap() >= 3, "{out}");
    eprintln!("{out}");
}

/// The card as the Hub renders it (CommonMark): prose never becomes an indented code
/// block (a paragraph indented four or more spaces after a blank line), and the only code
/// blocks are fenced: the examples (python, sh), the layout tree and the citation.
#[test]
fn the_card_parses_as_commonmark_without_indented_code() {
    use pulldown_cmark::{CodeBlockKind, Event, Parser, Tag};
    let (_dir, out) = single();
    let card = fs::read_to_string(out.join("README.md")).unwrap();
    // The YAML front matter (`---` … `---`) is the Hub's metadata, not Markdown.
    let body = card
        .strip_prefix("---\n")
        .and_then(|rest| rest.split_once("\n---\n"))
        .map(|(_, body)| body)
        .expect("the card starts with YAML front matter");
    let mut fenced = Vec::new();
    let mut headings = 0;
    for event in Parser::new(body) {
        match event {
            Event::Start(Tag::CodeBlock(CodeBlockKind::Indented)) => {
                panic!("the card has an indented code block (prose indented 4+ spaces?)")
            }
            Event::Start(Tag::CodeBlock(CodeBlockKind::Fenced(lang))) => {
                fenced.push(lang.to_string())
            }
            Event::Start(Tag::Heading { .. }) => headings += 1,
            _ => {}
        }
    }
    assert!(
        headings >= 5,
        "{headings} headings: the card did not parse as Markdown"
    );
    assert!(
        fenced
            .iter()
            .all(|l| ["", "python", "sh", "bibtex"].contains(&l.as_str())),
        "{fenced:?}"
    );
    assert!(fenced.iter().any(|l| l == "python"), "{fenced:?}");
    // Nothing is HTML (a bare `list<string>` would be read as a tag and vanish): every
    // feature type is visible text of the rendered table.
    let opts = pulldown_cmark::Options::ENABLE_TABLES;
    let html: Vec<String> = Parser::new_ext(body, opts)
        .filter_map(|e| match e {
            Event::Html(h) | Event::InlineHtml(h) => Some(h.to_string()),
            _ => None,
        })
        .collect();
    assert!(html.is_empty(), "raw HTML in the card: {html:?}");
    let code: Vec<String> = Parser::new_ext(body, opts)
        .filter_map(|e| match e {
            Event::Code(c) => Some(c.to_string()),
            _ => None,
        })
        .collect();
    for t in ["list<string>", "float64[3]", "bool", "string"] {
        assert!(
            code.iter().any(|c| c == t),
            "the rendered card shows no `{t}`"
        );
    }
    assert!(Parser::new("| a | list<string> |").any(|e| matches!(e, Event::InlineHtml(_))));
    // Counter-check that the test can fail: the same text with one paragraph indented.
    let broken = format!("Intro.\n\n    **Segmentation and depth.** prose\n");
    assert!(Parser::new(&broken)
        .any(|e| matches!(e, Event::Start(Tag::CodeBlock(CodeBlockKind::Indented)))));
}

/// The card's YAML front matter parses (the Hub's metadata: licence, configs) and its
/// BibTeX entries parse, each with a title and a year.
#[test]
fn the_card_front_matter_and_citations_parse() {
    let (_dir, out) = single();
    let script = format!(
        r#"
import json, yaml, bibtexparser
card = open({card:?}).read()
front = yaml.safe_load(card.split("---\n")[1])
bib = card.split("```bibtex\n")[1].split("```")[0]
lib = bibtexparser.parse_string(bib)
print(json.dumps({{
  "license": front["license"],
  "configs": [c["config_name"] for c in front["configs"]],
  "entries": [[e.entry_type, e.key, "title" in e.fields_dict, "year" in e.fields_dict] for e in lib.entries],
  "failed": len(lib.failed_blocks),
}}))
"#,
        card = out.join("README.md").display().to_string()
    );
    let v: serde_json::Value = serde_json::from_str(rh_e2e::python(&script).trim()).unwrap();
    assert_eq!(v["license"], "cc-by-4.0", "{v}");
    assert_eq!(v["configs"], serde_json::json!(["default", "eval"]), "{v}");
    assert_eq!(v["failed"], 0, "{v}");
    let entries = v["entries"].as_array().unwrap();
    assert_eq!(entries.len(), 2, "{v}");
    for e in entries {
        assert_eq!(e[0], "misc", "{v}");
        assert!(e[2].as_bool().unwrap() && e[3].as_bool().unwrap(), "{v}");
    }
}

/// A build whose stderr is a log (not a terminal) prints a progress line every
/// `--progress-every` seconds: scenes done of total, rate, ETA.
#[test]
fn a_logged_build_prints_progress_with_an_eta() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("progress");
    let args = [
        "build",
        "--n",
        "240",
        "--no-render",
        "--progress-every",
        "0.05",
        "--out",
        out.to_str().unwrap(),
    ];
    let run_out = run("rh-pipeline", &args);
    let err = String::from_utf8_lossy(&run_out.stderr);
    assert!(run_out.status.success(), "{err}");
    let lines: Vec<&str> = err
        .lines()
        .filter(|l| l.starts_with("building: "))
        .collect();
    assert!(!lines.is_empty(), "no progress line in:\n{err}");
    assert!(
        lines
            .iter()
            .all(|l| l.contains("/240 scenes") && l.contains("ETA")),
        "{lines:?}"
    );
    let bad = run(
        "rh-pipeline",
        &[
            "build",
            "--n",
            "4",
            "--progress-every",
            "0",
            "--out",
            out.to_str().unwrap(),
        ],
    );
    assert_eq!(bad.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&bad.stderr).contains("--progress-every"));
}
