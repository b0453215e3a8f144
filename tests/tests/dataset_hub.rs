//! `rh-pipeline download` and `rh-score --dataset owner/name` against a local stand-in
//! for the Hugging Face Hub (`rh_e2e::fake_hub`: a small HTTP server on 127.0.0.1) that
//! serves a freshly built dataset. The test downloads it into a
//! private HF cache, stops the server, and proves that the cache alone serves both
//! programs; a missing repository is a clear usage error.

use rh_contract::digest::sha256_hex;
use rh_e2e::fake_hub::{
    git_sha1, hub_cmd, hub_run, hub_run_token, ok, Hub, Mode, COMMIT, REPO, TOKEN,
};
use rh_e2e::{files_under, run_ok};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::atomic::Ordering;
use std::time::Instant;

#[test]
fn dataset_hub_download_then_offline_from_cache() {
    let tmp = tempfile::tempdir().unwrap();
    let dataset = tmp.path().join("built");
    run_ok(
        "rh-pipeline",
        &[
            "build",
            "--n",
            "16",
            "--seed",
            "3",
            "--no-render",
            "--quiet",
            "--families",
            "object_drop,shelf_slide,ceiling_drop,sliding_object,rolling_ball,thrown_object",
            "--out",
            dataset.to_str().unwrap(),
        ],
    );
    let original = files_under(&dataset);
    let hf_home = tmp.path().join("hf-home");
    let mut hub = Hub::serve(original.clone());
    let endpoint = hub.endpoint.clone();

    // Online: into the cache, and copied out with --out.
    let copy = tmp.path().join("copy");
    let out = hub_run(
        "rh-pipeline",
        &["download", REPO, "--out", copy.to_str().unwrap()],
        &endpoint,
        &hf_home,
    );
    assert_eq!(ok(&out, "download --out").trim(), copy.to_str().unwrap());
    assert!(files_under(&copy) == original, "--out copy differs");
    let snapshot = ok(
        &hub_run("rh-pipeline", &["download", REPO], &endpoint, &hf_home),
        "download",
    );
    let snapshot = PathBuf::from(snapshot.trim());
    let repo_cache = hf_home.join("hub/datasets--rh-test--tiny");
    assert_eq!(snapshot, repo_cache.join("snapshots").join(COMMIT));
    assert!(
        files_under(&snapshot) == original,
        "cached snapshot differs"
    );
    assert_eq!(
        std::fs::read_to_string(repo_cache.join("refs/main"))
            .unwrap()
            .trim(),
        COMMIT
    );

    // A repository the server does not have: exit 2, naming it and the endpoint.
    let out = hub_run(
        "rh-pipeline",
        &["download", "rh-test/missing"],
        &endpoint,
        &hf_home,
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("rh-test/missing") && err.contains(&endpoint),
        "{err}"
    );

    // Without the token the server refuses: exit 2, saying how to give one.
    let out = hub_run_token(
        "rh-pipeline",
        &["download", REPO],
        &endpoint,
        &hf_home,
        None,
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains(REPO) && err.contains("HF_TOKEN"), "{err}");

    // Predictions to score, made from the local copy while the Hub is still up.
    let preds = tmp.path().join("preds.jsonl");
    let text = run_ok(
        "rh-score",
        &["baseline", "oracle", "--dataset", dataset.to_str().unwrap()],
    );
    std::fs::write(&preds, text).unwrap();

    // The Hub goes away: both programs work from the cache alone.
    hub.shutdown();
    let served = hub.requests.load(Ordering::SeqCst);
    assert!(served > 0);
    let offline = ok(
        &hub_run("rh-pipeline", &["download", REPO], &endpoint, &hf_home),
        "offline download",
    );
    assert_eq!(PathBuf::from(offline.trim()), snapshot);
    let copy2 = tmp.path().join("copy2");
    ok(
        &hub_run(
            "rh-pipeline",
            &["download", REPO, "--out", copy2.to_str().unwrap()],
            &endpoint,
            &hf_home,
        ),
        "offline download --out",
    );
    assert!(files_under(&copy2) == original);
    let report = ok(
        &hub_run(
            "rh-score",
            &[preds.to_str().unwrap(), "--dataset", REPO, "--json", "-"],
            &endpoint,
            &hf_home,
        ),
        "offline rh-score",
    );
    let report: serde_json::Value = serde_json::from_str(&report).unwrap();
    assert!(report.to_string().contains("baseline-oracle"));
    assert_eq!(
        hub.requests.load(Ordering::SeqCst),
        served,
        "the stopped Hub was reached"
    );

    // Offline, a repository the cache does not hold: exit 1, naming repo, endpoint, cache.
    let out = hub_run(
        "rh-pipeline",
        &["download", "rh-test/other"],
        &endpoint,
        &hf_home,
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("rh-test/other") && err.contains(&endpoint) && err.contains("cache"),
        "{err}"
    );
}

/// A small dataset to serve (4 scenes, no videos), as a file map.
fn small_dataset(dir: &Path) -> BTreeMap<String, Vec<u8>> {
    run_ok(
        "rh-pipeline",
        &[
            "build",
            "--n",
            "4",
            "--seed",
            "5",
            "--no-render",
            "--quiet",
            "--families",
            "object_drop",
            "--out",
            dir.to_str().unwrap(),
        ],
    );
    files_under(dir)
}

/// Runs with 1-second timeouts and returns (exit code, stderr, stdout, seconds taken).
fn timed(mut cmd: Command) -> (Option<i32>, String, String, f64) {
    let start = Instant::now();
    let out = cmd
        .env("HF_HUB_ETAG_TIMEOUT", "1")
        .env("HF_HUB_DOWNLOAD_TIMEOUT", "1")
        .output()
        .unwrap();
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stderr).to_string(),
        String::from_utf8_lossy(&out.stdout).to_string(),
        start.elapsed().as_secs_f64(),
    )
}

#[test]
fn hung_hub_times_out_to_the_cache_or_a_clear_error() {
    let tmp = tempfile::tempdir().unwrap();
    let files = small_dataset(&tmp.path().join("built"));
    let hung = Hub::serve_mode(files.clone(), Mode::Hang);

    // Nothing cached: a clear error within the timeout, naming the timeout's variables.
    let empty_home = tmp.path().join("empty-home");
    let (code, err, _, secs) = timed(hub_cmd(
        "rh-pipeline",
        &["download", REPO],
        &hung.endpoint,
        &empty_home,
        Some(TOKEN),
    ));
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains("no answer within 1 s") && err.contains("HF_HUB_ETAG_TIMEOUT"),
        "{err}"
    );
    assert!(err.contains("holds no copy"), "{err}");
    assert!(secs < 20.0, "took {secs} s");

    // A complete cached copy: used, exit 0, for both programs.
    let home = tmp.path().join("home");
    let mut good = Hub::serve(files.clone());
    let snapshot = ok(
        &hub_run("rh-pipeline", &["download", REPO], &good.endpoint, &home),
        "download",
    );
    good.shutdown();
    let (code, err, out, secs) = timed(hub_cmd(
        "rh-pipeline",
        &["download", REPO],
        &hung.endpoint,
        &home,
        Some(TOKEN),
    ));
    assert_eq!(code, Some(0), "{err}");
    assert_eq!(out.trim(), snapshot.trim());
    assert!(
        err.contains("comes from the Hugging Face cache") && err.contains("no answer"),
        "{err}"
    );
    assert!(secs < 20.0, "took {secs} s");
    let (code, err, _, _) = timed(hub_cmd(
        "rh-score",
        &["baseline", "majority", "--dataset", REPO],
        &hung.endpoint,
        &home,
        Some(TOKEN),
    ));
    assert_eq!(code, Some(0), "{err}");

    // A partial cache (one file gone), offline: exit 2 naming the missing file.
    let snap = PathBuf::from(snapshot.trim());
    let victim = files
        .keys()
        .find(|k| k.starts_with("specs/"))
        .unwrap()
        .clone();
    std::fs::remove_file(snap.join(&victim)).unwrap();
    let (code, err, _, _) = timed(hub_cmd(
        "rh-pipeline",
        &["download", REPO],
        &hung.endpoint,
        &home,
        Some(TOKEN),
    ));
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains(&victim) && err.contains("missing"), "{err}");
    let mut offline = hub_cmd(
        "rh-pipeline",
        &["download", REPO],
        &hung.endpoint,
        &home,
        Some(TOKEN),
    );
    offline.env("HF_HUB_OFFLINE", "1");
    let (code, err, _, _) = timed(offline);
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains(&victim), "{err}");
}

#[test]
fn corrupt_bodies_never_enter_the_cache_and_bad_blobs_are_refetched() {
    let tmp = tempfile::tempdir().unwrap();
    let files = small_dataset(&tmp.path().join("built"));
    let data = files
        .keys()
        .find(|k| k.ends_with(".parquet") && k.starts_with("data/"))
        .unwrap()
        .clone();
    let spec = files
        .keys()
        .find(|k| k.starts_with("specs/"))
        .unwrap()
        .clone();
    let home = tmp.path().join("home");

    // An LFS file (hash: SHA-256) and a plain one (git blob SHA-1) served altered.
    // (Each into a fresh cache: the other files are stored meanwhile.)
    for (i, victim) in [&data, &spec].into_iter().enumerate() {
        let bad = Hub::serve_mode(files.clone(), Mode::Corrupt(victim.clone()));
        let fresh = tmp.path().join(format!("fresh-{i}"));
        let blobs = fresh.join("hub/datasets--rh-test--tiny/blobs");
        let (code, err, _, _) = timed(hub_cmd(
            "rh-pipeline",
            &["download", REPO],
            &bad.endpoint,
            &fresh,
            Some(TOKEN),
        ));
        assert_eq!(code, Some(1), "{victim}: {err}");
        assert!(
            err.contains(victim.as_str()) && err.contains("corrupt"),
            "{err}"
        );
        // Every blob in the store matches its name; no temporary is left.
        for entry in std::fs::read_dir(&blobs).unwrap() {
            let path = entry.unwrap().path();
            let name = path.file_name().unwrap().to_string_lossy().to_string();
            let bytes = std::fs::read(&path).unwrap();
            let real = if name.len() == 64 {
                sha256_hex(&bytes)
            } else {
                git_sha1(&bytes)
            };
            assert_eq!(real, name, "blob {name} does not match its content");
        }
    }

    // Download whole, then damage one blob in the store.
    let mut good = Hub::serve(files.clone());
    let snapshot = PathBuf::from(
        ok(
            &hub_run("rh-pipeline", &["download", REPO], &good.endpoint, &home),
            "download",
        )
        .trim(),
    );
    let blob = std::fs::canonicalize(snapshot.join(&data)).unwrap();
    let mut bytes = std::fs::read(&blob).unwrap();
    let mid = bytes.len() / 2;
    bytes[mid] ^= 1;
    std::fs::write(&blob, &bytes).unwrap();
    // Offline: reported (exit 2, naming it), not returned.
    let mut offline = hub_cmd(
        "rh-pipeline",
        &["download", REPO],
        &good.endpoint,
        &home,
        Some(TOKEN),
    );
    offline.env("HF_HUB_OFFLINE", "1");
    let (code, err, _, _) = timed(offline);
    assert_eq!(code, Some(2), "{err}");
    assert!(
        err.contains(&data) && err.contains("does not match"),
        "{err}"
    );
    // Online: fetched again, and the snapshot equals the served dataset.
    let (code, err, _, _) = timed(hub_cmd(
        "rh-pipeline",
        &["download", REPO],
        &good.endpoint,
        &home,
        Some(TOKEN),
    ));
    assert_eq!(code, Some(0), "{err}");
    assert!(
        err.contains("does not match its hash; fetching it again"),
        "{err}"
    );
    assert!(
        files_under(&snapshot) == files,
        "snapshot differs after the re-fetch"
    );
    good.shutdown();
}
