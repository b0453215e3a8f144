//! Lenient plan parsing (specification §9): a `plan` object, or a model's raw `response` text with
//! the JSON inside code fences or prose; both keyframe forms.

use crate::config::Config;
use serde_json::{Map, Value};

/// One hand keyframe in the body frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Keyframe {
    pub t: f64,
    pub left: [f64; 3],
    pub right: [f64; 3],
    pub knee_bend: f64,
}

impl Keyframe {
    /// Mean of both hands (body frame).
    pub fn mid(&self) -> [f64; 3] {
        [
            0.5 * (self.left[0] + self.right[0]),
            0.5 * (self.left[1] + self.right[1]),
            0.5 * (self.left[2] + self.right[2]),
        ]
    }
}

/// Which keyframe form a plan used.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum KeyframeForm {
    None,
    Objects,
    BarePoints,
    Mixed,
}

/// A parsed motor plan.
#[derive(Debug, Clone, PartialEq)]
pub struct Plan {
    pub intent: String,
    pub confidence: Option<f64>,
    /// `[vx, vy, yaw_rate]` in the body frame.
    pub walking_cmd: [f64; 3],
    pub walking_duration: f64,
    /// Sorted by `t` (stable).
    pub keyframes: Vec<Keyframe>,
    pub form: KeyframeForm,
    /// Non-fatal notes (warning kinds) raised while parsing.
    pub notes: Vec<&'static str>,
}

/// Why no plan could be had (every variant scores as R1).
#[derive(Debug, Clone, PartialEq)]
pub enum PlanError {
    /// The text contains no JSON object at all.
    NoJson,
    /// JSON objects were found but none has `walking_cmd` or `keyframes`.
    NotAPlan,
    /// A plan field has the wrong shape.
    Malformed(String),
    /// A number is NaN/inf or outside the sanity bounds.
    Absurd(String),
    /// More keyframes or deeper nesting than the configured caps.
    TooLarge(String),
}

impl PlanError {
    /// The warning kind this error is counted under.
    pub fn kind(&self) -> &'static str {
        match self {
            PlanError::NoJson => "r1_no_json_in_response",
            PlanError::NotAPlan => "r1_not_a_plan",
            PlanError::Malformed(_) => "r1_malformed_plan",
            PlanError::Absurd(_) => "absurd_number",
            PlanError::TooLarge(_) => "r1_plan_too_large",
        }
    }
}

fn num(v: &Value) -> Option<f64> {
    match v {
        Value::Number(n) => n.as_f64(),
        Value::String(s) => s.trim().parse::<f64>().ok(),
        _ => None,
    }
}

fn vec3(v: &Value, field: &str) -> Result<[f64; 3], PlanError> {
    let malformed = || PlanError::Malformed(format!("{field} is not a list of 3 numbers"));
    match v {
        Value::Array(a) if a.len() == 3 => {
            let mut out = [0.0; 3];
            for (o, x) in out.iter_mut().zip(a) {
                *o = num(x).ok_or_else(malformed)?;
            }
            Ok(out)
        }
        Value::Object(m) => {
            let get = |k: &str| m.get(k).and_then(num);
            match (get("x"), get("y"), get("z")) {
                (Some(x), Some(y), Some(z)) => Ok([x, y, z]),
                _ => Err(malformed()),
            }
        }
        _ => Err(malformed()),
    }
}

fn walking_cmd(v: &Value) -> Result<[f64; 3], PlanError> {
    let malformed = || PlanError::Malformed("walking_cmd is not [vx, vy, yaw_rate]".into());
    match v {
        Value::Null => Ok([0.0; 3]),
        Value::Array(a) if (2..=3).contains(&a.len()) => {
            let mut out = [0.0; 3];
            for (o, x) in out.iter_mut().zip(a) {
                *o = num(x).ok_or_else(malformed)?;
            }
            Ok(out)
        }
        Value::Object(m) => {
            let get = |keys: &[&str]| keys.iter().find_map(|k| m.get(*k).and_then(num));
            let vx = get(&["vx", "x", "forward"]);
            let vy = get(&["vy", "y", "lateral", "left"]);
            let w = get(&["yaw_rate", "wz", "omega", "yaw"]);
            if vx.is_none() && vy.is_none() && w.is_none() {
                return Err(malformed());
            }
            Ok([vx.unwrap_or(0.0), vy.unwrap_or(0.0), w.unwrap_or(0.0)])
        }
        _ => Err(malformed()),
    }
}

/// True when the object carries motor content.
fn has_plan_keys(m: &Map<String, Value>) -> bool {
    m.contains_key("walking_cmd") || m.contains_key("keyframes")
}

/// A keyframe before defaults are applied.
#[derive(Debug, Clone, Copy)]
struct RawKf {
    t: Option<f64>,
    left: Option<[f64; 3]>,
    right: Option<[f64; 3]>,
    knee_bend: f64,
    bare: bool,
}

/// A plan's fields before defaults and sanity checks.
#[derive(Debug, Clone, Default)]
struct Parts {
    /// `None`: missing or null.
    intent: Option<String>,
    confidence: Option<f64>,
    cmd: [f64; 3],
    duration: Option<f64>,
    keyframes: Vec<RawKf>,
}

/// Parses a plan from a JSON value. Accepts a plan object, or an object holding one under
/// `plan` / `reaction_plan` / `output` / `response`.
pub fn plan_from_value(v: &Value, cfg: &Config) -> Result<Plan, PlanError> {
    let Value::Object(m) = v else {
        return Err(PlanError::NotAPlan);
    };
    if !has_plan_keys(m) {
        for key in ["plan", "reaction_plan", "output", "response"] {
            if let Some(inner @ Value::Object(im)) = m.get(key) {
                if has_plan_keys(im) {
                    return plan_from_value(inner, cfg);
                }
            }
        }
        return Err(PlanError::NotAPlan);
    }
    let intent = match m.get("intent") {
        Some(Value::String(s)) => Some(s.clone()),
        Some(Value::Null) | None => None,
        Some(other) => Some(other.to_string()),
    };
    let confidence = m.get("confidence").and_then(num);
    let cmd = walking_cmd(m.get("walking_cmd").unwrap_or(&Value::Null))?;
    let duration = match m.get("walking_duration") {
        Some(Value::Null) | None => None,
        Some(d) => Some(
            num(d)
                .ok_or_else(|| PlanError::Malformed("walking_duration is not a number".into()))?,
        ),
    };
    let keyframes = raw_keyframes(m.get("keyframes"))?;
    finish(
        Parts {
            intent,
            confidence,
            cmd,
            duration,
            keyframes,
        },
        cfg,
    )
}

/// Where a byte of a JSON text stands: inside a string literal (escapes respected) or not.
#[derive(Default)]
struct JsonStrings {
    in_str: bool,
    esc: bool,
}

impl JsonStrings {
    /// Feeds the next byte; true when it is outside any string and not a quote, i.e. a
    /// byte that can open or close a container.
    fn structural(&mut self, b: u8) -> bool {
        if self.in_str {
            if self.esc {
                self.esc = false;
            } else if b == b'\\' {
                self.esc = true;
            } else if b == b'"' {
                self.in_str = false;
            }
            false
        } else if b == b'"' {
            self.in_str = true;
            false
        } else {
            true
        }
    }
}

/// Containers (`{`, `[`) and the deepest nesting of a JSON text, strings skipped: a
/// bound on the tree a parse would build, had without building it.
pub fn json_shape(text: &str) -> (usize, usize) {
    let (mut containers, mut depth, mut max_depth) = (0usize, 0usize, 0usize);
    let mut strings = JsonStrings::default();
    for &b in text.as_bytes() {
        if !strings.structural(b) {
            continue;
        }
        match b {
            b'{' | b'[' => {
                containers += 1;
                depth += 1;
                max_depth = max_depth.max(depth);
            }
            b'}' | b']' => depth = depth.saturating_sub(1),
            _ => {}
        }
    }
    (containers, max_depth)
}

/// The size caps (`sanity.max_keyframes`, `sanity.max_nesting`) on raw JSON text. A
/// keyframe is at most 3 containers (itself and two hands), so a text with more than
/// `4 * max_keyframes + 64` containers cannot be a plan within the cap.
pub fn check_size(text: &str, cfg: &Config) -> Result<(), PlanError> {
    let s = &cfg.sanity;
    let (containers, depth) = json_shape(text);
    if depth > s.max_nesting {
        return Err(PlanError::TooLarge(format!(
            "JSON nested {depth} levels deep, more than sanity.max_nesting = {}",
            s.max_nesting
        )));
    }
    if containers > 4 * s.max_keyframes + 64 {
        return Err(PlanError::TooLarge(format!(
            "{containers} JSON objects/lists, more than a plan of sanity.max_keyframes = {} keyframes can hold",
            s.max_keyframes
        )));
    }
    Ok(())
}

/// Parses a plan from JSON text. `None` when the text is not JSON at all.
pub fn plan_from_json_str(text: &str, cfg: &Config) -> Option<Result<Plan, PlanError>> {
    if let Err(e) = check_size(text, cfg) {
        // Only JSON-looking text is reported (a plan's caller treats `None` as "no JSON").
        let t = text.trim_start();
        return (t.starts_with('{') || t.starts_with('[')).then_some(Err(e));
    }
    if let Some(parts) = fast::parts(text) {
        return Some(finish(parts, cfg));
    }
    let v: Value = match serde_json::from_str(text) {
        Ok(v) => v,
        // Literal NaN / Infinity (Python's json.dumps writes them) are numbers to us: they
        // are read as their string forms and then fail the sanity check like them.
        Err(_) => serde_json::from_str(&quote_nonfinite(text)?).ok()?,
    };
    Some(plan_from_value(&v, cfg))
}

/// `text` with every bare `NaN`, `Infinity`, `-Infinity` (`+Infinity`) value outside
/// strings written as a JSON string (`"NaN"`, …), which the plan reader parses as the
/// number; `None` when there is none.
pub fn quote_nonfinite(text: &str) -> Option<String> {
    const TOKENS: [&str; 4] = ["-Infinity", "+Infinity", "Infinity", "NaN"];
    let bytes = text.as_bytes();
    let mut out = String::with_capacity(text.len() + 8);
    let mut strings = JsonStrings::default();
    let (mut last, mut prev, mut i, mut any) = (0usize, b'[', 0usize, false);
    while i < bytes.len() {
        let b = bytes[i];
        if strings.structural(b) && matches!(prev, b'[' | b',' | b':') {
            let hit = TOKENS.iter().find(|t| {
                bytes[i..].starts_with(t.as_bytes())
                    && bytes
                        .get(i + t.len())
                        .is_none_or(|c| matches!(c, b',' | b']' | b'}') || c.is_ascii_whitespace())
            });
            if let Some(t) = hit {
                out.push_str(&text[last..i]);
                out.push('"');
                out.push_str(t);
                out.push('"');
                i += t.len();
                last = i;
                prev = b'0';
                any = true;
                continue;
            }
        }
        if !b.is_ascii_whitespace() {
            prev = b;
        }
        i += 1;
    }
    any.then(|| {
        out.push_str(&text[last..]);
        out
    })
}

/// Applies defaults and the sanity policy.
fn finish(p: Parts, cfg: &Config) -> Result<Plan, PlanError> {
    let mut notes = Vec::new();
    let intent = p.intent.unwrap_or_else(|| {
        notes.push("missing_intent");
        String::new()
    });
    if p.confidence.is_some_and(|c| !(0.0..=1.0).contains(&c)) {
        notes.push("confidence_out_of_range");
    }
    let cmd = p.cmd;
    let duration = match p.duration {
        Some(d) => d,
        None if cmd != [0.0; 3] => {
            notes.push("missing_walking_duration");
            1.0
        }
        None => 0.0,
    };
    let s = &cfg.sanity;
    let absurd = |what: String| Err(PlanError::Absurd(what));
    if !(duration.is_finite() && (0.0..=s.max_duration).contains(&duration)) {
        return absurd(format!(
            "walking_duration {duration} outside [0, {}] s",
            s.max_duration
        ));
    }
    for (i, v) in cmd.iter().enumerate() {
        let lim = if i < 2 { s.max_speed } else { s.max_yaw_rate };
        if !(v.is_finite() && v.abs() <= lim) {
            return absurd(format!("walking_cmd[{i}] = {v} outside ±{lim}"));
        }
    }
    let n = p.keyframes.len();
    if n > s.max_keyframes {
        return Err(PlanError::TooLarge(format!(
            "{n} keyframes, more than sanity.max_keyframes = {}",
            s.max_keyframes
        )));
    }
    let (mut objects, mut bare) = (false, false);
    let mut keyframes: Vec<Keyframe> = Vec::with_capacity(n);
    for (i, k) in p.keyframes.iter().enumerate() {
        if k.bare {
            bare = true;
        } else {
            objects = true;
        }
        keyframes.push(Keyframe {
            t: k.t.unwrap_or_else(|| default_time(i, n, duration, cfg)),
            left: k.left.unwrap_or(cfg.body.rest_left),
            right: k.right.unwrap_or(cfg.body.rest_right),
            knee_bend: k.knee_bend,
        });
    }
    for k in &keyframes {
        if !(k.t.is_finite() && (0.0..=s.max_duration).contains(&k.t)) {
            return absurd(format!(
                "keyframe t = {} outside [0, {}] s",
                k.t, s.max_duration
            ));
        }
        for c in k.left.iter().chain(&k.right) {
            if !(c.is_finite() && c.abs() <= s.max_abs_coordinate) {
                return absurd(format!(
                    "hand coordinate {c} outside ±{} m",
                    s.max_abs_coordinate
                ));
            }
        }
        if !k.knee_bend.is_finite() {
            return absurd("knee_bend is not finite".into());
        }
    }
    // Stable sort by time (all finite here).
    keyframes.sort_by(|a, b| a.t.total_cmp(&b.t));
    let form = match (objects, bare) {
        (false, false) => KeyframeForm::None,
        (true, false) => KeyframeForm::Objects,
        (false, true) => KeyframeForm::BarePoints,
        (true, true) => KeyframeForm::Mixed,
    };
    Ok(Plan {
        intent,
        confidence: p.confidence,
        walking_cmd: cmd,
        walking_duration: duration,
        keyframes,
        form,
        notes,
    })
}

/// Keyframe times for position `i` of `n` when the plan gives none: evenly spread over the
/// walking duration (the last keyframe at its end), else `(i + 1) * default_keyframe_dt`,
/// compressed evenly into `(0, max_duration]` when that would run past it — an automatic
/// time is never outside the sanity bound.
pub fn default_time(i: usize, n: usize, duration: f64, cfg: &Config) -> f64 {
    if duration > 0.0 {
        duration * (i + 1) as f64 / n as f64
    } else {
        let dt = cfg.body.default_keyframe_dt;
        let span = (dt * n as f64).min(cfg.sanity.max_duration);
        if span < dt * n as f64 {
            span * (i + 1) as f64 / n as f64
        } else {
            dt * (i + 1) as f64
        }
    }
}

fn raw_keyframes(v: Option<&Value>) -> Result<Vec<RawKf>, PlanError> {
    let list = match v {
        None | Some(Value::Null) => return Ok(Vec::new()),
        Some(Value::Array(a)) => a,
        Some(_) => return Err(PlanError::Malformed("keyframes is not a list".into())),
    };
    let mut out = Vec::with_capacity(list.len());
    for k in list {
        match k {
            Value::Array(_) => {
                let p = vec3(k, "keyframe")?;
                out.push(RawKf {
                    t: None,
                    left: Some(p),
                    right: Some(p),
                    knee_bend: 0.0,
                    bare: true,
                });
            }
            Value::Object(o) => {
                let t = match o.get("t").or_else(|| o.get("time")) {
                    None | Some(Value::Null) => None,
                    Some(t) => Some(num(t).ok_or_else(|| {
                        PlanError::Malformed("keyframe t is not a number".into())
                    })?),
                };
                let hand = |keys: &[&str]| -> Result<Option<[f64; 3]>, PlanError> {
                    for key in keys {
                        if let Some(h) = o.get(*key) {
                            if !h.is_null() {
                                return vec3(h, key).map(Some);
                            }
                        }
                    }
                    Ok(None)
                };
                let left = hand(&["left_hand", "left"])?;
                let right = hand(&["right_hand", "right"])?;
                let both = hand(&["hands", "hand", "position", "pos"])?;
                if left.is_none() && right.is_none() && both.is_none() {
                    return Err(PlanError::Malformed(
                        "keyframe has neither left_hand nor right_hand".into(),
                    ));
                }
                out.push(RawKf {
                    t,
                    left: left.or(both),
                    right: right.or(both),
                    knee_bend: o.get("knee_bend").and_then(num).unwrap_or(0.0),
                    bare: false,
                });
            }
            _ => {
                return Err(PlanError::Malformed(
                    "keyframe is neither an object nor [x, y, z]".into(),
                ))
            }
        }
    }
    Ok(out)
}

/// The fast path: a strictly typed parse of the common plan shape (`fast.rs`).
mod fast;

/// Upper bound on bytes scanned while looking for balanced `{...}` in one response.
const SCAN_BUDGET: usize = 8 << 20;
/// Upper bound on candidate objects tried per response.
const MAX_CANDIDATES: usize = 64;

/// Extracts a plan from a model's raw text: first every ```json fenced block, then every
/// balanced `{...}` in the text, in order; the first that parses as a plan wins.
pub fn plan_from_text(text: &str, cfg: &Config) -> Result<Plan, PlanError> {
    let mut saw_json = false;
    let mut first_err: Option<PlanError> = None;
    // Some(result) when `candidate` is JSON; a plan or a non-NotAPlan error stops here.
    let mut consider = |candidate: &str| -> Option<Option<Result<Plan, PlanError>>> {
        let r = plan_from_json_str(candidate, cfg)?;
        saw_json = true;
        Some(match r {
            Ok(p) => Some(Ok(p)),
            Err(PlanError::NotAPlan) => None,
            Err(e) => {
                if first_err.is_none() {
                    first_err = Some(e);
                }
                None
            }
        })
    };
    // 1. Fenced blocks.
    for block in fenced_blocks(text) {
        match consider(block.trim()) {
            Some(Some(r)) => return r,
            Some(None) => {}
            None => {
                if let Some(r) = scan_braces(block, &mut |c| consider(c).flatten()) {
                    return r;
                }
            }
        }
    }
    // 2. Balanced braces anywhere in the text.
    if let Some(r) = scan_braces(text, &mut |c| consider(c).flatten()) {
        return r;
    }
    if let Some(e) = first_err {
        return Err(e);
    }
    Err(if saw_json {
        PlanError::NotAPlan
    } else {
        PlanError::NoJson
    })
}

/// Contents of ``` fenced blocks (the language tag line is dropped).
fn fenced_blocks(text: &str) -> Vec<&str> {
    let mut out = Vec::new();
    let mut rest = text;
    while let Some(start) = rest.find("```") {
        let after = &rest[start + 3..];
        let body_start = after.find('\n').map(|i| i + 1).unwrap_or(0);
        // A tag like `json` sits on the fence line; `{` right after the fence is content.
        let body_start = if after.trim_start().starts_with('{') {
            0
        } else {
            body_start
        };
        let body = &after[body_start..];
        match body.find("```") {
            Some(end) => {
                out.push(&body[..end]);
                rest = &body[end + 3..];
            }
            None => {
                out.push(body);
                break;
            }
        }
    }
    out
}

/// Tries each balanced `{...}` substring (strings and escapes respected) in order.
fn scan_braces<T>(text: &str, f: &mut dyn FnMut(&str) -> Option<T>) -> Option<T> {
    let bytes = text.as_bytes();
    let mut budget = SCAN_BUDGET;
    let mut candidates = 0;
    let mut start = 0;
    while let Some(off) = bytes[start..].iter().position(|&b| b == b'{') {
        let s = start + off;
        if candidates >= MAX_CANDIDATES || budget == 0 {
            return None;
        }
        candidates += 1;
        let (mut depth, mut strings) = (0usize, JsonStrings::default());
        let mut end = None;
        for (i, &b) in bytes[s..].iter().enumerate() {
            if budget == 0 {
                break;
            }
            budget -= 1;
            if !strings.structural(b) {
                continue;
            }
            match b {
                b'{' => depth += 1,
                b'}' => {
                    depth -= 1;
                    if depth == 0 {
                        end = Some(s + i + 1);
                        break;
                    }
                }
                _ => {}
            }
        }
        match end {
            Some(e) => {
                // A candidate that is not a plan: look inside it too (nested objects are
                // tried by continuing just after its opening brace).
                if let Some(r) = f(&text[s..e]) {
                    return Some(r);
                }
                start = s + 1;
            }
            None => start = s + 1,
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn cfg() -> Config {
        Config::default()
    }

    #[test]
    fn object_keyframes_parse_and_sort() {
        let v = json!({"intent": "catch", "walking_cmd": [0.5, 0, 0], "walking_duration": 1.0,
        "keyframes": [
            {"t": 0.8, "left_hand": [0.4, 0.1, 0.1], "right_hand": [0.4, -0.1, 0.1], "knee_bend": 0.2},
            {"t": 0.2, "left_hand": [0.2, 0.1, 0.0], "right_hand": [0.2, -0.1, 0.0]}
        ]});
        let p = plan_from_value(&v, &cfg()).unwrap();
        assert_eq!(p.form, KeyframeForm::Objects);
        assert_eq!(p.keyframes.len(), 2);
        assert_eq!(p.keyframes[0].t, 0.2);
        assert_eq!(p.keyframes[1].left, [0.4, 0.1, 0.1]);
        assert_eq!(p.keyframes[1].knee_bend, 0.2);
    }

    #[test]
    fn bare_keyframes_are_both_hands_spread_over_duration() {
        let v = json!({"intent": "x", "walking_cmd": [0.5, 0, 0], "walking_duration": 2.0,
            "keyframes": [[0.3, 0.0, 0.1], [0.5, 0.0, 0.2]]});
        let p = plan_from_value(&v, &cfg()).unwrap();
        assert_eq!(p.form, KeyframeForm::BarePoints);
        assert_eq!(p.keyframes[0].t, 1.0);
        assert_eq!(p.keyframes[1].t, 2.0);
        assert_eq!(p.keyframes[1].left, p.keyframes[1].right);
        assert_eq!(p.keyframes[1].mid(), [0.5, 0.0, 0.2]);
        // No walking: index-based default times.
        let v = json!({"walking_cmd": [0, 0, 0], "walking_duration": 0,
            "keyframes": [[0.3, 0.0, 0.1], [0.5, 0.0, 0.2]]});
        let p = plan_from_value(&v, &cfg()).unwrap();
        assert_eq!(p.keyframes[0].t, 0.25);
        assert_eq!(p.keyframes[1].t, 0.5);
    }

    #[test]
    fn response_text_with_fences_and_prose() {
        let text = "Sure! Here is my plan:\n```json\n{\"intent\": \"dodge\", \"walking_cmd\": [-1, 0, 0], \"walking_duration\": 0.5, \"keyframes\": []}\n```\nStay safe.";
        let p = plan_from_text(text, &cfg()).unwrap();
        assert_eq!(p.walking_cmd, [-1.0, 0.0, 0.0]);
        let prose = "I think {not json} then {\"note\": {\"a\": 1}} and finally {\"intent\": \"catch it\", \"walking_cmd\": [0,0,0], \"keyframes\": [[0.5,0,0]]} ok";
        let p = plan_from_text(prose, &cfg()).unwrap();
        assert_eq!(p.intent, "catch it");
        // A plan nested in a wrapper object.
        let nested = "{\"plan\": {\"intent\": \"stay\", \"walking_cmd\": [0,0,0]}}";
        assert_eq!(plan_from_text(nested, &cfg()).unwrap().intent, "stay");
    }

    #[test]
    fn unparseable_responses() {
        assert_eq!(
            plan_from_text("I would catch it.", &cfg()),
            Err(PlanError::NoJson)
        );
        assert_eq!(
            plan_from_text("{\"answer\": \"CATCH\"}", &cfg()),
            Err(PlanError::NotAPlan)
        );
        assert!(matches!(
            plan_from_text("{\"walking_cmd\": \"fast\"}", &cfg()),
            Err(PlanError::Malformed(_))
        ));
        assert!(matches!(
            plan_from_text("{\"walking_cmd\": [1, 0", &cfg()),
            Err(PlanError::NoJson)
        ));
    }

    #[test]
    fn literal_nonfinite_numbers_are_absurd_like_their_strings() {
        for (lit, quoted) in [
            (
                r#"{"walking_cmd": [NaN, 0, 0]}"#,
                r#"{"walking_cmd": ["NaN", 0, 0]}"#,
            ),
            (
                r#"{"walking_cmd": [0,0,0], "keyframes": [[Infinity, 0, 0]]}"#,
                r#"{"walking_cmd": [0,0,0], "keyframes": [["Infinity", 0, 0]]}"#,
            ),
            (
                r#"{"walking_cmd": [0, -Infinity, 0], "intent": "NaN, Infinity"}"#,
                r#"{"walking_cmd": [0, "-Infinity", 0], "intent": "NaN, Infinity"}"#,
            ),
        ] {
            assert_eq!(quote_nonfinite(lit).as_deref(), Some(quoted));
            for text in [lit, quoted] {
                let r = plan_from_json_str(text, &cfg());
                assert!(
                    matches!(r, Some(Err(PlanError::Absurd(_)))),
                    "{text}: {r:?}"
                );
                let r = plan_from_text(&format!("Plan: {text}"), &cfg());
                assert!(matches!(r, Err(PlanError::Absurd(_))), "{text}: {r:?}");
            }
        }
        // Inside strings and inside words nothing changes.
        assert_eq!(quote_nonfinite(r#"{"intent": "NaN"}"#), None);
        assert_eq!(quote_nonfinite(r#"{"a": NaNa}"#), None);
    }

    #[test]
    fn absurd_numbers_are_rejected() {
        for v in [
            json!({"walking_cmd": [50, 0, 0], "walking_duration": 1}),
            json!({"walking_cmd": [0, 0, 0], "walking_duration": 100}),
            json!({"walking_cmd": [0, 0, 0], "walking_duration": -1}),
            json!({"walking_cmd": [0, 0, 0], "keyframes": [[20, 0, 0]]}),
            json!({"walking_cmd": [0, 0, 99], "walking_duration": 1}),
        ] {
            assert!(
                matches!(plan_from_value(&v, &cfg()), Err(PlanError::Absurd(_))),
                "{v}"
            );
        }
    }

    /// The typed fast path and the lenient `Value` path agree on every input.
    #[test]
    fn fast_and_lenient_paths_agree() {
        use rand::{RngExt, SeedableRng};
        let cfg = cfg();
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
        let num = |rng: &mut rand_chacha::ChaCha8Rng| -> Value {
            match rng.random_range(0..6) {
                0 => json!(rng.random_range(-2.0..2.0)),
                1 => json!(rng.random_range(0..3)),
                2 => json!(format!("{}", rng.random_range(0.0..1.0))),
                3 => json!(null),
                4 => json!(50.0),
                _ => json!(rng.random_range(0.0..1.5)),
            }
        };
        let mut fast_used = 0;
        for _ in 0..20_000 {
            let mut m = serde_json::Map::new();
            if rng.random_range(0..4) > 0 {
                let v = match rng.random_range(0..4) {
                    0 => json!(null),
                    1 => json!(7),
                    _ => json!("catch it, do not dodge"),
                };
                m.insert("intent".into(), v);
            }
            if rng.random_range(0..3) > 0 {
                m.insert("confidence".into(), num(&mut rng));
            }
            if rng.random_range(0..4) > 0 {
                let v = match rng.random_range(0..6) {
                    0 => json!(null),
                    1 => json!([num(&mut rng), num(&mut rng)]),
                    2 => json!({"vx": 0.5}),
                    3 => json!("fast"),
                    _ => json!([num(&mut rng), num(&mut rng), num(&mut rng)]),
                };
                m.insert("walking_cmd".into(), v);
            }
            if rng.random_range(0..3) > 0 {
                m.insert("walking_duration".into(), num(&mut rng));
            }
            if rng.random_range(0..4) > 0 {
                let n = rng.random_range(0..4);
                let mut list = Vec::new();
                for _ in 0..n {
                    let k = match rng.random_range(0..7) {
                        0 => json!([num(&mut rng), num(&mut rng), num(&mut rng)]),
                        1 => json!([num(&mut rng), num(&mut rng)]),
                        2 => json!({"hands": [0.5, 0.0, 0.1]}),
                        3 => json!({"t": num(&mut rng), "left_hand": [0.3, 0.1, 0.0]}),
                        4 => json!({"time": 0.2, "right_hand": [0.3, -0.1, 0.0], "knee_bend": 0.1}),
                        5 => json!({"t": 0.4}),
                        _ => json!({"t": num(&mut rng), "left_hand": [0.4, 0.1, 0.1],
                                    "right_hand": [num(&mut rng), -0.1, 0.1], "knee_bend": num(&mut rng)}),
                    };
                    list.push(k);
                }
                let v = if rng.random_range(0..10) == 0 {
                    json!("none")
                } else {
                    Value::Array(list)
                };
                m.insert("keyframes".into(), v);
            }
            if rng.random_range(0..10) == 0 {
                m.insert("object_identified".into(), json!("ball"));
            }
            let v = if rng.random_range(0..10) == 0 {
                json!({"plan": Value::Object(m)})
            } else {
                Value::Object(m)
            };
            let text = v.to_string();
            if fast::parts(&text).is_some() {
                fast_used += 1;
            }
            let a = plan_from_json_str(&text, &cfg).expect("valid JSON");
            let b = plan_from_value(&v, &cfg);
            assert_eq!(a, b, "{text}");
        }
        assert!(fast_used > 1000, "fast path used {fast_used} times");
    }

    #[test]
    fn pathological_text_terminates() {
        // Unbalanced braces: no candidate closes, so no JSON is found — quickly.
        let start = std::time::Instant::now();
        let text = "{".repeat(200_000) + &"}".repeat(10);
        let r = plan_from_text(&text, &cfg());
        assert!(
            matches!(r, Err(PlanError::NoJson) | Err(PlanError::TooLarge(_))),
            "{r:?}"
        );
        let text = "```".repeat(10_000);
        assert_eq!(plan_from_text(&text, &cfg()), Err(PlanError::NoJson));
        // Deep but balanced nesting: R1 for its depth, never a stack overflow.
        let text = "[".repeat(100_000) + &"]".repeat(100_000);
        let text = format!("{{\"walking_cmd\": [0,0,0], \"keyframes\": {text}}}");
        assert!(matches!(
            plan_from_text(&text, &cfg()),
            Err(PlanError::TooLarge(_))
        ));
        assert!(start.elapsed().as_secs() < 20, "took {:?}", start.elapsed());
    }

    #[test]
    fn keyframe_and_nesting_caps_make_r1_with_a_reason() {
        let cfg = cfg();
        let many: Vec<String> = (0..cfg.sanity.max_keyframes + 1)
            .map(|i| format!("{{\"t\": {}, \"pos\": [0.3, 0, 0.1]}}", i as f64 * 0.01))
            .collect();
        let text = format!(
            "{{\"walking_cmd\": [0,0,0], \"keyframes\": [{}]}}",
            many.join(",")
        );
        match plan_from_json_str(&text, &cfg) {
            Some(Err(PlanError::TooLarge(why))) => assert!(why.contains("max_keyframes"), "{why}"),
            other => panic!("{other:?}"),
        }
        // Exactly at the cap: parsed.
        let ok: Vec<String> = (0..cfg.sanity.max_keyframes)
            .map(|_| "[0.3, 0, 0.1]".to_string())
            .collect();
        let text = format!(
            "{{\"walking_cmd\": [0,0,0], \"keyframes\": [{}]}}",
            ok.join(",")
        );
        assert_eq!(
            plan_from_json_str(&text, &cfg)
                .unwrap()
                .unwrap()
                .keyframes
                .len(),
            cfg.sanity.max_keyframes
        );
        let deep = format!(
            "{{\"walking_cmd\": [0,0,0], \"x\": {}1{}}}",
            "[".repeat(40),
            "]".repeat(40)
        );
        match plan_from_json_str(&deep, &cfg) {
            Some(Err(PlanError::TooLarge(why))) => assert!(why.contains("max_nesting"), "{why}"),
            other => panic!("{other:?}"),
        }
        assert_eq!(json_shape(r#"{"a": "[[[{{", "b": [1, {"c": []}]}"#), (4, 4));
    }

    #[test]
    fn automatic_times_are_never_absurd() {
        let cfg = cfg();
        // 200 bare keyframes without walking: (i+1) * 0.25 s would reach 50 s.
        let pts: Vec<String> = (0..200).map(|_| "[0.3, 0, 0.1]".to_string()).collect();
        let text = format!(
            "{{\"walking_cmd\": [0,0,0], \"walking_duration\": 0, \"keyframes\": [{}]}}",
            pts.join(",")
        );
        let p = plan_from_json_str(&text, &cfg).unwrap().unwrap();
        let last = p.keyframes.last().unwrap().t;
        assert!(last <= cfg.sanity.max_duration && last > 29.0, "{last}");
        assert!(p.keyframes.windows(2).all(|w| w[0].t < w[1].t));
        // Few keyframes keep the documented (i + 1) * dt.
        assert_eq!(default_time(1, 3, 0.0, &cfg), 0.5);
    }
}
