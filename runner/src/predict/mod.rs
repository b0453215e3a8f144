//! `rh-score predict`: runs a model over a dataset through the OpenAI-compatible chat API
//! with the canonical prompt and writes `preds.jsonl` (specification §9).
//!
//! Entry point: [`run`] over [`PredictOptions`]. Pieces: [`config`] (the runner's
//! configuration), the canonical prompt (rh-prompt: one scene's messages, frames → JPEG
//! data URLs; the scenes to run, `rh_prompt::select_scenes`), [`output`]
//! (resume, torn-line repair, append), [`runner`] (the async loop: bounded in-flight
//! scenes, the shared [`rh_llm::Client`] with its cache, retries and adaptive limit, cost
//! budget, progress).

pub mod config;
pub mod estimate;
pub mod output;
pub mod runner;

use anyhow::Result;
use rh_grade::dataset::Subset;
use rh_grade::error::InputError;

use std::path::PathBuf;

use rh_prompt::messages as prompt;
pub use runner::Summary;

/// Everything `rh-score predict` was asked to do.
#[derive(Debug, Clone)]
pub struct PredictOptions {
    pub dataset: PathBuf,
    pub model: String,
    pub out: PathBuf,
    pub subset: Subset,
    pub limit: Option<usize>,
    /// Client settings, already merged from config, flags and environment.
    pub client: rh_llm::ClientConfig,
    pub generation: config::Generation,
    pub price: Option<config::Price>,
    pub max_cost: Option<f64>,
    pub retry_errors: bool,
    /// `None`: `--no-cache`.
    pub cache_dir: Option<PathBuf>,
    pub sample: u32,
    pub prompt: config::PromptConfig,
    pub progress: bool,
    /// Stop (exit 2) when this many first requests all fail (`[run]` of predict.toml).
    pub abort_after_failures: usize,
    /// Seconds between progress lines when stderr is not a terminal.
    pub progress_every_s: f64,
}

#[cfg(test)]
mod tests {
    #[test]
    fn a_closed_port_is_refused_and_an_open_one_passes() {
        let url = |port: u16| format!("http://127.0.0.1:{port}/v1");
        let listener = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
        let port = listener.local_addr().unwrap().port();
        super::probe_endpoint(&url(port)).unwrap();
        drop(listener);
        // A port just freed is closed, unless a test running beside this one took it at
        // once (seen in CI): then another freed port.
        let e = std::iter::once(port)
            .chain((0..20).map(|_| {
                let l = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
                l.local_addr().unwrap().port()
            }))
            .find_map(|port| super::probe_endpoint(&url(port)).err())
            .expect("a freed port refuses connections");
        assert!(e.to_string().contains("connection refused"), "{e}");
        assert!(rh_grade::error::is_input_error(&e));
        // Not a URL: nothing to probe.
        super::probe_endpoint("not a url").unwrap();
    }
}

/// Refuses `--max-cost` for a model without a price: the budget could never stop it.
pub fn check_price(model: &str, max_cost: Option<f64>, price: Option<config::Price>) -> Result<()> {
    if max_cost.is_some() && price.is_none() {
        return Err(InputError(format!(
            "--max-cost: the price of model {model:?} is unknown (not in the price table of configs/predict.toml), \
             so its cost would count as $0 and the budget could never stop the run; give --price-in and \
             --price-out (USD per million tokens)"
        ))
        .into());
    }
    Ok(())
}

/// The first scene's request, as `--dry-run` prints it (images elided, no key), with the
/// estimate of the whole run's tokens and cost ([`estimate`]).
pub fn dry_run(opts: &PredictOptions, scenes: &[String]) -> Result<serde_json::Value> {
    let scene_id = scenes.first().map(String::as_str).unwrap_or_default();
    let built =
        prompt::build(&opts.prompt, &opts.dataset, scene_id).map_err(|e| InputError(e.into()))?;
    let est = estimate::estimate(
        &built.messages,
        scenes.len(),
        opts.generation.max_tokens,
        opts.price,
    );
    let req = runner::request(opts, built.messages);
    Ok(serde_json::json!({
        "estimate": est,
        "url": format!("{}/chat/completions", opts.client.base_url.trim_end_matches('/')),
        "scene_id": scene_id,
        "prompt_version": opts.prompt.version,
        "prompt_hash": req.prompt_hash(),
        "body": prompt::elide_images(&req.body()),
    }))
}

/// Runs the model over the selected scenes of the dataset into `opts.out`.
pub fn run(opts: &PredictOptions, scenes: &[String]) -> Result<Summary> {
    probe_endpoint(&opts.client.base_url)?;
    runner::run(opts, scenes)
}

/// Refuses (exit 2) an endpoint whose port refuses connections, before any request: a
/// closed port would otherwise cost every request its retries (with `--max-cost`, one
/// scene at a time). Only a refused connection counts (a slow or filtered network is
/// left to the run's own failure check), and nothing is probed when a proxy is set.
pub fn probe_endpoint(base_url: &str) -> Result<()> {
    use std::net::{TcpStream, ToSocketAddrs};
    let proxied = [
        "HTTPS_PROXY",
        "https_proxy",
        "HTTP_PROXY",
        "http_proxy",
        "ALL_PROXY",
        "all_proxy",
    ]
    .iter()
    .any(|v| std::env::var_os(v).is_some_and(|x| !x.is_empty()));
    let Some((scheme, rest)) = base_url.split_once("://") else {
        return Ok(());
    };
    if proxied {
        return Ok(());
    }
    let authority = rest.split(['/', '?', '#']).next().unwrap_or_default();
    let authority = authority.rsplit('@').next().unwrap_or_default();
    let default_port = if scheme.eq_ignore_ascii_case("https") {
        443
    } else {
        80
    };
    let host_port = if authority.starts_with('[') {
        match authority.rfind("]:") {
            Some(_) => authority.to_string(),
            None => format!("{authority}:{default_port}"),
        }
    } else if authority.contains(':') {
        authority.to_string()
    } else {
        format!("{authority}:{default_port}")
    };
    let Ok(addrs) = host_port.to_socket_addrs() else {
        return Ok(()); // name resolution problems: the run's requests say what failed
    };
    let addrs: Vec<_> = addrs.collect();
    if addrs.is_empty() {
        return Ok(());
    }
    let refused = addrs.iter().all(|a| {
        matches!(
            TcpStream::connect_timeout(a, std::time::Duration::from_secs(5)),
            Err(e) if e.kind() == std::io::ErrorKind::ConnectionRefused
        )
    });
    if refused {
        return Err(InputError(format!(
            "cannot connect to {base_url}: connection refused at {host_port}; is the server running? Check --base-url (nothing was sent, nothing written)"
        ))
        .into());
    }
    Ok(())
}
