//! Progress lines for logs: the one implementation lives in `rh_contract::progress`
//! (`rh-pipeline build` uses it too).

pub use rh_contract::progress::{eta_text, ProgressLog, LOG_EVERY_S};
