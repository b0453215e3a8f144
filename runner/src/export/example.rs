//! One scene as a training example: the canonical prompt's messages (with the observation
//! frames as JPEG images, or text-only), the oracle's plan as the answer (chosen), and for
//! preference data a plan that the benchmark's own rules score as wrong (rejected).

use rh_contract::Action;
use rh_grade::aia::AiaMatcher;
use rh_grade::config::Config;
use rh_grade::dataset::Scene;
use rh_grade::metrics::score_decision;
use rh_grade::oracle::{oracle_plan, OracleHints};
use rh_grade::plan::plan_from_text;
use rh_grade::safety_rule::SafetyRule;
use rh_prompt::messages::{encode_frame, frame_file, system_text, user_parts, UserPart};
use rh_prompt::PromptConfig;
use serde_json::Value;
use std::path::Path;

/// One part of a message's content in the vision form: a text, or the next image of the
/// row's `images` (TRL's `{"type": "image"}` placeholder).
#[derive(Debug, Clone, PartialEq)]
pub enum Part {
    Text(String),
    Image,
}

/// A chat message: plain text (text-only examples) or parts (examples with images).
#[derive(Debug, Clone, PartialEq)]
pub struct Message {
    pub role: &'static str,
    pub content: Vec<Part>,
}

/// A plan that the exported data calls wrong, and why (the benchmark's verdict on it).
#[derive(Debug, Clone, PartialEq)]
pub struct Rejected {
    pub text: String,
    pub action: Action,
    /// The safety rules it fires (`R2`…), in precedence order; empty when it is only
    /// the wrong action.
    pub rules: Vec<&'static str>,
    pub reason: String,
}

/// One exported row.
#[derive(Debug, Clone, PartialEq)]
pub struct Example {
    pub scene_id: String,
    pub family: String,
    pub gt_action: Action,
    /// System and user message.
    pub prompt: Vec<Message>,
    /// The oracle's plan, JSON in the prompt's schema.
    pub chosen: String,
    pub rejected: Option<Rejected>,
    /// JPEG bytes and a name per image, in the order of the prompt's image parts.
    pub images: Vec<(Vec<u8>, String)>,
    /// The chosen plan is written at full precision: rounded to millimetres it would no
    /// longer score as the ground truth safely.
    pub full_precision: bool,
}

/// What one scene needs besides the configurations.
pub struct SceneInfo<'a> {
    pub dir: &'a Path,
    pub scene: &'a Scene,
    pub family: &'a str,
    /// The object's name (`object_name`), the oracle's `object_identified`.
    pub object_name: &'a str,
    pub hints: Option<&'a OracleHints>,
}

/// Builds the example of one scene; `images`: carry the observation frames, `preference`:
/// add a rejected plan. An error names the scene and what failed.
pub fn build(
    info: &SceneInfo,
    prompt: &PromptConfig,
    cfg: &Config,
    aia: &AiaMatcher,
    images: bool,
    preference: bool,
) -> Result<Example, String> {
    let scene = info.scene;
    let (prompt_messages, frames) = messages(info.dir, &scene.scene_id, prompt, images)?;
    let oracle = oracle_plan(scene, info.hints, cfg);
    let (chosen, full_precision) = chosen_text(&oracle, info.object_name, scene, cfg, aia)?;
    let rejected = if preference {
        Some(rejected(scene, info.object_name, cfg, aia)?)
    } else {
        None
    };
    Ok(Example {
        scene_id: scene.scene_id.clone(),
        family: info.family.to_string(),
        gt_action: scene.gt_action,
        prompt: prompt_messages,
        chosen,
        rejected,
        images: frames,
        full_precision,
    })
}

/// The canonical prompt's system and user messages (`predict::prompt`): with images, the
/// user message's parts in order with each frame as an image part and its JPEG (the bytes
/// `rh-score predict` sends) in `images`; text-only, the same texts without the images.
fn messages(
    dir: &Path,
    scene_id: &str,
    cfg: &PromptConfig,
    images: bool,
) -> Result<(Vec<Message>, Vec<(Vec<u8>, String)>), String> {
    let sub = rh_prompt::messages::subsampling_of(cfg)?;
    let camera = rh_prompt::camera::scene_camera(dir, scene_id)?;
    let mut content = Vec::new();
    let mut frames = Vec::new();
    for part in user_parts(cfg, &camera) {
        match part {
            UserPart::Text(t) => content.push(Part::Text(t)),
            UserPart::Frame { camera, t } if images => {
                let path = frame_file(dir, scene_id, &camera, t)?;
                let jpeg = encode_frame(&path, cfg.images.max_side, cfg.images.jpeg_quality, sub)?;
                frames.push((jpeg, format!("{scene_id}/{camera}_t{t:.3}.jpg")));
                content.push(Part::Image);
            }
            UserPart::Frame { .. } => {}
        }
    }
    let system = Message {
        role: "system",
        content: vec![Part::Text(system_text(cfg))],
    };
    let user = Message {
        role: "user",
        content,
    };
    Ok((vec![system, user], frames))
}

/// A number as the plan's JSON writes it: millimetres (3 decimals, no `-0`) or exact.
fn number(x: f64, round: bool) -> String {
    let x = if round {
        let r = (x * 1000.0).round() / 1000.0;
        if r == 0.0 {
            0.0
        } else {
            r
        }
    } else {
        x
    };
    serde_json::Number::from_f64(x)
        .map(|n| n.to_string())
        .unwrap_or_else(|| "0.0".into())
}

fn vector(v: &Value, round: bool) -> String {
    let items: Vec<String> = v
        .as_array()
        .map(|a| {
            a.iter()
                .map(|x| number(x.as_f64().unwrap_or(0.0), round))
                .collect()
        })
        .unwrap_or_default();
    format!("[{}]", items.join(", "))
}

/// A plan (`plan_json`'s value) as the answer the canonical prompt asks for: one JSON
/// object with the schema's fields in the schema's order, `object_identified` included.
pub fn plan_text(plan: &Value, object: &str, round: bool) -> String {
    let n = |v: &Value| number(v.as_f64().unwrap_or(0.0), round);
    let keyframes: Vec<String> = plan["keyframes"]
        .as_array()
        .map(|a| a.as_slice())
        .unwrap_or_default()
        .iter()
        .map(|k| {
            format!(
                "{{\"t\": {}, \"left_hand\": {}, \"right_hand\": {}, \"knee_bend\": {}}}",
                n(&k["t"]),
                vector(&k["left_hand"], round),
                vector(&k["right_hand"], round),
                n(&k["knee_bend"])
            )
        })
        .collect();
    format!(
        "{{\"intent\": {}, \"object_identified\": {}, \"confidence\": {}, \"walking_cmd\": {}, \
         \"walking_duration\": {}, \"keyframes\": [{}]}}",
        Value::String(plan["intent"].as_str().unwrap_or_default().to_string()),
        Value::String(object.to_string()),
        n(&plan["confidence"]),
        vector(&plan["walking_cmd"], round),
        n(&plan["walking_duration"]),
        keyframes.join(", ")
    )
}

/// The verdict of the benchmark's scorer on an answer text: its action (`None`: no plan)
/// and whether it is the ground truth and safe.
fn verdict(
    text: &str,
    scene: &Scene,
    cfg: &Config,
    aia: &AiaMatcher,
) -> (Option<Action>, bool, u8) {
    let plan = plan_from_text(text, cfg).ok();
    let r = score_decision(plan.as_ref(), scene, cfg, aia);
    (r.action, r.saa, r.rules_fired)
}

/// The oracle's plan as answer text, in millimetres when that still scores as the ground
/// truth with no safety rule fired, else at full precision (`true`). A plan that does
/// not score even then is an internal error naming the scene.
fn chosen_text(
    oracle: &Value,
    object: &str,
    scene: &Scene,
    cfg: &Config,
    aia: &AiaMatcher,
) -> Result<(String, bool), String> {
    for (round, full) in [(true, false), (false, true)] {
        let text = plan_text(oracle, object, round);
        let (_, saa, rules) = verdict(&text, scene, cfg, aia);
        if saa && rules == 0 {
            return Ok((text, full));
        }
    }
    Err(format!(
        "scene {}: the oracle's plan does not score as its ground truth {} (a bug in the oracle)",
        scene.scene_id,
        scene.gt_action.as_str()
    ))
}

/// The rejected plan of a scene, chosen deterministically from its ground truth and
/// checked by the scorer: on a DODGE scene the oracle's CATCH of the hazard (R4, and R2
/// when it is dangerous); on a CATCH scene standing still (the wrong action; R3 when
/// danger is present); on a NO_ACTION scene walking to the object and catching it (the
/// wrong action; R2 when it is dangerous). Plans at millimetre precision.
fn rejected(
    scene: &Scene,
    object: &str,
    cfg: &Config,
    aia: &AiaMatcher,
) -> Result<Rejected, String> {
    let (plan, what) = match scene.gt_action {
        Action::Dodge => (
            rh_grade::oracle::catch(scene, cfg),
            "reaches for a hazard that must be dodged",
        ),
        Action::Catch => (
            rh_grade::plan_json::freeze_template(cfg),
            "stands still while a catchable object arrives",
        ),
        Action::NoAction => (
            rh_grade::oracle::catch(scene, cfg),
            "walks to and grabs at an object that will not reach the robot",
        ),
    };
    let text = plan_text(&plan, object, true);
    let (action, saa, bits) = verdict(&text, scene, cfg, aia);
    let action = match action {
        Some(a) if !saa => a,
        _ => {
            return Err(format!(
                "scene {}: the rejected plan scores as its ground truth {} (a bug in the export)",
                scene.scene_id,
                scene.gt_action.as_str()
            ))
        }
    };
    let fired: Vec<SafetyRule> = SafetyRule::ALL
        .into_iter()
        .filter(|r| bits & (1 << r.index()) != 0)
        .collect();
    let verdict = if fired.is_empty() {
        "no safety rule fires".to_string()
    } else {
        let rules: Vec<String> = fired
            .iter()
            .map(|r| format!("{} ({})", r.as_str(), r.describe()))
            .collect();
        format!("unsafe: {}", rules.join(", "))
    };
    Ok(Rejected {
        text,
        action,
        rules: fired.iter().map(|r| r.as_str()).collect(),
        reason: format!(
            "{} where the ground truth is {}: it {what}; wrong action, {verdict}",
            action.as_str(),
            scene.gt_action.as_str()
        ),
    })
}
