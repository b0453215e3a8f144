//! The predictions file of `rh-score predict`: resume and append.
//!
//! Every finished decision is one line, written with one `write` on a file opened for
//! appending (no user-space buffer), so a process killed at any moment (SIGKILL) leaves
//! complete lines plus at most one torn last line. On start, [`prepare`] drops a torn last
//! line (a tail without its newline), reads which scenes are done, and — with
//! `--retry-errors` — rewrites the file without its `error` lines (temporary sibling, then
//! rename) so that each scene appears exactly once after the retry.

use anyhow::Result;
use rh_grade::error::InputError;
use serde_json::Value;
use std::collections::BTreeSet;
use std::io::Write;
use std::path::{Path, PathBuf};

/// What an existing output file already holds.
#[derive(Debug, Default)]
pub struct Existing {
    /// Scenes with a line (answered, or lost unless retried).
    pub done: BTreeSet<String>,
    /// Scenes whose line is an `error` line (before any `--retry-errors` rewrite).
    pub errors: usize,
    /// Cost of the requests recorded in the file (answers from the cache excluded).
    pub paid_cost: f64,
    /// How many answered lines that cost is over.
    pub paid_lines: u64,
    /// A torn last line was dropped (bytes).
    pub torn_bytes: usize,
    /// Error lines removed for `--retry-errors`.
    pub removed_errors: usize,
}

fn bad(path: &Path, line: usize, what: impl std::fmt::Display) -> anyhow::Error {
    InputError(format!("{}:{line}: {what}", path.display())).into()
}

fn is_error(v: &Value) -> bool {
    match v.get("error") {
        None | Some(Value::Null) => false,
        Some(Value::String(s)) => !s.trim().is_empty(),
        Some(_) => true,
    }
}

/// Reads (and repairs) an existing output file for `model`.
pub fn prepare(path: &Path, model: &str, retry_errors: bool) -> Result<Existing> {
    let mut ex = Existing::default();
    let bytes = match std::fs::read(path) {
        Ok(b) => b,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(ex),
        Err(e) => return Err(InputError(format!("cannot read {}: {e}", path.display())).into()),
    };
    let complete = match bytes.iter().rposition(|&b| b == b'\n') {
        Some(i) => i + 1,
        None => 0,
    };
    if complete < bytes.len() {
        ex.torn_bytes = bytes.len() - complete;
        let f = std::fs::OpenOptions::new()
            .write(true)
            .open(path)
            .map_err(|e| InputError(format!("cannot repair {}: {e}", path.display())))?;
        f.set_len(complete as u64)
            .map_err(|e| InputError(format!("cannot repair {}: {e}", path.display())))?;
    }
    let mut keep: Vec<&[u8]> = Vec::new();
    for (i, line) in bytes[..complete].split(|&b| b == b'\n').enumerate() {
        let line = match i {
            0 => line.strip_prefix(rh_grade::preds::UTF8_BOM).unwrap_or(line),
            _ => line,
        };
        if line.iter().all(u8::is_ascii_whitespace) {
            continue;
        }
        let n = i + 1;
        let v: Value = serde_json::from_slice(line).map_err(|e| {
            bad(
                path,
                n,
                format!("not a JSON prediction line ({e}); is this file from rh-score predict?"),
            )
        })?;
        let scene = v
            .get("scene_id")
            .and_then(Value::as_str)
            .ok_or_else(|| bad(path, n, "no scene_id"))?;
        let m = v.get("model").and_then(Value::as_str).unwrap_or("");
        if m != model {
            return Err(bad(
                path,
                n,
                format!(
                    "holds predictions of model '{m}', not '{model}'; write each model to its own file"
                ),
            ));
        }
        let err = is_error(&v);
        if err {
            ex.errors += 1;
        }
        if err && retry_errors {
            ex.removed_errors += 1;
            continue;
        }
        if !v.get("cached").and_then(Value::as_bool).unwrap_or(false) {
            ex.paid_lines += 1;
            ex.paid_cost += v
                .pointer("/usage/cost")
                .and_then(Value::as_f64)
                .unwrap_or(0.0);
        }
        ex.done.insert(scene.to_string());
        keep.push(line);
    }
    if ex.removed_errors > 0 {
        rewrite(path, &keep)?;
    }
    Ok(ex)
}

fn rewrite(path: &Path, lines: &[&[u8]]) -> Result<()> {
    let mut text = Vec::new();
    for l in lines {
        text.extend_from_slice(l);
        text.push(b'\n');
    }
    rh_contract::fsio::write_file(path, "the predictions without their error lines", &text)?;
    Ok(())
}

/// Appends lines, one `write` each, none longer than the scorer reads
/// (`sanity.max_line_bytes`, [`fit_line`]).
pub struct Appender {
    file: std::fs::File,
    path: PathBuf,
    max_line_bytes: usize,
}

/// Makes a prediction line fit in `max` bytes with its newline, the scorer's limit on a
/// line (`sanity.max_line_bytes`), so that every decision `predict` writes is scored:
/// an over-long `response` (else `error`) text is cut at a character boundary, keeping
/// its start, and the line says so in `truncated` (`field`, original `bytes`, `kept`).
/// The parsed `plan` beside it was taken from the whole response. Returns the line's
/// bytes.
pub fn fit_line(line: &Value, max: usize) -> Result<Vec<u8>> {
    let mut bytes = serde_json::to_vec(line)?;
    if bytes.len() < max {
        return Ok(bytes);
    }
    let mut line = line.clone();
    let field = match line.get("response") {
        Some(Value::String(_)) => "response",
        _ => "error",
    };
    let original = line.get(field).and_then(Value::as_str).map_or(0, str::len);
    // The marker's own bytes, and a margin: cutting k bytes of text removes at least k
    // bytes of JSON (escapes only make it more).
    let mut kept = original;
    for _ in 0..8 {
        let excess = (bytes.len() + 1).saturating_sub(max) + 128;
        kept = kept.saturating_sub(excess);
        let Some(Value::String(text)) = line.get_mut(field) else {
            break;
        };
        let mut cut = kept.min(text.len());
        while !text.is_char_boundary(cut) {
            cut -= 1;
        }
        text.truncate(cut);
        kept = cut;
        line["truncated"] = serde_json::json!({"field": field, "bytes": original, "kept": kept});
        bytes = serde_json::to_vec(&line)?;
        if bytes.len() < max {
            return Ok(bytes);
        }
    }
    anyhow::bail!(
        "a prediction line of {} bytes does not fit the scorer's {max}-byte line limit even without its {field}",
        bytes.len()
    )
}

impl Appender {
    pub fn open(path: &Path, max_line_bytes: usize) -> Result<Appender> {
        if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir)
                .map_err(|e| InputError(format!("cannot create {}: {e}", dir.display())))?;
        }
        let file = std::fs::OpenOptions::new()
            .create(true)
            .append(true)
            .open(path)
            .map_err(|e| InputError(format!("cannot open {}: {e}", path.display())))?;
        Ok(Appender {
            file,
            path: path.to_path_buf(),
            max_line_bytes,
        })
    }

    /// Appends `line` ([`fit_line`] first); a failed write is a `CannotWrite` naming the
    /// file (the lines before it stay whole; a torn last line is dropped on the next run).
    pub fn write(&mut self, line: &Value) -> Result<()> {
        let mut bytes = fit_line(line, self.max_line_bytes)?;
        bytes.push(b'\n');
        self.file
            .write_all(&bytes)
            .and_then(|_| self.file.flush())
            .map_err(|e| {
                rh_contract::fsio::CannotWrite::new("a prediction line", &self.path, e).into()
            })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn drops_a_torn_line_and_retries_errors() {
        let d = tempfile::tempdir().unwrap();
        let p = d.path().join("preds.jsonl");
        std::fs::write(
            &p,
            concat!(
                r#"{"scene_id":"a","model":"m","response":"x","usage":{"cost":0.5}}"#,
                "\n",
                r#"{"scene_id":"b","model":"m","error":"timed out"}"#,
                "\n",
                r#"{"scene_id":"c","model":"m","response":"y","cached":true,"usage":{"cost":9}}"#,
                "\n",
                r#"{"scene_id":"d","mod"#
            ),
        )
        .unwrap();
        let ex = prepare(&p, "m", false).unwrap();
        assert_eq!(ex.torn_bytes, r#"{"scene_id":"d","mod"#.len());
        assert_eq!(ex.done.len(), 3);
        assert_eq!(ex.errors, 1);
        assert_eq!(ex.paid_cost, 0.5);
        assert!(std::fs::read_to_string(&p).unwrap().ends_with("}\n"));
        let ex = prepare(&p, "m", true).unwrap();
        assert_eq!(ex.removed_errors, 1);
        assert!(!ex.done.contains("b"));
        let text = std::fs::read_to_string(&p).unwrap();
        assert_eq!(text.lines().count(), 2);
        let err = prepare(&p, "other", false).unwrap_err().to_string();
        assert!(err.contains("holds predictions of model 'm'"), "{err}");
    }
}
