//! The merged board ([`super::Board`]) as a terminal table, Markdown (the scorer's one
//! table writer, [`crate::text_table::Table`]) and a one-page site in the report site's
//! style ([`crate::html`]'s page and stylesheet).

use super::{Board, BoardRow};
use crate::results::Estimate;
use crate::text_table::{num, num_ci, pct, pct_ci, Table};
use anyhow::Result;
use std::fmt::Write as _;
use std::path::Path;

const HEAD: [&str; 10] = [
    "model",
    "answered",
    "SAA %",
    "safety %",
    "bal. acc %",
    "AIA",
    "d_end (m)",
    "d_min (m)",
    "freeze %",
    "prompt",
];

fn rate(e: &Estimate) -> String {
    format!("{} [{}]", pct(e.value), pct_ci(e.ci))
}

fn mean(e: &Estimate) -> String {
    format!("{} [{}]", num(e.value, 2), num_ci(e.ci, 2))
}

/// A row's cells, in [`HEAD`]'s order.
fn cells(r: &BoardRow) -> Vec<String> {
    let h = &r.headline;
    let c = &r.coverage;
    vec![
        r.model.clone(),
        format!("{}/{}", c.answered, c.expected),
        rate(&h.saa),
        rate(&h.safety),
        rate(&h.balanced_accuracy),
        mean(&h.aia),
        mean(&h.d_end),
        mean(&h.d_min),
        rate(&h.freeze_rate),
        r.prompt_version.clone().unwrap_or_else(|| "—".into()),
    ]
}

fn table(b: &Board) -> Table {
    let mut t = Table::new(&HEAD);
    for r in &b.rows {
        t.row(cells(r));
    }
    t
}

/// What every run measured, one line each.
fn identity_lines(b: &Board) -> Vec<String> {
    let d = &b.dataset;
    let or_dash = |v: Option<String>| v.unwrap_or_else(|| "—".into());
    vec![
        format!(
            "dataset: {} (seed {}, label rule {}, build {})",
            d.dir,
            or_dash(d.seed.map(|s| s.to_string())),
            or_dash(d.label_rule.clone()),
            or_dash(d.build_fingerprint.as_ref().map(|f| f[..12].to_string())),
        ),
        format!(
            "scenes: {} expected ({} subset, ids {}…)",
            d.expected_scenes,
            d.subset,
            &d.subset_sha256[..12]
        ),
        format!(
            "prompt: {}; action rule {}; scoring config {}…{}",
            or_dash(b.prompt.as_ref().and_then(|p| p.version.clone())),
            b.action_rule.version,
            &b.scoring.config_sha256[..12],
            if b.scoring.answered_only {
                " (answered only)"
            } else {
                ""
            }
        ),
    ]
}

/// The board for a terminal.
pub fn terminal(b: &Board) -> String {
    let mut s = String::new();
    for l in identity_lines(b) {
        let _ = writeln!(s, "{l}");
    }
    s.push('\n');
    s.push_str(&table(b).text());
    s.push_str("Rates in %, [95% interval]; unanswered expected scenes count as failed.\n");
    s
}

/// The board as Markdown.
pub fn markdown(b: &Board) -> String {
    let mut s = String::from("# ReactHuman leaderboard\n\n");
    for l in identity_lines(b) {
        let _ = writeln!(s, "- {l}");
    }
    s.push('\n');
    s.push_str(&table(b).markdown());
    s.push_str("\nRates in %, [95% interval]; unanswered expected scenes count as failed.\n");
    s
}

/// Writes the board as `DIR/index.html` with the site's stylesheet and script.
pub fn write_html(b: &Board, dir: &Path) -> Result<()> {
    use crate::html::esc;
    let mut body = String::from("<h1>Leaderboard</h1>\n<ul class=\"note\">\n");
    for l in identity_lines(b) {
        let _ = writeln!(body, "<li>{}</li>", esc(&l));
    }
    body.push_str("</ul>\n<table id=\"leaderboard\"><thead><tr>");
    for h in HEAD {
        let _ = write!(body, "<th>{}</th>", esc(h));
    }
    body.push_str("</tr></thead><tbody>\n");
    for r in &b.rows {
        body.push_str("<tr>");
        for c in cells(r) {
            let _ = write!(body, "<td>{}</td>", esc(&c));
        }
        body.push_str("</tr>\n");
    }
    body.push_str(
        "</tbody></table>\n<p class=\"note\">Rates in %, [95% interval]; unanswered expected \
         scenes count as failed. Each row is one results file (rh-score --results).</p>",
    );
    let html = crate::html::page_with(
        "ReactHuman — leaderboard",
        "page-leaderboard",
        &body,
        &[],
        "<a href=\"index.html\">Leaderboard</a>",
    );
    let put = |rel: &str, text: &str| -> Result<()> {
        let path = dir.join(rel);
        Ok(rh_contract::fsio::write_file(
            &path,
            "the leaderboard site",
            text.as_bytes(),
        )?)
    };
    put("assets/site.css", crate::html::CSS)?;
    put("assets/site.js", crate::html::JS)?;
    put("index.html", &html)
}
