//! The scorer's input errors: what the user gave us is wrong (exit status 2); and
//! outputs that cannot be written (exit status 3).

/// An error in what the user gave us (exit status 2).
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct InputError(pub String);

/// True when any error in the chain is an [`InputError`].
pub fn is_input_error(err: &anyhow::Error) -> bool {
    err.chain()
        .any(|e| e.downcast_ref::<InputError>().is_some())
}

/// True when any error in the chain is an output that could not be written (exit status
/// [`rh_contract::fsio::EXIT_CANNOT_WRITE`])
/// (also one carried inside an `std::io::Error`, as a writer's error).
pub fn is_cannot_write(err: &anyhow::Error) -> bool {
    err.chain().any(|e| {
        e.is::<CannotWrite>()
            || e.downcast_ref::<std::io::Error>()
                .and_then(|io| io.get_ref())
                .is_some_and(|inner| inner.is::<CannotWrite>())
    })
}

use rh_contract::fsio::CannotWrite;
