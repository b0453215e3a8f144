//! On-disk response cache: one JSON file per successful answer, named by the SHA-256 of
//! (base URL, model, prompt hash, generation parameters, sample index). Entries hold the
//! answer and its usage — never a header, so never the API key. Written to a temporary
//! sibling and renamed, so a killed run leaves no half-written entry.

use crate::Reply;
use rh_contract::digest::sha256_hex;
use std::path::{Path, PathBuf};

/// The cache directory: `$RH_LLM_CACHE`, else `$XDG_CACHE_HOME/reacthuman/llm`, else
/// `~/.cache/reacthuman/llm`.
pub fn default_dir() -> PathBuf {
    if let Some(d) = std::env::var_os("RH_LLM_CACHE").filter(|d| !d.is_empty()) {
        return PathBuf::from(d);
    }
    let base = std::env::var_os("XDG_CACHE_HOME")
        .filter(|d| !d.is_empty())
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".cache")))
        .unwrap_or_else(std::env::temp_dir);
    base.join("reacthuman").join("llm")
}

/// The cache key of one request.
pub fn key(
    base_url: &str,
    model: &str,
    prompt_hash: &str,
    params: &serde_json::Value,
    sample: u32,
) -> String {
    let canonical = serde_json::json!({
        "base_url": base_url.trim_end_matches('/'),
        "model": model,
        "prompt_hash": prompt_hash,
        "params": params,
        "sample": sample,
    });
    sha256_hex(canonical.to_string().as_bytes())
}

#[derive(Debug, Clone)]
pub struct Cache {
    dir: PathBuf,
}

impl Cache {
    pub fn new(dir: PathBuf) -> Cache {
        Cache { dir }
    }

    pub fn dir(&self) -> &Path {
        &self.dir
    }

    fn path(&self, key: &str) -> PathBuf {
        self.dir.join(&key[..2]).join(format!("{key}.json"))
    }

    /// The cached answer, if any; an unreadable entry counts as a miss.
    pub fn get(&self, key: &str) -> Option<Reply> {
        let bytes = std::fs::read(self.path(key)).ok()?;
        let mut reply: Reply = serde_json::from_slice(&bytes).ok()?;
        reply.cached = true;
        Some(reply)
    }

    /// Stores an answer; failures are reported to the caller, who may ignore them.
    pub fn put(&self, key: &str, reply: &Reply) -> std::io::Result<()> {
        let mut stored = reply.clone();
        stored.cached = false;
        rh_contract::fsio::write_atomic(&self.path(key), &serde_json::to_vec(&stored)?)
    }
}
