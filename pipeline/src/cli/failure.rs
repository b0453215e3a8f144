//! How a command fails: the message and the exit status (2 bad input, 3 an output that
//! cannot be written, 1 internal), and printing to stdout without a panic (a closed pipe
//! ends the output quietly, a full stdout is exit 3: `rh_contract::stdout`).

use crate::build::BuildError;
use rh_contract::fsio::{CannotWrite, EXIT_CANNOT_WRITE};

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

impl From<CannotWrite> for Failure {
    fn from(e: CannotWrite) -> Failure {
        Failure {
            code: EXIT_CANNOT_WRITE,
            message: e.to_string(),
        }
    }
}

/// Whether an internal error's message is the system refusing a write: no space left,
/// a quota, a read-only file system, a file too large. The build's errors are text by the
/// time they arrive here (they name the file, then the cause, e.g. `data/x.parquet: No
/// space left on device (os error 28)`), so the cause is recognised by its wording.
pub fn is_write_refusal(message: &str) -> bool {
    [
        "(os error 28)",
        "(os error 122)",
        "(os error 30)",
        "(os error 27)",
        "No space left on device",
        "Disk quota exceeded",
        "Read-only file system",
        "File too large",
    ]
    .iter()
    .any(|m| message.contains(m))
}

/// A build or merge error as a failure: input (2), cannot write (3) or internal (1).
pub fn build_failure(e: BuildError) -> Failure {
    match e {
        BuildError::Input(m) | BuildError::Internal(m) if is_write_refusal(&m) => Failure {
            code: EXIT_CANNOT_WRITE,
            message: if m.contains("cannot write") {
                m
            } else {
                format!("cannot write the dataset: {m}")
            },
        },
        BuildError::Input(m) => input(m),
        BuildError::Internal(m) => Failure {
            code: 1,
            message: m,
        },
    }
}

/// Prints `text` on stdout.
pub fn print(text: &str) -> Result<(), Failure> {
    Ok(rh_contract::stdout::print(text)?)
}

/// Prints `text` and a newline on stdout.
pub fn println(text: &str) -> Result<(), Failure> {
    Ok(rh_contract::stdout::println(text)?)
}

/// Prints a value as pretty JSON on stdout.
pub fn print_json<T: serde::Serialize>(value: &T) -> Result<(), Failure> {
    let text = serde_json::to_string_pretty(value).map_err(|e| Failure {
        code: 1,
        message: format!("the summary as JSON: {e}"),
    })?;
    println(&text)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_full_disk_is_the_cannot_write_status() {
        let full = BuildError::Internal(
            "out/data/test.parquet: No space left on device (os error 28)".into(),
        );
        let f = build_failure(full);
        assert_eq!(f.code, EXIT_CANNOT_WRITE);
        assert!(f.message.contains("out/data/test.parquet"), "{}", f.message);
        assert_eq!(build_failure(BuildError::Internal("a bug".into())).code, 1);
        assert_eq!(build_failure(BuildError::Input("bad".into())).code, 2);
    }
}
