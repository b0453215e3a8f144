//! The site's per-decision details: a second pass over the predictions that keeps, per
//! (scene, model), what the report's aggregates drop — the intent text, the derived
//! action, every rule that fired, the distances and the planned hand path in the world
//! frame — plus each model's `prompt_version`s.
//!
//! The same policy as the scoring pass ([`crate::preds`]): unknown, invalid and
//! unexpected scenes (outside the report's subset) are skipped, the first line of a (scene, model) pair wins, and a scored line after an
//! `error` line replaces it (a retry).

use crate::action_rule::kinematics;
use crate::aia::AiaMatcher;
use crate::config::Config;
use crate::dataset::Dataset;
use crate::error::InputError;
use crate::metrics::score_decision;
use crate::preds::{plan_of, LineReader, RawLine};
use crate::safety_rule::SafetyRule;
use anyhow::Result;
use serde::Serialize;
use serde_json::Value;
use std::collections::{BTreeMap, BTreeSet};
use std::io::BufReader;
use std::path::Path;

/// One model's decision on one scene, as the scene page shows it.
#[derive(Debug, Clone, Serialize)]
pub struct Decision {
    /// `scored` or `lost` (an `error` line: never scored).
    pub status: &'static str,
    /// Derived action; null for no parseable plan (R1) or a lost decision.
    pub action: Option<&'static str>,
    pub saa: Option<bool>,
    pub first_rule: Option<&'static str>,
    /// Every rule that fired, in order.
    pub rules: Vec<&'static str>,
    pub intent: Option<String>,
    pub d_end: Option<f64>,
    pub d_min: Option<f64>,
    pub closing: Option<f64>,
    pub aia: Option<f64>,
    /// Planned mean-hand position per keyframe: `[t, x, y, z]` (t from the decision
    /// moment Δ, world frame).
    pub hands: Vec<[f64; 4]>,
    /// Base (pelvis) floor position `[x, y]` at the end of the walk.
    pub base_end: Option<[f64; 2]>,
    pub prompt_version: Option<String>,
}

impl Decision {
    /// Action index for the browser index: 0 R1, 1 CATCH, 2 DODGE, 3 NO_ACTION, 4 lost.
    pub fn action_code(&self) -> u32 {
        match (self.status, self.action) {
            ("lost", _) => 4,
            (_, Some("CATCH")) => 1,
            (_, Some("DODGE")) => 2,
            (_, Some(_)) => 3,
            _ => 0,
        }
    }

    /// Bit i set when rule R(i+1) fired.
    pub fn rule_bits(&self) -> u32 {
        SafetyRule::ALL
            .iter()
            .enumerate()
            .filter(|(_, r)| self.rules.contains(&r.as_str()))
            .map(|(i, _)| 1 << i)
            .sum()
    }
}

/// Everything collected: decisions per scene index, then per model index.
pub struct Collected {
    pub prompt_versions: Vec<BTreeSet<String>>,
    pub decisions: BTreeMap<u32, BTreeMap<usize, Decision>>,
}

fn text_field(obj: &serde_json::Map<String, Value>, key: &str) -> Option<String> {
    match obj.get(key) {
        Some(Value::String(s)) if !s.trim().is_empty() => Some(s.trim().to_string()),
        Some(Value::Number(n)) => Some(n.to_string()),
        _ => None,
    }
}

fn is_error(v: Option<&Value>) -> bool {
    match v {
        None | Some(Value::Null) | Some(Value::Bool(false)) => false,
        Some(Value::String(s)) => !s.trim().is_empty(),
        Some(_) => true,
    }
}

fn decide(
    obj: &serde_json::Map<String, Value>,
    ds: &Dataset,
    cfg: &Config,
    aia: &AiaMatcher,
    scene: u32,
) -> Decision {
    let sc = &ds.scenes[scene as usize];
    let prompt_version = text_field(obj, "prompt_version");
    if is_error(obj.get("error")) {
        return Decision {
            status: "lost",
            action: None,
            saa: None,
            first_rule: None,
            rules: Vec::new(),
            intent: None,
            d_end: None,
            d_min: None,
            closing: None,
            aia: None,
            hands: Vec::new(),
            base_end: None,
            prompt_version,
        };
    }
    let plan = plan_of(obj, cfg).ok();
    let r = score_decision(plan.as_ref(), sc, cfg, aia);
    let (hands, base_end) = match &plan {
        Some(p) => {
            let k = kinematics(p, sc, cfg);
            let times: Vec<f64> = if p.keyframes.is_empty() {
                vec![p.walking_duration]
            } else {
                p.keyframes.iter().map(|k| k.t).collect()
            };
            let hands = times
                .iter()
                .zip(&k.hands_world)
                .map(|(t, h)| [*t, h[0], h[1], h[2]])
                .collect();
            (hands, Some([k.final_base.x, k.final_base.y]))
        }
        None => (Vec::new(), None),
    };
    Decision {
        status: "scored",
        action: r.action.map(|a| a.as_str()),
        saa: Some(r.saa),
        first_rule: r.first_rule.map(|x| x.as_str()),
        rules: SafetyRule::ALL
            .into_iter()
            .filter(|&x| r.fired(x))
            .map(|x| x.as_str())
            .collect(),
        intent: plan.as_ref().map(|p| p.intent.clone()),
        d_end: r.d_end,
        d_min: r.d_min,
        closing: r.closing,
        aia: Some(r.aia),
        hands,
        base_end,
        prompt_version,
    }
}

/// Reads the predictions file again and keeps each decision's details. `models` is the
/// report's model order (models that appear only on skipped lines are left out).
pub fn collect(
    path: &Path,
    ds: &Dataset,
    cfg: &Config,
    models: &[String],
    expected: &[bool],
) -> Result<Collected> {
    let f = std::fs::File::open(path)
        .map_err(|e| InputError(format!("cannot read predictions {}: {e}", path.display())))?;
    let aia = AiaMatcher::new(&cfg.aia);
    let index: BTreeMap<&str, usize> = models
        .iter()
        .enumerate()
        .map(|(i, m)| (m.as_str(), i))
        .collect();
    let mut out = Collected {
        prompt_versions: vec![BTreeSet::new(); models.len()],
        decisions: BTreeMap::new(),
    };
    let mut reader = LineReader::new(
        BufReader::with_capacity(1 << 20, f),
        cfg.sanity.max_line_bytes,
    );
    while let Some((_, line)) = reader.next_line()? {
        let RawLine::Line(bytes) = line else { continue };
        let Ok(Value::Object(obj)) = serde_json::from_slice::<Value>(&bytes) else {
            continue;
        };
        let (Some(scene_id), Some(model)) =
            (text_field(&obj, "scene_id"), text_field(&obj, "model"))
        else {
            continue;
        };
        let (Some(&mi), Some((si, sc))) = (index.get(model.as_str()), ds.get(&scene_id)) else {
            continue;
        };
        if !sc.valid || !expected.get(si as usize).copied().unwrap_or(false) {
            continue;
        }
        let per_scene = out.decisions.entry(si).or_default();
        let replace = match per_scene.get(&mi) {
            None => true,
            Some(d) => d.status == "lost" && !is_error(obj.get("error")),
        };
        if replace {
            let d = decide(&obj, ds, cfg, &aia, si);
            if let Some(v) = &d.prompt_version {
                out.prompt_versions[mi].insert(v.clone());
            }
            per_scene.insert(mi, d);
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::synthetic::synth_rows;

    #[test]
    fn first_line_wins_a_retry_replaces_an_error_and_prompt_versions_are_kept() {
        let rows = synth_rows(8, 3);
        let valid: Vec<&str> = rows
            .iter()
            .filter(|r| r.scene.valid)
            .map(|r| r.scene.scene_id.as_str())
            .collect();
        let (a, b) = (valid[0], valid[1]);
        let ds = Dataset::from_scenes(
            "fixture".into(),
            rows.iter().map(|r| r.scene.clone()).collect(),
        );
        let cfg = Config::default();
        let plan = |intent: &str| {
            serde_json::json!({"intent": intent, "walking_cmd": [0.0, 0.0, 0.0], "walking_duration": 0.0,
                "keyframes": [{"t": 0.2, "left_hand": [0.6, 0.15, 0.3], "right_hand": [0.6, -0.15, 0.3]}]})
        };
        let lines = [
            serde_json::json!({"scene_id": a, "model": "m", "error": "timeout", "prompt_version": "p1"}),
            serde_json::json!({"scene_id": a, "model": "m", "plan": plan("catch it"), "prompt_version": "p1"}),
            serde_json::json!({"scene_id": a, "model": "m", "plan": plan("second answer ignored")}),
            serde_json::json!({"scene_id": b, "model": "m", "plan": plan("first wins"), "prompt_version": "p2"}),
            serde_json::json!({"scene_id": b, "model": "m", "error": "late error ignored"}),
            serde_json::json!({"scene_id": "nosuchid", "model": "m", "plan": plan("unknown scene")}),
            serde_json::json!({"scene_id": a, "model": "other", "plan": plan("not in the report")}),
        ];
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("preds.jsonl");
        let text: String = lines.iter().map(|l| l.to_string() + "\n").collect();
        std::fs::write(&path, text + "not json\n").unwrap();
        let all: Vec<bool> = ds.scenes.iter().map(|s| s.valid).collect();
        let c = collect(&path, &ds, &cfg, &["m".to_string()], &all).unwrap();
        let (ia, ib) = (ds.get(a).unwrap().0, ds.get(b).unwrap().0);
        assert_eq!(c.decisions.len(), 2);
        let da = &c.decisions[&ia][&0];
        assert_eq!(
            (da.status, da.intent.as_deref()),
            ("scored", Some("catch it"))
        );
        assert_eq!(da.action, Some("CATCH"));
        assert_eq!(da.hands.len(), 1);
        assert!((da.hands[0][0] - 0.2).abs() < 1e-12);
        let db = &c.decisions[&ib][&0];
        assert_eq!(db.intent.as_deref(), Some("first wins"));
        let pv: Vec<&str> = c.prompt_versions[0].iter().map(String::as_str).collect();
        assert_eq!(pv, ["p1", "p2"]);
        assert_eq!(da.action_code(), 1);
    }
}
