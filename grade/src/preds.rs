//! Streaming, lenient reading of `preds.jsonl` (specification §9).
//!
//! Lines are read one at a time with a length cap (longer lines are skipped without being
//! held in memory), parsed in parallel batches, and folded in file order.

use crate::aia::AiaMatcher;
use crate::config::Config;
use crate::dataset::Dataset;
use crate::metrics::{score_decision, DecisionResult};
use crate::plan::{plan_from_json_str, plan_from_text, plan_from_value, Plan, PlanError};
use serde_json::value::RawValue;
use serde_json::Value;
use std::io::{self, BufRead};

/// One raw line of input.
#[derive(Debug)]
pub enum RawLine {
    Line(Vec<u8>),
    /// Longer than the cap; its bytes were discarded.
    TooLong(u64),
}

/// Reads lines with a cap on their length, never holding more than `max` bytes of one.
/// The UTF-8 byte-order mark, skipped at the start of a predictions file.
pub const UTF8_BOM: &[u8] = b"\xEF\xBB\xBF";

pub struct LineReader<R: BufRead> {
    r: R,
    max: usize,
    line_no: u64,
}

impl<R: BufRead> LineReader<R> {
    pub fn new(r: R, max: usize) -> Self {
        LineReader { r, max, line_no: 0 }
    }

    /// The next line and its 1-based number.
    pub fn next_line(&mut self) -> io::Result<Option<(u64, RawLine)>> {
        let mut buf = Vec::new();
        let mut too_long = false;
        let mut total = 0u64;
        let mut any = false;
        loop {
            let avail = match self.r.fill_buf() {
                Ok(a) => a,
                Err(e) if e.kind() == io::ErrorKind::Interrupted => continue,
                Err(e) => return Err(e),
            };
            if avail.is_empty() {
                if !any {
                    return Ok(None);
                }
                break;
            }
            any = true;
            let (chunk_len, consume, done) = match avail.iter().position(|&b| b == b'\n') {
                Some(i) => (i, i + 1, true),
                None => (avail.len(), avail.len(), false),
            };
            total += chunk_len as u64;
            if !too_long {
                if buf.len() + chunk_len > self.max {
                    too_long = true;
                    buf = Vec::new();
                } else {
                    buf.extend_from_slice(&avail[..chunk_len]);
                }
            }
            self.r.consume(consume);
            if done {
                break;
            }
        }
        self.line_no += 1;
        if too_long {
            return Ok(Some((self.line_no, RawLine::TooLong(total))));
        }
        if buf.last() == Some(&b'\r') {
            buf.pop();
        }
        // A UTF-8 byte-order mark (editors on Windows write one) opens the file, not a line.
        if self.line_no == 1 && buf.starts_with(UTF8_BOM) {
            buf.drain(..UTF8_BOM.len());
        }
        Ok(Some((self.line_no, RawLine::Line(buf))))
    }
}

/// What one line amounts to.
#[derive(Debug)]
pub enum LineOutcome {
    Blank,
    /// Not a decision; counted under `kind` (with an optional detail, e.g. the unknown id).
    Skip {
        kind: &'static str,
        detail: Option<String>,
    },
    Decision {
        scene: u32,
        model: String,
        /// `None`: lost to an API error (not scored).
        result: Option<DecisionResult>,
        /// Non-fatal warnings (also the reason for R1, if any).
        notes: Vec<&'static str>,
        /// The line's `prompt_version` (rh-score predict), if any.
        prompt_version: Option<String>,
        /// The parsed plan (`None`: lost or R1), for `--execute`.
        plan: Option<Box<Plan>>,
    },
}

fn skip(kind: &'static str) -> LineOutcome {
    LineOutcome::Skip { kind, detail: None }
}

fn is_error_value(v: &Value) -> bool {
    match v {
        Value::Null | Value::Bool(false) => false,
        Value::String(s) => !s.trim().is_empty(),
        _ => true,
    }
}

/// Extracts the plan from a prediction object (the `plan`, else the `response`).
pub fn plan_of(obj: &serde_json::Map<String, Value>, cfg: &Config) -> Result<Plan, PlanError> {
    let from = |v: &Value| match v {
        Value::Object(_) => plan_from_value(v, cfg),
        Value::String(s) => plan_from_text(s, cfg),
        _ => Err(PlanError::Malformed(
            "plan/response is neither an object nor text".into(),
        )),
    };
    let plan = obj.get("plan").filter(|v| !v.is_null());
    let response = obj.get("response").filter(|v| !v.is_null());
    match (plan, response) {
        (Some(p), Some(r)) => match from(p) {
            Ok(plan) => Ok(plan),
            Err(e) => from(r).map_err(|_| e),
        },
        (Some(p), None) => from(p),
        (None, Some(r)) => from(r),
        (None, None) => Err(PlanError::NoJson),
    }
}

/// The common line shape, parsed without building a tree; `None` fields are absent.
#[derive(serde::Deserialize)]
struct FastLine<'a> {
    #[serde(borrow)]
    scene_id: Option<&'a RawValue>,
    #[serde(borrow)]
    model: Option<&'a RawValue>,
    #[serde(borrow)]
    plan: Option<&'a RawValue>,
    #[serde(borrow)]
    response: Option<&'a RawValue>,
    #[serde(borrow)]
    error: Option<&'a RawValue>,
    #[serde(default)]
    prompt_version: Option<String>,
}

fn raw_present(v: Option<&RawValue>) -> Option<&str> {
    v.map(|r| r.get()).filter(|s| *s != "null")
}

/// Plan from raw JSON of the `plan` / `response` fields (same policy as [`plan_of`]).
fn plan_of_raw(
    plan: Option<&str>,
    response: Option<&str>,
    cfg: &Config,
) -> Result<Plan, PlanError> {
    let from = |raw: &str| -> Result<Plan, PlanError> {
        if raw.starts_with('"') {
            match serde_json::from_str::<String>(raw) {
                Ok(text) => plan_from_text(&text, cfg),
                Err(_) => Err(PlanError::NoJson),
            }
        } else if raw.starts_with('{') {
            plan_from_json_str(raw, cfg).unwrap_or(Err(PlanError::NoJson))
        } else {
            Err(PlanError::Malformed(
                "plan/response is neither an object nor text".into(),
            ))
        }
    };
    match (plan, response) {
        (Some(p), Some(r)) => match from(p) {
            Ok(plan) => Ok(plan),
            Err(e) => from(r).map_err(|_| e),
        },
        (Some(p), None) => from(p),
        (None, Some(r)) => from(r),
        (None, None) => Err(PlanError::NoJson),
    }
}

/// Parses and scores one line (pure; runs in parallel).
pub fn process_line(raw: &RawLine, ds: &Dataset, cfg: &Config, aia: &AiaMatcher) -> LineOutcome {
    let bytes = match raw {
        RawLine::TooLong(_) => return skip("line_too_long"),
        RawLine::Line(b) => b,
    };
    let Ok(text) = std::str::from_utf8(bytes) else {
        return skip("invalid_utf8");
    };
    let text = text.trim();
    if text.is_empty() {
        return LineOutcome::Blank;
    }
    if text.starts_with('[') {
        // A JSON array (or its first line) where JSON Lines are expected.
        return skip("json_array");
    }
    // Fast path: typed parse of the line's top level.
    if let Ok(line) = serde_json::from_str::<FastLine>(text) {
        let scene_id = match raw_present(line.scene_id).map(serde_json::from_str::<Value>) {
            Some(Ok(Value::String(s))) => s.trim().to_string(),
            Some(Ok(Value::Number(n))) => n.to_string(),
            _ => return skip("missing_scene_id"),
        };
        let model = match raw_present(line.model).map(serde_json::from_str::<Value>) {
            Some(Ok(Value::String(s))) if !s.trim().is_empty() => s.trim().to_string(),
            None => return skip("missing_model"),
            Some(_) => return skip("bad_model"),
        };
        let error = line
            .error
            .and_then(|r| serde_json::from_str::<Value>(r.get()).ok())
            .is_some_and(|v| is_error_value(&v));
        let plan = raw_present(line.plan);
        let response = raw_present(line.response);
        let version = line.prompt_version;
        return decide(ds, cfg, aia, scene_id, model, error, version, || {
            let none = plan.is_none() && response.is_none();
            (plan_of_raw(plan, response, cfg), none)
        });
    }
    // The lenient path builds a tree: only within the size caps (memory stays flat).
    if text.starts_with('{') && crate::plan::check_size(text, cfg).is_err() {
        return skip("plan_too_large");
    }
    let v: Value = match serde_json::from_str(text) {
        Ok(v) => v,
        // Literal NaN / Infinity are read as their string forms (then R1 absurd_number).
        Err(_) => match crate::plan::quote_nonfinite(text).map(|t| serde_json::from_str(&t)) {
            Some(Ok(v)) => v,
            _ => return skip("malformed_json"),
        },
    };
    let Value::Object(obj) = v else {
        return skip("not_an_object");
    };
    let scene_id = match obj.get("scene_id") {
        Some(Value::String(s)) => s.trim().to_string(),
        Some(Value::Number(n)) => n.to_string(),
        _ => return skip("missing_scene_id"),
    };
    let model = match obj.get("model") {
        Some(Value::String(s)) if !s.trim().is_empty() => s.trim().to_string(),
        None | Some(Value::Null) => return skip("missing_model"),
        Some(_) => return skip("bad_model"),
    };
    let error = obj.get("error").is_some_and(is_error_value);
    let version = obj
        .get("prompt_version")
        .and_then(Value::as_str)
        .map(str::to_string);
    decide(ds, cfg, aia, scene_id, model, error, version, || {
        let none = obj.get("plan").is_none_or(Value::is_null)
            && obj.get("response").is_none_or(Value::is_null);
        (plan_of(&obj, cfg), none)
    })
}

fn decide(
    ds: &Dataset,
    cfg: &Config,
    aia: &AiaMatcher,
    scene_id: String,
    model: String,
    error: bool,
    prompt_version: Option<String>,
    plan: impl FnOnce() -> (Result<Plan, PlanError>, bool),
) -> LineOutcome {
    let Some((idx, scene)) = ds.get(&scene_id) else {
        return LineOutcome::Skip {
            kind: "unknown_scene_id",
            detail: Some(scene_id),
        };
    };
    if !scene.valid {
        return LineOutcome::Skip {
            kind: "invalid_scene",
            detail: Some(scene_id),
        };
    }
    if error {
        return LineOutcome::Decision {
            scene: idx,
            model,
            result: None,
            notes: Vec::new(),
            prompt_version,
            plan: None,
        };
    }
    let (plan, none) = plan();
    let (plan, mut notes) = match plan {
        Ok(p) => {
            let notes = p.notes.clone();
            (Some(p), notes)
        }
        Err(e) => (
            None,
            vec![if none {
                "r1_no_plan_or_response"
            } else {
                e.kind()
            }],
        ),
    };
    notes.sort_unstable();
    notes.dedup();
    let result = score_decision(plan.as_ref(), scene, cfg, aia);
    LineOutcome::Decision {
        scene: idx,
        model,
        result: Some(result),
        notes,
        prompt_version,
        plan: plan.map(Box::new),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Cursor;

    #[test]
    fn line_reader_caps_and_counts() {
        let data = b"short\n".to_vec();
        let mut long = vec![b'x'; 5000];
        long.push(b'\n');
        let input = [data.clone(), long, b"after\r\nlast-no-newline".to_vec()].concat();
        let mut r = LineReader::new(io::BufReader::with_capacity(64, Cursor::new(input)), 1024);
        let mut got = Vec::new();
        while let Some((n, l)) = r.next_line().unwrap() {
            got.push((
                n,
                match l {
                    RawLine::Line(b) => String::from_utf8(b).unwrap(),
                    RawLine::TooLong(len) => format!("<{len}>"),
                },
            ));
        }
        assert_eq!(
            got,
            vec![
                (1, "short".to_string()),
                (2, "<5000>".to_string()),
                (3, "after".to_string()),
                (4, "last-no-newline".to_string())
            ]
        );
    }

    #[test]
    fn a_byte_order_mark_opens_the_file_not_its_first_line() {
        let input = b"\xEF\xBB\xBF{\"a\":1}\n\xEF\xBB\xBFsecond\n".to_vec();
        let mut r = LineReader::new(io::BufReader::with_capacity(2, Cursor::new(input)), 1024);
        let Some((1, RawLine::Line(first))) = r.next_line().unwrap() else {
            panic!("a first line");
        };
        assert_eq!(first, b"{\"a\":1}");
        // Only the file's first bytes are a BOM; later ones are content.
        let Some((2, RawLine::Line(second))) = r.next_line().unwrap() else {
            panic!("a second line");
        };
        assert_eq!(second, b"\xEF\xBB\xBFsecond");
    }
}
