//! Closed-loop control of the humanoid from the decision moment Δ (issue 26): the
//! stepping session behind the Gymnasium environment `ReactHuman-v0`.
//!
//! A [`Session`] starts from a checked [`Replay`] (the scene replayed bit for bit to Δ)
//! and runs the executor's own [`Execution`]: the same kinematic humanoid, the same base,
//! hand and knee limits of `[execution]`, the same grasp and the same outcome rule
//! (`execute::outcome`). Only the reference the body tracks differs: instead of one plan
//! fixed at Δ, each [`Session::step`] takes a whole-body [`Command`] and holds it for one
//! control period (`substeps` physics steps at 240 Hz; 8 at 30 Hz):
//!
//! * **Base.** The twist `[vx, vy, yaw_rate]` (body frame at the start of the period) is
//!   action rule v1's closed-form walk for one period, continued from where the previous
//!   period's reference ended; the base tracks it under the executor's speed and
//!   acceleration limits (`execute::motion`). A plan's walk is the same arc cut into
//!   periods.
//! * **Hands and knee.** The targets (body frame, as a plan's keyframes) are reached at
//!   the end of the period, linearly from the previous period's targets (first-order
//!   hold), then clamped to the arm's reach and `max_hand_speed` as for a plan.
//! * **Catch attempt.** The grasp gate and the `missed` test use the largest forward hand
//!   extension commanded so far (a plan uses its keyframes' largest).
//! * **The end.** A session is *terminated* when the outcome is settled (struck, caught,
//!   or the hazard lies still on the floor after the last command that moved anything),
//!   and *truncated* at the executor's horizon; either way [`Execution::outcome`] gives
//!   the verdict, as for a plan.
//!
//! [`plan_command`] turns a plan into the command of each period (the scripted policy);
//! stepped through a session it reaches the executor's outcome (checked on every scene of
//! a build by the Python tests). It is not bit-identical to the plan's execution: the
//! hand targets are sampled at the period ends, and a reference continued period by
//! period rounds differently from one closed-form arc.

use crate::body::{REST_LEFT, REST_RIGHT};
use crate::execute::motion::{plan_targets, reference_base, Reference};
use crate::execute::outcome::Execution;
use crate::execute::{ExecConfig, ExecFrame, ExecPlan, Outcome, Replay};
use crate::spec::{vec3, Vec3};

/// One control period's whole-body command.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Command {
    /// Base twist `[vx, vy, yaw_rate]` (m/s, rad/s) in the body frame.
    pub twist: Vec3,
    /// Hand targets (body frame, m), reached at the end of the period.
    pub left: Vec3,
    pub right: Vec3,
    /// 0 straight … 1 deep crouch (clamped like a plan's).
    pub knee_bend: f64,
}

/// Why a session cannot start or take a command; the message names the field or rate.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ControlError {
    #[error("command field {field} is not finite ({value})")]
    NotFinite { field: &'static str, value: f64 },
    #[error(transparent)]
    Config(#[from] rh_contract::execution::ExecConfigError),
    /// `max_hz`: the physics rate.
    #[error("control_hz must be in (0, {max_hz}] (the physics rate), got {control_hz}")]
    RateOutOfRange { max_hz: f64, control_hz: f64 },
    #[error("control_hz must divide the physics rate {physics_hz} Hz (a whole number of physics steps per command), got {control_hz}")]
    NotADivisor { physics_hz: f64, control_hz: f64 },
    #[error("the session has ended (terminated or truncated); start a new one")]
    Ended,
}

/// The message, for callers that pass errors on as text.
impl From<ControlError> for String {
    fn from(e: ControlError) -> String {
        e.to_string()
    }
}

impl Command {
    /// Standing still with the hands at rest.
    pub fn rest() -> Command {
        Command {
            twist: [0.0; 3],
            left: REST_LEFT,
            right: REST_RIGHT,
            knee_bend: 0.0,
        }
    }

    /// Refuses a non-finite number, naming the field.
    pub fn validate(&self) -> Result<(), ControlError> {
        let fields: [(&str, &[f64]); 4] = [
            ("twist", &self.twist),
            ("left_hand", &self.left),
            ("right_hand", &self.right),
            ("knee_bend", std::slice::from_ref(&self.knee_bend)),
        ];
        for (name, values) in fields {
            if let Some(x) = values.iter().find(|x| !x.is_finite()) {
                return Err(ControlError::NotFinite {
                    field: name,
                    value: *x,
                });
            }
        }
        Ok(())
    }
}

/// The reference of one control period (see the module doc).
#[derive(Debug, Clone, Copy)]
struct Period {
    t0: f64,
    base0: Vec3,
    twist: Vec3,
    duration: f64,
    from: (Vec3, Vec3, f64),
    to: (Vec3, Vec3, f64),
}

impl Reference for Period {
    fn base(&self, t: f64) -> Vec3 {
        reference_base(self.base0, self.twist, self.duration, t - self.t0)
    }

    fn targets(&self, t: f64) -> (Vec3, Vec3, f64) {
        let f = ((t - self.t0) / self.duration).clamp(0.0, 1.0);
        let lerp = |a: Vec3, b: Vec3| vec3::add(a, vec3::scale(vec3::sub(b, a), f));
        (
            lerp(self.from.0, self.to.0),
            lerp(self.from.1, self.to.1),
            self.from.2 + (self.to.2 - self.from.2) * f,
        )
    }
}

/// How a session ended.
#[derive(Debug, Clone, PartialEq)]
pub enum End {
    /// The outcome is settled (struck, caught, or the hazard at rest on the floor).
    Terminated(Outcome),
    /// The executor's horizon was reached first.
    Truncated(Outcome),
}

impl End {
    pub fn outcome(&self) -> &Outcome {
        match self {
            End::Terminated(o) | End::Truncated(o) => o,
        }
    }
}

/// The robot's own state: 14 numbers (see [`Session::robot_state`]).
pub const ROBOT_STATE_LEN: usize = 14;
/// The hazard's state: 9 numbers (see [`Session::hazard_state`]).
pub const HAZARD_STATE_LEN: usize = 9;

/// A closed-loop execution in progress.
pub struct Session {
    ex: Execution,
    substeps: u32,
    period: Period,
    start: Vec3,
    reach: f64,
    motion_end: f64,
    end: Option<End>,
}

impl Session {
    /// A session from Δ of `replay` (check it first: [`Replay::check`]) under `cfg`,
    /// commanded at `control_hz` (the physics rate divided by a whole number of steps).
    pub fn new(
        replay: &Replay,
        cfg: &ExecConfig,
        control_hz: f64,
    ) -> Result<Session, ControlError> {
        cfg.validate()?;
        let dt = replay.spec().physics.dt;
        let ratio = 1.0 / (dt * control_hz);
        if !control_hz.is_finite() || control_hz <= 0.0 || ratio < 1.0 - 1e-9 {
            return Err(ControlError::RateOutOfRange {
                max_hz: 1.0 / dt,
                control_hz,
            });
        }
        if (ratio - ratio.round()).abs() > 1e-6 {
            return Err(ControlError::NotADivisor {
                physics_hz: 1.0 / dt,
                control_hz,
            });
        }
        let substeps = ratio.round() as u32;
        let ex = replay.start(cfg);
        let start = ex.motion().pose.base;
        let rest = (REST_LEFT, REST_RIGHT, 0.0);
        Ok(Session {
            period: Period {
                t0: 0.0,
                base0: start,
                twist: [0.0; 3],
                duration: substeps as f64 * dt,
                from: rest,
                to: rest,
            },
            ex,
            substeps,
            start,
            reach: 0.0,
            motion_end: 0.0,
            end: None,
        })
    }

    /// Physics steps per control period.
    pub fn substeps(&self) -> u32 {
        self.substeps
    }

    /// The control period (s).
    pub fn period(&self) -> f64 {
        self.substeps as f64 * self.ex.dt()
    }

    /// Control periods until the horizon (the last one may be shorter).
    pub fn horizon_periods(&self) -> u32 {
        self.ex.horizon().div_ceil(self.substeps)
    }

    /// Seconds since Δ.
    pub fn time(&self) -> f64 {
        self.ex.executed() as f64 * self.ex.dt()
    }

    /// How the session ended, once it has.
    pub fn end(&self) -> Option<&End> {
        self.end.as_ref()
    }

    /// The verdict if the run stopped now (the final one once [`Session::end`] is set).
    pub fn outcome(&self) -> Outcome {
        match &self.end {
            Some(e) => e.outcome().clone(),
            None => self.ex.outcome(self.reach),
        }
    }

    /// Applies `cmd` for one control period (fewer steps if the outcome settles or the
    /// horizon comes first). Refuses after the end and on non-finite numbers.
    pub fn step(&mut self, cmd: &Command) -> Result<Option<&End>, ControlError> {
        if self.end.is_some() {
            return Err(ControlError::Ended);
        }
        cmd.validate()?;
        let t0 = self.time();
        let to = (cmd.left, cmd.right, cmd.knee_bend);
        let from = self.period.targets(t0);
        self.period = Period {
            t0,
            base0: self.period.base(t0),
            twist: cmd.twist,
            duration: self.period(),
            from,
            to,
        };
        if cmd.twist != [0.0; 3] || from != to {
            self.motion_end = t0 + self.period();
        }
        self.reach = self
            .reach
            .max(cmd.left[0] - REST_LEFT[0])
            .max(cmd.right[0] - REST_RIGHT[0]);
        for _ in 0..self.substeps {
            if self.ex.at_horizon() {
                break;
            }
            if self.ex.step(&self.period, self.reach) || self.ex.quiet(self.motion_end) {
                self.end = Some(End::Terminated(self.ex.outcome(self.reach)));
                return Ok(self.end.as_ref());
            }
        }
        if self.ex.at_horizon() {
            self.end = Some(End::Truncated(self.ex.outcome(self.reach)));
        }
        Ok(self.end.as_ref())
    }

    /// The world now (every moving body, the humanoid's links, base and pelvis drop):
    /// what the ego camera draws (`rh_render::EgoCamera`).
    pub fn frame(&self) -> ExecFrame {
        self.ex.frame()
    }

    /// The robot's own state: base `(x, y, yaw)` relative to its pose at Δ (in that
    /// pose's frame), base velocity `(vx, vy)` in the current body frame and yaw rate,
    /// pelvis drop, left and right palm (body frame), seconds since Δ.
    pub fn robot_state(&self) -> [f64; ROBOT_STATE_LEN] {
        let m = self.ex.motion();
        let p = &m.pose;
        let [sx, sy, syaw] = self.start;
        let rel = rotate([p.base[0] - sx, p.base[1] - sy], -syaw);
        let [vx, vy, w] = m.base_velocity();
        let v = rotate([vx, vy], -p.base[2]);
        [
            rel[0],
            rel[1],
            p.base[2] - syaw,
            v[0],
            v[1],
            w,
            p.drop,
            p.left[0],
            p.left[1],
            p.left[2],
            p.right[0],
            p.right[1],
            p.right[2],
            self.time(),
        ]
    }

    /// The hazard's state (privileged): its position relative to the base on the floor,
    /// its velocity (both in the body frame) and its angular velocity (world frame).
    pub fn hazard_state(&self) -> [f64; HAZARD_STATE_LEN] {
        let (pos, vel, ang) = self.ex.hazard_state();
        let [bx, by, yaw] = self.ex.motion().pose.base;
        let p = rotate([pos[0] - bx, pos[1] - by], -yaw);
        let v = rotate([vel[0], vel[1]], -yaw);
        [
            p[0], p[1], pos[2], v[0], v[1], vel[2], ang[0], ang[1], ang[2],
        ]
    }
}

fn rotate(v: [f64; 2], angle: f64) -> [f64; 2] {
    let (s, c) = angle.sin_cos();
    [c * v[0] - s * v[1], s * v[0] + c * v[1]]
}

/// The scripted policy: the command of control period `j` (of `period` s) that carries
/// `plan` out — its twist while it walks (scaled down in the period where the walk ends,
/// which keeps the arc's end pose), its hand targets and knee bend at the period's end.
pub fn plan_command(plan: &ExecPlan, period: f64, j: u32) -> Command {
    let (ta, tb) = (j as f64 * period, (j + 1) as f64 * period);
    let d = plan.walking_duration;
    let scale = if tb <= d {
        1.0
    } else if ta < d {
        (d - ta) / period
    } else {
        0.0
    };
    let (left, right, knee_bend) = plan_targets(plan, tb);
    Command {
        twist: vec3::scale(plan.walking_cmd, scale),
        left,
        right,
        knee_bend,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn plan() -> ExecPlan {
        ExecPlan {
            walking_cmd: [0.9, 0.3, 0.8],
            walking_duration: 0.5,
            keyframes: vec![],
        }
    }

    #[test]
    fn plan_commands_cut_the_walk_into_periods() {
        let p = plan();
        let period = 8.0 / 240.0;
        // Periods 0..15 walk fully (15 × 1/30 = 0.5 s), then standing.
        assert_eq!(plan_command(&p, period, 14).twist, p.walking_cmd);
        assert_eq!(plan_command(&p, period, 15).twist, [0.0; 3]);
        // The period where a walk ends: scaled so the arc ends where the plan's does.
        let q = ExecPlan {
            walking_duration: 0.51,
            ..p.clone()
        };
        let c = plan_command(&q, period, 15);
        let f = (0.51 - 0.5) / period;
        assert!((c.twist[0] - 0.9 * f).abs() < 1e-12, "{c:?}");
        // Pieces of the arc compose to the arc.
        let start = [0.2, -0.4, 0.3];
        let mut pose = start;
        for j in 0..16 {
            let c = plan_command(&q, period, j);
            pose = reference_base(pose, c.twist, period, period);
        }
        let want = reference_base(start, q.walking_cmd, 0.51, 0.51);
        for i in 0..3 {
            assert!((pose[i] - want[i]).abs() < 1e-9, "{pose:?} {want:?}");
        }
    }

    #[test]
    fn non_finite_commands_are_refused_by_name() {
        let mut c = Command::rest();
        c.right[1] = f64::NAN;
        assert!(c.validate().unwrap_err().to_string().contains("right_hand"));
        c = Command::rest();
        c.knee_bend = f64::INFINITY;
        assert!(c.validate().unwrap_err().to_string().contains("knee_bend"));
        assert!(Command::rest().validate().is_ok());
    }
}
