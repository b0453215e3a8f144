//! Integrity end to end: `verify` catches a flipped byte in the data Parquet, a spec edit
//! that leaves the physics alone (a label threshold, `selection.object_id`), a deleted
//! spec; `merge` checks shard checksums first; a finished build notices a missing or
//! altered file and rebuilds only that group, byte-identical; a build refuses a
//! directory holding unrelated files.

use rh_e2e::{files_under, run, run_ok};
use std::fs;
use std::path::{Path, PathBuf};
use std::process::Output;
use std::sync::OnceLock;

const FAMILIES: &str = "object_drop,rolling_ball";

fn build_args<'a>(out: &'a str, extra: &[&'a str]) -> Vec<&'a str> {
    let mut a = vec![
        "build",
        "--n",
        "8",
        "--seed",
        "11",
        "--no-render",
        "--quiet",
        "--families",
        FAMILIES,
        "--out",
        out,
    ];
    a.extend_from_slice(extra);
    a
}

/// One reference build, shared (read only) by the tests.
fn reference() -> &'static (tempfile::TempDir, PathBuf) {
    static REF: OnceLock<(tempfile::TempDir, PathBuf)> = OnceLock::new();
    REF.get_or_init(|| {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("ref");
        run_ok("rh-pipeline", &build_args(out.to_str().unwrap(), &[]));
        (dir, out)
    })
}

/// A private copy of the reference build.
fn copy_of_reference(into: &Path) -> PathBuf {
    let (_, reference) = reference();
    let dest = into.join("copy");
    for (name, bytes) in files_under(reference) {
        let path = dest.join(&name);
        fs::create_dir_all(path.parent().unwrap()).unwrap();
        fs::write(path, bytes).unwrap();
    }
    dest
}

fn verify(dir: &Path, fast: bool) -> (Option<i32>, String, String) {
    let mut args = vec!["verify", dir.to_str().unwrap()];
    if fast {
        args.push("--fast");
    }
    let out: Output = run("rh-pipeline", &args);
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stdout).to_string(),
        String::from_utf8_lossy(&out.stderr).to_string(),
    )
}

fn first_spec(dir: &Path) -> PathBuf {
    let mut specs: Vec<PathBuf> = fs::read_dir(dir.join("specs"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    specs.sort();
    specs.remove(0)
}

/// Rewrites a spec with one field changed, in the build's own formatting.
fn edit_spec(path: &Path, edit: impl FnOnce(&mut serde_json::Value)) {
    let mut spec: serde_json::Value =
        serde_json::from_str(&fs::read_to_string(path).unwrap()).unwrap();
    edit(&mut spec);
    fs::write(path, serde_json::to_string_pretty(&spec).unwrap() + "\n").unwrap();
}

#[test]
fn a_clean_build_verifies_and_records_every_file() {
    let (_, reference) = reference();
    let manifest: serde_json::Value =
        serde_json::from_str(&fs::read_to_string(reference.join("build.json")).unwrap()).unwrap();
    let files = manifest["files"].as_object().unwrap();
    let on_disk = files_under(reference);
    // Every file but the manifest itself, with its true SHA-256.
    assert_eq!(files.len(), on_disk.len() - 1);
    for (name, bytes) in &on_disk {
        if name == "build.json" {
            continue;
        }
        let sha = rh_contract::digest::sha256_hex(bytes);
        assert_eq!(files[name].as_str(), Some(sha.as_str()), "{name}");
    }
    let (code, stdout, stderr) = verify(reference, false);
    assert_eq!(code, Some(0), "{stdout}{stderr}");
    assert!(
        stdout.contains("0 problem(s); 8 scenes derived again: 8 match, 0 differ"),
        "{stdout}"
    );
}

#[test]
fn verify_catches_a_flipped_byte_in_the_data_parquet() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = copy_of_reference(tmp.path());
    let data = dir.join("data/test-00000-of-00001.parquet");
    let mut bytes = fs::read(&data).unwrap();
    let mid = bytes.len() / 2;
    bytes[mid] ^= 0x01;
    fs::write(&data, bytes).unwrap();
    let (code, stdout, stderr) = verify(&dir, false);
    assert_eq!(code, Some(2), "{stdout}{stderr}");
    assert!(
        stdout.contains("FILE data/test-00000-of-00001.parquet: altered"),
        "{stdout}"
    );
    assert!(stderr.contains("file problem"), "{stderr}");
}

#[test]
fn verify_catches_spec_edits_that_leave_the_physics_alone() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = copy_of_reference(tmp.path());
    let spec = first_spec(&dir);
    let id = spec.file_stem().unwrap().to_string_lossy().to_string();
    edit_spec(&spec, |s| {
        let r = s["labels"]["reach_radius"].as_f64().unwrap();
        s["labels"]["reach_radius"] = serde_json::json!(r + 0.5);
    });
    // The replay-only check cannot see it: the physics is the same.
    let (code, stdout, _) = verify(&dir, true);
    assert_eq!(code, Some(0), "{stdout}");
    let (code, stdout, _) = verify(&dir, false);
    assert_eq!(code, Some(2), "{stdout}");
    assert!(stdout.contains(&format!("MISMATCH {id}")), "{stdout}");
    assert!(stdout.contains("`labels.reach_radius`"), "{stdout}");
    assert!(
        stdout.contains(&format!("FILE specs/{id}.json: altered")),
        "{stdout}"
    );

    // The same for the selection's object (what the scene claims to show).
    let tmp2 = tempfile::tempdir().unwrap();
    let dir = copy_of_reference(tmp2.path());
    let spec = first_spec(&dir);
    edit_spec(&spec, |s| {
        s["selection"]["object_id"] = serde_json::json!("not_the_object")
    });
    let (code, stdout, _) = verify(&dir, false);
    assert_eq!(code, Some(2), "{stdout}");
    assert!(stdout.contains("`selection.object_id`"), "{stdout}");
}

#[test]
fn verify_catches_an_edited_label_in_the_parquet_even_with_matching_checksums() {
    // Rewrite the Parquet with one label changed and record the new file's checksum in
    // build.json, as a careful forger would: the re-derived labels still catch it.
    let tmp = tempfile::tempdir().unwrap();
    let dir = copy_of_reference(tmp.path());
    let data = dir.join("data/test-00000-of-00001.parquet");
    let script = format!(
        "import pyarrow.parquet as pq, pyarrow as pa, hashlib, json\n\
         t = pq.read_table('{d}')\n\
         a = t.column('gt_action').to_pylist()\n\
         a[0] = 'DODGE' if a[0] != 'DODGE' else 'CATCH'\n\
         t = t.set_column(t.schema.get_field_index('gt_action'), t.schema.field('gt_action'), pa.array(a, pa.string()))\n\
         pq.write_table(t, '{d}', use_compliant_nested_type=False)\n\
         m = json.load(open('{m}'))\n\
         m['files']['data/test-00000-of-00001.parquet'] = hashlib.sha256(open('{d}','rb').read()).hexdigest()\n\
         json.dump(m, open('{m}','w'), indent=2)\n",
        d = data.display(),
        m = dir.join("build.json").display()
    );
    rh_e2e::python(&script);
    let (code, stdout, _) = verify(&dir, false);
    assert_eq!(code, Some(2), "{stdout}");
    assert!(stdout.contains("column gt_action: stored"), "{stdout}");
    assert!(!stdout.contains("FILE data/"), "{stdout}");
}

#[test]
fn a_deleted_spec_is_caught_and_a_rerun_rebuilds_only_its_group() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = copy_of_reference(tmp.path());
    let spec = first_spec(&dir);
    let rel = format!("specs/{}", spec.file_name().unwrap().to_string_lossy());
    fs::remove_file(&spec).unwrap();
    let (code, stdout, _) = verify(&dir, false);
    assert_eq!(code, Some(2), "{stdout}");
    assert!(stdout.contains(&format!("FILE {rel}: missing")), "{stdout}");

    // The finished build, run again, is no longer "nothing to do": it recomputes the
    // one group and ends byte-identical to the reference.
    let out = run(
        "rh-pipeline",
        &build_args(dir.to_str().unwrap(), &["--json"]),
    );
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{stderr}");
    let summary: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(summary["computed_groups"], 1, "{summary}");
    assert_eq!(summary["resumed_groups"], 1, "{summary}");
    assert!(
        files_under(&dir) == files_under(&reference().1),
        "repaired build differs"
    );

    // An altered data file: every group is rebuilt (its rows cannot be trusted), same bytes.
    let data = dir.join("data/test-00000-of-00001.parquet");
    let mut bytes = fs::read(&data).unwrap();
    let last = bytes.len() - 100;
    bytes[last] ^= 0xff;
    fs::write(&data, bytes).unwrap();
    let out = run(
        "rh-pipeline",
        &build_args(dir.to_str().unwrap(), &["--json"]),
    );
    let summary: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(summary["computed_groups"], 2, "{summary}");
    assert!(
        files_under(&dir) == files_under(&reference().1),
        "repaired build differs"
    );
}

#[test]
fn merge_checks_shard_checksums_and_equals_the_single_build() {
    let tmp = tempfile::tempdir().unwrap();
    let shards: Vec<PathBuf> = (0..2).map(|i| tmp.path().join(format!("s{i}"))).collect();
    for (i, s) in shards.iter().enumerate() {
        let shard = format!("{i}/2");
        run_ok(
            "rh-pipeline",
            &build_args(s.to_str().unwrap(), &["--shard", &shard]),
        );
    }
    let merged = tmp.path().join("merged");
    let args = |out: &Path| -> Vec<String> {
        let mut a = vec!["merge".to_string(), out.display().to_string()];
        a.extend(shards.iter().map(|s| s.display().to_string()));
        a
    };
    let a = args(&merged);
    run_ok(
        "rh-pipeline",
        &a.iter().map(|s| s.as_str()).collect::<Vec<_>>(),
    );
    assert!(
        files_under(&merged) == files_under(&reference().1),
        "merge differs from the single build"
    );

    // A flipped byte in a shard's spec: refused before anything is written, naming it.
    let spec = first_spec(&shards[1]);
    let mut bytes = fs::read(&spec).unwrap();
    bytes[10] ^= 0x01;
    fs::write(&spec, bytes).unwrap();
    let merged2 = tmp.path().join("merged2");
    let a = args(&merged2);
    let out = run(
        "rh-pipeline",
        &a.iter().map(|s| s.as_str()).collect::<Vec<_>>(),
    );
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains(spec.file_name().unwrap().to_str().unwrap()) && stderr.contains("altered"),
        "{stderr}"
    );
    assert!(!merged2.exists());

    // A killed merge's staging folder is removed by the next merge into the same OUT.
    let stale = tmp.path().join(".merged3.rh-merge.999999999");
    fs::create_dir_all(stale.join("specs")).unwrap();
    fs::write(stale.join("specs/x.json"), "{}").unwrap();
    fs::write(
        &spec,
        fs::read(reference().1.join(spec.strip_prefix(&shards[1]).unwrap())).unwrap(),
    )
    .unwrap();
    let merged3 = tmp.path().join("merged3");
    let a = args(&merged3);
    run_ok(
        "rh-pipeline",
        &a.iter().map(|s| s.as_str()).collect::<Vec<_>>(),
    );
    assert!(!stale.exists(), "stale merge folder left behind");
}

#[test]
fn build_refuses_a_directory_holding_unrelated_files() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("mine");
    fs::create_dir_all(&out).unwrap();
    fs::write(out.join("notes.txt"), "mine").unwrap();
    let res = run("rh-pipeline", &build_args(out.to_str().unwrap(), &[]));
    let stderr = String::from_utf8_lossy(&res.stderr);
    assert_eq!(res.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("not empty") && stderr.contains("notes.txt"),
        "{stderr}"
    );
    assert_eq!(
        fs::read_dir(&out).unwrap().count(),
        1,
        "the build wrote into it"
    );
}

#[test]
fn a_missing_speed_bands_entry_names_the_config_file() {
    let tmp = tempfile::tempdir().unwrap();
    let configs = Path::new(env!("CARGO_MANIFEST_DIR")).join("../configs");
    fs::copy(configs.join("labels.toml"), tmp.path().join("labels.toml")).unwrap();
    let default = fs::read_to_string(configs.join("default.toml")).unwrap();
    let without: String = default
        .lines()
        .filter(|l| !l.trim_start().starts_with("rolling_ball ="))
        .map(|l| format!("{l}\n"))
        .collect();
    assert_ne!(without, default);
    let config = tmp.path().join("mine.toml");
    fs::write(&config, without).unwrap();
    let out = tmp.path().join("out");
    let res = run(
        "rh-pipeline",
        &[
            "--config",
            config.to_str().unwrap(),
            "build",
            "--n",
            "4",
            "--families",
            "rolling_ball",
            "--no-render",
            "--out",
            out.to_str().unwrap(),
        ],
    );
    let stderr = String::from_utf8_lossy(&res.stderr);
    assert_eq!(res.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("mine.toml")
            && stderr.contains("[speed_bands]")
            && stderr.contains("rolling_ball"),
        "{stderr}"
    );
}
