//! ReactHuman's canonical prompt (specification §9): the one definition of what a model is
//! shown — its configuration ([`config`], `configs/prompt.toml`), the scene's head camera
//! calibration ([`camera`]), the system and user texts and the observation frames as JPEG
//! data URLs ([`messages`]; the image bytes are part of `prompt_hash`, so the encoder is
//! here too) and the scenes a run covers ([`select_scenes`]). `rh-score predict` sends it
//! (rh-runner), `rh-score export` writes it as training data, the Python package returns
//! it; no LLM client, network or async runtime here.

pub mod camera;
pub mod config;
pub mod messages;
mod scenes;

pub use config::{canonical_generation, Generation, PromptConfig};
pub use messages::{canonical, prompt_hash, BuiltPrompt, PromptError, UserPart};
pub use scenes::select_scenes;
