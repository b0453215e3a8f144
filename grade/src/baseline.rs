//! Reference baselines (`rh-score baseline KIND`): predictions written as `preds.jsonl`.
//!
//! * `oracle` — on every scene a plan the action rule classifies as the ground-truth
//!   action, timed and placed so that the humanoid can carry it out in physics: see
//!   [`crate::oracle`] (CATCH: hands on the impact point before the object arrives;
//!   DODGE: out of the hazard's path).
//! * `always-catch` — arms forward (0.45 m), no walking. `always-dodge` — walk 0.8 m
//!   straight away from the hazard, hands at rest. `freeze` — no walking, hands at rest.
//! * `majority` — the dataset's most frequent ground-truth action (ties: DODGE, NO_ACTION,
//!   CATCH) on every scene, as the template plan above.
//! * `random` — per scene, a uniformly chosen action with random plan parameters, from
//!   `ChaCha8Rng` seeded by (seed, scene id): reproducible and order-independent.

use crate::config::Config;
use crate::dataset::{Dataset, Scene};
use crate::oracle::{oracle_plan, OracleHints};
use crate::plan_json::freeze_template;
use crate::plan_json::{kf, plan, rest_kf};
use anyhow::Result;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rh_contract::Action;
use serde_json::Value;
use std::io::Write;

#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum BaselineKind {
    Majority,
    Oracle,
    Random,
    AlwaysCatch,
    AlwaysDodge,
    Freeze,
}

impl BaselineKind {
    pub fn name(self) -> &'static str {
        match self {
            BaselineKind::Majority => "majority",
            BaselineKind::Oracle => "oracle",
            BaselineKind::Random => "random",
            BaselineKind::AlwaysCatch => "always-catch",
            BaselineKind::AlwaysDodge => "always-dodge",
            BaselineKind::Freeze => "freeze",
        }
    }
}

/// Hazard direction on the floor in the observer's body frame (default: straight ahead).
fn hazard_dir_body(scene: &Scene) -> [f64; 2] {
    let [x0, y0, th] = scene.observer_pose;
    let p = scene.hazard_point();
    let (dx, dy) = (p[0] - x0, p[1] - y0);
    let n = dx.hypot(dy);
    if n < 1e-9 {
        return [1.0, 0.0];
    }
    let (s, c) = th.sin_cos();
    [(c * dx + s * dy) / n, (-s * dx + c * dy) / n]
}

/// Arms forward, no walking.
pub fn catch_template() -> Value {
    plan(
        "Reach out with both hands and catch the object.",
        [0.0; 3],
        0.0,
        vec![kf(0.3, [0.45, 0.15, 0.10], [0.45, -0.15, 0.10], 0.0)],
    )
}

/// Walk `dist` metres straight away from the hazard in `dur` seconds, hands at rest.
pub fn dodge_template(scene: &Scene, cfg: &Config, dist: f64, dur: f64) -> Value {
    let u = hazard_dir_body(scene);
    let v = dist / dur;
    plan(
        "Dodge: step back and move away from the hazard's path.",
        [-u[0] * v, -u[1] * v, 0.0],
        dur,
        vec![rest_kf(dur, cfg)],
    )
}

/// The plan a baseline writes for one scene (the oracle without its optional hints).
pub fn baseline_plan(
    kind: BaselineKind,
    scene: &Scene,
    majority: Action,
    seed: u64,
    cfg: &Config,
) -> Value {
    baseline_plan_with(kind, scene, majority, seed, cfg, None)
}

/// [`baseline_plan`] with the oracle's hints (the hazard's motion) when there are any.
pub fn baseline_plan_with(
    kind: BaselineKind,
    scene: &Scene,
    majority: Action,
    seed: u64,
    cfg: &Config,
    hints: Option<&OracleHints>,
) -> Value {
    let template = |a: Action| match a {
        Action::Catch => catch_template(),
        Action::Dodge => dodge_template(scene, cfg, 0.8, 1.0),
        Action::NoAction => freeze_template(cfg),
    };
    match kind {
        BaselineKind::AlwaysCatch => template(Action::Catch),
        BaselineKind::AlwaysDodge => template(Action::Dodge),
        BaselineKind::Freeze => template(Action::NoAction),
        BaselineKind::Majority => template(majority),
        BaselineKind::Oracle => oracle_plan(scene, hints, cfg),
        BaselineKind::Random => random_plan(scene, seed, cfg),
    }
}

fn random_plan(scene: &Scene, seed: u64, cfg: &Config) -> Value {
    let mut h = seed ^ 0x5248_5f52_414e_444d;
    for b in scene.scene_id.bytes() {
        h = (h ^ b as u64).wrapping_mul(0x0100_0000_01b3);
    }
    let mut rng = ChaCha8Rng::seed_from_u64(h);
    let u = hazard_dir_body(scene);
    match rng.random_range(0..3) {
        0 => {
            let x = rng.random_range(0.35..0.65);
            let y = rng.random_range(-0.2..0.2);
            let z = rng.random_range(-0.3..0.5);
            let step = rng.random_range(0.0..0.6);
            let dur = rng.random_range(0.5..1.5);
            plan(
                "Catch it.",
                [u[0] * step / dur, u[1] * step / dur, 0.0],
                dur,
                vec![kf(dur, [x, y + 0.1, z], [x, y - 0.1, z], 0.0)],
            )
        }
        1 => {
            let ang = rng.random_range(-1.0..1.0);
            let (s, c) = f64::sin_cos(ang);
            let away = [-(c * u[0] - s * u[1]), -(s * u[0] + c * u[1])];
            let dist = rng.random_range(0.3..1.2);
            let dur = rng.random_range(0.5..1.5);
            plan(
                "Dodge away.",
                [away[0] * dist / dur, away[1] * dist / dur, 0.0],
                dur,
                vec![rest_kf(dur, cfg)],
            )
        }
        _ => {
            let jitter = rng.random_range(0.0..0.1);
            plan(
                "Stay put.",
                [jitter, 0.0, 0.0],
                1.0,
                vec![rest_kf(1.0, cfg)],
            )
        }
    }
}

/// The dataset's most frequent ground-truth action (ties: DODGE, NO_ACTION, CATCH).
pub fn majority_action(ds: &Dataset) -> Action {
    let mut counts = [0usize; 3];
    for s in ds.scenes.iter().filter(|s| s.valid) {
        counts[s.gt_action.index()] += 1;
    }
    let mut best = Action::Dodge;
    for a in [Action::NoAction, Action::Catch] {
        if counts[a.index()] > counts[best.index()] {
            best = a;
        }
    }
    best
}

/// Writes one prediction line per scene, in dataset order; the oracle's dodges are
/// checked in physics with `check` (without one, a dataset with specs is refused).
#[allow(clippy::too_many_arguments)]
pub fn write_baseline(
    kind: BaselineKind,
    ds: &Dataset,
    seed: u64,
    model: &str,
    cfg: &Config,
    check: Option<crate::oracle::DodgeCheck>,
    out: &mut dyn Write,
) -> Result<()> {
    let majority = majority_action(ds);
    let hints = if kind == BaselineKind::Oracle {
        crate::oracle::load_hints(ds, cfg, check)?
    } else {
        Default::default()
    };
    #[derive(serde::Serialize)]
    struct Line<'a> {
        scene_id: &'a str,
        model: &'a str,
        plan: Value,
    }
    for scene in ds.scenes.iter().filter(|s| s.valid) {
        let line = Line {
            scene_id: &scene.scene_id,
            model,
            plan: baseline_plan_with(kind, scene, majority, seed, cfg, hints.get(&scene.scene_id)),
        };
        serde_json::to_writer(&mut *out, &line)?;
        out.write_all(b"\n")?;
    }
    out.flush()?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::aia::AiaMatcher;
    use crate::metrics::score_decision;
    use crate::plan::plan_from_value;
    use crate::synthetic::{dataset_of, synth_rows};
    use std::f64::consts::PI;

    #[test]
    fn oracle_is_perfect_on_synthetic_scenes() {
        let cfg = Config::default();
        let aia = AiaMatcher::new(&cfg.aia);
        let ds = dataset_of(&synth_rows(2000, 3));
        let maj = majority_action(&ds);
        for s in &ds.scenes {
            let v = baseline_plan(BaselineKind::Oracle, s, maj, 0, &cfg);
            // Through JSON text, as the scorer will see it.
            let v: Value = serde_json::from_str(&v.to_string()).unwrap();
            let p = plan_from_value(&v, &cfg).unwrap();
            let r = score_decision(Some(&p), s, &cfg, &aia);
            assert!(r.saa, "{} {:?} {:?}", s.scene_id, s.gt_action, r.action);
            assert!(r.safe(), "{}", s.scene_id);
            assert_eq!(r.aia, 1.0, "{}", p.intent);
            if s.gt_action == Action::Catch {
                // Exact under rule v2 (the knee bend's pelvis drop lowers the rule's
                // hands and the oracle's crouched body frame alike).
                assert!(
                    r.d_end.unwrap() < 1e-6,
                    "{} d_end {:?}",
                    s.scene_id,
                    r.d_end
                );
                let speed = p.walking_cmd[0].hypot(p.walking_cmd[1]);
                assert!(speed <= 1.5 + 1e-9, "speed {speed}");
            }
        }
    }

    #[test]
    fn oracle_handles_extreme_geometry() {
        let cfg = Config::default();
        let aia = AiaMatcher::new(&cfg.aia);
        let mut cases = Vec::new();
        for yaw in [0.0, 1.0, -2.5, PI] {
            for rel in [
                [0.0, 0.0, 0.9],   // directly above the pelvis
                [0.05, 0.0, 0.2],  // very close, low
                [-0.1, 0.02, 1.6], // just behind, high
                [0.0, 1.2, 0.9],   // beside
                [-3.0, -2.0, 0.9], // far behind
                [8.0, 3.0, 0.5],   // far ahead
                [0.4, 0.0, 0.79],  // already in hand
            ] {
                cases.push((yaw, rel));
            }
        }
        for (yaw, rel) in cases {
            let pose = [1.0, -2.0, yaw];
            let (s, c) = f64::sin_cos(yaw);
            let p = [
                pose[0] + c * rel[0] - s * rel[1],
                pose[1] + s * rel[0] + c * rel[1],
                rel[2],
            ];
            let mut sc = crate::action_rule::tests::scene(pose, Some(p));
            sc.gt_action = Action::Catch;
            let v = crate::oracle::catch(&sc, &cfg);
            let pl = plan_from_value(&v, &cfg).unwrap();
            let r = score_decision(Some(&pl), &sc, &cfg, &aia);
            assert_eq!(r.action, Some(Action::Catch), "yaw {yaw} rel {rel:?}");
            assert!(
                r.d_end.unwrap() < 1e-6,
                "yaw {yaw} rel {rel:?}: {:?}",
                r.d_end
            );
            assert!(pl.walking_cmd[0].hypot(pl.walking_cmd[1]) <= 1.5 + 1e-9);
        }
    }

    #[test]
    fn templates_classify_as_named() {
        let cfg = Config::default();
        let aia = AiaMatcher::new(&cfg.aia);
        let ds = dataset_of(&synth_rows(400, 5));
        for s in &ds.scenes {
            for (kind, want) in [
                (BaselineKind::AlwaysCatch, Action::Catch),
                (BaselineKind::AlwaysDodge, Action::Dodge),
                (BaselineKind::Freeze, Action::NoAction),
            ] {
                let v = baseline_plan(kind, s, Action::Dodge, 0, &cfg);
                let p = plan_from_value(&v, &cfg).unwrap();
                assert_eq!(score_decision(Some(&p), s, &cfg, &aia).action, Some(want));
            }
            // Random plans are reproducible.
            let a = baseline_plan(BaselineKind::Random, s, Action::Dodge, 9, &cfg);
            let b = baseline_plan(BaselineKind::Random, s, Action::Dodge, 9, &cfg);
            assert_eq!(a, b);
        }
    }
}
