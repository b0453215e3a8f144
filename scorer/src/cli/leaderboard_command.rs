//! `rh-score leaderboard FILE...`: results files merged into one board
//! ([`rh_report::leaderboard::merge`]), printed and written in the forms asked for.

use super::output::print_out;
use anyhow::Result;
use rh_report::leaderboard::{merge, render};
use std::path::{Path, PathBuf};

/// Merges `files`; writes `--html`, `--markdown`; prints the table (or JSON with `--json`).
pub fn run(
    files: &[PathBuf],
    html: Option<&Path>,
    markdown: Option<&Path>,
    json: bool,
) -> Result<()> {
    let board = merge(files)?;
    if let Some(dir) = html {
        render::write_html(&board, dir)?;
        rh_contract::note!(
            "rh-score: leaderboard site in {}",
            dir.join("index.html").display()
        );
    }
    if let Some(p) = markdown {
        rh_contract::fsio::write_file(
            p,
            "the Markdown board",
            render::markdown(&board).as_bytes(),
        )?;
    }
    if json {
        print_out(&(serde_json::to_string_pretty(&board)? + "\n"))
    } else {
        print_out(&render::terminal(&board))
    }
}
