//! A local stand-in for the Hugging Face Hub: a small HTTP server on 127.0.0.1 serving
//! dataset repositories through the routes the `hf-hub` client calls (repository info, the
//! tree listing, `resolve`), for the tests of `rh-pipeline download` and `rh-score
//! --dataset owner/name`.
//!
//! Network rules: loopback only, one server thread that stops when told to (or after two
//! minutes by itself), bounded request sizes and loops.

use crate::bin;
use rh_contract::digest::{hex, sha256_hex};
use std::collections::BTreeMap;
use std::io::{Read, Write};
use std::net::{TcpListener, TcpStream};
use std::path::Path;
use std::process::{Command, Output};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// The repository `Hub::serve` serves.
pub const REPO: &str = "rh-test/tiny";
/// The commit every repository of the stand-in is at.
pub const COMMIT: &str = "0123456789abcdef0123456789abcdef01234567";
/// The stand-in Hub answers only requests that carry this token (`HF_TOKEN`).
pub const TOKEN: &str = "hf_rh_test_token";

/// The git blob hash the Hub uses for files not stored in LFS.
pub fn git_sha1(bytes: &[u8]) -> String {
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
pub enum Mode {
    /// Answers like the Hub.
    Serve,
    /// Accepts the connection, then never answers (a hung server).
    Hang,
    /// Answers like the Hub, but serves this file with one byte changed.
    Corrupt(String),
}

/// The stand-in Hub.
pub struct Hub {
    pub endpoint: String,
    stop: Arc<AtomicBool>,
    /// Connections accepted so far.
    pub requests: Arc<AtomicUsize>,
    thread: Option<JoinHandle<()>>,
}

impl Hub {
    /// Serves `files` as repository [`REPO`].
    pub fn serve(files: BTreeMap<String, Vec<u8>>) -> Hub {
        Hub::serve_mode(files, Mode::Serve)
    }

    /// Serves `files` as repository [`REPO`], the way `mode` says.
    pub fn serve_mode(files: BTreeMap<String, Vec<u8>>, mode: Mode) -> Hub {
        Hub::serve_repos(BTreeMap::from([(REPO.to_string(), files)]), mode)
    }

    /// Serves each repository of `repos` (id → its files), at revision `main`, at
    /// [`COMMIT`], and at any other name (a tag).
    pub fn serve_repos(repos: BTreeMap<String, BTreeMap<String, Vec<u8>>>, mode: Mode) -> Hub {
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
                                let _ = handle(stream, &repos, None);
                            }
                            Mode::Corrupt(f) => {
                                let _ = handle(stream, &repos, Some(f));
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

    /// Stops the server and closes its port.
    pub fn shutdown(&mut self) {
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
    repos: &BTreeMap<String, BTreeMap<String, Vec<u8>>>,
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
    let (repo, files) = match parts.as_slice() {
        ["api", "datasets", owner, name, ..] | ["datasets", owner, name, ..] => {
            match repos.get_key_value(&format!("{owner}/{name}")) {
                Some((r, f)) => (r.as_str(), f),
                None => return not_found(&mut stream, "RepoNotFound", head),
            }
        }
        _ => return not_found(&mut stream, "RepoNotFound", head),
    };
    // A revision is `main`, the commit, or a tag (any other name without a slash).
    let known_rev = |rev: &str| !rev.is_empty();
    match parts.as_slice() {
        // Repo info at a revision: the commit and the file list.
        ["api", "datasets", owner, name, "revision", rev]
            if format!("{owner}/{name}") == repo && known_rev(rev) =>
        {
            let siblings: Vec<_> = files
                .keys()
                .map(|f| serde_json::json!({ "rfilename": f }))
                .collect();
            json(
                &mut stream,
                serde_json::json!({ "id": repo, "sha": COMMIT, "siblings": siblings }),
            )
        }
        // The recursive tree listing (one page).
        ["api", "datasets", owner, name, "tree", rev]
            if format!("{owner}/{name}") == repo && known_rev(rev) =>
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
            if format!("{owner}/{name}") == repo && known_rev(rev) =>
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

/// Runs program `name` against the stand-in at `endpoint` with its token.
pub fn hub_run(name: &str, args: &[&str], endpoint: &str, hf_home: &Path) -> Output {
    hub_run_token(name, args, endpoint, hf_home, Some(TOKEN))
}

/// Runs program `name` against `endpoint` with `token` (or none).
pub fn hub_run_token(
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

/// The command of program `name` against `endpoint`, `HF_HOME` at `hf_home`, no
/// other Hub or dataset variable inherited.
pub fn hub_cmd(
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

/// The stdout of a run that must succeed (its output in the panic otherwise).
pub fn ok(out: &Output, what: &str) -> String {
    assert!(
        out.status.success(),
        "{what} failed with {:?}\nstdout:\n{}\nstderr:\n{}",
        out.status.code(),
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout.clone()).unwrap()
}
