//! The three action primitives (specification §10): the dataset's `gt_action` values and what a
//! model's plan chooses.

use serde::{Deserialize, Serialize};

#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub enum Action {
    #[serde(rename = "CATCH")]
    Catch,
    #[serde(rename = "DODGE")]
    Dodge,
    #[serde(rename = "NO_ACTION")]
    NoAction,
}

impl Action {
    pub const ALL: [Action; 3] = [Action::Catch, Action::Dodge, Action::NoAction];

    /// Lenient parse of a model's answer: case, spaces and dashes are ignored, and the
    /// primitive names (`EXECUTE_CATCH`, `TRIGGER_DODGE`) are accepted.
    pub fn parse(s: &str) -> Option<Action> {
        match s
            .trim()
            .to_ascii_uppercase()
            .replace([' ', '-'], "_")
            .as_str()
        {
            "CATCH" | "EXECUTE_CATCH" => Some(Action::Catch),
            "DODGE" | "TRIGGER_DODGE" => Some(Action::Dodge),
            "NO_ACTION" | "NOACTION" | "NONE" => Some(Action::NoAction),
            _ => None,
        }
    }

    /// The dataset's spelling: `CATCH`, `DODGE`, `NO_ACTION`.
    pub fn as_str(self) -> &'static str {
        match self {
            Action::Catch => "CATCH",
            Action::Dodge => "DODGE",
            Action::NoAction => "NO_ACTION",
        }
    }

    /// Same as [`Action::as_str`].
    pub fn name(self) -> &'static str {
        self.as_str()
    }

    pub fn index(self) -> usize {
        self as usize
    }

    pub fn from_index(i: usize) -> Option<Action> {
        Action::ALL.get(i).copied()
    }
}

impl std::fmt::Display for Action {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip() {
        for a in Action::ALL {
            assert_eq!(Action::parse(a.as_str()), Some(a));
            assert_eq!(Action::from_index(a.index()), Some(a));
        }
        assert_eq!(Action::parse(" trigger-dodge "), Some(Action::Dodge));
        assert_eq!(Action::parse("jump"), None);
    }
}

/// The base pose `[x, y, yaw]` at time `t` of a walk from `start` (`[x, y, yaw]`) under the
/// body-frame command `cmd` (`[vx, vy, yaw rate]`) held for `duration` s: the closed-form
/// arc of action rule v1 (the straight line when `|yaw rate · t| < 1e-9`), `t` clamped to
/// the walk. One definition for the scorer's rule and the executor's reference path.
pub fn walk_pose(start: [f64; 3], cmd: [f64; 3], duration: f64, t: f64) -> [f64; 3] {
    let t = t.clamp(0.0, duration.max(0.0));
    let [x0, y0, th0] = start;
    let [vx, vy, w] = cmd;
    let th = th0 + w * t;
    if (w * t).abs() < 1e-9 {
        let (s, c) = th0.sin_cos();
        return [x0 + (c * vx - s * vy) * t, y0 + (s * vx + c * vy) * t, th];
    }
    let (s0, c0) = th0.sin_cos();
    let (s1, c1) = th.sin_cos();
    [
        x0 + (vx * (s1 - s0) + vy * (c1 - c0)) / w,
        y0 + (-vx * (c1 - c0) + vy * (s1 - s0)) / w,
        th,
    ]
}
