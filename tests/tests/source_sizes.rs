//! House rule (ARCHITECTURE.md, "Invariants"): no non-test source file over 800 lines
//! and no function over 150 lines. Test code (`tests/`, `benches/`, `tests.rs`, and a
//! file's trailing `#[cfg(test)]` module) is exempt.

use std::path::{Path, PathBuf};

const MAX_FILE_LINES: usize = 800;
const MAX_FN_LINES: usize = 150;
/// Every crate of the workspace (the root Cargo.toml's `members`).
fn crates(root: &Path) -> Vec<String> {
    let text = std::fs::read_to_string(root.join("Cargo.toml")).unwrap();
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

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let path = entry.path();
        let name = entry.file_name().to_string_lossy().to_string();
        if path.is_dir() {
            if !matches!(name.as_str(), "tests" | "benches" | "target") {
                rust_files(&path, out);
            }
        } else if name.ends_with(".rs") && name != "tests.rs" {
            out.push(path);
        }
    }
}

/// Functions (by name) longer than `MAX_FN_LINES`: a `fn` line up to the closing brace
/// at the same indentation (rustfmt layout).
fn long_functions(lines: &[&str]) -> Vec<(usize, String, usize)> {
    let mut found = Vec::new();
    for (i, line) in lines.iter().enumerate() {
        let trimmed = line.trim_start();
        let indent = &line[..line.len() - trimmed.len()];
        let rest = ["pub(crate) ", "pub(super) ", "pub "]
            .iter()
            .find_map(|p| trimmed.strip_prefix(p))
            .unwrap_or(trimmed);
        let rest = rest.strip_prefix("const ").unwrap_or(rest);
        let Some(sig) = rest.strip_prefix("fn ") else {
            continue;
        };
        if line.ends_with(';') {
            continue;
        }
        let name: String = sig
            .chars()
            .take_while(|c| c.is_alphanumeric() || *c == '_')
            .collect();
        let close = format!("{indent}}}");
        if let Some(end) = lines[i + 1..].iter().position(|l| *l == close) {
            let len = end + 2;
            if len > MAX_FN_LINES {
                found.push((i + 1, name, len));
            }
        }
    }
    found
}

#[test]
fn no_source_file_over_800_lines_and_no_function_over_150() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).parent().unwrap();
    let mut files = Vec::new();
    let crates = crates(root);
    assert!(crates.len() >= 10, "members: {crates:?}");
    for krate in &crates {
        rust_files(&root.join(krate).join("src"), &mut files);
    }
    assert!(files.len() > 50, "found only {} source files", files.len());
    let mut problems = Vec::new();
    for file in &files {
        let text = std::fs::read_to_string(file).unwrap();
        let all: Vec<&str> = text.lines().collect();
        let code_end = all
            .iter()
            .position(|l| l.starts_with("#[cfg(test)]"))
            .unwrap_or(all.len());
        let code = &all[..code_end];
        let rel = file.strip_prefix(root).unwrap().display().to_string();
        if code.len() > MAX_FILE_LINES {
            problems.push(format!("{rel}: {} lines", code.len()));
        }
        for (line, name, len) in long_functions(code) {
            problems.push(format!("{rel}:{line}: fn {name} is {len} lines"));
        }
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

#[test]
fn the_function_check_finds_a_long_function() {
    let mut text = vec!["fn long() {"];
    text.extend(std::iter::repeat_n("    let x = 1;", MAX_FN_LINES));
    text.push("}");
    assert_eq!(long_functions(&text).len(), 1);
    assert!(long_functions(&text[..3]).is_empty());
}
