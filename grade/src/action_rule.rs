//! Action rule v2 (specification §10) and the world-frame kinematics of a plan.
//!
//! The base follows the walking command `[vx, vy, yaw_rate]` (body frame, constant twist)
//! for `walking_duration` seconds and then stands still. With constant twist the path is
//! a circular arc, integrated in closed form (`yaw(t) = yaw0 + w t`):
//!
//! ```text
//! x(t) = x0 + (vx (sin yaw(t) - sin yaw0) + vy (cos yaw(t) - cos yaw0)) / w
//! y(t) = y0 + (-vx (cos yaw(t) - cos yaw0) + vy (sin yaw(t) - sin yaw0)) / w
//! ```
//!
//! and, for `|w t| < 1e-9`, the straight-line limit `x0 + R(yaw0) (vx, vy) t`.
//! A hand at body-frame `(hx, hy, hz)` at keyframe time `t` is at world
//! `base_xy(t) + R(yaw(t)) (hx, hy)` and height `pelvis_height − drop + hz`, where the
//! keyframe's knee bend lowers the pelvis (the body frame's origin) by
//! `drop = clamp(knee_bend, 0, 1) × max_pelvis_drop` — the executor's body (`[execution]`),
//! so the metrics read the hands where `--execute` puts them. Rule v1 left the drop out;
//! the classification itself (reach, D, u) is unchanged.

use crate::config::Config;
use crate::dataset::Scene;
use crate::plan::Plan;
use rh_contract::Action;

/// The base on the floor: position and heading.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BasePose {
    pub x: f64,
    pub y: f64,
    pub yaw: f64,
}

/// Base pose at time `t` for a walk starting at `start` (x, y, yaw).
pub fn base_pose_at(start: [f64; 3], cmd: [f64; 3], duration: f64, t: f64) -> BasePose {
    let [x, y, yaw] = rh_contract::action::walk_pose(start, cmd, duration, t);
    BasePose { x, y, yaw }
}

/// World position of a body-frame point for a base pose.
pub fn body_to_world(pose: BasePose, p: [f64; 3], pelvis_height: f64) -> [f64; 3] {
    let (s, c) = pose.yaw.sin_cos();
    [
        pose.x + c * p[0] - s * p[1],
        pose.y + s * p[0] + c * p[1],
        pelvis_height + p[2],
    ]
}

/// Height of the pelvis (the body frame's origin) above the floor at a keyframe's knee
/// bend (0 straight … 1 deep crouch, clamped; NaN counts as straight): the executor's.
pub fn pelvis_height(knee_bend: f64, cfg: &Config) -> f64 {
    let bend = if knee_bend.is_nan() {
        0.0
    } else {
        knee_bend.clamp(0.0, 1.0)
    };
    cfg.body.pelvis_height - bend * cfg.execution.max_pelvis_drop
}

/// What the rule saw in a plan.
#[derive(Debug, Clone, PartialEq)]
pub struct Kinematics {
    /// Base displacement over the walk (world, floor plane).
    pub displacement: [f64; 2],
    /// Unit floor direction from the observer to the hazard, when defined.
    pub hazard_dir: Option<[f64; 2]>,
    /// `D · u` (0 when `u` is undefined).
    pub d_dot_u: f64,
    /// Largest forward hand extension beyond rest, over keyframes and both hands.
    pub reach: f64,
    /// Final base pose.
    pub final_base: BasePose,
    /// World position of the mean hand at each keyframe (time order). A plan without
    /// keyframes has one implicit keyframe: hands at rest at the end of the walk.
    pub hands_world: Vec<[f64; 3]>,
}

/// Computes the kinematics of a plan in a scene.
pub fn kinematics(plan: &Plan, scene: &Scene, cfg: &Config) -> Kinematics {
    let start = scene.observer_pose;
    let dur = plan.walking_duration;
    let end = base_pose_at(start, plan.walking_cmd, dur, dur);
    let displacement = [end.x - start[0], end.y - start[1]];
    let target = scene.hazard_point();
    let (ux, uy) = (target[0] - start[0], target[1] - start[1]);
    let norm = ux.hypot(uy);
    let hazard_dir = (norm > 1e-9).then(|| [ux / norm, uy / norm]);
    let d_dot_u = hazard_dir.map_or(0.0, |u| displacement[0] * u[0] + displacement[1] * u[1]);
    let mut reach = 0.0f64;
    let mut hands_world = Vec::with_capacity(plan.keyframes.len().max(1));
    for k in &plan.keyframes {
        reach = reach.max(k.left[0] - cfg.body.rest_left[0]);
        reach = reach.max(k.right[0] - cfg.body.rest_right[0]);
        let pose = base_pose_at(start, plan.walking_cmd, dur, k.t);
        hands_world.push(body_to_world(
            pose,
            k.mid(),
            pelvis_height(k.knee_bend, cfg),
        ));
    }
    if plan.keyframes.is_empty() {
        let mid = [
            0.5 * (cfg.body.rest_left[0] + cfg.body.rest_right[0]),
            0.5 * (cfg.body.rest_left[1] + cfg.body.rest_right[1]),
            0.5 * (cfg.body.rest_left[2] + cfg.body.rest_right[2]),
        ];
        hands_world.push(body_to_world(end, mid, cfg.body.pelvis_height));
    }
    Kinematics {
        displacement,
        hazard_dir,
        d_dot_u,
        reach,
        final_base: end,
        hands_world,
    }
}

/// Tolerance of the threshold comparisons (m), so that a value meant to sit exactly on a
/// threshold (0.30 − 0.10 = 0.19999999999999998) counts as on it.
pub const THRESHOLD_EPS: f64 = 1e-9;

/// Action rule v2's classification (as v1's): reach ≥ τ_reach and not (D·u ≤ −τ_retreat) → CATCH; else
/// |D| ≥ τ_move → DODGE; else NO_ACTION (comparisons with [`THRESHOLD_EPS`]).
pub fn classify_kinematics(k: &Kinematics, cfg: &Config) -> Action {
    let r = &cfg.action_rule;
    let retreating = k.d_dot_u <= -r.retreat_threshold + THRESHOLD_EPS;
    if k.reach >= r.reach_threshold - THRESHOLD_EPS && !retreating {
        Action::Catch
    } else if k.displacement[0].hypot(k.displacement[1]) >= r.move_threshold - THRESHOLD_EPS {
        Action::Dodge
    } else {
        Action::NoAction
    }
}

/// Classifies a plan in a scene.
pub fn classify(plan: &Plan, scene: &Scene, cfg: &Config) -> (Action, Kinematics) {
    let k = kinematics(plan, scene, cfg);
    (classify_kinematics(&k, cfg), k)
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::plan::{Keyframe, KeyframeForm};
    use std::f64::consts::{FRAC_PI_2, PI};

    pub(crate) fn scene(pose: [f64; 3], impact: Option<[f64; 3]>) -> Scene {
        Scene {
            scene_id: "00000000".into(),
            group_id: "g".into(),
            family: 0,
            speed_band: Some(1),
            speed_band_name: "normal".into(),
            speed_sweep: true,
            object_id: "ball".into(),
            looks_like: None,
            adversarial: false,
            twin_scene_id: None,
            gt_action: Action::Catch,
            dangerous: false,
            danger_present: true,
            impact_point: impact,
            object_start: [pose[0] + 2.0, pose[1], 1.5],
            observer_pose: pose,
            valid: true,
        }
    }

    pub(crate) fn plan(cmd: [f64; 3], dur: f64, hands: &[[f64; 3]]) -> Plan {
        let n = hands.len();
        Plan {
            intent: String::new(),
            confidence: None,
            walking_cmd: cmd,
            walking_duration: dur,
            keyframes: hands
                .iter()
                .enumerate()
                .map(|(i, h)| Keyframe {
                    t: if dur > 0.0 {
                        dur * (i + 1) as f64 / n as f64
                    } else {
                        0.0
                    },
                    left: [h[0], h[1] + 0.15, h[2]],
                    right: [h[0], h[1] - 0.15, h[2]],
                    knee_bend: 0.0,
                })
                .collect(),
            form: KeyframeForm::Objects,
            notes: vec![],
        }
    }

    fn close(a: [f64; 3], b: [f64; 3]) -> bool {
        a.iter().zip(&b).all(|(x, y)| (x - y).abs() < 1e-12)
    }

    #[test]
    fn yaw_quarter_turn_maps_body_x_to_world_y() {
        let pose = BasePose {
            x: 1.0,
            y: 2.0,
            yaw: FRAC_PI_2,
        };
        let w = body_to_world(pose, [1.0, 0.0, 0.1], 0.79);
        assert!(close(w, [1.0, 3.0, 0.89]), "{w:?}");
        let w = body_to_world(pose, [0.0, 1.0, 0.0], 0.79);
        assert!(close(w, [0.0, 2.0, 0.79]), "{w:?}");
        // Walking forward with yaw π/2 moves along world +y.
        let p = base_pose_at([0.0, 0.0, FRAC_PI_2], [1.0, 0.0, 0.0], 2.0, 2.0);
        assert!(close([p.x, p.y, p.yaw], [0.0, 2.0, FRAC_PI_2]), "{p:?}");
    }

    #[test]
    fn knee_bend_lowers_the_hands_with_the_pelvis() {
        // Rule v2: knee_bend b lowers the body frame by clamp(b, 0, 1) × 0.25 m.
        let c = Config::default();
        assert_eq!(c.execution.max_pelvis_drop, 0.25);
        let s = scene([0.0, 0.0, 0.0], Some([0.4, 0.0, 0.3]));
        let z = |bend: f64| {
            let mut p = plan([0.0; 3], 0.0, &[[0.4, 0.0, -0.3]]);
            p.keyframes[0].knee_bend = bend;
            kinematics(&p, &s, &c).hands_world[0][2]
        };
        assert!((z(0.0) - 0.49).abs() < 1e-12);
        assert!((z(0.4) - (0.49 - 0.1)).abs() < 1e-12);
        assert!((z(1.0) - 0.24).abs() < 1e-12);
        assert!((z(3.0) - 0.24).abs() < 1e-12, "clamped to 1");
        assert!((z(-1.0) - 0.49).abs() < 1e-12, "clamped to 0");
        // The classification does not depend on it.
        let mut p = plan([0.0; 3], 0.0, &[[0.4, 0.0, -0.3]]);
        p.keyframes[0].knee_bend = 1.0;
        assert_eq!(classify(&p, &s, &c).0, Action::Catch);
    }

    #[test]
    fn arc_integration_matches_numeric() {
        let start = [0.3, -0.2, 0.7];
        let cmd = [0.8, 0.3, 1.1];
        let exact = base_pose_at(start, cmd, 1.5, 1.2);
        let (mut x, mut y, mut th) = (start[0], start[1], start[2]);
        let n = 200_000;
        let dt = 1.2 / n as f64;
        for _ in 0..n {
            let thm = th + 0.5 * cmd[2] * dt;
            x += (cmd[0] * thm.cos() - cmd[1] * thm.sin()) * dt;
            y += (cmd[0] * thm.sin() + cmd[1] * thm.cos()) * dt;
            th += cmd[2] * dt;
        }
        assert!((exact.x - x).abs() < 1e-9 && (exact.y - y).abs() < 1e-9);
        assert!((exact.yaw - th).abs() < 1e-9);
        // After the walk the base stands still.
        let after = base_pose_at(start, cmd, 1.5, 10.0);
        assert_eq!(after, base_pose_at(start, cmd, 1.5, 1.5));
        // A full turn in place returns to the start.
        let p = base_pose_at(start, [0.0, 0.0, PI], 2.0, 2.0);
        assert!((p.x - start[0]).abs() < 1e-12 && (p.y - start[1]).abs() < 1e-12);
    }

    #[test]
    fn rule_branches() {
        let c = Config::default();
        let s = scene([0.0, 0.0, 0.0], Some([1.0, 0.0, 0.9]));
        // Reach forward, no walking → CATCH.
        assert_eq!(
            classify(&plan([0.0; 3], 0.0, &[[0.35, 0.0, 0.1]]), &s, &c).0,
            Action::Catch
        );
        // Reach exactly at threshold → CATCH (≥).
        assert_eq!(
            classify(&plan([0.0; 3], 0.0, &[[0.30, 0.0, 0.1]]), &s, &c).0,
            Action::Catch
        );
        // Reach just under threshold, no walking → NO_ACTION.
        assert_eq!(
            classify(&plan([0.0; 3], 0.0, &[[0.29, 0.0, 0.1]]), &s, &c).0,
            Action::NoAction
        );
        // Reach + walking toward the hazard → CATCH.
        assert_eq!(
            classify(&plan([0.5, 0.0, 0.0], 1.0, &[[0.5, 0.0, 0.1]]), &s, &c).0,
            Action::Catch
        );
        // Reach while retreating (D·u = -0.5) → DODGE.
        assert_eq!(
            classify(&plan([-0.5, 0.0, 0.0], 1.0, &[[0.5, 0.0, 0.1]]), &s, &c).0,
            Action::Dodge
        );
        // Reach while retreating just under the threshold (D·u = -0.14) → CATCH.
        assert_eq!(
            classify(&plan([-0.14, 0.0, 0.0], 1.0, &[[0.5, 0.0, 0.1]]), &s, &c).0,
            Action::Catch
        );
        // Retreat of exactly 0.15 counts as retreating (≤).
        assert_eq!(
            classify(&plan([-0.15, 0.0, 0.0], 1.0, &[[0.5, 0.0, 0.1]]), &s, &c).0,
            Action::Dodge
        );
        // Sidestep without reach → DODGE; too small a step → NO_ACTION.
        assert_eq!(
            classify(&plan([0.0, 0.3, 0.0], 1.0, &[]), &s, &c).0,
            Action::Dodge
        );
        assert_eq!(
            classify(&plan([0.0, 0.1, 0.0], 1.0, &[]), &s, &c).0,
            Action::NoAction
        );
        // Turning in place is not moving.
        assert_eq!(
            classify(&plan([0.0, 0.0, 1.0], 1.0, &[]), &s, &c).0,
            Action::NoAction
        );
        // No impact point: u comes from the object's start (+x here), retreat → DODGE.
        let s2 = scene([0.0, 0.0, 0.0], None);
        let (a, k) = classify(&plan([-0.3, 0.0, 0.0], 1.0, &[[0.5, 0.0, 0.0]]), &s2, &c);
        assert_eq!(a, Action::Dodge);
        assert!((k.d_dot_u + 0.3).abs() < 1e-12);
    }

    #[test]
    fn reach_is_forward_extension_of_either_hand() {
        let c = Config::default();
        let s = scene([0.0, 0.0, 0.0], Some([1.0, 0.0, 0.9]));
        let mut p = plan([0.0; 3], 0.0, &[[0.1, 0.0, 0.0]]);
        p.keyframes[0].right = [0.45, -0.15, 0.0];
        let (a, k) = classify(&p, &s, &c);
        assert!((k.reach - 0.35).abs() < 1e-12);
        assert_eq!(a, Action::Catch);
        // Hands raised high but not forward: no reach.
        let p = plan([0.0; 3], 0.0, &[[0.1, 0.0, 0.5]]);
        assert_eq!(classify(&p, &s, &c).0, Action::NoAction);
    }

    #[test]
    fn hands_use_base_pose_at_keyframe_time() {
        let c = Config::default();
        // Observer facing +y; walks forward 1 m over 1 s; keyframes at 0.5 s and 1 s.
        let s = scene([0.0, 0.0, FRAC_PI_2], Some([0.0, 1.5, 0.9]));
        let p = plan([1.0, 0.0, 0.0], 1.0, &[[0.3, 0.0, 0.0], [0.5, 0.0, 0.11]]);
        let k = kinematics(&p, &s, &c);
        assert!(
            close(k.hands_world[0], [0.0, 0.8, 0.79]),
            "{:?}",
            k.hands_world
        );
        assert!(
            close(k.hands_world[1], [0.0, 1.5, 0.90]),
            "{:?}",
            k.hands_world
        );
    }
}
