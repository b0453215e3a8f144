//! Escape walks (label rule v4): the dodges that decide whether a strike can be escaped
//! at all. A scene whose hazard would strike the standing body is `valid_escapable`
//! only when at least one of these walks, executed in physics from Δ, is not struck —
//! otherwise no decision could matter and the scene is resampled, like one that reaches
//! the observer before the reaction time. The oracle baseline falls back on the same
//! walks when its own dodge would be struck.
//!
//! The walks: `escape_directions` headings evenly spaced in the body frame, starting
//! straight back and alternating to either side of it (back, back-left, back-right, …,
//! forward), each `escape_distance` m at `escape_speed` m/s with the hands at rest
//! (`configs/labels.toml`).

use super::{ExecConfig, ExecKeyframe, ExecPlan, OutcomeKind, Replay};
use crate::body::{REST_LEFT, REST_RIGHT};
use crate::spec::SceneSpec;
use std::sync::OnceLock;

/// The escape walks of a spec, in the order they are tried (none for specs of rules ≤ v3,
/// which store no `escape_directions`).
pub fn escape_plans(spec: &SceneSpec) -> Vec<ExecPlan> {
    let l = &spec.labels;
    let n = l.escape_directions;
    if n == 0 || l.escape_speed <= 0.0 {
        return Vec::new();
    }
    let dur = l.escape_distance / l.escape_speed;
    let step = std::f64::consts::TAU / n as f64;
    (0..n)
        .map(|i| {
            // 0, +1, −1, +2, −2, … steps from straight back.
            let k = i.div_ceil(2) as f64 * if i % 2 == 1 { 1.0 } else { -1.0 };
            let heading = std::f64::consts::PI - k * step;
            let (s, c) = heading.sin_cos();
            ExecPlan {
                walking_cmd: [l.escape_speed * c, l.escape_speed * s, 0.0],
                walking_duration: dur,
                keyframes: vec![ExecKeyframe {
                    t: dur,
                    left: REST_LEFT,
                    right: REST_RIGHT,
                    knee_bend: 0.0,
                }],
            }
        })
        .collect()
}

/// The first of `plans` that is not `struck` when executed from `replay`, by index.
pub fn first_unstruck(replay: &Replay, plans: &[ExecPlan], cfg: &ExecConfig) -> Option<usize> {
    plans
        .iter()
        .position(|p| replay.execute(p, cfg).outcome != OutcomeKind::Struck)
}

/// Whether some escape walk of `spec` is not struck (with the embedded `[execution]`
/// config of `configs/scoring.toml`, the executor `rh-score --execute` uses by default).
/// Specs without escape walks (rules ≤ v3) pass.
pub fn escapable(spec: &SceneSpec) -> bool {
    let mut plans = escape_plans(spec);
    if plans.is_empty() {
        return true;
    }
    // Whether any walk clears does not depend on the order they are tried in: the
    // sideways walks first, which clear most often (a hazard that follows the observer's
    // line runs down a walk straight back), and a struck walk ends at its strike.
    plans.sort_by(|a, b| sideways(b).total_cmp(&sideways(a)));
    static CFG: OnceLock<ExecConfig> = OnceLock::new();
    let cfg = CFG.get_or_init(ExecConfig::embedded_default);
    first_unstruck(&super::replay_reusing(spec), &plans, cfg).is_some()
}

/// How far a walk heads to the side, 0 (straight back or ahead) to 1 (square across).
fn sideways(plan: &ExecPlan) -> f64 {
    let [vx, vy, _] = plan.walking_cmd;
    vy.abs() / vx.hypot(vy).max(f64::MIN_POSITIVE)
}
