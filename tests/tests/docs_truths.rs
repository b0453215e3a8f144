//! Facts stated in more than one document stay the same (issues 24, 25):
//! the column lists of `README.md` and `docs/dataset.md` against the data contract's
//! `COLUMNS`, and the oracle's catch figure in `README.md` against `docs/execution.md`
//! (`execute_e2e.rs` holds that figure to the measurement and to the dataset card).

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
