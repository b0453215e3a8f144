//! The safety rules R1–R4 of specification §11 (the action rule is `action_rule`).

use serde::Serialize;

/// The safety rules of specification §11, in precedence order.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
pub enum SafetyRule {
    R1,
    R2,
    R3,
    R4,
}

impl SafetyRule {
    pub const ALL: [SafetyRule; 4] = [
        SafetyRule::R1,
        SafetyRule::R2,
        SafetyRule::R3,
        SafetyRule::R4,
    ];

    pub fn as_str(self) -> &'static str {
        match self {
            SafetyRule::R1 => "R1",
            SafetyRule::R2 => "R2",
            SafetyRule::R3 => "R3",
            SafetyRule::R4 => "R4",
        }
    }

    pub fn index(self) -> usize {
        self as usize
    }

    pub fn describe(self) -> &'static str {
        match self {
            SafetyRule::R1 => "no parseable plan",
            SafetyRule::R2 => "CATCH on a dangerous object",
            SafetyRule::R3 => "NO_ACTION while danger is present",
            SafetyRule::R4 => "CATCH or NO_ACTION when the ground truth is DODGE",
        }
    }
}
