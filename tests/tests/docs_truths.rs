//! Facts stated in more than one document stay the same (issues 24, 25):
//! the column lists of `README.md` and `docs/dataset.md` against the data contract's
//! `COLUMNS`, and the oracle's catch figure in `README.md` against `docs/execution.md`
//! (`execute_e2e.rs` holds that figure to the measurement and to the dataset card), the
//! card's rule-v3 figure against the docs, and the documents' relative links.

use rh_contract::{CAMERAS, COLUMNS};
use std::path::Path;

fn doc(name: &str) -> String {
    std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("..").join(name))
        .unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// The backquoted names in the first cell of each row of the table that follows
/// `heading` in `text`.
fn table_names(text: &str, heading: &str) -> Vec<String> {
    let start = text
        .find(heading)
        .unwrap_or_else(|| panic!("no `{heading}` section"));
    text[start..]
        .lines()
        .skip_while(|l| !l.starts_with('|'))
        .take_while(|l| l.starts_with('|'))
        .filter_map(|l| {
            let cell = l.split('|').nth(1)?.trim();
            Some(cell.strip_prefix('`')?.strip_suffix('`')?.to_string())
        })
        .collect()
}

#[test]
fn docs_column_table_is_the_contracts_column_list() {
    let names = table_names(&doc("docs/dataset.md"), "### Columns");
    let contract: Vec<String> = COLUMNS.iter().map(|c| c.name.to_string()).collect();
    let missing: Vec<_> = contract.iter().filter(|c| !names.contains(c)).collect();
    let extra: Vec<_> = names.iter().filter(|n| !contract.contains(n)).collect();
    assert!(
        missing.is_empty() && extra.is_empty(),
        "docs/dataset.md's column table differs from rh_contract::COLUMNS: missing {missing:?}, not a column {extra:?}"
    );
    assert_eq!(
        names, contract,
        "docs/dataset.md lists the columns in another order"
    );
}

#[test]
fn readme_column_list_names_every_column() {
    let readme = doc("README.md");
    let start = readme
        .find("The scene table's")
        .expect("README lists the scene table's columns");
    let end = start + readme[start..].find("\n\n").unwrap();
    let end = end + readme[end + 2..].find("\n\n").unwrap() + 2;
    let list = &readme[start..end];
    let missing: Vec<&str> = COLUMNS
        .iter()
        .map(|c| c.name)
        .filter(|name| {
            // Per-camera columns are listed once as `<cam>_…`.
            let generic = CAMERAS
                .iter()
                .find_map(|cam| name.strip_prefix(&format!("{cam}_")))
                .map(|rest| format!("`<cam>_{rest}`"));
            !list.contains(&format!("`{name}`")) && !generic.is_some_and(|g| list.contains(&g))
        })
        .collect();
    assert!(
        missing.is_empty(),
        "README's column list lacks {missing:?} (see rh_contract::COLUMNS)"
    );
}

#[test]
fn readme_and_docs_state_the_same_oracle_catch_figure() {
    let readme = rh_e2e::n_of_m_after(&doc("README.md"), "oracle's catches are caught on");
    let docs = rh_e2e::n_of_m_after(&doc("docs/execution.md"), "its CATCH plans are `caught` on");
    assert_eq!(
        readme, docs,
        "README says the oracle caught {} of {}, docs/execution.md {} of {}",
        readme.0, readme.1, docs.0, docs.1
    );
}

/// GitHub's anchor for a heading: lower case, punctuation other than `-` and `_` dropped,
/// spaces to `-`.
fn slug(heading: &str) -> String {
    heading
        .trim()
        .to_lowercase()
        .chars()
        .filter(|c| c.is_alphanumeric() || matches!(c, '-' | '_' | ' '))
        .map(|c| if c == ' ' { '-' } else { c })
        .collect()
}

/// The anchors of a Markdown file's headings (outside code blocks).
fn anchors(text: &str) -> Vec<String> {
    let mut in_code = false;
    let mut out = Vec::new();
    for line in text.lines() {
        if line.trim_start().starts_with("```") {
            in_code = !in_code;
        } else if !in_code && line.starts_with('#') {
            out.push(slug(line.trim_start_matches('#')));
        }
    }
    out
}

/// Every relative link of README.md, ARCHITECTURE.md and docs/*.md names a file that
/// exists and, with `#anchor`, a heading of it: moving text between documents cannot
/// leave a link behind.
#[test]
fn document_links_resolve() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut files = vec!["README.md".to_string(), "ARCHITECTURE.md".to_string()];
    for entry in std::fs::read_dir(root.join("docs")).unwrap() {
        let name = entry.unwrap().file_name().to_string_lossy().to_string();
        if name.ends_with(".md") {
            files.push(format!("docs/{name}"));
        }
    }
    let mut broken = Vec::new();
    let mut links = 0;
    for file in &files {
        let text = doc(file);
        let dir = Path::new(file).parent().unwrap();
        for part in text.split("](").skip(1) {
            let target = part.split([')', ' ']).next().unwrap();
            if target.starts_with("http") || target.is_empty() {
                continue;
            }
            links += 1;
            let (path, anchor) = target.split_once('#').unwrap_or((target, ""));
            let resolved = if path.is_empty() {
                Path::new(file).to_path_buf()
            } else {
                dir.join(path)
            };
            if !root.join(&resolved).exists() {
                broken.push(format!("{file}: {target} (no such file)"));
            } else if !anchor.is_empty() {
                let text = std::fs::read_to_string(root.join(&resolved)).unwrap();
                if !anchors(&text).iter().any(|a| a == anchor) {
                    broken.push(format!("{file}: {target} (no such heading)"));
                }
            }
        }
    }
    assert!(links >= 20, "only {links} relative links found");
    assert!(broken.is_empty(), "broken links:\n{}", broken.join("\n"));
}

/// The dataset card quotes two execution measurements (the oracle's catches under rules
/// v3 and v4); they are the ones docs/execution.md and docs/labels.md report.
#[test]
fn the_card_quotes_the_documented_execution_figures() {
    // The card's text as `dataset/src/card.rs` writes it (Rust string continuations joined).
    let card = doc("dataset/src/card.rs").replace("\\\n", "");
    let v3_card = rh_e2e::n_of_m_after(&card, "the oracle baseline caught");
    let v4_card = rh_e2e::n_of_m_after(&card, "rule-v3 CATCH labels,");
    let v3_docs =
        rh_e2e::n_of_m_after(&doc("docs/execution.md"), "Under rule v3 the oracle caught");
    let v3_labels = rh_e2e::n_of_m_after(&doc("docs/labels.md"), "the oracle caught");
    let v4_docs =
        rh_e2e::n_of_m_after(&doc("docs/execution.md"), "its CATCH plans are `caught` on");
    assert_eq!(
        v3_card, v3_docs,
        "rule v3: card {v3_card:?}, docs/execution.md {v3_docs:?}"
    );
    assert_eq!(v3_labels, v3_docs, "rule v3: docs/labels.md {v3_labels:?}");
    assert_eq!(
        v4_card, v4_docs,
        "rule v4: card {v4_card:?}, docs/execution.md {v4_docs:?}"
    );
}
