//! End-to-end tests of `rh-score predict` and the LLM planner against the scripted
//! OpenAI-compatible test server (`tests/llm_server.py`, on 127.0.0.1, bounded in time,
//! stopped by PID), over a small rendered build (4 scenes of one family at 160×96):
//! answers in every form and refusals, the report's prompt version and lost decisions,
//! resume after SIGKILL with a torn last line, the response cache, retries of every
//! transient failure, 429 with and without Retry-After, a hang past the timeout, lost
//! decisions and `--retry-errors`, `--max-cost`, a fatal 401, the API key never in any
//! output, `--dry-run`, paper-layout datasets, and the planner's validation, re-asking,
//! fallback and cache.

use rh_e2e::{bin, run, run_ok};
use serde_json::Value;
use std::collections::BTreeSet;
use std::io::BufRead;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::sync::OnceLock;
use std::time::{Duration, Instant};

const KEY: &str = "sk-test-DO-NOT-LEAK-5f1e2d";

/// The shared small rendered build (built once per test binary).
fn dataset() -> &'static Path {
    static DS: OnceLock<PathBuf> = OnceLock::new();
    DS.get_or_init(|| {
        let root = std::env::temp_dir().join(format!("rh-predict-e2e-{}", std::process::id()));
        std::fs::create_dir_all(&root).unwrap();
        let configs = Path::new(env!("CARGO_MANIFEST_DIR")).join("../configs");
        let default = std::fs::read_to_string(configs.join("default.toml")).unwrap();
        let small = default
            .replace("\nwidth = 1280\n", "\nwidth = 160\n")
            .replace("\nheight = 720\n", "\nheight = 96\n")
            .replace("\nfull_width = 640\n", "\nfull_width = 160\n")
            .replace("\nfull_height = 360\n", "\nfull_height = 96\n");
        assert_ne!(small, default, "the [render] keys moved; update this test");
        for name in ["labels.toml", "scoring.toml"] {
            std::fs::copy(configs.join(name), root.join(name)).unwrap();
        }
        let cfg = root.join("small.toml");
        std::fs::write(&cfg, small).unwrap();
        let out = root.join("ds");
        run_ok(
            "rh-pipeline",
            &[
                "--config",
                cfg.to_str().unwrap(),
                "build",
                "--n",
                "4",
                "--seed",
                "5",
                "--quiet",
                "--families",
                "object_drop",
                "--out",
                out.to_str().unwrap(),
            ],
        );
        out
    })
}

struct Server {
    child: Child,
    port: u16,
    log: PathBuf,
}

impl Drop for Server {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

impl Server {
    fn start(dir: &Path, script: &str, then: &str, extra: &[&str]) -> Server {
        let log = dir.join(format!("server-{}.log", rand_suffix()));
        let mut child = Command::new("python3")
            .arg(Path::new(env!("CARGO_MANIFEST_DIR")).join("llm_server.py"))
            .args([
                "--script",
                script,
                "--then",
                then,
                "--lifetime",
                "240",
                "--hang",
                "3",
            ])
            .arg("--log")
            .arg(&log)
            .args(extra)
            .stdout(Stdio::piped())
            .spawn()
            .expect("python3");
        let mut line = String::new();
        std::io::BufReader::new(child.stdout.take().unwrap())
            .read_line(&mut line)
            .unwrap();
        let port = line
            .trim()
            .strip_prefix("PORT ")
            .expect("PORT line")
            .parse()
            .unwrap();
        Server { child, port, log }
    }

    fn url(&self) -> String {
        format!("http://127.0.0.1:{}/v1", self.port)
    }

    fn requests(&self) -> Vec<Value> {
        std::fs::read_to_string(&self.log)
            .unwrap_or_default()
            .lines()
            .map(|l| serde_json::from_str(l).unwrap())
            .collect()
    }
}

fn rand_suffix() -> String {
    use std::sync::atomic::{AtomicU64, Ordering};
    static N: AtomicU64 = AtomicU64::new(0);
    format!(
        "{}-{}",
        std::process::id(),
        N.fetch_add(1, Ordering::SeqCst)
    )
}

/// A runner config with quick backoff (the real one waits seconds).
fn fast_config(dir: &Path) -> PathBuf {
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../configs/predict.toml"),
    )
    .unwrap();
    let fast = text
        .replace("backoff_base_s = 1.0", "backoff_base_s = 0.05")
        .replace("backoff_max_s = 30.0", "backoff_max_s = 0.2")
        .replace("max_retries = 4", "max_retries = 9");
    assert_ne!(fast, text);
    let p = dir.join("predict-fast.toml");
    std::fs::write(&p, fast).unwrap();
    p
}

fn predict(dir: &Path, server_url: &str, out: &Path, extra: &[&str]) -> Output {
    Command::new(bin("rh-score"))
        .arg("predict")
        .args([
            "--dataset",
            dataset().to_str().unwrap(),
            "--model",
            "test-model",
        ])
        .arg("--out")
        .arg(out)
        .args([
            "--base-url",
            server_url,
            "--subset",
            "all",
            "--quiet",
            "--json",
        ])
        .arg("--config")
        .arg(fast_config(dir))
        .args(extra)
        .env("OPENAI_API_KEY", KEY)
        .env("RH_LLM_CACHE", dir.join("cache"))
        .env_remove("OPENAI_BASE_URL")
        .output()
        .unwrap()
}

fn ok_json(o: &Output) -> Value {
    assert!(
        o.status.success(),
        "exit {:?}\n{}\n{}",
        o.status.code(),
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
    assert_no_key(&o.stdout);
    assert_no_key(&o.stderr);
    serde_json::from_slice(&o.stdout).unwrap()
}

fn assert_no_key(bytes: &[u8]) {
    assert!(
        !String::from_utf8_lossy(bytes).contains(KEY),
        "the API key leaked: {}",
        String::from_utf8_lossy(bytes)
    );
}

/// Every file under `dir` (but the test server's own request logs, which record the
/// Authorization header it received), checked for the key.
fn assert_no_key_under(dir: &Path) {
    for (name, bytes) in rh_e2e::files_under(dir) {
        if name.starts_with("server-") {
            continue;
        }
        assert!(
            !String::from_utf8_lossy(&bytes).contains(KEY),
            "the API key leaked into {name}"
        );
    }
}

fn lines(path: &Path) -> Vec<Value> {
    let text = std::fs::read_to_string(path).unwrap();
    assert!(text.is_empty() || text.ends_with('\n'), "torn last line");
    text.lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect()
}

/// Asserts every selected scene appears exactly once; returns the scene count.
fn once_each(ls: &[Value], n: usize) {
    let ids: BTreeSet<&str> = ls.iter().map(|l| l["scene_id"].as_str().unwrap()).collect();
    assert_eq!(ids.len(), ls.len(), "a scene appears twice");
    assert_eq!(ls.len(), n);
}

/// One `predict` run in a fresh directory against a fresh test server (scripted replies
/// `script`, then `then`), checked to have written every scene exactly once.
struct FirstRun {
    dir: tempfile::TempDir,
    srv: Server,
    out: PathBuf,
    summary: Value,
    n: usize,
    lines: Vec<Value>,
}

fn first_run(script: &str, then: &str, args: &[&str]) -> FirstRun {
    let dir = tempfile::tempdir().unwrap();
    let srv = Server::start(dir.path(), script, then, &[]);
    let out = dir.path().join("preds.jsonl");
    let summary = ok_json(&predict(dir.path(), &srv.url(), &out, args));
    let n = summary["scenes"].as_u64().unwrap() as usize;
    let ls = lines(&out);
    once_each(&ls, n);
    FirstRun {
        dir,
        srv,
        out,
        summary,
        n,
        lines: ls,
    }
}

#[test]
fn answers_resume_cache_report_and_no_key_anywhere() {
    let price = ["--price-in", "10", "--price-out", "100"];
    let FirstRun {
        dir,
        srv,
        out,
        summary: s,
        n,
        lines: ls,
    } = first_run("refusal", "cycle", &price);
    let d = dir.path();
    assert!(n >= 2, "the build has valid scenes: {s}");
    assert_eq!(srv.requests().len(), n);
    for r in srv.requests() {
        assert_eq!(r["images"], 5, "five ego frames per request");
        assert_eq!(
            r["authorization"].as_str(),
            Some(format!("Bearer {KEY}").as_str())
        );
        assert_eq!(r["model"], "test-model");
    }
    let refusals: Vec<&Value> = ls.iter().filter(|l| l["refusal"] == true).collect();
    assert_eq!(refusals.len(), 1);
    assert!(refusals[0].get("plan").is_none() && refusals[0]["error"].is_null());
    for l in ls.iter().filter(|l| l["refusal"] != true) {
        assert!(
            l["plan"]["keyframes"].is_array(),
            "fenced, prose and bare JSON all parse: {l}"
        );
        assert!(l["error"].is_null());
        // 1000 prompt tokens at $10/M + 100 completion tokens at $100/M.
        assert!((l["usage"]["cost"].as_f64().unwrap() - 0.02).abs() < 1e-12);
        assert_eq!(l["prompt_version"], "rh-prompt-v5");
        assert_eq!(l["prompt_hash"].as_str().unwrap().len(), 64);
        assert!(l["latency_s"].as_f64().unwrap() >= 0.0);
    }
    // Run again: nothing to do, no request.
    let again = ok_json(&predict(d, &srv.url(), &out, &price));
    assert_eq!(again["written"], 0);
    assert_eq!(srv.requests().len(), n);
    // A second output file for the same model: every answer from the cache.
    let out2 = d.join("preds2.jsonl");
    let s2 = ok_json(&predict(d, &srv.url(), &out2, &price));
    assert_eq!(s2["cache_hits"].as_u64().unwrap() as usize, n);
    assert_eq!(srv.requests().len(), n);
    assert!(lines(&out2).iter().all(|l| l["cached"] == true));
    // --no-cache asks again.
    let out3 = d.join("preds3.jsonl");
    ok_json(&predict(d, &srv.url(), &out3, &["--no-cache"]));
    assert_eq!(srv.requests().len(), 2 * n);
    // The report carries the prompt version; the refusal is R1, nothing is lost.
    let rep = run_ok(
        "rh-score",
        &[
            out.to_str().unwrap(),
            "--dataset",
            dataset().to_str().unwrap(),
            "--json",
            "-",
        ],
    );
    let rep: Value = serde_json::from_str(&rep).unwrap();
    assert_eq!(rep["models"][0]["prompt_version"], "rh-prompt-v5");
    assert_eq!(rep["models"][0]["lost"], 0);
    assert_eq!(rep["models"][0]["overall"]["first_rule"]["R1"], 1);
    let table = run_ok(
        "rh-score",
        &[
            out.to_str().unwrap(),
            "--dataset",
            dataset().to_str().unwrap(),
        ],
    );
    assert!(table.contains("rh-prompt-v5"), "{table}");
    assert_no_key_under(d);
}

#[test]
fn transient_failures_are_retried_and_retry_after_is_honoured() {
    let FirstRun {
        dir,
        srv,
        summary: s,
        n,
        lines: ls,
        ..
    } = first_run(
        "429ra=1;429;500;502;503;malformed;empty;drop;hang",
        "bare",
        &["--concurrency", "1", "--timeout", "1", "--no-cache"],
    );
    let d = dir.path();
    assert!(
        ls.iter()
            .all(|l| l["error"].is_null() && l["plan"].is_object()),
        "{ls:?}"
    );
    assert_eq!(s["lost"], 0);
    assert_eq!(s["rate_limited"], 2);
    assert_eq!(
        s["retries"], 7,
        "500, 502, 503, malformed, empty, drop and the hang: {s}"
    );
    assert_eq!(srv.requests().len(), n + 9);
    let first = ls.iter().find(|l| l["attempts"] == 10);
    assert!(first.is_some(), "one decision took ten attempts: {ls:?}");
    // Retry-After: 1 — the next request came at least a second later.
    let r = srv.requests();
    let gap = r[1]["time"].as_f64().unwrap() - r[0]["time"].as_f64().unwrap();
    assert!(gap >= 0.95, "Retry-After not honoured: {gap:.3} s");
    assert_no_key_under(d);
}

#[test]
fn lost_decisions_retry_errors_and_fatal_errors() {
    let args = ["--concurrency", "1", "--max-retries", "1"];
    let FirstRun {
        dir,
        srv,
        out,
        summary: s,
        n,
        lines: ls,
    } = first_run("500;503", "bare", &args);
    let d = dir.path();
    assert_eq!(s["lost"], 1);
    let lost: Vec<&Value> = ls.iter().filter(|l| !l["error"].is_null()).collect();
    assert_eq!(lost.len(), 1);
    assert!(
        lost[0]["error"].as_str().unwrap().contains("503"),
        "{}",
        lost[0]
    );
    assert!(lost[0]["response"].is_null() && lost[0].get("plan").is_none());
    // The scorer counts it as lost, never as R1.
    let rep: Value = serde_json::from_str(&run_ok(
        "rh-score",
        &[
            out.to_str().unwrap(),
            "--dataset",
            dataset().to_str().unwrap(),
            "--json",
            "-",
        ],
    ))
    .unwrap();
    assert_eq!(rep["models"][0]["lost"], 1);
    assert_eq!(rep["input"]["decisions_lost"], 1);
    assert_eq!(rep["models"][0]["overall"]["first_rule"]["R1"], 0);
    // A plain rerun keeps the error line; --retry-errors asks again for it only.
    let before = srv.requests().len();
    ok_json(&predict(d, &srv.url(), &out, &args));
    assert_eq!(srv.requests().len(), before);
    let s = ok_json(&predict(
        d,
        &srv.url(),
        &out,
        &[&args[..], &["--retry-errors"]].concat(),
    ));
    assert_eq!(s["error_lines_retried"], 1);
    assert_eq!(srv.requests().len(), before + 1);
    let ls = lines(&out);
    once_each(&ls, n);
    assert!(ls.iter().all(|l| l["error"].is_null()));
    // A bad key is fatal: exit 2, a clear message, and the key (echoed by the server)
    // is never printed.
    let bad = Server::start(d, "", "401", &[]);
    let o = predict(d, &bad.url(), &d.join("bad.jsonl"), &["--no-cache"]);
    assert_eq!(
        o.status.code(),
        Some(2),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("401"), "{err}");
    assert_no_key(&o.stderr);
    assert_no_key(&o.stdout);
    assert_no_key_under(d);
}

#[test]
fn sigkill_resume_and_max_cost() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let srv = Server::start(d, "", "fenced", &["--delay", "0.5"]);
    let out = d.join("preds.jsonl");
    let cfg = fast_config(d);
    let mut child = Command::new(bin("rh-score"))
        .arg("predict")
        .args([
            "--dataset",
            dataset().to_str().unwrap(),
            "--model",
            "test-model",
        ])
        .arg("--out")
        .arg(&out)
        .args([
            "--base-url",
            &srv.url(),
            "--subset",
            "all",
            "--quiet",
            "--concurrency",
            "1",
        ])
        .arg("--config")
        .arg(&cfg)
        .env("RH_LLM_CACHE", d.join("cache"))
        .env("OPENAI_API_KEY", KEY)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let t = Instant::now();
    while t.elapsed() < Duration::from_secs(20) {
        if std::fs::read_to_string(&out).is_ok_and(|s| s.lines().count() >= 1) {
            break;
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    child.kill().unwrap(); // SIGKILL
    child.wait().unwrap();
    let written = lines(&out).len();
    assert!(written >= 1);
    // What a kill in the middle of a write leaves: a torn last line.
    let mut text = std::fs::read_to_string(&out).unwrap();
    text.push_str("{\"scene_id\": \"0bad\", \"model\": \"te");
    std::fs::write(&out, text).unwrap();
    let s = ok_json(&predict(d, &srv.url(), &out, &[]));
    assert_eq!(s["torn_line_dropped"], true);
    let n = s["scenes"].as_u64().unwrap() as usize;
    assert_eq!(s["already_done"].as_u64().unwrap() as usize, written);
    once_each(&lines(&out), n);

    // --max-cost: each answer costs $0.02; a $0.05 budget stops after two.
    let costly = d.join("costly.jsonl");
    let price = ["--price-in", "10", "--price-out", "100", "--no-cache"];
    let s = ok_json(&predict(
        d,
        &srv.url(),
        &costly,
        &[&price[..], &["--max-cost", "0.05"]].concat(),
    ));
    assert_eq!(s["stopped"], "max_cost");
    assert_eq!(lines(&costly).len(), 2);
    assert!(s["total_cost_usd"].as_f64().unwrap() <= 0.05);
    // The same budget again: nothing more to spend.
    let s = ok_json(&predict(
        d,
        &srv.url(),
        &costly,
        &[&price[..], &["--max-cost", "0.05"]].concat(),
    ));
    assert_eq!(s["written"], 0);
    // A higher one resumes and finishes.
    let s = ok_json(&predict(
        d,
        &srv.url(),
        &costly,
        &[&price[..], &["--max-cost", "10"]].concat(),
    ));
    assert_eq!(s["stopped"], "complete");
    once_each(&lines(&costly), n);
    assert_no_key_under(d);
}

#[test]
fn dry_run_prints_the_request_and_paper_layout_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let o = Command::new(bin("rh-score"))
        .args([
            "predict",
            "--dataset",
            dataset().to_str().unwrap(),
            "--model",
            "m",
        ])
        .args([
            "--dry-run",
            "--subset",
            "all",
            "--base-url",
            "http://127.0.0.1:9/v1",
        ])
        .env("OPENAI_API_KEY", KEY)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_no_key(&o.stdout);
    let v: Value = serde_json::from_slice(&o.stdout).unwrap();
    let msgs = v["body"]["messages"].as_array().unwrap();
    assert!(msgs[0]["content"].as_str().unwrap().contains("Unitree G1"));
    let user = msgs[1]["content"].as_array().unwrap();
    let images: Vec<&str> = user
        .iter()
        .filter_map(|p| p["image_url"]["url"].as_str())
        .collect();
    assert_eq!(images.len(), 5);
    assert!(images
        .iter()
        .all(|u| u.contains("base64 characters elided")));
    assert!(user.iter().any(|p| p["text"] == "t = 0.60 s (ego camera)"));
    assert_eq!(v["prompt_version"], "rh-prompt-v5");
    // Prompt v5 states the scene's head camera: its field of view (the spec's) and pose.
    let camera = user[0]["text"].as_str().unwrap();
    let spec: Value = serde_json::from_slice(
        &std::fs::read(dataset().join(format!("specs/{}.json", v["scene_id"].as_str().unwrap())))
            .unwrap(),
    )
    .unwrap();
    let ego = spec["cameras"]
        .as_array()
        .unwrap()
        .iter()
        .find(|c| c["name"] == "ego")
        .unwrap();
    let fov = ego["fov_y"].as_f64().unwrap().to_degrees();
    assert!(camera.contains(&format!("{fov:.1}° vertical")), "{camera}");
    assert!(
        camera.contains("m in the body frame") && camera.contains("pitch"),
        "{camera}"
    );
    assert_eq!(v["body"]["temperature"], 0.0);
    // The estimate covers the whole run: 4 scenes of 5 images each; no price for "m".
    let e = &v["estimate"];
    assert_eq!(e["scenes"], 4);
    assert_eq!(e["images_per_scene"], 5);
    let per = e["input_tokens_per_scene"].as_u64().unwrap();
    assert!(per > 5 * 85, "{e}");
    assert_eq!(e["input_tokens"].as_u64(), Some(4 * per));
    assert_eq!(e["output_tokens_at_most"], 4 * 1024);
    assert!(e["cost_usd_at_most"].is_null());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("4 scenes ≈") && err.contains("cost unknown"),
        "{err}"
    );

    // The paper's metadata-only layout, and a directory without Parquet.
    let paper = d.join("paper");
    let scene = paper.join("object_drop/object_drop__d1_v1");
    std::fs::create_dir_all(&scene).unwrap();
    std::fs::write(scene.join("metadata.json"), "{}").unwrap();
    std::fs::write(scene.join("spec.json"), "{}").unwrap();
    let preds = d.join("p.jsonl");
    std::fs::write(&preds, "").unwrap();
    for args in [
        vec![
            "predict",
            "--dataset",
            paper.to_str().unwrap(),
            "--model",
            "m",
            "--out",
            preds.to_str().unwrap(),
        ],
        vec![
            preds.to_str().unwrap(),
            "--dataset",
            paper.to_str().unwrap(),
        ],
    ] {
        let o = run("rh-score", &args);
        assert_eq!(o.status.code(), Some(2));
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(
            err.contains("metadata-only") && err.contains("data/*.parquet"),
            "{err}"
        );
    }
    let empty = d.join("empty");
    std::fs::create_dir_all(empty.join("specs")).unwrap();
    let o = run(
        "rh-score",
        &[
            preds.to_str().unwrap(),
            "--dataset",
            empty.to_str().unwrap(),
        ],
    );
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("no data/*.parquet (found: specs/)"), "{err}");
}

fn pipeline(d: &Path, args: &[&str]) -> Output {
    Command::new(bin("rh-pipeline"))
        .args(args)
        .env("RH_LLM_CACHE", d.join("cache"))
        .env("OPENAI_API_KEY", KEY)
        .env("XDG_RUNTIME_DIR", std::env::temp_dir())
        .env_remove("OPENAI_BASE_URL")
        .output()
        .unwrap()
}

#[test]
fn llm_planner_validates_reasks_falls_back_and_caches() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let bad = r#"select:{"family": "juggling", "object_id": "apple", "room_id": "kitchen"}"#;
    let good =
        r#"select:{"family": "bouncing_object", "object_id": "steel_apple", "room_id": "kitchen"}"#;
    let srv = Server::start(d, bad, &good, &[]);
    let text = "someone throws a heavy apple-shaped thing at the robot";
    let o = pipeline(
        d,
        &[
            "plan",
            text,
            "--llm",
            "--model",
            "planner-model",
            "--base-url",
            &srv.url(),
        ],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: Value = serde_json::from_slice(&o.stdout).unwrap();
    let sel = &v["selection"];
    assert_eq!(sel["object_id"], "steel_apple");
    assert_eq!(sel["planner"]["planner"], "llm");
    assert_eq!(sel["planner"]["tries"], 2);
    assert_eq!(sel["description"], text);
    let r = srv.requests();
    assert_eq!(r.len(), 2);
    assert_eq!(
        r[1]["messages"], 4,
        "the re-ask carries the answer and the error"
    );

    // Never a valid answer: the lexicon decides, and the spec says so.
    let never = Server::start(d, "", bad, &[]);
    let desc = d.join("descriptions.txt");
    std::fs::write(&desc, "# one scene group\nan apple rolls off the counter\n").unwrap();
    let out = d.join("built");
    let build = |out: &Path, url: &str| {
        pipeline(
            d,
            &[
                "build",
                "--descriptions",
                desc.to_str().unwrap(),
                "--planner",
                "llm",
                "--model",
                "planner-model",
                "--base-url",
                url,
                "--no-render",
                "--quiet",
                "--seed",
                "2",
                "--out",
                out.to_str().unwrap(),
            ],
        )
    };
    let o = build(&out, &never.url());
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let tries = never.requests().len();
    assert_eq!(tries, 3, "max_tries of configs/planner.toml");
    let specs: Vec<PathBuf> = std::fs::read_dir(out.join("specs"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    assert_eq!(specs.len(), 4, "four speed bands of the one description");
    let spec: Value = serde_json::from_str(&std::fs::read_to_string(&specs[0]).unwrap()).unwrap();
    let sel = &spec["selection"];
    assert_eq!(sel["description"], "an apple rolls off the counter");
    assert_eq!(sel["planner"]["planner"], "lexicon");
    assert!(sel["planner"]["fallback"]
        .as_str()
        .unwrap()
        .contains("no valid selection"));
    assert_eq!(sel["object_id"], "apple");
    // A rebuild from the same descriptions makes no request (the cache answers) and
    // gives the same specs.
    let out2 = d.join("built2");
    let o = build(&out2, &never.url());
    assert!(o.status.success());
    assert_eq!(never.requests().len(), tries);
    let a = rh_e2e::files_under(&out.join("specs"));
    let b = rh_e2e::files_under(&out2.join("specs"));
    assert_eq!(a, b);
    assert_no_key_under(d);
}

/// Safe runs (issue 24): `--max-cost` for a model without a price is refused; a closed
/// port stops the run with exit 2 within 30 s (default client settings) and writes
/// nothing; off a terminal, progress is a line every `progress_every_s`.
#[test]
fn unpriced_budget_dead_endpoint_and_progress_lines() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let base = |url: &str, out: &Path| {
        let mut c = Command::new(bin("rh-score"));
        c.args(["predict", "--dataset", dataset().to_str().unwrap()])
            .args(["--model", "my-local-model", "--subset", "all", "--no-cache"])
            .arg("--out")
            .arg(out)
            .args(["--base-url", url])
            .env_remove("OPENAI_BASE_URL");
        c
    };
    // --max-cost without a price: refused before any request.
    let o = base("http://127.0.0.1:9/v1", &d.join("a.jsonl"))
        .args(["--max-cost", "1"])
        .output()
        .unwrap();
    assert_eq!(
        o.status.code(),
        Some(2),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("price") && err.contains("--price-in"), "{err}");
    assert!(!d.join("a.jsonl").exists());
    // With a price it is accepted (and then the closed port below stops it).
    // A port nobody listens on: bind, take the number, close.
    let port = std::net::TcpListener::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap()
        .port();
    let url = format!("http://127.0.0.1:{port}/v1");
    let out = d.join("dead.jsonl");
    let t = Instant::now();
    let o = base(&url, &out)
        .args(["--max-cost", "1", "--price-in", "1", "--price-out", "1"])
        .output()
        .unwrap();
    let took = t.elapsed();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(took < Duration::from_secs(30), "took {took:?}");
    assert!(
        err.contains("connection refused") && err.contains(&url),
        "{err}"
    );
    assert!(
        std::fs::read_to_string(&out).unwrap_or_default().is_empty(),
        "no lost lines written"
    );
    // A server that answers every request with HTTP 500: the first 4 (every scene here)
    // fail after their retries, and the run stops with exit 2 without writing them.
    let failing = Server::start(d, "", "500", &[]);
    let out = d.join("failing.jsonl");
    let o = base(&failing.url(), &out)
        .arg("--config")
        .arg(fast_config(d))
        .env("OPENAI_API_KEY", KEY)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("first 4 request(s)") && err.contains("500"),
        "{err}"
    );
    assert!(std::fs::read_to_string(&out).unwrap_or_default().is_empty());
    // Progress lines off a terminal (stderr is a pipe here), every 0.3 s.
    let srv = Server::start(d, "", "bare", &["--delay", "0.5"]);
    let cfg = std::fs::read_to_string(fast_config(d))
        .unwrap()
        .replace("progress_every_s = 10.0", "progress_every_s = 0.3");
    assert!(cfg.contains("progress_every_s = 0.3"));
    std::fs::write(d.join("progress.toml"), cfg).unwrap();
    let o = base(&srv.url(), &d.join("p.jsonl"))
        .args(["--concurrency", "1", "--config"])
        .arg(d.join("progress.toml"))
        .env("OPENAI_API_KEY", KEY)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    let progress: Vec<&str> = err
        .lines()
        .filter(|l| l.contains("new scenes done"))
        .collect();
    assert!(progress.len() >= 2, "{err}");
    assert!(
        progress[0].contains("/4 new scenes done")
            && progress[0].contains("ETA")
            && progress[0].contains("lost")
            && progress[0].contains("so far"),
        "{err}"
    );
}

/// Issue 48: `predict` and the scorer share one line-length limit. A 20 MB answer is
/// stored cut to fit `sanity.max_line_bytes` (16 MiB), marked `truncated`, with the plan
/// parsed from the whole answer: the decision is scored, not lost as `line_too_long`.
#[test]
fn a_20_mb_answer_is_stored_within_the_line_limit_and_scored() {
    let FirstRun {
        dir, out, lines, ..
    } = first_run("huge:20", "bare", &["--limit", "2"]);
    let limit = 16 * 1024 * 1024;
    let text = std::fs::read(&out).unwrap();
    for line in text.split(|&b| b == b'\n').filter(|l| !l.is_empty()) {
        assert!(line.len() < limit, "a line of {} bytes", line.len());
    }
    let huge: Vec<&Value> = lines.iter().filter(|l| !l["truncated"].is_null()).collect();
    assert_eq!(huge.len(), 1, "one answer was over the limit");
    let t = &huge[0]["truncated"];
    assert_eq!(t["field"], "response");
    assert!(t["bytes"].as_u64().unwrap() > 20_000_000, "{t}");
    assert_eq!(
        t["kept"].as_u64().unwrap(),
        huge[0]["response"].as_str().unwrap().len() as u64
    );
    assert!(
        huge[0]["plan"].is_object(),
        "the plan of the whole answer is kept"
    );
    let report = dir.path().join("report.json");
    let o = run(
        "rh-score",
        &[
            out.to_str().unwrap(),
            "--dataset",
            dataset().to_str().unwrap(),
            "--subset",
            "all",
            "--json",
            report.to_str().unwrap(),
            "--quiet",
        ],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let r: Value = serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    assert_eq!(
        r["models"][0]["coverage"]["answered"], 2,
        "{}",
        r["models"][0]["coverage"]
    );
    let warnings = r["input"]["warnings"].to_string();
    assert!(!warnings.contains("line_too_long"), "{warnings}");
}
