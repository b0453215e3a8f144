//! Issue 48, "nothing lost, nothing half-trusted", end to end on the real binaries: every
//! report, table, figure, decision file, results file and export is written whole or not
//! at all (a full disk leaves the previous file as it was, exit 3 naming the file; two
//! concurrent writers never tear one); an unfinished build is refused (exit 2) by score,
//! baseline, export and predict unless `--allow-incomplete`; a closed stdout ends quietly
//! and a full one is exit 3, never a panic.
//!
//! A full disk is a small tmpfs where this machine lets the test mount one (root), and
//! always also a file-size limit (`RLIMIT_FSIZE`, the writes failing with EFBIG), which
//! needs no privileges.

use rh_e2e::{bin, run, run_ok};
use serde_json::Value;
use std::os::unix::process::CommandExt;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::sync::OnceLock;

/// A finished label-only build of 16 scenes, and the oracle's and the random baseline's
/// predictions for it (built once per test binary).
struct Fixture {
    _root: tempfile::TempDir,
    ds: PathBuf,
    oracle: PathBuf,
    random: PathBuf,
}

fn fixture() -> &'static Fixture {
    static F: OnceLock<Fixture> = OnceLock::new();
    F.get_or_init(|| {
        let root = tempfile::tempdir().unwrap();
        let ds = root.path().join("ds");
        run_ok(
            "rh-pipeline",
            &[
                "build",
                "--n",
                "16",
                "--no-render",
                "--quiet",
                "--out",
                s(&ds),
            ],
        );
        let preds = |kind: &str| {
            let p = root.path().join(format!("{kind}.jsonl"));
            std::fs::write(
                &p,
                run_ok("rh-score", &["baseline", kind, "--dataset", s(&ds)]),
            )
            .unwrap();
            p
        };
        let (oracle, random) = (preds("oracle"), preds("random"));
        Fixture {
            _root: root,
            ds,
            oracle,
            random,
        }
    })
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

fn assert_no_panic(o: &Output, what: &str) {
    let err = text(&o.stderr);
    assert!(
        !err.contains("panicked") && !err.contains("RUST_BACKTRACE"),
        "{what} panicked: {err}"
    );
    assert!(
        !matches!(o.status.code(), Some(101 | 134 | 137) | None),
        "{what}: exit {:?}\n{err}",
        o.status.code()
    );
}

/// A tmpfs mounted on a fresh directory (unmounted on drop), if this machine allows it.
struct Tmpfs {
    dir: tempfile::TempDir,
}

impl Tmpfs {
    fn mount(size: &str) -> Option<Tmpfs> {
        let dir = tempfile::tempdir().ok()?;
        let ok = Command::new("mount")
            .args(["-t", "tmpfs", "-o", &format!("size={size}"), "tmpfs"])
            .arg(dir.path())
            .stderr(Stdio::null())
            .status()
            .is_ok_and(|s| s.success());
        ok.then_some(Tmpfs { dir })
    }

    fn path(&self) -> &Path {
        self.dir.path()
    }

    /// Fills the file system up: a filler file written until the disk refuses.
    fn fill(&self) {
        use std::io::Write;
        let mut f = std::fs::File::create(self.path().join("filler")).unwrap();
        let chunk = vec![0u8; 4096];
        while f.write_all(&chunk).is_ok() {}
        let _ = f.flush();
    }

    fn free(&self) {
        let _ = std::fs::remove_file(self.path().join("filler"));
    }
}

impl Drop for Tmpfs {
    fn drop(&mut self) {
        let _ = Command::new("umount").arg(self.dir.path()).status();
    }
}

/// How the disk is full for a command: a filled tmpfs, or a 256-byte file-size limit.
#[derive(Clone, Copy, Debug)]
enum Full {
    Tmpfs,
    FileSizeLimit,
}

fn run_full(full: Full, name: &str, args: &[&str]) -> Output {
    let mut cmd = Command::new(bin(name));
    cmd.args(args);
    if let Full::FileSizeLimit = full {
        // SAFETY: only async-signal-safe calls between fork and exec.
        unsafe {
            cmd.pre_exec(|| {
                libc::signal(libc::SIGXFSZ, libc::SIG_IGN);
                let lim = libc::rlimit {
                    rlim_cur: 256,
                    rlim_max: 256,
                };
                if libc::setrlimit(libc::RLIMIT_FSIZE, &lim) != 0 {
                    return Err(std::io::Error::last_os_error());
                }
                Ok(())
            });
        }
    }
    cmd.output().unwrap()
}

/// Every file under `dir` with its bytes (temporaries included, to see none is left).
fn snapshot(dir: &Path) -> std::collections::BTreeMap<String, Vec<u8>> {
    rh_e2e::files_under(dir)
        .into_iter()
        .filter(|(k, _)| k != "filler")
        .collect()
}

/// The previous outputs survive a full disk, every failure is exit 3 naming the file,
/// and no temporary file is left behind.
fn full_disk_case(full: Full, dir: &Path, fill: &dyn Fn(), free: &dyn Fn()) {
    let f = fixture();
    let p = |name: &str| dir.join(name);
    let score = |preds: &Path, extra: &[&str]| -> Vec<String> {
        let mut a = vec![s(preds).to_string(), "--dataset".into(), s(&f.ds).into()];
        a.extend(extra.iter().map(|x| x.to_string()));
        a.push("--quiet".into());
        a
    };
    let outputs: Vec<(&str, PathBuf)> = vec![
        ("--json", p("keep.json")),
        ("--csv", p("keep.csv")),
        ("--markdown", p("keep.md")),
        ("--decisions", p("keep.jsonl")),
        ("--figures", p("figures")),
        ("--results", p("results")),
    ];
    let mut all: Vec<&str> = Vec::new();
    for (flag, path) in &outputs {
        all.push(flag);
        all.push(s(path));
    }
    let args = score(&f.oracle, &all);
    run_ok(
        "rh-score",
        &args.iter().map(String::as_str).collect::<Vec<_>>(),
    );
    let board = p("board.md");
    let results_file = p("results/baseline-oracle.json");
    run_ok(
        "rh-score",
        &["leaderboard", s(&results_file), "--markdown", s(&board)],
    );
    let before = snapshot(dir);
    assert!(before.len() >= 12, "{:?}", before.keys());
    fill();
    for (flag, path) in &outputs {
        let args = score(&f.random, &[flag, s(path)]);
        let o = run_full(
            full,
            "rh-score",
            &args.iter().map(String::as_str).collect::<Vec<_>>(),
        );
        assert_no_panic(&o, flag);
        let err = text(&o.stderr);
        assert_eq!(o.status.code(), Some(3), "{full:?} {flag}: {err}");
        assert!(
            err.contains("cannot write") && err.contains(s(dir)),
            "{flag}: {err}"
        );
        assert_eq!(
            snapshot(dir),
            before,
            "{full:?} {flag} changed the previous outputs"
        );
    }
    let o = run_full(
        full,
        "rh-score",
        &["leaderboard", s(&results_file), "--markdown", s(&board)],
    );
    assert_eq!(o.status.code(), Some(3), "{}", text(&o.stderr));
    let export = p("export");
    let o = run_full(
        full,
        "rh-score",
        &[
            "export",
            "--dataset",
            s(&f.ds),
            "--split",
            "all",
            "--out",
            s(&export),
        ],
    );
    assert_no_panic(&o, "export");
    assert_eq!(
        o.status.code(),
        Some(3),
        "{full:?} export: {}",
        text(&o.stderr)
    );
    assert!(
        !export.exists(),
        "a failed export leaves no {}",
        export.display()
    );
    let build = p("build");
    let o = run_full(
        full,
        "rh-pipeline",
        &[
            "build",
            "--n",
            "8",
            "--no-render",
            "--quiet",
            "--out",
            s(&build),
        ],
    );
    assert_no_panic(&o, "build");
    assert_eq!(
        o.status.code(),
        Some(3),
        "{full:?} build: {}",
        text(&o.stderr)
    );
    assert!(
        text(&o.stderr).contains("cannot write"),
        "{}",
        text(&o.stderr)
    );
    let _ = std::fs::remove_dir_all(&build);
    assert_eq!(snapshot(dir), before, "{full:?}: something was left behind");
    // With room again, the export runs (no half-written out/ to remove by hand).
    free();
    run_ok(
        "rh-score",
        &[
            "export",
            "--dataset",
            s(&f.ds),
            "--split",
            "all",
            "--out",
            s(&export),
        ],
    );
}

#[test]
fn a_full_disk_keeps_every_previous_output_and_exits_3() {
    let dir = tempfile::tempdir().unwrap();
    full_disk_case(Full::FileSizeLimit, dir.path(), &|| {}, &|| {});
    match Tmpfs::mount("8m") {
        Some(fs) => full_disk_case(Full::Tmpfs, fs.path(), &|| fs.fill(), &|| fs.free()),
        None => eprintln!("no tmpfs here (not root): the file-size limit stood in for a full disk"),
    }
}

#[test]
fn two_concurrent_writers_never_tear_a_report() {
    let f = fixture();
    let dir = tempfile::tempdir().unwrap();
    let reference = |preds: &Path| {
        run_ok(
            "rh-score",
            &[s(preds), "--dataset", s(&f.ds), "--json", "-"],
        )
    };
    let (a, b) = (reference(&f.oracle), reference(&f.random));
    assert_ne!(a, b);
    let out = dir.path().join("same.json");
    for trial in 0..12 {
        let spawn = |preds: &Path| {
            Command::new(bin("rh-score"))
                .args([
                    s(preds),
                    "--dataset",
                    s(&f.ds),
                    "--quiet",
                    "--json",
                    s(&out),
                ])
                .stderr(Stdio::piped())
                .spawn()
                .unwrap()
        };
        let (pa, pb) = (spawn(&f.oracle), spawn(&f.random));
        for child in [pa, pb] {
            let o = child.wait_with_output().unwrap();
            assert!(o.status.success(), "trial {trial}: {}", text(&o.stderr));
        }
        let got = std::fs::read_to_string(&out).unwrap();
        assert!(
            got == a || got == b,
            "trial {trial}: a torn or mixed report"
        );
        serde_json::from_str::<Value>(&got).unwrap();
        let names: Vec<String> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        assert_eq!(names, ["same.json"], "trial {trial}: temporaries left");
    }
}

/// A build stopped before it finished, as a kill leaves it: rows in data/, but no eval/
/// subset and no file checksums in build.json (they are written last).
fn unfinished_copy(dir: &Path) -> PathBuf {
    let f = fixture();
    let ds = dir.join("unfinished");
    for (rel, bytes) in rh_e2e::files_under(&f.ds) {
        if rel.starts_with("eval/") {
            continue;
        }
        let path = ds.join(&rel);
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(&path, bytes).unwrap();
    }
    let manifest = ds.join("build.json");
    let mut m: Value = serde_json::from_str(&std::fs::read_to_string(&manifest).unwrap()).unwrap();
    assert!(m.as_object_mut().unwrap().remove("files").is_some());
    std::fs::write(&manifest, serde_json::to_string_pretty(&m).unwrap()).unwrap();
    ds
}

fn assert_refused_as_unfinished(o: &Output, ds: &Path, what: &str) {
    let err = text(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{what}: {err}");
    assert!(err.contains("is not a finished build"), "{what}: {err}");
    assert!(err.contains("records no file checksums"), "{what}: {err}");
    assert!(
        err.contains(&format!(
            "rh-pipeline build --n 16 --seed 0 --out {}",
            ds.display()
        )),
        "{what}: {err}"
    );
    assert!(err.contains("--allow-incomplete"), "{what}: {err}");
}

#[test]
fn an_unfinished_build_is_refused_until_it_is_finished() {
    let f = fixture();
    let dir = tempfile::tempdir().unwrap();
    let ds = unfinished_copy(dir.path());
    let oracle = s(&f.oracle);
    let score = run("rh-score", &[oracle, "--dataset", s(&ds), "--quiet"]);
    assert_refused_as_unfinished(&score, &ds, "score");
    let out = dir.path().join("x");
    for (what, args) in [
        ("baseline", vec!["baseline", "oracle", "--dataset", s(&ds)]),
        (
            "export",
            vec!["export", "--dataset", s(&ds), "--out", s(&out)],
        ),
        (
            "predict",
            vec!["predict", "--dataset", s(&ds), "--model", "m", "--dry-run"],
        ),
    ] {
        assert_refused_as_unfinished(&run("rh-score", &args), &ds, what);
    }
    assert!(!out.exists());
    // Explicitly allowed: scored over what is there (every valid scene: no eval/ yet).
    let o = run(
        "rh-score",
        &[
            oracle,
            "--dataset",
            s(&ds),
            "--allow-incomplete",
            "--json",
            "-",
        ],
    );
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert!(
        text(&o.stderr).contains("--allow-incomplete"),
        "{}",
        text(&o.stderr)
    );
    // The command the message names finishes it; then it is scored as the whole build.
    run_ok(
        "rh-pipeline",
        &[
            "build",
            "--n",
            "16",
            "--seed",
            "0",
            "--no-render",
            "--quiet",
            "--out",
            s(&ds),
        ],
    );
    let finished = run_ok("rh-score", &[oracle, "--dataset", s(&ds), "--json", "-"]);
    let whole = run_ok("rh-score", &[oracle, "--dataset", s(&f.ds), "--json", "-"]);
    let expected = |t: &str| serde_json::from_str::<Value>(t).unwrap()["coverage"].clone();
    assert_eq!(expected(&finished), expected(&whole));
    // A file the finished build records, gone: refused, naming it.
    let spec = std::fs::read_dir(ds.join("specs"))
        .unwrap()
        .next()
        .unwrap()
        .unwrap();
    std::fs::remove_file(spec.path()).unwrap();
    let o = run("rh-score", &[oracle, "--dataset", s(&ds), "--quiet"]);
    let err = text(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("1 file(s) its build.json records are missing (specs/"),
        "{err}"
    );
}

#[test]
fn a_killed_build_is_refused_and_resumes_to_a_scorable_one() {
    let dir = tempfile::tempdir().unwrap();
    let ds = dir.path().join("killed");
    let args = [
        "build",
        "--n",
        "48",
        "--no-render",
        "--quiet",
        "--jobs",
        "1",
        "--out",
        s(&ds),
    ];
    let mut child = Command::new(bin("rh-pipeline")).args(args).spawn().unwrap();
    let groups = ds.join(".rh-build/groups");
    let t0 = std::time::Instant::now();
    while std::fs::read_dir(&groups).map_or(0, |d| d.count()) == 0 && t0.elapsed().as_secs() < 60 {
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    child.kill().unwrap();
    let status = child.wait().unwrap();
    if status.success() {
        eprintln!("the build finished before it could be killed; nothing to check");
        return;
    }
    let preds = fixture().oracle.clone();
    let o = run("rh-score", &[s(&preds), "--dataset", s(&ds), "--quiet"]);
    let err = text(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("is not a finished build"), "{err}");
    assert!(
        err.contains("rh-pipeline build --n 48 --seed 0 --out"),
        "{err}"
    );
    run_ok("rh-pipeline", &args);
    run_ok("rh-pipeline", &["verify", s(&ds), "--fast"]);
    let b = run_ok("rh-score", &["baseline", "oracle", "--dataset", s(&ds)]);
    assert!(b.lines().count() >= 40, "{b}");
}

/// A pipe whose reader is already gone: every write to it fails with EPIPE.
fn closed_pipe() -> Stdio {
    let (reader, writer) = std::io::pipe().unwrap();
    drop(reader);
    Stdio::from(writer)
}

fn with_stdout(name: &str, args: &[&str], stdout: Stdio) -> Output {
    Command::new(bin(name))
        .args(args)
        .stdout(stdout)
        .stderr(Stdio::piped())
        .output()
        .unwrap()
}

#[test]
fn a_closed_pipe_ends_quietly_and_a_full_stdout_is_exit_3() {
    let f = fixture();
    let dir = tempfile::tempdir().unwrap();
    let results = dir.path().join("results");
    run_ok(
        "rh-score",
        &[
            s(&f.oracle),
            "--dataset",
            s(&f.ds),
            "--results",
            s(&results),
            "--quiet",
        ],
    );
    let board = results.join("baseline-oracle.json");
    let export_a = dir.path().join("export-a");
    let export_b = dir.path().join("export-b");
    let build_a = dir.path().join("build-a");
    let build_b = dir.path().join("build-b");
    let cases: Vec<(&str, Vec<&str>, Vec<&str>)> = vec![
        (
            "rh-pipeline",
            vec!["plan", "a ball rolls off a table"],
            vec![],
        ),
        ("rh-pipeline", vec!["verify", s(&f.ds), "--fast"], vec![]),
        (
            "rh-pipeline",
            vec!["verify", s(&f.ds), "--fast", "--json"],
            vec![],
        ),
        (
            "rh-pipeline",
            vec![
                "balance",
                "--families",
                "object_drop",
                "--per-family",
                "1",
                "--pool",
                "4",
            ],
            vec![],
        ),
        (
            "rh-pipeline",
            vec![
                "build",
                "--n",
                "4",
                "--no-render",
                "--quiet",
                "--json",
                "--out",
            ],
            vec![s(&build_a), s(&build_b)],
        ),
        ("rh-pipeline", vec!["--help"], vec![]),
        ("rh-score", vec!["--explain"], vec![]),
        (
            "rh-score",
            vec![s(&f.oracle), "--dataset", s(&f.ds)],
            vec![],
        ),
        (
            "rh-score",
            vec![s(&f.oracle), "--dataset", s(&f.ds), "--json", "-"],
            vec![],
        ),
        (
            "rh-score",
            vec!["baseline", "oracle", "--dataset", s(&f.ds)],
            vec![],
        ),
        ("rh-score", vec!["leaderboard", s(&board)], vec![]),
        (
            "rh-score",
            vec!["export", "--dataset", s(&f.ds), "--split", "all", "--out"],
            vec![s(&export_a), s(&export_b)],
        ),
    ];
    for (name, args, outs) in cases {
        let with = |i: usize| -> Vec<&str> {
            let mut a = args.clone();
            if let Some(o) = outs.get(i) {
                a.push(o);
            }
            a
        };
        let what = format!("{name} {args:?}");
        let o = with_stdout(name, &with(0), closed_pipe());
        assert_no_panic(&o, &what);
        assert_eq!(
            o.status.code(),
            Some(0),
            "{what} | closed pipe: {}",
            text(&o.stderr)
        );
        let full = std::fs::OpenOptions::new()
            .write(true)
            .open("/dev/full")
            .unwrap();
        let o = with_stdout(name, &with(1), Stdio::from(full));
        assert_no_panic(&o, &what);
        let err = text(&o.stderr);
        assert_eq!(o.status.code(), Some(3), "{what} > /dev/full: {err}");
        assert!(err.contains("cannot write stdout"), "{what}: {err}");
    }
    // A decision file on a device that is full: exit 3 naming it, not the predictions.
    let o = run(
        "rh-score",
        &[
            s(&f.oracle),
            "--dataset",
            s(&f.ds),
            "--quiet",
            "--decisions",
            "/dev/full",
        ],
    );
    let err = text(&o.stderr);
    assert_eq!(o.status.code(), Some(3), "{err}");
    assert!(
        err.contains("/dev/full") && !err.contains("error reading"),
        "{err}"
    );
    assert!(
        !std::fs::metadata("/dev/full").unwrap().is_file(),
        "/dev/full replaced"
    );
    // A full stderr drops the message, never panics: the exit status still says why.
    for (name, args, code) in [
        (
            "rh-score",
            vec![s(&f.oracle), "--dataset", "/nonexistent"],
            2,
        ),
        (
            "rh-pipeline",
            vec!["build", "--n", "0", "--out", "/nonexistent"],
            2,
        ),
    ] {
        let full = std::fs::OpenOptions::new()
            .write(true)
            .open("/dev/full")
            .unwrap();
        let o = Command::new(bin(name))
            .args(&args)
            .stderr(Stdio::from(full))
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(code), "{name} {args:?} 2> /dev/full");
    }
}

fn refused(o: &Output, needles: &[&str], what: &str) {
    assert_no_panic(o, what);
    let err = text(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{what}: {err}");
    for n in needles {
        assert!(err.contains(n), "{what}: `{n}` not in: {err}");
    }
}

#[test]
fn every_number_has_a_bound_checked_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("never");
    for (n, needle) in [
        ("18446744073709551615", "at most 1000000 scenes"),
        ("1000001", "at most 1000000 scenes"),
    ] {
        let o = run(
            "rh-pipeline",
            &["build", "--n", n, "--no-render", "--out", s(&out)],
        );
        refused(&o, &["--n", needle], n);
        assert!(!out.exists(), "--n {n}: {} was written", out.display());
    }
    for (args, needle) in [
        (vec!["--jobs", "100000"], "--jobs 100000: at most 1024"),
        (vec!["--shard", "0/100000"], "at most 10000 shards"),
        (vec!["--progress-every", "1e300"], "at most 86400"),
    ] {
        let mut a = vec!["build", "--n", "4", "--no-render", "--out", s(&out)];
        a.extend(args);
        refused(&run("rh-pipeline", &a), &[needle], needle);
        assert!(!out.exists());
    }
    let balance = run("rh-pipeline", &["balance", "--per-family", "1000000000"]);
    refused(&balance, &["--per-family", "at most 100000"], "balance");
    // A configuration's numbers, named by file and field: the horizon of rh-pipeline
    // has the bound rh-score's has (60 s).
    let configs = Path::new(env!("CARGO_MANIFEST_DIR")).join("../configs");
    let default = std::fs::read_to_string(configs.join("default.toml")).unwrap();
    let labels = std::fs::read_to_string(configs.join("labels.toml")).unwrap();
    std::fs::write(dir.path().join("labels.toml"), &labels).unwrap();
    let cfg = dir.path().join("big.toml");
    for (from, to, field) in [
        (
            "horizon_s = 4.0",
            "horizon_s = 1e9",
            "field 'physics.horizon_s'",
        ),
        (
            "\nwidth = 1280\n",
            "\nwidth = 4000000000\n",
            "field 'render.width'",
        ),
        (
            "solver_iterations = 2",
            "solver_iterations = 1000000000",
            "field 'physics.solver_iterations'",
        ),
    ] {
        let changed = default.replace(from, to);
        assert_ne!(changed, default, "{from} moved");
        std::fs::write(&cfg, changed).unwrap();
        let o = run(
            "rh-pipeline",
            &[
                "--config",
                s(&cfg),
                "build",
                "--n",
                "4",
                "--no-render",
                "--out",
                s(&out),
            ],
        );
        refused(&o, &["big.toml", field, "must be within"], field);
        assert!(!out.exists());
    }
    // A label threshold's error names labels.toml, the file it is in.
    std::fs::write(&cfg, &default).unwrap();
    let bad = labels.replace("escape_directions = 8", "escape_directions = 0");
    assert_ne!(bad, labels);
    std::fs::write(dir.path().join("labels.toml"), bad).unwrap();
    let o = run(
        "rh-pipeline",
        &[
            "--config",
            s(&cfg),
            "build",
            "--n",
            "4",
            "--no-render",
            "--out",
            s(&out),
        ],
    );
    refused(
        &o,
        &["labels.toml: field 'labels.escape_directions'"],
        "labels",
    );
    assert!(!text(&o.stderr).contains("big.toml"), "{}", text(&o.stderr));
    // rh-score's own numbers.
    let f = fixture();
    let scoring = std::fs::read_to_string(configs.join("scoring.toml")).unwrap();
    let huge = scoring.replace(
        "max_line_bytes = 16777216",
        "max_line_bytes = 18446744073709551615",
    );
    assert_ne!(huge, scoring);
    let sc = dir.path().join("scoring.toml");
    std::fs::write(&sc, huge).unwrap();
    let o = run(
        "rh-score",
        &[s(&f.oracle), "--dataset", s(&f.ds), "--config", s(&sc)],
    );
    refused(&o, &["sanity.max_line_bytes"], "max_line_bytes");
    for (flag, v, needle) in [
        (
            "--concurrency",
            "100000000",
            "concurrency 100000000: must be 1-1024",
        ),
        ("--timeout", "1e300", "timeout_s"),
        ("--temperature", "inf", "temperature"),
        ("--max-tokens", "0", "max_tokens"),
    ] {
        let o = run(
            "rh-score",
            &[
                "predict",
                "--dataset",
                s(&f.ds),
                "--model",
                "m",
                "--dry-run",
                flag,
                v,
            ],
        );
        refused(&o, &[needle], flag);
    }
}

#[test]
fn a_bom_a_name_clash_and_the_messages_read_right() {
    let f = fixture();
    let dir = tempfile::tempdir().unwrap();
    // A UTF-8 byte-order mark opens the file; the oracle still scores 100%.
    let bom = dir.path().join("bom.jsonl");
    let mut bytes = b"\xEF\xBB\xBF".to_vec();
    bytes.extend(std::fs::read(&f.oracle).unwrap());
    std::fs::write(&bom, bytes).unwrap();
    let r: Value = serde_json::from_str(&run_ok(
        "rh-score",
        &[s(&bom), "--dataset", s(&f.ds), "--json", "-"],
    ))
    .unwrap();
    assert_eq!(
        r["models"][0]["overall"]["saa"], 1.0,
        "{}",
        r["models"][0]["overall"]
    );
    assert_eq!(
        r["input"]["warnings"],
        serde_json::json!([]),
        "{}",
        r["input"]
    );
    // Two models whose results files would be one: refused before anything is written.
    let oracle = std::fs::read_to_string(&f.oracle).unwrap();
    let clash = dir.path().join("clash.jsonl");
    std::fs::write(
        &clash,
        oracle.replace("\"baseline-oracle\"", "\"a/b\"")
            + &oracle.replace("\"baseline-oracle\"", "\"a_b\""),
    )
    .unwrap();
    let results = dir.path().join("results");
    let report = dir.path().join("report.json");
    let decisions = dir.path().join("decisions.jsonl");
    let o = run(
        "rh-score",
        &[
            s(&clash),
            "--dataset",
            s(&f.ds),
            "--results",
            s(&results),
            "--json",
            s(&report),
            "--decisions",
            s(&decisions),
            "--quiet",
        ],
    );
    refused(
        &o,
        &["models \"a/b\" and \"a_b\" would both be written to a_b.json"],
        "clash",
    );
    assert!(!results.exists() && !report.exists() && !decisions.exists());
    assert_eq!(
        std::fs::read_dir(dir.path()).unwrap().count(),
        2,
        "temporaries left"
    );
    // The messages of the issue.
    let no_model = dir.path().join("no-model.jsonl");
    std::fs::write(
        &no_model,
        oracle.replace("\"model\":\"baseline-oracle\",", ""),
    )
    .unwrap();
    let o = run("rh-score", &[s(&no_model), "--dataset", s(&f.ds)]);
    refused(
        &o,
        &["line(s) without a `model` field (first at line 1"],
        "no model",
    );
    let numeric = dir.path().join("numeric-model.jsonl");
    std::fs::write(&numeric, oracle.replace("\"baseline-oracle\"", "123")).unwrap();
    let o = run("rh-score", &[s(&numeric), "--dataset", s(&f.ds)]);
    refused(
        &o,
        &["whose `model` is not a non-empty string"],
        "model 123",
    );
    assert!(
        !text(&o.stderr).contains("without a `model`"),
        "{}",
        text(&o.stderr)
    );
    let file = dir.path().join("a-file");
    std::fs::write(&file, "x").unwrap();
    let o = run(
        "rh-score",
        &["export", "--dataset", s(&f.ds), "--out", s(&file)],
    );
    refused(&o, &["is a file; give a directory"], "export --out FILE");
    for name in ["rh-score", "rh-pipeline"] {
        let o = run(name, &["help", "--help"]);
        assert_eq!(
            o.status.code(),
            Some(0),
            "{name} help --help: {}",
            text(&o.stderr)
        );
        assert!(text(&o.stdout).contains("Usage"), "{}", text(&o.stdout));
    }
    let table = run_ok(
        "rh-pipeline",
        &[
            "balance",
            "--families",
            "object_drop",
            "--per-family",
            "1",
            "--pool",
            "4",
        ],
    );
    let header = table.lines().next().unwrap();
    assert!(header.trim_end().ends_with("other n"), "{header}");
    for row in table.lines().skip(1).take_while(|l| !l.contains(':')) {
        let last = row.split_whitespace().last().unwrap();
        assert!(last.parse::<u32>().is_ok(), "`other n` is a count: {row}");
    }
}
