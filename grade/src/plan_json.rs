//! Plan JSON in the specification §9 schema, as the baselines and the oracle write it: keyframes,
//! the rest pose, a whole plan, and the constant-twist walk between two base poses.

use crate::config::Config;
use serde_json::{json, Value};
use std::f64::consts::PI;

pub fn kf(t: f64, left: [f64; 3], right: [f64; 3], knee: f64) -> Value {
    json!({"t": t, "left_hand": left, "right_hand": right, "knee_bend": knee})
}

pub(crate) fn rest_kf(t: f64, cfg: &Config) -> Value {
    kf(t, cfg.body.rest_left, cfg.body.rest_right, 0.0)
}

/// A plan in the specification §9 schema (confidence 1).
pub fn plan(intent: &str, cmd: [f64; 3], dur: f64, keyframes: Vec<Value>) -> Value {
    json!({
        "intent": intent,
        "confidence": 1.0,
        "walking_cmd": cmd,
        "walking_duration": dur,
        "keyframes": keyframes,
    })
}

/// No walking, hands at rest.
pub fn freeze_template(cfg: &Config) -> Value {
    plan(
        "Stay still; no action is needed.",
        [0.0; 3],
        0.0,
        vec![rest_kf(0.25, cfg)],
    )
}

pub fn wrap_angle(a: f64) -> f64 {
    let mut a = (a + PI).rem_euclid(2.0 * PI) - PI;
    if a <= -PI {
        a += 2.0 * PI;
    }
    a
}

/// Body-frame walking command `[vx, vy, w]` that takes the base from `start` to the world
/// position `goal` with final heading `yaw1` in `dur` seconds (constant twist).
pub fn solve_walk(start: [f64; 3], goal: [f64; 2], yaw1: f64, dur: f64) -> [f64; 3] {
    let [x0, y0, th0] = start;
    let dth = wrap_angle(yaw1 - th0);
    let (dx, dy) = (goal[0] - x0, goal[1] - y0);
    if dth.abs() < 1e-12 {
        let (s, c) = th0.sin_cos();
        return [(c * dx + s * dy) / dur, (-s * dx + c * dy) / dur, 0.0];
    }
    let w = dth / dur;
    let (s0, c0) = th0.sin_cos();
    let (s1, c1) = (th0 + dth).sin_cos();
    let a = (s1 - s0) / w;
    let b = (c1 - c0) / w;
    let det = a * a + b * b;
    [(a * dx - b * dy) / det, (b * dx + a * dy) / det, w]
}
