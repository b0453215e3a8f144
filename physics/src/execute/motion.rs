//! How the body follows a plan, step by step (pure kinematics, no physics):
//!
//! * **Base.** The reference is action rule v1's closed-form walk: constant twist
//!   `[vx, vy, yaw_rate]` (body frame) for `walking_duration`, then standing
//!   ([`reference_base`]). Each step the base moves by the reference's own step plus a
//!   correction of its lag (`lag / track_time_constant`), then the robot's limits clip it:
//!   horizontal speed ≤ `max_speed`, horizontal acceleration ≤ `max_accel`, yaw rate ≤
//!   `max_yaw_rate`, yaw acceleration ≤ `max_yaw_accel`. When no limit binds the base is
//!   exactly on the reference (to rounding), i.e. integrated as rule v1 integrates it.
//! * **Knee bend** (0 straight … 1 deep crouch, clamped) lowers the pelvis by
//!   `knee_bend × max_pelvis_drop`, at most `max_drop_speed` per second.
//! * **Hands** track the keyframe targets, piecewise-linear in time from the rest pose at
//!   t = 0 (the decision moment) and held after the last keyframe; two targets closer than
//!   [`HAND_GAP`] are spread apart about their midpoint (the bare `[x, y, z]` form gives
//!   both hands one point); each target is clamped to the arm's reach and joint limits
//!   ([`Geometry::reachable`]), and a hand moves at most `max_hand_speed`.

use super::{ExecConfig, ExecPlan};
use crate::body::{BodyPose, Geometry, HAND_GAP, REST_LEFT, REST_RIGHT};
use crate::spec::{vec3, Vec3};

/// Rest hand positions (body frame), specification §2.

/// Rule v1's base pose `(x, y, yaw)` at time `t` after the decision for a walk from
/// `start` (closed-form arc; the straight limit when `|w t| < 1e-9`).
pub fn reference_base(start: Vec3, cmd: Vec3, duration: f64, t: f64) -> Vec3 {
    rh_contract::action::walk_pose(start, cmd, duration, t)
}

/// What the body tracks, as functions of the time `t` after the decision: the reference
/// base pose and the hand targets (body frame) with the knee bend. A plan is one
/// ([`PlanReference`]); the closed-loop controller (`crate::control`) builds another from
/// its commands.
pub trait Reference {
    /// The reference base pose `(x, y, yaw)` at `t`.
    fn base(&self, t: f64) -> Vec3;
    /// Left and right hand targets (body frame) and knee bend at `t`.
    fn targets(&self, t: f64) -> (Vec3, Vec3, f64);
}

/// A plan as a [`Reference`]: rule v1's walk from `start`, hands linear between keyframes
/// from the rest pose at t = 0, held after the last keyframe.
pub struct PlanReference<'a> {
    pub plan: &'a ExecPlan,
    pub start: Vec3,
}

impl Reference for PlanReference<'_> {
    fn base(&self, t: f64) -> Vec3 {
        let p = self.plan;
        reference_base(self.start, p.walking_cmd, p.walking_duration, t)
    }

    fn targets(&self, t: f64) -> (Vec3, Vec3, f64) {
        plan_targets(self.plan, t)
    }
}

/// Hand targets and knee bend of `plan` at time `t`: linear between keyframes, from the
/// rest pose at t = 0, held after the last keyframe.
pub fn plan_targets(plan: &ExecPlan, t: f64) -> (Vec3, Vec3, f64) {
    let mut prev = (0.0, REST_LEFT, REST_RIGHT, 0.0);
    for k in &plan.keyframes {
        if t <= k.t {
            let span = k.t - prev.0;
            let f = if span > 1e-12 {
                ((t - prev.0) / span).clamp(0.0, 1.0)
            } else {
                1.0
            };
            let lerp = |a: Vec3, b: Vec3| vec3::add(a, vec3::scale(vec3::sub(b, a), f));
            return (
                lerp(prev.1, k.left),
                lerp(prev.2, k.right),
                prev.3 + (k.knee_bend - prev.3) * f,
            );
        }
        prev = (k.t, k.left, k.right, k.knee_bend);
    }
    (prev.1, prev.2, prev.3)
}

/// The body's state while executing one plan (or a stream of commands).
pub struct Motion {
    cfg: ExecConfig,
    geometry: Geometry,
    dt: f64,
    pub pose: BodyPose,
    velocity: [f64; 2],
    yaw_rate: f64,
    /// Base limits that bound at least once (speed, accel, yaw rate, yaw accel).
    pub limits_hit: [bool; 4],
}

impl Motion {
    pub fn new(cfg: &ExecConfig, geometry: Geometry, start: Vec3, dt: f64) -> Self {
        Motion {
            cfg: cfg.clone(),
            geometry,
            dt,
            pose: geometry.rest_pose(start),
            velocity: [0.0; 2],
            yaw_rate: 0.0,
            limits_hit: [false; 4],
        }
    }

    /// Whether the plan is reaching now: a palm is more than `reaching_offset` from its
    /// rest position (body frame). Only then do the hands and forearms count as catching
    /// (a touch there is no strike short of `hand_strike_impulse`); a body standing with
    /// its hands at rest is struck on the forearms like anywhere else.
    pub fn reaching(&self) -> bool {
        let rest = self.geometry.rest_pose(self.pose.base);
        let off = |a: Vec3, b: Vec3| vec3::norm(vec3::sub(a, b));
        off(self.pose.left, rest.left) > self.cfg.reaching_offset
            || off(self.pose.right, rest.right) > self.cfg.reaching_offset
    }

    /// The base's horizontal velocity (world frame, m/s) and yaw rate (rad/s) over the
    /// last step.
    pub fn base_velocity(&self) -> Vec3 {
        [self.velocity[0], self.velocity[1], self.yaw_rate]
    }

    /// Advances the body from step `k` to step `k + 1` after the decision, tracking `r`.
    pub fn advance(&mut self, k: u32, r: &dyn Reference) {
        let (t0, t1) = (k as f64 * self.dt, (k + 1) as f64 * self.dt);
        self.advance_base(r.base(t0), r.base(t1));
        let (left, right, knee) = r.targets(t1);
        let drop_target = knee.clamp(0.0, 1.0) * self.cfg.max_pelvis_drop;
        let max_drop_step = self.cfg.max_drop_speed * self.dt;
        self.pose.drop += (drop_target - self.pose.drop).clamp(-max_drop_step, max_drop_step);
        let max_hand_step = self.cfg.max_hand_speed * self.dt;
        let step_to = |from: Vec3, to: Vec3| {
            let d = vec3::sub(to, from);
            let n = vec3::norm(d);
            if n <= max_hand_step {
                to
            } else {
                vec3::add(from, vec3::scale(d, max_hand_step / n))
            }
        };
        let (left, right) = spread(left, right);
        self.pose.left = step_to(self.pose.left, self.geometry.reachable(1.0, left));
        self.pose.right = step_to(self.pose.right, self.geometry.reachable(-1.0, right));
    }

    fn advance_base(&mut self, r0: Vec3, r1: Vec3) {
        let tau = self.cfg.track_time_constant;
        let dt = self.dt;
        let [x, y, yaw] = self.pose.base;
        // Horizontal: reference step + lag correction, then speed and acceleration limits.
        let mut v = [
            (r1[0] - r0[0]) / dt + (r0[0] - x) / tau,
            (r1[1] - r0[1]) / dt + (r0[1] - y) / tau,
        ];
        let speed = v[0].hypot(v[1]);
        if speed > self.cfg.max_speed {
            v = [
                v[0] * self.cfg.max_speed / speed,
                v[1] * self.cfg.max_speed / speed,
            ];
            self.limits_hit[0] = true;
        }
        let dv = [v[0] - self.velocity[0], v[1] - self.velocity[1]];
        let dv_n = dv[0].hypot(dv[1]);
        let dv_max = self.cfg.max_accel * dt;
        if dv_n > dv_max {
            v = [
                self.velocity[0] + dv[0] * dv_max / dv_n,
                self.velocity[1] + dv[1] * dv_max / dv_n,
            ];
            self.limits_hit[1] = true;
        }
        // Yaw likewise.
        let mut w = (r1[2] - r0[2]) / dt + (r0[2] - yaw) / tau;
        if w.abs() > self.cfg.max_yaw_rate {
            w = w.clamp(-self.cfg.max_yaw_rate, self.cfg.max_yaw_rate);
            self.limits_hit[2] = true;
        }
        let dw_max = self.cfg.max_yaw_accel * dt;
        if (w - self.yaw_rate).abs() > dw_max {
            w = self.yaw_rate + (w - self.yaw_rate).clamp(-dw_max, dw_max);
            self.limits_hit[3] = true;
        }
        self.velocity = v;
        self.yaw_rate = w;
        self.pose.base = [x + v[0] * dt, y + v[1] * dt, yaw + w * dt];
    }
}

/// Moves two hand targets apart (symmetrically, sideways in the body frame) until their
/// centres are at least [`HAND_GAP`] apart sideways or in total.
fn spread(left: Vec3, right: Vec3) -> (Vec3, Vec3) {
    if vec3::norm(vec3::sub(left, right)) >= HAND_GAP {
        return (left, right);
    }
    let mid = vec3::scale(vec3::add(left, right), 0.5);
    let half = HAND_GAP / 2.0;
    (
        [left[0], mid[1] + half, left[2]],
        [right[0], mid[1] - half, right[2]],
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::execute::ExecKeyframe;

    fn cfg() -> ExecConfig {
        ExecConfig::embedded_default()
    }

    fn geometry() -> Geometry {
        Geometry {
            pelvis_z: 0.79,
            shoulder_z: 1.10,
            height: 1.32,
        }
    }

    fn run(plan: &ExecPlan, cfg: &ExecConfig, steps: u32) -> Motion {
        let start = [0.5, -1.0, 0.4];
        let mut m = Motion::new(cfg, geometry(), start, 1.0 / 240.0);
        let r = PlanReference { plan, start };
        for k in 0..steps {
            m.advance(k, &r);
        }
        m
    }

    #[test]
    fn base_follows_rule_v1_when_no_limit_binds() {
        // Generous limits: the base is on the closed-form arc at every step.
        let mut c = cfg();
        c.max_accel = 1e9;
        c.max_yaw_accel = 1e9;
        let plan = ExecPlan {
            walking_cmd: [0.8, 0.3, 1.1],
            walking_duration: 1.0,
            keyframes: vec![],
        };
        let m = run(&plan, &c, 360);
        let want = reference_base([0.5, -1.0, 0.4], plan.walking_cmd, 1.0, 1.5);
        for i in 0..3 {
            assert!(
                (m.pose.base[i] - want[i]).abs() < 1e-9,
                "{:?} {want:?}",
                m.pose.base
            );
        }
        assert_eq!(m.limits_hit, [false; 4]);
    }

    #[test]
    fn limits_bind_speed_and_catch_up() {
        let c = cfg();
        // 3 m/s asked: capped at 1.5 m/s, so after 1 s the base is at most 1.5 m away.
        let plan = ExecPlan {
            walking_cmd: [3.0, 0.0, 0.0],
            walking_duration: 1.0,
            keyframes: vec![],
        };
        let m = run(&plan, &c, 240);
        let d = (m.pose.base[0] - 0.5).hypot(m.pose.base[1] + 1.0);
        assert!(d <= 1.5 + 1e-9 && d > 1.0, "{d}");
        assert!(m.limits_hit[0] && m.limits_hit[1]);
        // A slow walk lags at the start (acceleration limit) but ends on the reference.
        let plan = ExecPlan {
            walking_cmd: [0.6, 0.0, 0.0],
            walking_duration: 1.0,
            keyframes: vec![],
        };
        let m = run(&plan, &c, 480);
        let want = reference_base([0.5, -1.0, 0.4], plan.walking_cmd, 1.0, 2.0);
        assert!(
            (m.pose.base[0] - want[0]).abs() < 0.01,
            "{:?} {want:?}",
            m.pose.base
        );
    }

    #[test]
    fn hands_and_knees_follow_keyframes() {
        let c = cfg();
        let plan = ExecPlan {
            walking_cmd: [0.0; 3],
            walking_duration: 0.0,
            keyframes: vec![ExecKeyframe {
                t: 0.5,
                left: [0.4, 0.1, 0.2],
                right: [0.4, -0.1, 0.2],
                knee_bend: 0.5,
            }],
        };
        let m = run(&plan, &c, 240);
        assert!(vec3::norm(vec3::sub(m.pose.left, [0.4, 0.1, 0.2])) < 1e-9);
        assert!((m.pose.drop - 0.5 * c.max_pelvis_drop).abs() < 1e-9);
        // One point for both hands: spread to a palm's width apart.
        let bare = ExecPlan {
            keyframes: vec![ExecKeyframe {
                t: 0.3,
                left: [0.4, 0.0, 0.1],
                right: [0.4, 0.0, 0.1],
                knee_bend: 0.0,
            }],
            ..plan
        };
        let m = run(&bare, &c, 240);
        assert!((m.pose.left[1] - m.pose.right[1] - HAND_GAP).abs() < 1e-9);
    }
}
