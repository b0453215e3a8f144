//! Helpers shared by the end-to-end tests: locate the real binaries and run them.
//!
//! The binaries are built by `scripts/test.sh` (`cargo build --release --bins`) before
//! `cargo test --release` runs; a test binary lives in `target/<profile>/deps/`, so the
//! programs sit one directory up.

pub mod cdp;
pub mod fake_hub;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// Path of a workspace binary built in the same profile as the running test.
pub fn bin(name: &str) -> PathBuf {
    let exe = std::env::current_exe().expect("current test executable");
    let profile_dir = exe
        .parent()
        .and_then(|deps| deps.parent())
        .expect("test binary lives in target/<profile>/deps");
    let path = profile_dir.join(name);
    assert!(
        path.exists(),
        "{} is not built; run `cargo build --release --bins` first (scripts/test.sh does)",
        path.display()
    );
    path
}

/// Runs a workspace binary with arguments and returns its output (never panics on exit code).
pub fn run(name: &str, args: &[&str]) -> Output {
    run_env(name, args, &[])
}

/// Like `run`, with these environment variables set too.
pub fn run_env(name: &str, args: &[&str], env: &[(&str, &str)]) -> Output {
    Command::new(bin(name))
        .args(args)
        .env("XDG_RUNTIME_DIR", std::env::temp_dir())
        .envs(env.iter().copied())
        .output()
        .unwrap_or_else(|e| panic!("cannot start {name}: {e}"))
}

/// Like `run`, but asserts success and returns stdout as text.
pub fn run_ok(name: &str, args: &[&str]) -> String {
    run_ok_env(name, args, &[])
}

/// Like `run_env`, but asserts success and returns stdout as text.
pub fn run_ok_env(name: &str, args: &[&str], env: &[(&str, &str)]) -> String {
    let out = run_env(name, args, env);
    assert!(
        out.status.success(),
        "{name} {args:?} failed with {:?}\nstdout:\n{}\nstderr:\n{}",
        out.status.code(),
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).expect("utf-8 stdout")
}

/// A synthetic scored dataset (`rh-score make-fixture`) of `n` scenes in `dir`.
pub fn make_fixture(dir: &Path, n: u32, seed: u64) {
    run_ok(
        "rh-score",
        &[
            "make-fixture",
            "--out",
            dir.to_str().unwrap(),
            "--n",
            &n.to_string(),
            "--seed",
            &seed.to_string(),
        ],
    );
}

/// The JSON values of a JSON-lines file (`--decisions`, `preds.jsonl`), one a line.
pub fn read_json_lines(path: &Path) -> Vec<serde_json::Value> {
    std::fs::read_to_string(path)
        .unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()))
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect()
}

/// Runs a Python snippet (pyarrow and friends come from scripts/setup.sh).
pub fn python(script: &str) -> String {
    let out = Command::new("python3")
        .arg("-c")
        .arg(script)
        .output()
        .expect("python3 is installed by scripts/setup.sh");
    assert!(
        out.status.success(),
        "python failed:\n{}\n{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).expect("utf-8 stdout")
}

/// Every file below `dir` (following links), keyed by its path relative to `dir`, with
/// its bytes: for comparing whole dataset trees.
pub fn files_under(dir: &Path) -> BTreeMap<String, Vec<u8>> {
    let mut out = BTreeMap::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for entry in std::fs::read_dir(&d).unwrap() {
            let path = entry.unwrap().path();
            // `metadata` follows links (a Hub cache snapshot links into blobs/).
            if std::fs::metadata(&path).unwrap().is_dir() {
                stack.push(path);
            } else {
                let rel = path
                    .strip_prefix(dir)
                    .unwrap()
                    .to_string_lossy()
                    .to_string();
                out.insert(rel, std::fs::read(&path).unwrap());
            }
        }
    }
    out
}

/// A configuration for small rendered test builds, written into `dir` (with the
/// `labels.toml` and `scoring.toml` it names): the embedded defaults at a `width` ×
/// `height` render size. With `scale_visibility`, the visibility rule's pixel sizes
/// (`visible_size_px_min`, `frame_size_px`, pixels at the configured resolution) shrink
/// with the height, so tiny builds keep the scenes a full-size build would.
pub fn small_render_config(dir: &Path, width: u32, height: u32, scale_visibility: bool) -> PathBuf {
    let configs = Path::new(env!("CARGO_MANIFEST_DIR")).join("../configs");
    for name in ["labels.toml", "scoring.toml"] {
        std::fs::copy(configs.join(name), dir.join(name)).unwrap();
    }
    let default = std::fs::read_to_string(configs.join("default.toml")).unwrap();
    let mut small = default
        .replace("\nwidth = 1280\n", &format!("\nwidth = {width}\n"))
        .replace("\nheight = 720\n", &format!("\nheight = {height}\n"))
        .replace("\nfull_width = 640\n", &format!("\nfull_width = {width}\n"))
        .replace(
            "\nfull_height = 360\n",
            &format!("\nfull_height = {height}\n"),
        );
    assert_ne!(
        small, default,
        "the [render] keys moved; update this helper"
    );
    if scale_visibility {
        let scale = |px: f64| ((px * height as f64 / 720.0) as u32).max(1);
        let scaled = small
            .replace(
                "\nvisible_size_px_min = 8\n",
                &format!("\nvisible_size_px_min = {}\n", scale(8.0)),
            )
            .replace(
                "\nframe_size_px = [24, 400]\n",
                &format!("\nframe_size_px = [{}, {}]\n", scale(24.0), scale(400.0)),
            );
        assert!(
            scaled.contains(&format!("\nvisible_size_px_min = {}\n", scale(8.0)))
                && scaled.contains(&format!("\nframe_size_px = [{}, ", scale(24.0))),
            "the [validators] pixel keys moved; update this helper"
        );
        small = scaled;
    }
    let path = dir.join("small.toml");
    std::fs::write(&path, small).unwrap();
    path
}

/// The figure "N of M" that follows `marker` in a document (line breaks and `**` bold
/// ignored): for holding a figure stated in prose to the measurement.
pub fn n_of_m_after(text: &str, marker: &str) -> (u32, u32) {
    let text = text.replace('\n', " ").replace("**", "");
    let at = text
        .find(marker)
        .unwrap_or_else(|| panic!("the text has no `{marker}`"))
        + marker.len();
    let words: Vec<&str> = text[at..].split_whitespace().take(3).collect();
    assert_eq!(
        words.get(1),
        Some(&"of"),
        "`{marker}` is not followed by `N of M`: {words:?}"
    );
    let num = |w: &str| {
        w.trim_matches(|c: char| !c.is_ascii_digit())
            .parse()
            .unwrap_or_else(|_| panic!("`{w}` after `{marker}` is not a number"))
    };
    (num(words[0]), num(words[2]))
}
