//! `rh-pipeline download` and `rh-score --dataset owner/name` against a local stand-in
//! for the Hugging Face Hub: a small HTTP server on 127.0.0.1 that serves a freshly built
//! dataset through the routes the `hf-hub` client calls. The test downloads it into a
//! private HF cache, stops the server, and proves that the cache alone serves both
//! programs; a missing repository is a clear usage error.
//!
//! Network rules: loopback only, one server thread that stops when told to (or after two
//! minutes by itself), bounded request sizes and loops.

use rh_contract::digest::{hex, sha256_hex};
use rh_e2e::{bin, files_under, run_ok};
use std::collections::BTreeMap;
use std::io::{Read, Write};
use std::net::{TcpListener, TcpStream};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

const REPO: &str = "rh-test/tiny";
const COMMIT: &str = "0123456789abcdef0123456789abcdef01234567";
/// The stand-in Hub answers only requests that carry this token (`HF_TOKEN`).
const TOKEN: &str = "hf_rh_test_token";

/// The git blob hash the Hub uses for files not stored in LFS.
fn git_sha1(bytes: &[u8]) -> String {
    use sha1::Digest as _;
    let mut h = sha1::Sha1::new();
    h.update(format!("blob {}\0", bytes.len()).as_bytes());
    h.update(bytes);
    hex(&h.finalize())
}

/// Files the stand-in stores in LFS (as the real dataset's `.gitattributes` does).
fn is_lfs(path: &str) -> bool {
    [".parquet", ".mp4", ".png"]
        .iter()
        .any(|e| path.ends_with(e))
}

/// What the stand-in Hub does with a connection.
#[derive(Clone)]
enum Mode {
    /// Answers like the Hub.
    Serve,
    /// Accepts the connection, then never answers (a hung server).
    Hang,
    /// Answers like the Hub, but serves this file with one byte changed.
    Corrupt(String),
}

/// The stand-in Hub.
struct Hub {
    endpoint: String,
    stop: Arc<AtomicBool>,
    requests: Arc<AtomicUsize>,
    thread: Option<JoinHandle<()>>,
}

impl Hub {
    fn serve(files: BTreeMap<String, Vec<u8>>) -> Hub {
        Hub::serve_mode(files, Mode::Serve)
    }

    fn serve_mode(files: BTreeMap<String, Vec<u8>>, mode: Mode) -> Hub {
        let listener = TcpListener::bind("127.0.0.1:0").unwrap();
        listener.set_nonblocking(true).unwrap();
        let endpoint = format!("http://{}", listener.local_addr().unwrap());
        let stop = Arc::new(AtomicBool::new(false));
        let requests = Arc::new(AtomicUsize::new(0));
        let (stop2, requests2) = (stop.clone(), requests.clone());
        let thread = std::thread::spawn(move || {
            let deadline = Instant::now() + Duration::from_secs(120);
            // Connections a hung server holds open (closed when it stops).
            let mut held = Vec::new();
            while !stop2.load(Ordering::SeqCst) && Instant::now() < deadline {
                match listener.accept() {
                    Ok((stream, _)) => {
                        requests2.fetch_add(1, Ordering::SeqCst);
                        match &mode {
                            Mode::Hang => held.push(stream),
                            Mode::Serve => {
                                let _ = handle(stream, &files, None);
                            }
                            Mode::Corrupt(f) => {
                                let _ = handle(stream, &files, Some(f));
                            }
                        }
                    }
                    Err(_) => std::thread::sleep(Duration::from_millis(2)),
                }
            }
            // Dropping the listener closes the port: from now on the Hub is unreachable.
        });
        Hub {
            endpoint,
            stop,
            requests,
            thread: Some(thread),
        }
    }

    fn shutdown(&mut self) {
        self.stop.store(true, Ordering::SeqCst);
        if let Some(t) = self.thread.take() {
            t.join().unwrap();
        }
    }
}

impl Drop for Hub {
    fn drop(&mut self) {
        self.shutdown();
    }
}

fn respond(
    stream: &mut TcpStream,
    status: &str,
    headers: &[(&str, String)],
    body: &[u8],
    head: bool,
) -> std::io::Result<()> {
    let mut text = format!("HTTP/1.1 {status}\r\nConnection: close\r\n");
    let mut has_length = false;
    for (k, v) in headers {
        has_length |= k.eq_ignore_ascii_case("content-length");
        text.push_str(&format!("{k}: {v}\r\n"));
    }
    if !has_length {
        text.push_str(&format!("Content-Length: {}\r\n", body.len()));
    }
    text.push_str("\r\n");
    stream.write_all(text.as_bytes())?;
    if !head {
        stream.write_all(body)?;
    }
    stream.flush()
}

fn not_found(stream: &mut TcpStream, code: &str, head: bool) -> std::io::Result<()> {
    let body = format!("{{\"error\":\"{code}\"}}");
    respond(
        stream,
        "404 Not Found",
        &[
            ("Content-Type", "application/json".into()),
            ("X-Error-Code", code.into()),
            ("X-Error-Message", code.into()),
        ],
        body.as_bytes(),
        head,
    )
}

/// One request per connection (the response closes it).
fn handle(
    mut stream: TcpStream,
    files: &BTreeMap<String, Vec<u8>>,
    corrupt: Option<&String>,
) -> std::io::Result<()> {
    stream.set_nonblocking(false)?;
    stream.set_read_timeout(Some(Duration::from_secs(5)))?;
    let mut buf = Vec::new();
    let mut chunk = [0u8; 4096];
    while !buf.windows(4).any(|w| w == b"\r\n\r\n") && buf.len() < 65536 {
        let n = stream.read(&mut chunk)?;
        if n == 0 {
            break;
        }
        buf.extend_from_slice(&chunk[..n]);
    }
    let request = String::from_utf8_lossy(&buf);
    let mut first = request.lines().next().unwrap_or("").split_whitespace();
    let (method, target) = (first.next().unwrap_or(""), first.next().unwrap_or(""));
    let head = method == "HEAD";
    let path = target.split('?').next().unwrap_or("");
    let authorized = request.lines().any(|l| {
        l.to_ascii_lowercase() == format!("authorization: bearer {}", TOKEN.to_ascii_lowercase())
    });
    if !authorized {
        return respond(
            &mut stream,
            "401 Unauthorized",
            &[("X-Error-Message", "Invalid credentials".into())],
            b"{\"error\":\"Invalid credentials\"}",
            head,
        );
    }
    let parts: Vec<&str> = path.trim_start_matches('/').split('/').collect();
    let json = |stream: &mut TcpStream, value: serde_json::Value| {
        respond(
            stream,
            "200 OK",
            &[("Content-Type", "application/json".into())],
            value.to_string().as_bytes(),
            head,
        )
    };
    let known_rev = |rev: &str| rev == "main" || rev == COMMIT;
    match parts.as_slice() {
        // Repo info at a revision: the commit and the file list.
        ["api", "datasets", owner, name, "revision", rev]
            if format!("{owner}/{name}") == REPO && known_rev(rev) =>
        {
            let siblings: Vec<_> = files
                .keys()
                .map(|f| serde_json::json!({ "rfilename": f }))
                .collect();
            json(
                &mut stream,
                serde_json::json!({ "id": REPO, "sha": COMMIT, "siblings": siblings }),
            )
        }
        // The recursive tree listing (one page).
        ["api", "datasets", owner, name, "tree", rev]
            if format!("{owner}/{name}") == REPO && known_rev(rev) =>
        {
            let entries: Vec<_> = files
                .iter()
                .map(|(f, bytes)| {
                    let mut e = serde_json::json!({
                        "type": "file", "path": f, "size": bytes.len(),
                        "oid": git_sha1(bytes),
                    });
                    if is_lfs(f) {
                        e["lfs"] = serde_json::json!({
                            "oid": sha256_hex(bytes), "size": bytes.len(), "pointerSize": 134
                        });
                    }
                    e
                })
                .collect();
            json(&mut stream, serde_json::Value::Array(entries))
        }
        ["datasets", owner, name, "resolve", rev, file @ ..]
            if format!("{owner}/{name}") == REPO && known_rev(rev) =>
        {
            let name = file.join("/");
            match files.get(&name) {
                Some(bytes) => {
                    // The ETag names the true content; a corrupting server still sends
                    // it (as a proxy that damages bodies would).
                    let etag = if is_lfs(&name) {
                        sha256_hex(bytes)
                    } else {
                        git_sha1(bytes)
                    };
                    let mut body = bytes.clone();
                    if corrupt == Some(&name) {
                        let mid = body.len() / 2;
                        body[mid] ^= 0x20;
                    }
                    respond(
                        &mut stream,
                        "200 OK",
                        &[
                            ("Content-Type", "application/octet-stream".into()),
                            ("Content-Length", body.len().to_string()),
                            ("X-Repo-Commit", COMMIT.into()),
                            ("ETag", format!("\"{etag}\"")),
                        ],
                        &body,
                        head,
                    )
                }
                None => not_found(&mut stream, "EntryNotFound", head),
            }
        }
        _ => not_found(&mut stream, "RepoNotFound", head),
    }
}

fn hub_run(name: &str, args: &[&str], endpoint: &str, hf_home: &Path) -> Output {
    hub_run_token(name, args, endpoint, hf_home, Some(TOKEN))
}

fn hub_run_token(
    name: &str,
    args: &[&str],
    endpoint: &str,
    hf_home: &Path,
    token: Option<&str>,
) -> Output {
    hub_cmd(name, args, endpoint, hf_home, token)
        .output()
        .unwrap()
}

fn hub_cmd(
    name: &str,
    args: &[&str],
    endpoint: &str,
    hf_home: &Path,
    token: Option<&str>,
) -> Command {
    let mut cmd = Command::new(bin(name));
    if let Some(t) = token {
        cmd.env("HF_TOKEN", t);
    } else {
        cmd.env_remove("HF_TOKEN");
    }
    cmd.args(args)
        .env("HF_ENDPOINT", endpoint)
        .env("HF_HOME", hf_home)
        .env("XDG_RUNTIME_DIR", std::env::temp_dir())
        .env_remove("HF_HUB_CACHE")
        .env_remove("HUGGINGFACE_HUB_CACHE")
        .env_remove("HF_HUB_OFFLINE")
        .env_remove("HF_TOKEN_PATH")
        .env_remove("HF_HUB_ETAG_TIMEOUT")
        .env_remove("HF_HUB_DOWNLOAD_TIMEOUT")
        .env_remove("RH_DATASET");
    cmd
}

fn ok(out: &Output, what: &str) -> String {
    assert!(
        out.status.success(),
        "{what} failed with {:?}\nstdout:\n{}\nstderr:\n{}",
        out.status.code(),
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout.clone()).unwrap()
}

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
