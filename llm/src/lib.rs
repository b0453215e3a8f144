//! `rh-llm`: the one OpenAI-compatible chat-completions client of ReactHuman, used by
//! `rh-score predict` and by the pipeline's LLM planner (`rh-pipeline plan --llm`,
//! `build --planner llm`).
//!
//! [`Client::chat`] sends one request (`POST {base_url}/chat/completions`, the API that
//! OpenAI, OpenRouter, vLLM, llama.cpp's server and Ollama serve) and returns the answer:
//! * the on-disk [`cache`] is consulted first (key: base URL, model, prompt hash,
//!   generation parameters, sample index) and filled on success;
//! * at most [`limiter::Limiter`]'s adaptive limit of requests are in flight; a 429
//!   halves it, pauses new requests for `Retry-After` (seconds; else the backoff), and
//!   success grows it back;
//! * transient failures (timeout, connection error or drop, 408/409/5xx, a body that is
//!   not JSON, no `choices`) are retried with exponential backoff and jitter (uniform in [½, 1] of min(max, base·2^k)) up to
//!   `max_retries` times; 429s have their own, larger budget (`max_rate_limit_retries`);
//! * 401/403/404 are [`LlmError::Fatal`]: every further request would fail the same way;
//!   another 4xx is [`LlmError::Rejected`] and not retried;
//! * a refusal (`message.refusal`, or `finish_reason = "content_filter"`) is an answer
//!   ([`Reply::refusal`]), not an error: the model decided.
//!
//! The API key is sent only in the `Authorization` header; every error message passes
//! through [`Client::redact`], and cache entries never hold headers.

pub mod cache;
pub mod limiter;

use cache::Cache;
use limiter::Limiter;
use serde::{Deserialize, Serialize};
use serde_json::Value;
use sha2::{Digest, Sha256};
use std::time::{Duration, Instant};

/// How a client behaves (defaults are config: `configs/predict.toml` `[client]`).
#[derive(Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct ClientConfig {
    /// e.g. `https://api.openai.com/v1` or `http://127.0.0.1:8000/v1`.
    pub base_url: String,
    /// Per-request timeout (whole request, headers to last body byte).
    pub timeout_s: f64,
    /// Retries of a transient failure (so up to `max_retries + 1` attempts).
    pub max_retries: u32,
    /// Retries after 429 (rate limit), counted separately.
    pub max_rate_limit_retries: u32,
    /// Backoff before retry k (0-based): uniform in [½, 1] × min(max, base · 2^k).
    pub backoff_base_s: f64,
    pub backoff_max_s: f64,
    /// A `Retry-After` longer than this is capped.
    pub max_retry_after_s: f64,
    /// The most requests in flight (the adaptive limit starts here).
    pub concurrency: usize,
    /// Never serialized, never printed.
    #[serde(skip)]
    pub api_key: Option<String>,
}

impl ClientConfig {
    /// The endpoint and key a command line gives: `base_url` (`--base-url`), else
    /// `$OPENAI_BASE_URL` when set, else the configured one; the key from the environment
    /// variable `api_key_env` (unset or empty: none, fine for local servers).
    pub fn with_endpoint(mut self, base_url: Option<String>, api_key_env: &str) -> Self {
        if let Some(u) = base_url.or_else(|| {
            std::env::var("OPENAI_BASE_URL")
                .ok()
                .filter(|s| !s.is_empty())
        }) {
            self.base_url = u;
        }
        self.api_key = std::env::var(api_key_env).ok().filter(|k| !k.is_empty());
        self
    }
}

impl std::fmt::Debug for ClientConfig {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ClientConfig")
            .field("base_url", &self.base_url)
            .field("timeout_s", &self.timeout_s)
            .field("max_retries", &self.max_retries)
            .field("concurrency", &self.concurrency)
            .field("api_key", &self.api_key.as_ref().map(|_| "<set>"))
            .finish()
    }
}

/// One chat request. `messages` is the OpenAI `messages` array as sent.
#[derive(Debug, Clone)]
pub struct ChatRequest {
    pub model: String,
    messages: Value,
    /// Generation parameters merged into the body (`temperature`, `max_tokens`, …); part
    /// of the cache key.
    pub params: serde_json::Map<String, Value>,
    /// Which independent sample of the same prompt this is (cache key only).
    pub sample: u32,
    prompt_hash: String,
}

impl ChatRequest {
    pub fn new(
        model: &str,
        messages: Value,
        params: serde_json::Map<String, Value>,
        sample: u32,
    ) -> ChatRequest {
        let prompt_hash = rh_contract::digest::sha256_hex(messages.to_string().as_bytes());
        ChatRequest {
            model: model.to_string(),
            messages,
            params,
            sample,
            prompt_hash,
        }
    }

    /// SHA-256 (hex) of the exact `messages` JSON sent: the prompt text and the image
    /// bytes (inside their data URLs).
    pub fn prompt_hash(&self) -> &str {
        &self.prompt_hash
    }

    pub fn messages(&self) -> &Value {
        &self.messages
    }

    /// The request body.
    pub fn body(&self) -> Value {
        let mut body = self.params.clone();
        body.insert("model".into(), Value::String(self.model.clone()));
        body.insert("messages".into(), self.messages.clone());
        Value::Object(body)
    }
}

#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Usage {
    pub prompt_tokens: u64,
    pub completion_tokens: u64,
}

/// An answer.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Reply {
    /// The assistant's text (the refusal text for a refusal).
    pub text: String,
    /// Set when the model refused.
    #[serde(default)]
    pub refusal: bool,
    pub finish_reason: Option<String>,
    pub usage: Usage,
    /// Seconds of the successful attempt.
    pub latency_s: f64,
    /// Attempts it took (1 = first try); for a cached answer, the original call's.
    pub attempts: u32,
    /// Served from the cache (no request made).
    #[serde(default, skip_serializing)]
    pub cached: bool,
}

/// A request that could not be answered. Messages never contain the API key.
#[derive(Debug, Clone, thiserror::Error)]
pub enum LlmError {
    #[error("timed out after {0:.1} s")]
    Timeout(f64),
    #[error("connection failed: {0}")]
    Connection(String),
    #[error("rate limited (HTTP 429){}", .0.map(|s| format!(", Retry-After {s:.1} s")).unwrap_or_default())]
    RateLimited(Option<f64>),
    #[error("server error HTTP {status}: {body}")]
    Server { status: u16, body: String },
    #[error("malformed response body: {0}")]
    Malformed(String),
    #[error("the response has no choices")]
    EmptyChoices,
    #[error("request rejected, HTTP {status}: {body}")]
    Rejected { status: u16, body: String },
    #[error("HTTP {status}: {body}")]
    Fatal { status: u16, body: String },
}

impl LlmError {
    fn transient(&self) -> bool {
        matches!(
            self,
            LlmError::Timeout(_)
                | LlmError::Connection(_)
                | LlmError::Server { .. }
                | LlmError::Malformed(_)
                | LlmError::EmptyChoices
        )
    }

    /// Every further request would fail the same way (bad key, unknown model or URL).
    pub fn is_fatal(&self) -> bool {
        matches!(self, LlmError::Fatal { .. })
    }
}

/// Counters of one client (for progress lines and summaries).
#[derive(Debug, Default, Clone, Copy, Serialize)]
pub struct Stats {
    pub requests: u64,
    pub retries: u64,
    pub rate_limited: u64,
    pub cache_hits: u64,
}

/// The client. Cheap to share by reference across tasks.
pub struct Client {
    cfg: ClientConfig,
    http: reqwest::Client,
    limiter: Limiter,
    cache: Option<Cache>,
    stats: std::sync::Mutex<Stats>,
}

impl Client {
    /// `cache`: `None` bypasses the cache (`--no-cache`).
    pub fn new(cfg: ClientConfig, cache: Option<Cache>) -> Result<Client, String> {
        let http = reqwest::Client::builder()
            .timeout(Duration::from_secs_f64(cfg.timeout_s.max(0.001)))
            .connect_timeout(Duration::from_secs_f64(cfg.timeout_s.clamp(0.001, 30.0)))
            .pool_max_idle_per_host(cfg.concurrency.max(1))
            .build()
            .map_err(|e| format!("cannot start the HTTP client: {e}"))?;
        Ok(Client {
            limiter: Limiter::new(cfg.concurrency),
            cfg,
            http,
            cache,
            stats: Default::default(),
        })
    }

    pub fn config(&self) -> &ClientConfig {
        &self.cfg
    }

    pub fn limiter(&self) -> &Limiter {
        &self.limiter
    }

    pub fn stats(&self) -> Stats {
        *self.stats.lock().expect("stats lock")
    }

    /// `text` with every occurrence of the API key replaced by `***`.
    pub fn redact(&self, text: &str) -> String {
        match self.cfg.api_key.as_deref() {
            Some(k) if !k.is_empty() => text.replace(k, "***"),
            _ => text.to_string(),
        }
    }

    /// The cache key of a request.
    pub fn cache_key(&self, req: &ChatRequest) -> String {
        cache::key(
            &self.cfg.base_url,
            &req.model,
            req.prompt_hash(),
            &Value::Object(req.params.clone()),
            req.sample,
        )
    }

    /// The cached answer of a request, without sending anything.
    pub fn cached(&self, req: &ChatRequest) -> Option<Reply> {
        self.cache.as_ref()?.get(&self.cache_key(req))
    }

    fn endpoint(&self) -> String {
        format!(
            "{}/chat/completions",
            self.cfg.base_url.trim_end_matches('/')
        )
    }

    /// Backoff before retry `k`: uniform in [½, 1] × min(max, base·2^k), the jitter drawn
    /// from a hash of (request, attempt) so concurrent retries spread out. Timing only:
    /// nothing it decides reaches an output.
    fn backoff(&self, seed: &str, k: u32) -> Duration {
        let cap =
            (self.cfg.backoff_base_s * 2f64.powi(k.min(30) as i32)).min(self.cfg.backoff_max_s);
        let h = Sha256::digest(format!("{seed}/{k}").as_bytes());
        let u = u64::from_le_bytes(h[..8].try_into().expect("8 bytes")) as f64 / u64::MAX as f64;
        Duration::from_secs_f64((cap * (0.5 + 0.5 * u)).max(0.0))
    }

    /// Sends a request (or answers it from the cache), retrying as described above.
    pub async fn chat(&self, req: &ChatRequest) -> Result<Reply, LlmError> {
        let key = self.cache_key(req);
        if let Some(hit) = self.cache.as_ref().and_then(|c| c.get(&key)) {
            self.stats.lock().expect("stats lock").cache_hits += 1;
            return Ok(hit);
        }
        let body = serde_json::to_vec(&req.body()).expect("request serializes");
        let mut retries = 0u32;
        let mut rate_retries = 0u32;
        let mut attempts = 0u32;
        loop {
            attempts += 1;
            let permit = self.limiter.acquire().await;
            self.stats.lock().expect("stats lock").requests += 1;
            let t0 = Instant::now();
            let result = self.send_once(&body).await;
            match result {
                Ok(mut reply) => {
                    self.limiter.on_success();
                    drop(permit);
                    reply.latency_s = t0.elapsed().as_secs_f64();
                    reply.attempts = attempts;
                    if let Some(c) = &self.cache {
                        // A cache that cannot be written costs a request next time, nothing more.
                        let _ = c.put(&key, &reply);
                    }
                    return Ok(reply);
                }
                Err(LlmError::RateLimited(after)) => {
                    self.stats.lock().expect("stats lock").rate_limited += 1;
                    let pause = match after {
                        Some(s) => Duration::from_secs_f64(s.min(self.cfg.max_retry_after_s)),
                        None => self.backoff(&key, rate_retries),
                    };
                    self.limiter.on_rate_limited(&permit, pause);
                    drop(permit);
                    if rate_retries >= self.cfg.max_rate_limit_retries {
                        return Err(LlmError::RateLimited(after));
                    }
                    rate_retries += 1;
                    // The limiter holds every request for `pause`; this one waits too.
                    tokio::time::sleep(pause).await;
                }
                Err(e) if e.transient() && retries < self.cfg.max_retries => {
                    drop(permit);
                    self.stats.lock().expect("stats lock").retries += 1;
                    tokio::time::sleep(self.backoff(&key, retries)).await;
                    retries += 1;
                }
                Err(e) => return Err(e),
            }
        }
    }

    async fn send_once(&self, body: &[u8]) -> Result<Reply, LlmError> {
        let mut rb = self
            .http
            .post(self.endpoint())
            .header(reqwest::header::CONTENT_TYPE, "application/json")
            .body(body.to_vec());
        if let Some(k) = self.cfg.api_key.as_deref().filter(|k| !k.is_empty()) {
            rb = rb.bearer_auth(k);
        }
        let resp = rb.send().await.map_err(|e| self.net_error(e))?;
        let status = resp.status().as_u16();
        let retry_after = resp
            .headers()
            .get(reqwest::header::RETRY_AFTER)
            .and_then(|v| v.to_str().ok())
            .and_then(|v| v.trim().parse::<f64>().ok())
            .filter(|s| s.is_finite() && *s >= 0.0);
        let bytes = resp.bytes().await.map_err(|e| self.net_error(e))?;
        let snippet = || {
            let text = String::from_utf8_lossy(&bytes[..bytes.len().min(300)]);
            self.redact(text.trim())
        };
        match status {
            200..=299 => parse_reply(&bytes).map_err(|e| match e {
                LlmError::Malformed(m) => LlmError::Malformed(self.redact(&m)),
                e => e,
            }),
            429 => Err(LlmError::RateLimited(retry_after)),
            408 | 409 | 425 | 500..=599 => Err(LlmError::Server {
                status,
                body: snippet(),
            }),
            401 | 403 | 404 => Err(LlmError::Fatal {
                status,
                body: snippet(),
            }),
            _ => Err(LlmError::Rejected {
                status,
                body: snippet(),
            }),
        }
    }

    fn net_error(&self, e: reqwest::Error) -> LlmError {
        if e.is_timeout() {
            LlmError::Timeout(self.cfg.timeout_s)
        } else {
            // Without the URL: it is known to the caller, and a key could hide in a query.
            let e = e.without_url();
            let mut text = e.to_string();
            let mut src = std::error::Error::source(&e);
            while let Some(s) = src {
                text.push_str(&format!(": {s}"));
                src = s.source();
            }
            LlmError::Connection(self.redact(&text))
        }
    }
}

/// Reads a chat-completions body.
fn parse_reply(bytes: &[u8]) -> Result<Reply, LlmError> {
    let v: Value = serde_json::from_slice(bytes).map_err(|e| {
        LlmError::Malformed(format!(
            "{e}; body starts {:?}",
            String::from_utf8_lossy(&bytes[..bytes.len().min(80)])
        ))
    })?;
    let choices = match v.get("choices") {
        Some(Value::Array(c)) => c,
        Some(_) => return Err(LlmError::Malformed("`choices` is not a list".into())),
        None if v.get("error").is_some() => {
            return Err(LlmError::Malformed(format!(
                "error object in a 2xx body: {}",
                v["error"]
            )))
        }
        None => return Err(LlmError::EmptyChoices),
    };
    let Some(first) = choices.first() else {
        return Err(LlmError::EmptyChoices);
    };
    let message = first.get("message").unwrap_or(&Value::Null);
    let content = match message.get("content") {
        Some(Value::String(s)) => Some(s.clone()),
        // Content as a list of parts: join the text parts.
        Some(Value::Array(parts)) => Some(
            parts
                .iter()
                .filter_map(|p| p.get("text").and_then(Value::as_str))
                .collect::<Vec<_>>()
                .join(""),
        ),
        _ => None,
    };
    let refusal_text = message
        .get("refusal")
        .and_then(Value::as_str)
        .filter(|s| !s.is_empty());
    let finish_reason = first
        .get("finish_reason")
        .and_then(Value::as_str)
        .map(str::to_string);
    let refusal = refusal_text.is_some() || finish_reason.as_deref() == Some("content_filter");
    let text = match (content, refusal_text) {
        (Some(c), _) if !c.is_empty() => c,
        (_, Some(r)) => r.to_string(),
        (Some(c), None) => c,
        (None, None) if refusal => String::new(),
        (None, None) => {
            return Err(LlmError::Malformed(
                "the first choice has no message content".into(),
            ))
        }
    };
    let usage = v.get("usage").unwrap_or(&Value::Null);
    let tokens = |k: &str| usage.get(k).and_then(Value::as_u64).unwrap_or(0);
    Ok(Reply {
        text,
        refusal,
        finish_reason,
        usage: Usage {
            prompt_tokens: tokens("prompt_tokens"),
            completion_tokens: tokens("completion_tokens"),
        },
        latency_s: 0.0,
        attempts: 0,
        cached: false,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_answers_refusals_and_failures() {
        let ok = br#"{"choices":[{"message":{"content":"hi"},"finish_reason":"stop"}],"usage":{"prompt_tokens":5,"completion_tokens":2}}"#;
        let r = parse_reply(ok).unwrap();
        assert_eq!(
            (r.text.as_str(), r.refusal, r.usage.prompt_tokens),
            ("hi", false, 5)
        );
        let refusal = br#"{"choices":[{"message":{"content":null,"refusal":"I can't help"}}]}"#;
        let r = parse_reply(refusal).unwrap();
        assert!(r.refusal);
        assert_eq!(r.text, "I can't help");
        assert!(matches!(
            parse_reply(br#"{"choices":[]}"#),
            Err(LlmError::EmptyChoices)
        ));
        assert!(matches!(
            parse_reply(b"{not json"),
            Err(LlmError::Malformed(_))
        ));
        let parts = br#"{"choices":[{"message":{"content":[{"type":"text","text":"a"},{"type":"text","text":"b"}]}}]}"#;
        assert_eq!(parse_reply(parts).unwrap().text, "ab");
    }

    #[test]
    fn cache_key_depends_on_every_part() {
        let p = serde_json::json!({"temperature": 0.0});
        let base = cache::key("http://a/v1", "m", "h", &p, 0);
        assert_eq!(base, cache::key("http://a/v1/", "m", "h", &p, 0));
        for other in [
            cache::key("http://b/v1", "m", "h", &p, 0),
            cache::key("http://a/v1", "n", "h", &p, 0),
            cache::key("http://a/v1", "m", "g", &p, 0),
            cache::key(
                "http://a/v1",
                "m",
                "h",
                &serde_json::json!({"temperature": 1.0}),
                0,
            ),
            cache::key("http://a/v1", "m", "h", &p, 1),
        ] {
            assert_ne!(base, other);
        }
    }

    #[test]
    fn debug_never_shows_the_key() {
        let cfg = ClientConfig {
            base_url: "http://x".into(),
            timeout_s: 1.0,
            max_retries: 0,
            max_rate_limit_retries: 0,
            backoff_base_s: 0.1,
            backoff_max_s: 1.0,
            max_retry_after_s: 1.0,
            concurrency: 1,
            api_key: Some("sk-SECRET".into()),
        };
        assert!(!format!("{cfg:?}").contains("sk-SECRET"));
        assert!(!serde_json::to_string(&cfg).unwrap().contains("sk-SECRET"));
        let c = Client::new(cfg, None).unwrap();
        assert_eq!(c.redact("bad key sk-SECRET"), "bad key ***");
    }
}
