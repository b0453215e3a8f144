//! The async loop of `rh-score predict`.
//!
//! Frames are encoded on the blocking pool ahead of the requests, overlapped with the
//! requests in flight: at most `concurrency` scenes are prepared and waiting and at most
//! `concurrency` are in flight (memory stays flat in the number of scenes: a scene's
//! prompt is dropped when its line is written); the shared [`rh_llm::Client`] bounds the
//! requests in flight adaptively. Lines are appended as decisions finish (completion order). The cost
//! budget (`--max-cost`) caps the cost of the requests recorded in the output file: a new
//! scene starts only while `spent + (in flight + 1) × mean cost per request` stays within
//! it (one scene at a time until the first paid answer gives a mean), so the run stops
//! before exceeding it, and a later run with a higher cap resumes.

use super::config::Price;
use super::output::{prepare, Appender};
use super::PredictOptions;
use anyhow::Result;
use futures_util::stream::{FuturesUnordered, StreamExt};
use rh_grade::config::Config;
use rh_grade::error::InputError;
use rh_grade::plan::{plan_from_text, Plan};
use rh_llm::{ChatRequest, Client, LlmError, Reply};
use rh_prompt::messages as prompt;
use serde::Serialize;
use serde_json::{json, Value};
use std::time::Instant;

/// What a run did (printed, or `--json`).
#[derive(Debug, Clone, Serialize)]
pub struct Summary {
    pub model: String,
    pub out: String,
    pub prompt_version: String,
    /// Scenes selected.
    pub scenes: usize,
    /// Scenes already in the output file when the run started.
    pub already_done: usize,
    /// Lines written by this run.
    pub written: usize,
    pub answered: usize,
    /// Decisions lost (written as `error` lines).
    pub lost: usize,
    pub refusals: usize,
    pub unparseable: usize,
    /// Scenes still to run (stopped by the cost budget, or by a fatal error).
    pub remaining: usize,
    /// "complete", or "max_cost".
    pub stopped: String,
    pub requests: u64,
    pub retries: u64,
    pub rate_limited: u64,
    pub cache_hits: u64,
    /// Cost of this run's requests (USD; answers from the cache cost nothing).
    pub cost_usd: f64,
    /// Cost of every request recorded in the output file.
    pub total_cost_usd: f64,
    pub wall_s: f64,
    pub decisions_per_s: f64,
    /// CPU seconds spent building prompts: decoding, scaling and JPEG-encoding frames
    /// (per-thread CPU time of the encoding threads, summed over this run's scenes).
    pub encode_cpu_s: f64,
    pub torn_line_dropped: bool,
    pub error_lines_retried: usize,
}

/// The chat request of one scene.
pub fn request(opts: &PredictOptions, messages: Value) -> ChatRequest {
    let mut params = serde_json::Map::new();
    params.insert("temperature".into(), json!(opts.generation.temperature));
    params.insert("max_tokens".into(), json!(opts.generation.max_tokens));
    ChatRequest::new(&opts.model, messages, params, opts.sample)
}

/// A plan as the scorer reads it, in the canonical object form.
fn plan_json(p: &Plan) -> Value {
    json!({
        "intent": p.intent,
        "confidence": p.confidence,
        "walking_cmd": p.walking_cmd,
        "walking_duration": p.walking_duration,
        "keyframes": p.keyframes.iter().map(|k| json!({
            "t": k.t, "left_hand": k.left, "right_hand": k.right, "knee_bend": k.knee_bend,
        })).collect::<Vec<_>>(),
    })
}

/// One finished scene.
struct Done {
    line: Value,
    paid: f64,
    lost: bool,
    refusal: bool,
    unparseable: bool,
    encode_cpu_s: f64,
}

enum Stop {
    Input(String),
    Fatal(String),
    /// The output file could not be written (exit 3).
    Write(anyhow::Error),
    /// The first requests all failed: (how many, the last error).
    Dead(usize, String),
}

/// Holds back the lost decisions until the endpoint has answered once: when the first
/// `limit` requests all fail, the run stops (exit 2) without writing them, instead of
/// marking every scene lost.
struct Gate {
    held: Vec<Done>,
    open: bool,
    limit: usize,
}

fn answer_line(
    opts: &PredictOptions,
    scene: &str,
    hash: &str,
    reply: &Reply,
    price: Option<Price>,
    scoring: &Config,
) -> (Value, Option<Plan>) {
    let plan = plan_from_text(&reply.text, scoring).ok();
    let cost = price.map_or(0.0, |p| p.cost(reply.usage));
    let mut line = json!({
        "scene_id": scene,
        "model": opts.model,
        "response": reply.text,
        "usage": {
            "prompt_tokens": reply.usage.prompt_tokens,
            "completion_tokens": reply.usage.completion_tokens,
            "cost": cost,
        },
        "latency_s": (reply.latency_s * 1000.0).round() / 1000.0,
        "prompt_version": opts.prompt.version,
        "prompt_hash": hash,
        "error": null,
    });
    let m = line.as_object_mut().expect("object");
    if let Some(p) = &plan {
        m.insert("plan".into(), plan_json(p));
    }
    if reply.refusal {
        m.insert("refusal".into(), json!(true));
    }
    if reply.cached {
        m.insert("cached".into(), json!(true));
    }
    if opts.sample != 0 {
        m.insert("sample".into(), json!(opts.sample));
    }
    m.insert("attempts".into(), json!(reply.attempts));
    (line, plan)
}

/// Builds one scene's prompt (frames decoded, scaled, JPEG-encoded) on the blocking pool.
fn prepare_scene(
    opts: &PredictOptions,
    scene: String,
) -> tokio::task::JoinHandle<(String, Result<prompt::BuiltPrompt, String>)> {
    let (p, dir) = (opts.prompt.clone(), opts.dataset.clone());
    tokio::task::spawn_blocking(move || {
        let built = prompt::build(&p, &dir, &scene).map_err(String::from);
        (scene, built)
    })
}

async fn one(
    opts: &PredictOptions,
    client: &Client,
    scoring: &Config,
    scene: String,
    built: prompt::BuiltPrompt,
) -> Result<Done, Stop> {
    let encode_cpu_s = built.encode_cpu_s;
    let req = request(opts, built.messages);
    let hash = req.prompt_hash().to_string();
    let started = Instant::now();
    match client.chat(&req).await {
        Ok(reply) => {
            let (line, plan) = answer_line(opts, &scene, &hash, &reply, opts.price, scoring);
            let paid = if reply.cached {
                0.0
            } else {
                line["usage"]["cost"].as_f64().unwrap_or(0.0)
            };
            Ok(Done {
                line,
                paid,
                lost: false,
                refusal: reply.refusal,
                unparseable: plan.is_none(),
                encode_cpu_s,
            })
        }
        Err(e) if e.is_fatal() => Err(Stop::Fatal(client.redact(&e.to_string()))),
        Err(e) => Ok(Done {
            line: error_line(opts, &scene, &hash, &e, client, started),
            paid: 0.0,
            lost: true,
            refusal: false,
            unparseable: false,
            encode_cpu_s,
        }),
    }
}

fn error_line(
    opts: &PredictOptions,
    scene: &str,
    hash: &str,
    e: &LlmError,
    client: &Client,
    started: Instant,
) -> Value {
    json!({
        "scene_id": scene,
        "model": opts.model,
        "response": null,
        "error": client.redact(&e.to_string()),
        "latency_s": (started.elapsed().as_secs_f64() * 1000.0).round() / 1000.0,
        "prompt_version": opts.prompt.version,
        "prompt_hash": hash,
    })
}

/// The cost budget: `spent` over the whole output file; the mean cost per request over
/// the file's paid lines and this run's requests.
struct Budget {
    max: Option<f64>,
    spent: f64,
    spent_run: f64,
    paid_requests: u64,
    /// Paid lines already in the file when the run started.
    paid_before: u64,
}

impl Budget {
    fn allows(&self, in_flight: usize) -> bool {
        let Some(max) = self.max else { return true };
        if self.spent >= max {
            return false;
        }
        let requests = self.paid_requests + self.paid_before;
        if requests == 0 {
            return in_flight == 0;
        }
        let mean = self.spent / requests as f64;
        self.spent + (in_flight as f64 + 1.0) * mean <= max
    }
}

pub fn run(opts: &PredictOptions, scenes: &[String]) -> Result<Summary> {
    let existing = prepare(&opts.out, &opts.model, opts.retry_errors)?;
    let todo: Vec<String> = scenes
        .iter()
        .filter(|s| !existing.done.contains(*s))
        .cloned()
        .collect();
    let already_done = scenes.len() - todo.len();
    let cache = opts.cache_dir.clone().map(rh_llm::cache::Cache::new);
    let client = Client::new(opts.client.clone(), cache).map_err(anyhow::Error::msg)?;
    let scoring = Config::default();
    let mut out = Appender::open(&opts.out, scoring.sanity.max_line_bytes)?;
    let bar = progress_bar(opts.progress, scenes.len(), already_done);
    let mut s = Summary {
        model: opts.model.clone(),
        out: opts.out.display().to_string(),
        prompt_version: opts.prompt.version.clone(),
        scenes: scenes.len(),
        already_done,
        written: 0,
        answered: 0,
        lost: 0,
        refusals: 0,
        unparseable: 0,
        remaining: todo.len(),
        stopped: "complete".into(),
        requests: 0,
        retries: 0,
        rate_limited: 0,
        cache_hits: 0,
        cost_usd: 0.0,
        total_cost_usd: existing.paid_cost,
        wall_s: 0.0,
        decisions_per_s: 0.0,
        encode_cpu_s: 0.0,
        torn_line_dropped: existing.torn_bytes > 0,
        error_lines_retried: existing.removed_errors,
    };
    let mut budget = Budget {
        max: opts.max_cost,
        spent: existing.paid_cost,
        spent_run: 0.0,
        paid_requests: 0,
        paid_before: existing.paid_lines,
    };
    limit_malloc_arenas();
    let rt = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .max_blocking_threads(std::thread::available_parallelism().map_or(2, |n| n.get()))
        .enable_all()
        .build()?;
    let start = Instant::now();
    let mut gate = Gate {
        held: Vec::new(),
        open: false,
        limit: opts.abort_after_failures.clamp(1, todo.len().max(1)),
    };
    let result = rt.block_on(drive(
        opts,
        &client,
        &scoring,
        &todo,
        &mut out,
        &bar,
        &mut s,
        &mut budget,
        &mut gate,
    ));
    bar.finish_and_clear();
    let stats = client.stats();
    s.requests = stats.requests;
    s.retries = stats.retries;
    s.rate_limited = stats.rate_limited;
    s.cache_hits = stats.cache_hits;
    s.cost_usd = budget.spent_run;
    s.total_cost_usd = budget.spent;
    s.wall_s = start.elapsed().as_secs_f64();
    s.decisions_per_s = if s.wall_s > 0.0 {
        s.written as f64 / s.wall_s
    } else {
        0.0
    };
    match result {
        Ok(()) => Ok(s),
        Err(Stop::Input(m)) => Err(InputError(m).into()),
        Err(Stop::Write(e)) => Err(e.context(format!(
            "stopped after {} new lines (they are kept; run again to resume)",
            s.written
        ))),
        Err(Stop::Fatal(m)) => Err(InputError(format!(
            "stopped after {} new lines: the server refused the request ({m}); check \
             --base-url, --model and the API key variable",
            s.written
        ))
        .into()),
        Err(Stop::Dead(n, m)) => Err(InputError(format!(
            "stopped: the first {n} request(s) to {} all failed (last: {m}); nothing was \
             written for them. Is the server up? Check --base-url, then run again",
            opts.client.base_url
        ))
        .into()),
    }
}

/// Makes glibc's malloc use one arena for the process. Prompts are built on blocking
/// threads and freed on the runtime's workers; with an arena per thread that pattern
/// fragments memory and the peak RSS grew with the number of scenes (32 → 41 MiB from
/// 120 to 1,158 scenes; two arenas: 35 → 42 MiB; one: 36 → 36 MiB, at the same
/// throughput: allocations are few and large). No effect on other allocators.
fn limit_malloc_arenas() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: mallopt only sets an allocator parameter; M_ARENA_MAX is valid for glibc.
    unsafe {
        libc::mallopt(libc::M_ARENA_MAX, 1);
    }
}

/// The run's loop: frames are encoded ahead of the requests on the blocking pool (at most
/// `concurrency` scenes prepared and waiting, so memory stays flat in the number of
/// scenes), at most `concurrency` scenes are in flight with the client, and each finished
/// scene's line is appended as it completes.
#[allow(clippy::too_many_arguments)]
async fn drive(
    opts: &PredictOptions,
    client: &Client,
    scoring: &Config,
    todo: &[String],
    out: &mut Appender,
    bar: &indicatif::ProgressBar,
    s: &mut Summary,
    budget: &mut Budget,
    gate: &mut Gate,
) -> Result<(), Stop> {
    use std::io::IsTerminal;
    let slots = opts.client.concurrency.max(1);
    // Not on a terminal (a log file, CI): one progress line every progress_every_s.
    let log = opts.progress && !std::io::stderr().is_terminal();
    let every = std::time::Duration::from_secs_f64(opts.progress_every_s.max(0.1));
    let mut ticker = tokio::time::interval_at(tokio::time::Instant::now() + every, every);
    let began = Instant::now();
    let mut prepared = futures_util::stream::iter(todo.iter().cloned())
        .map(|scene| prepare_scene(opts, scene))
        .buffered(slots);
    let mut pending = FuturesUnordered::new();
    let (mut started, mut exhausted) = (0usize, false);
    loop {
        let can_start = !exhausted && pending.len() < slots && budget.allows(pending.len());
        if !can_start && pending.is_empty() {
            break;
        }
        tokio::select! {
            biased;
            Some(done) = pending.next(), if !pending.is_empty() => {
                gated(done?, out, bar, s, budget, client, gate)?;
            }
            _ = ticker.tick(), if log => {
                rh_contract::note!("{}", progress_line(s, budget, began, todo.len()));
            }
            next = prepared.next(), if can_start => match next {
                None => exhausted = true,
                Some(joined) => {
                    let (scene, built) = joined
                        .map_err(|e| Stop::Fatal(format!("frame encoding failed: {e}")))?;
                    pending.push(one(opts, client, scoring, scene, built.map_err(Stop::Input)?));
                    started += 1;
                }
            },
        }
    }
    for held in std::mem::take(&mut gate.held) {
        record(held, out, bar, s, budget, client)?;
    }
    if started < todo.len() {
        s.stopped = "max_cost".into();
    }
    Ok(())
}

/// Records a finished scene through the [`Gate`].
fn gated(
    done: Done,
    out: &mut Appender,
    bar: &indicatif::ProgressBar,
    s: &mut Summary,
    budget: &mut Budget,
    client: &Client,
    gate: &mut Gate,
) -> Result<(), Stop> {
    if !gate.open {
        if done.lost {
            let err = done.line["error"].as_str().unwrap_or("error").to_string();
            gate.held.push(done);
            if gate.held.len() >= gate.limit {
                return Err(Stop::Dead(gate.held.len(), err));
            }
            return Ok(());
        }
        gate.open = true;
        for held in std::mem::take(&mut gate.held) {
            record(held, out, bar, s, budget, client)?;
        }
    }
    record(done, out, bar, s, budget, client)
}

/// "12/60 new scenes done · 0.80/s · ETA 1m00s · 0 lost · $0.0123 so far".
fn progress_line(s: &Summary, budget: &Budget, began: Instant, todo: usize) -> String {
    let secs = began.elapsed().as_secs_f64();
    let rate = s.written as f64 / secs.max(1e-9);
    let left = todo.saturating_sub(s.written);
    let eta = if s.written == 0 {
        "unknown".to_string()
    } else {
        rh_contract::progress::eta_text(left as f64 / rate)
    };
    format!(
        "rh-score predict: {}/{todo} new scenes done ({} already there) · {rate:.2}/s · ETA {eta} · {} lost · ${:.4} so far (file ${:.4})",
        s.written, s.already_done, s.lost, budget.spent_run, budget.spent
    )
}

/// Appends one finished scene's line and counts it.
fn record(
    done: Done,
    out: &mut Appender,
    bar: &indicatif::ProgressBar,
    s: &mut Summary,
    budget: &mut Budget,
    client: &Client,
) -> Result<(), Stop> {
    out.write(&done.line).map_err(Stop::Write)?;
    s.written += 1;
    s.remaining -= 1;
    s.encode_cpu_s += done.encode_cpu_s;
    if done.lost {
        s.lost += 1;
    } else {
        s.answered += 1;
        s.refusals += done.refusal as usize;
        s.unparseable += done.unparseable as usize;
    }
    if !done.lost && done.line.get("cached").is_none() {
        budget.spent += done.paid;
        budget.spent_run += done.paid;
        budget.paid_requests += 1;
    }
    bar.inc(1);
    bar.set_message(format!(
        "lost {} · ${:.4} · limit {}",
        s.lost,
        budget.spent,
        client.limiter().limit()
    ));
    Ok(())
}

fn progress_bar(show: bool, total: usize, done: usize) -> indicatif::ProgressBar {
    if !show {
        return indicatif::ProgressBar::hidden();
    }
    let bar = indicatif::ProgressBar::new(total as u64);
    bar.set_style(
        indicatif::ProgressStyle::with_template(
            "{bar:30} {pos}/{len} scenes · {per_sec} · ETA {eta} · {msg}",
        )
        .expect("valid template"),
    );
    bar.set_position(done as u64);
    bar.reset_eta();
    bar
}
