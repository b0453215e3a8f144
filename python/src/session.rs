//! `reacthuman._native.NativeSession`: one closed-loop episode of `ReactHuman-v0`
//! (`rh_physics::control::Session`), and the scripted policy's commands.

use crate::dataset::{parse_plan, NativeDataset};
use crate::errors::{guard, run, Error, Result};
use pyo3::prelude::*;
use rh_physics::control::{plan_command, Command, End, Session};
use rh_physics::execute::{ExecFrame, Replay};
use std::sync::{Arc, Mutex};

/// Numbers in an action: twist (3), left hand (3), right hand (3), knee bend.
pub const ACTION_LEN: usize = 10;

fn command(a: &[f64]) -> Result<Command> {
    if a.len() != ACTION_LEN {
        return Err(Error::Value(format!(
            "action must have {ACTION_LEN} numbers (twist vx vy yaw_rate, left_hand xyz, right_hand xyz, knee_bend), got {}",
            a.len()
        )));
    }
    let c = Command {
        twist: [a[0], a[1], a[2]],
        left: [a[3], a[4], a[5]],
        right: [a[6], a[7], a[8]],
        knee_bend: a[9],
    };
    c.validate().map_err(|e| Error::Value(e.to_string()))?;
    Ok(c)
}

fn flat(c: &Command) -> Vec<f64> {
    let mut v = Vec::with_capacity(ACTION_LEN);
    v.extend(c.twist);
    v.extend(c.left);
    v.extend(c.right);
    v.push(c.knee_bend);
    v
}

/// One episode: the scene replayed to Δ (checked), then commands at the control rate.
#[pyclass(module = "reacthuman._native", frozen)]
pub struct NativeSession {
    session: Mutex<Session>,
    /// The scene replayed to Δ (its spec: what the ego camera draws).
    replay: Arc<Replay>,
}

impl NativeSession {
    fn with<T>(&self, f: impl FnOnce(&mut Session) -> Result<T>) -> Result<T> {
        let mut s = self
            .session
            .lock()
            .map_err(|_| Error::Internal("the session was poisoned by an earlier panic".into()))?;
        f(&mut s)
    }

    /// The world now and the scene's replay (for the ego camera, `crate::ego`).
    pub fn frame(&self) -> Result<(ExecFrame, Arc<Replay>)> {
        self.with(|s| Ok((s.frame(), self.replay.clone())))
    }
}

#[pymethods]
impl NativeSession {
    #[new]
    fn new(
        py: Python<'_>,
        dataset: &NativeDataset,
        scene_id: String,
        control_hz: f64,
    ) -> PyResult<Self> {
        run(py, || {
            let replay = dataset.replay(&scene_id)?;
            let s = Session::new(&replay, &dataset.cfg.execution, control_hz)
                .map_err(|e| Error::Value(e.to_string()))?;
            Ok(NativeSession {
                session: Mutex::new(s),
                replay,
            })
        })
    }

    /// Applies one action for a control period; returns "terminated", "truncated" or None.
    fn step(&self, py: Python<'_>, action: Vec<f64>) -> PyResult<Option<&'static str>> {
        run(py, || {
            let c = command(&action)?;
            self.with(|s| {
                let end = s.step(&c).map_err(|e| Error::Value(e.to_string()))?;
                Ok(end.map(|e| match e {
                    End::Terminated(_) => "terminated",
                    End::Truncated(_) => "truncated",
                }))
            })
        })
    }

    fn robot_state(&self) -> PyResult<Vec<f64>> {
        guard(|| self.with(|s| Ok(s.robot_state().to_vec())))
    }

    fn hazard_state(&self) -> PyResult<Vec<f64>> {
        guard(|| self.with(|s| Ok(s.hazard_state().to_vec())))
    }

    /// The outcome (JSON text): the verdict so far, or the final one after the end.
    fn outcome(&self) -> PyResult<String> {
        guard(|| {
            self.with(|s| {
                serde_json::to_string(&s.outcome()).map_err(|e| Error::Internal(e.to_string()))
            })
        })
    }

    /// Seconds since the decision moment.
    fn time(&self) -> PyResult<f64> {
        guard(|| self.with(|s| Ok(s.time())))
    }

    /// The control period (s).
    fn period(&self) -> PyResult<f64> {
        guard(|| self.with(|s| Ok(s.period())))
    }

    /// Control periods until the executor's horizon.
    fn horizon_periods(&self) -> PyResult<u32> {
        guard(|| self.with(|s| Ok(s.horizon_periods())))
    }
}

/// The scripted policy's action for control period `j` (`rh_physics::control::plan_command`).
#[pyfunction]
pub fn plan_action(dataset: &NativeDataset, plan: &str, period: f64, j: u32) -> PyResult<Vec<f64>> {
    guard(|| {
        let p = parse_plan(plan, &dataset.cfg)?;
        Ok(flat(&plan_command(&rh_execute::exec_plan(&p), period, j)))
    })
}

/// The resting action (stand still, hands at rest).
#[pyfunction]
pub fn rest_action() -> Vec<f64> {
    flat(&Command::rest())
}

/// Lengths of the robot and hazard observations.
#[pyfunction]
pub fn state_lengths() -> (usize, usize) {
    (
        rh_physics::control::ROBOT_STATE_LEN,
        rh_physics::control::HAZARD_STATE_LEN,
    )
}
