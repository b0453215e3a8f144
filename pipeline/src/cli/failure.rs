//! How a command fails: the message and the exit status (2 bad input, 1 internal), and
//! printing a summary as JSON.

use crate::build::BuildError;

/// A failure with its exit code.
pub struct Failure {
    pub code: u8,
    pub message: String,
}

/// A failure of the input (exit status 2).
pub fn input(message: impl Into<String>) -> Failure {
    Failure {
        code: 2,
        message: message.into(),
    }
}

/// A build or merge error as a failure: input (2) or internal (1).
pub fn build_failure(e: BuildError) -> Failure {
    match e {
        BuildError::Input(m) => input(m),
        BuildError::Internal(m) => Failure {
            code: 1,
            message: m,
        },
    }
}

/// Prints a value as pretty JSON on stdout.
pub fn print_json<T: serde::Serialize>(value: &T) {
    println!(
        "{}",
        serde_json::to_string_pretty(value).expect("a summary serializes")
    );
}
