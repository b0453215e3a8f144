//! The house rules of the code's structure (ARCHITECTURE.md, "Crate graph" and
//! "Invariants"), checked from the sources themselves:
//!
//! * no import circle between the files of a crate, nor between its top-level modules
//!   (a folder counts as one module): `crate::…` and `super::…` paths are the edges;
//! * the crate graph that ARCHITECTURE.md draws is the one `cargo metadata` reports;
//! * dev-dependencies change no feature of a dependency the build already has, so the test
//!   build reuses what `cargo build --bins` compiled (docs/benchmarks.md, "The test
//!   suite's build").

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .unwrap()
        .to_path_buf()
}

/// The workspace's member folders, from the root Cargo.toml.
pub fn members() -> Vec<String> {
    let text = std::fs::read_to_string(root().join("Cargo.toml")).unwrap();
    let line = text
        .lines()
        .find(|l| l.trim_start().starts_with("members"))
        .expect("a members line");
    line.split('"')
        .skip(1)
        .step_by(2)
        .map(str::to_string)
        .collect()
}

/// Module path (`["execute", "outcome"]`) of every source file of a crate.
fn modules(src: &Path) -> BTreeMap<Vec<String>, PathBuf> {
    fn walk(dir: &Path, prefix: &[String], out: &mut BTreeMap<Vec<String>, PathBuf>) {
        let Ok(entries) = std::fs::read_dir(dir) else {
            return;
        };
        for e in entries.flatten() {
            let path = e.path();
            let name = e.file_name().to_string_lossy().to_string();
            if path.is_dir() {
                if name != "bin" {
                    let mut p = prefix.to_vec();
                    p.push(name);
                    walk(&path, &p, out);
                }
            } else if let Some(stem) = name.strip_suffix(".rs") {
                let mut p = prefix.to_vec();
                if stem != "mod" && stem != "lib" && stem != "main" {
                    p.push(stem.to_string());
                }
                out.insert(p, path);
            }
        }
    }
    let mut out = BTreeMap::new();
    walk(src, &[], &mut out);
    out
}

/// The code of a file without comments and its `#[cfg(test)]` tail.
fn code_of(text: &str) -> String {
    let end = text.find("\n#[cfg(test)]").unwrap_or(text.len());
    text[..end]
        .lines()
        .map(|l| match l.find("//") {
            Some(i) => &l[..i],
            None => l,
        })
        .collect::<Vec<_>>()
        .join("\n")
}

/// Paths a file names inside its crate: `crate::a::b…` and `super::…` (resolved against
/// the file's module), as module-path segments.
fn referenced_paths(code: &str, module: &[String]) -> Vec<Vec<String>> {
    let mut found = Vec::new();
    let bytes = code.as_bytes();
    for start in ["crate::", "super::"] {
        let mut from = 0;
        while let Some(i) = code[from..].find(start) {
            let at = from + i;
            from = at + start.len();
            if at > 0 && (bytes[at - 1].is_ascii_alphanumeric() || bytes[at - 1] == b'_') {
                continue;
            }
            let rest: String = code[at..]
                .chars()
                .take_while(|c| c.is_alphanumeric() || *c == '_' || *c == ':')
                .collect();
            let mut segs: Vec<String> = rest
                .split("::")
                .filter(|s| !s.is_empty())
                .map(str::to_string)
                .collect();
            let mut base: Vec<String> = Vec::new();
            if segs[0] == "crate" {
                segs.remove(0);
            } else {
                // Each `super` is the parent of the file's module. A folder's `mod.rs`
                // is the folder's own module (`gpu/mod.rs` is `gpu`), so its `super` is
                // the folder's parent, as for any other file.
                base = module.to_vec();
                while segs.first().is_some_and(|s| s == "super") {
                    segs.remove(0);
                    base.pop();
                }
            }
            base.extend(segs);
            found.push(base);
        }
    }
    found
}

/// The file-level import graph of a crate: file module → the file modules it uses.
fn file_graph(src: &Path) -> BTreeMap<Vec<String>, BTreeSet<Vec<String>>> {
    let mods = modules(src);
    let mut graph: BTreeMap<Vec<String>, BTreeSet<Vec<String>>> = BTreeMap::new();
    for (m, path) in &mods {
        let text = std::fs::read_to_string(path).unwrap();
        let edges = graph.entry(m.clone()).or_default();
        for p in referenced_paths(&code_of(&text), m) {
            // The longest module prefix of the path is the file it names.
            let target = (0..=p.len())
                .rev()
                .map(|k| p[..k].to_vec())
                .find(|prefix| mods.contains_key(prefix));
            if let Some(t) = target {
                // A folder's mod.rs naming its own children is not an import.
                if t != *m && !t.starts_with(m) && !t.is_empty() {
                    edges.insert(t);
                }
            }
        }
    }
    graph
}

/// A cycle in a directed graph, if there is one.
fn find_cycle<N: Ord + Clone>(graph: &BTreeMap<N, BTreeSet<N>>) -> Option<Vec<N>> {
    fn visit<N: Ord + Clone>(
        n: &N,
        graph: &BTreeMap<N, BTreeSet<N>>,
        state: &mut BTreeMap<N, u8>,
        stack: &mut Vec<N>,
    ) -> Option<Vec<N>> {
        state.insert(n.clone(), 1);
        stack.push(n.clone());
        for m in graph.get(n).into_iter().flatten() {
            match state.get(m) {
                Some(1) => {
                    let i = stack.iter().position(|x| x == m).unwrap();
                    let mut c = stack[i..].to_vec();
                    c.push(m.clone());
                    return Some(c);
                }
                Some(_) => {}
                None => {
                    if let Some(c) = visit(m, graph, state, stack) {
                        return Some(c);
                    }
                }
            }
        }
        stack.pop();
        state.insert(n.clone(), 2);
        None
    }
    let mut state = BTreeMap::new();
    for n in graph.keys() {
        if !state.contains_key(n) {
            if let Some(c) = visit(n, graph, &mut state, &mut Vec::new()) {
                return Some(c);
            }
        }
    }
    None
}

/// The same graph with every node cut to its top-level module (a folder is one node).
fn folder_graph(
    files: &BTreeMap<Vec<String>, BTreeSet<Vec<String>>>,
) -> BTreeMap<String, BTreeSet<String>> {
    let top = |m: &Vec<String>| m.first().cloned().unwrap_or_else(|| "lib".into());
    let mut g: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for (a, bs) in files {
        let entry = g.entry(top(a)).or_default();
        for b in bs {
            if top(b) != top(a) && !a.is_empty() {
                entry.insert(top(b));
            }
        }
    }
    g
}

#[test]
fn no_import_circle_in_any_crate() {
    let mut problems = Vec::new();
    for krate in members() {
        let src = root().join(&krate).join("src");
        let files = file_graph(&src);
        if let Some(c) = find_cycle(&files) {
            let names: Vec<String> = c.iter().map(|m| m.join("::")).collect();
            problems.push(format!("{krate}: file circle {}", names.join(" -> ")));
        }
        if let Some(c) = find_cycle(&folder_graph(&files)) {
            problems.push(format!("{krate}: module circle {}", c.join(" -> ")));
        }
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

#[test]
fn the_circle_check_finds_a_circle() {
    let dir = tempfile::tempdir().unwrap();
    let src = dir.path();
    std::fs::create_dir_all(src.join("exec")).unwrap();
    std::fs::write(src.join("lib.rs"), "pub mod a;\npub mod exec;\n").unwrap();
    std::fs::write(src.join("a.rs"), "use crate::exec::body::Part;\n").unwrap();
    std::fs::write(src.join("exec/mod.rs"), "pub mod body;\npub mod run;\n").unwrap();
    std::fs::write(src.join("exec/body.rs"), "// crate::a is only a comment\n").unwrap();
    std::fs::write(src.join("exec/run.rs"), "use super::body::X;\n").unwrap();
    let files = file_graph(src);
    assert!(find_cycle(&files).is_none(), "{files:?}");
    assert!(find_cycle(&folder_graph(&files)).is_none());
    // run -> a closes a folder-level circle (a -> exec -> a) without a file circle.
    std::fs::write(src.join("exec/run.rs"), "use crate::a::f;\n").unwrap();
    let files = file_graph(src);
    assert!(find_cycle(&files).is_none(), "{files:?}");
    assert!(find_cycle(&folder_graph(&files)).is_some());
    // body -> a makes a file circle (a -> exec::body -> a).
    std::fs::write(src.join("exec/body.rs"), "fn g() { crate::a::f(); }\n").unwrap();
    assert!(find_cycle(&file_graph(src)).is_some());
}

#[test]
fn super_in_a_mod_file_names_a_sibling_of_its_folder() {
    let dir = tempfile::tempdir().unwrap();
    let src = dir.path();
    std::fs::create_dir_all(src.join("gpu")).unwrap();
    std::fs::write(src.join("lib.rs"), "mod gpu;\nmod regions;\n").unwrap();
    std::fs::write(src.join("gpu/mod.rs"), "use super::regions::area;\n").unwrap();
    std::fs::write(src.join("regions.rs"), "fn f() {}\n").unwrap();
    let files = file_graph(src);
    let edge = |a: &[&str], b: &[&str]| {
        let (a, b): (Vec<String>, Vec<String>) = (
            a.iter().map(|s| s.to_string()).collect(),
            b.iter().map(|s| s.to_string()).collect(),
        );
        files.get(&a).is_some_and(|e| e.contains(&b))
    };
    assert!(edge(&["gpu"], &["regions"]), "{files:?}");
    assert!(find_cycle(&files).is_none(), "{files:?}");
    // regions -> gpu closes the circle gpu -> regions -> gpu through `super::` in a mod.rs.
    std::fs::write(src.join("regions.rs"), "use super::gpu::MAX;\n").unwrap();
    let files = file_graph(src);
    assert!(find_cycle(&files).is_some(), "{files:?}");
    assert!(find_cycle(&folder_graph(&files)).is_some());
}

/// Runs cargo (the one running the tests) in the workspace root; its stdout.
fn cargo(args: &[&str]) -> String {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let out = std::process::Command::new(cargo)
        .args(args)
        .current_dir(root())
        .output()
        .expect("cargo runs");
    assert!(
        out.status.success(),
        "cargo {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).expect("utf-8 output")
}

/// `crate → dependencies` among the workspace's crates, from `cargo metadata` (normal
/// dependencies, optional ones included; dev-dependencies left out).
fn metadata_graph() -> BTreeMap<String, BTreeSet<String>> {
    let out = cargo(&[
        "metadata",
        "--format-version",
        "1",
        "--no-deps",
        "--offline",
    ]);
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    let packages = v["packages"].as_array().unwrap();
    let ours: BTreeSet<String> = packages
        .iter()
        .map(|p| p["name"].as_str().unwrap().to_string())
        .collect();
    let mut g = BTreeMap::new();
    for p in packages {
        let name = p["name"].as_str().unwrap().to_string();
        if name == "rh-e2e" {
            continue;
        }
        let deps: BTreeSet<String> = p["dependencies"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|d| d["kind"].is_null())
            .map(|d| d["name"].as_str().unwrap().to_string())
            .filter(|d| ours.contains(d))
            .collect();
        g.insert(name, deps);
    }
    g
}

/// The crate graph of ARCHITECTURE.md: the lines `rh-a → rh-b, rh-c` (or `→ —`) of the
/// fenced block under "### Crate graph".
fn documented_graph() -> BTreeMap<String, BTreeSet<String>> {
    let text = std::fs::read_to_string(root().join("ARCHITECTURE.md")).unwrap();
    let section = text
        .split("### Crate graph")
        .nth(1)
        .expect("ARCHITECTURE.md has a '### Crate graph' section");
    let block = section.split("```").nth(1).expect("a fenced block");
    let mut g = BTreeMap::new();
    for line in block.lines().filter(|l| l.contains('→')) {
        let (a, b) = line.split_once('→').unwrap();
        let deps = b
            .split(|c: char| c == ',' || c.is_whitespace() || c == '(' || c == ')')
            .filter(|s| s.starts_with("rh-"))
            .map(str::to_string)
            .collect();
        g.insert(a.trim().to_string(), deps);
    }
    g
}

#[test]
fn the_documented_crate_graph_is_cargos() {
    let cargo = metadata_graph();
    let documented = documented_graph();
    assert_eq!(
        documented, cargo,
        "ARCHITECTURE.md's crate graph (left) differs from cargo metadata (right)"
    );
    assert!(find_cycle(&cargo).is_none());
}

/// `package → its enabled features` of the workspace's resolution, from `cargo tree`
/// (`kinds`: "normal,build" or "normal,build,dev").
fn resolved_features(kinds: &str) -> BTreeMap<String, BTreeSet<String>> {
    let out = cargo(&[
        "tree",
        "--workspace",
        "--offline",
        "--prefix",
        "none",
        "-e",
        kinds,
        "-f",
        "{p}|{f}",
    ]);
    let mut map: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for line in out.lines() {
        let Some((package, features)) = line.split_once('|') else {
            continue;
        };
        let features = features.trim_end_matches(" (*)").trim();
        let set: BTreeSet<String> = features
            .split(',')
            .filter(|f| !f.is_empty())
            .map(str::to_string)
            .collect();
        map.entry(package.trim().to_string())
            .or_default()
            .extend(set);
    }
    map
}

#[test]
fn dev_dependencies_change_no_feature_of_the_built_dependencies() {
    let built = resolved_features("normal,build");
    let tested = resolved_features("normal,build,dev");
    assert!(
        built.len() > 100,
        "cargo tree listed {} packages",
        built.len()
    );
    let changed: Vec<String> = built
        .iter()
        .filter_map(|(package, features)| {
            let in_tests = tested.get(package)?;
            (in_tests != features).then(|| {
                let added: Vec<&String> = in_tests.difference(features).collect();
                format!("{package}: the test build adds {added:?}")
            })
        })
        .collect();
    assert!(
        changed.is_empty(),
        "a dev-dependency changes the features of built dependencies, so `cargo test` would \
         compile them (and everything above them) again; give them these features in a \
         normal dependency too (as contract/Cargo.toml does for bitflags) or drop the \
         dev-dependency:\n{}",
        changed.join("\n")
    );
}

/// The packages `package` links (normal dependencies, every level), from `cargo tree`.
fn linked_packages(package: &str) -> BTreeSet<String> {
    let out = cargo(&[
        "tree",
        "-p",
        package,
        "--offline",
        "--prefix",
        "none",
        "-e",
        "normal",
        "-f",
        "{p}",
    ]);
    out.lines()
        .filter_map(|l| l.split_whitespace().next())
        .map(str::to_string)
        .collect()
}

/// The scorer's seams (ARCHITECTURE.md, "Code map"): the grading core links no
/// simulator, renderer, FFmpeg, JPEG encoder, HTTP client or async runtime, and the Python
/// package none of the model runner, the report writers or the execution videos.
#[test]
fn the_grading_core_and_the_python_package_link_only_their_crates() {
    let heavy = [
        "rapier3d",
        "wgpu",
        "ffmpeg-next",
        "turbojpeg",
        "reqwest",
        "tokio",
    ];
    let core = linked_packages("rh-grade");
    assert!(
        core.contains("rh-contract") && core.contains("arrow"),
        "{core:?}"
    );
    let found: Vec<&&str> = heavy.iter().filter(|h| core.contains(**h)).collect();
    assert!(found.is_empty(), "rh-grade links {found:?}");
    let python = linked_packages("rh-python");
    assert!(
        python.contains("rh-execute") && python.contains("rh-prompt"),
        "{python:?}"
    );
    let not_python = [
        "rh-runner",
        "rh-report",
        "rh-execute-videos",
        "rh-llm",
        "rh-score",
    ];
    let found: Vec<&&str> = not_python.iter().filter(|h| python.contains(**h)).collect();
    assert!(found.is_empty(), "rh-python links {found:?}");
}
