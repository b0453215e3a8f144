//! `rh-pipeline download` and `rh-score --dataset owner/name` against a local stand-in
//! for the Hugging Face Hub: a small HTTP server on 127.0.0.1 that serves a freshly built
//! dataset through the routes the `hf-hub` client calls. The test downloads it into a
//! private HF cache, stops the server, and proves that the cache alone serves both
//! programs; a missing repository is a clear usage error.
//!
//! Network rules: loopback only, one server thread that stops when told to (or after two
//! minutes by itself), bounded request sizes and loops.

use rh_e2e::{bin, files_under, run_ok};
use sha2::{Digest, Sha256};
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

fn sha256_hex(bytes: &[u8]) -> String {
    Sha256::digest(bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
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
        let listener = TcpListener::bind("127.0.0.1:0").unwrap();
        listener.set_nonblocking(true).unwrap();
        let endpoint = format!("http://{}", listener.local_addr().unwrap());
        let stop = Arc::new(AtomicBool::new(false));
        let requests = Arc::new(AtomicUsize::new(0));
        let (stop2, requests2) = (stop.clone(), requests.clone());
        let thread = std::thread::spawn(move || {
            let deadline = Instant::now() + Duration::from_secs(120);
            while !stop2.load(Ordering::SeqCst) && Instant::now() < deadline {
                match listener.accept() {
                    Ok((stream, _)) => {
                        requests2.fetch_add(1, Ordering::SeqCst);
                        let _ = handle(stream, &files);
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
fn handle(mut stream: TcpStream, files: &BTreeMap<String, Vec<u8>>) -> std::io::Result<()> {
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
                    serde_json::json!({
                        "type": "file", "path": f, "size": bytes.len(),
                        "oid": sha256_hex(bytes),
                    })
                })
                .collect();
            json(&mut stream, serde_json::Value::Array(entries))
        }
        ["datasets", owner, name, "resolve", rev, file @ ..]
            if format!("{owner}/{name}") == REPO && known_rev(rev) =>
        {
            match files.get(&file.join("/")) {
                Some(bytes) => respond(
                    &mut stream,
                    "200 OK",
                    &[
                        ("Content-Type", "application/octet-stream".into()),
                        ("Content-Length", bytes.len().to_string()),
                        ("X-Repo-Commit", COMMIT.into()),
                        ("ETag", format!("\"{}\"", sha256_hex(bytes))),
                    ],
                    bytes,
                    head,
                ),
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
        .env_remove("RH_DATASET")
        .output()
        .unwrap()
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
