//! `rh-score predict`: runs a model over a dataset (`rh_runner::predict`) with the options
//! of [`PredictArgs`].

use super::args::PredictArgs;
use super::dataset_arg::resolve_dataset;
use super::output::print_out;
use anyhow::Result;
use rh_grade::error::InputError;
use rh_grade::Dataset;

/// `rh-score predict`: the runner's options from the arguments, then a dry run or the run,
/// and what happened on stderr (the summary as JSON on stdout with `--json`).
pub fn run(a: PredictArgs) -> Result<()> {
    use rh_runner::predict::config::{Generation, PredictConfig, Price, PromptConfig};
    let cfg = PredictConfig::load(a.config.as_deref())?;
    let prompt = PromptConfig::load(a.prompt.as_deref())?;
    let mut client = cfg
        .client
        .clone()
        .with_endpoint(a.base_url.clone(), &a.api_key_env);
    if let Some(c) = a.concurrency {
        if c == 0 {
            return Err(InputError("--concurrency must be at least 1".into()).into());
        }
        client.concurrency = c;
    }
    if let Some(t) = a.timeout {
        if !(t > 0.0) {
            return Err(InputError("--timeout must be positive".into()).into());
        }
        client.timeout_s = t;
    }
    if let Some(r) = a.max_retries {
        client.max_retries = r;
    }
    rh_runner::predict::config::check_client(&client, "--concurrency/--timeout/--max-retries:")?;
    let generation = Generation {
        temperature: a.temperature.unwrap_or(cfg.generation.temperature),
        max_tokens: a.max_tokens.unwrap_or(cfg.generation.max_tokens),
    };
    rh_runner::predict::config::check_generation(&generation, "--temperature/--max-tokens:")?;
    for (flag, v) in [("--price-in", a.price_in), ("--price-out", a.price_out)] {
        if v.is_some_and(|p| !(p.is_finite() && p >= 0.0)) {
            return Err(InputError(format!(
                "{flag} must be a non-negative number of USD per million tokens"
            ))
            .into());
        }
    }
    if a.max_cost.is_some_and(|c| !(c.is_finite() && c >= 0.0)) {
        return Err(InputError("--max-cost must be a non-negative number of USD".into()).into());
    }
    let table = cfg.price(&a.model);
    let price = match (a.price_in, a.price_out, table) {
        (None, None, t) => t,
        (i, o, t) => Some(Price {
            input: i.or(t.map(|p| p.input)).unwrap_or(0.0),
            output: o.or(t.map(|p| p.output)).unwrap_or(0.0),
        }),
    };
    rh_runner::predict::check_price(&a.model, a.max_cost, price)?;
    if price.is_none() && !a.dry_run {
        rh_contract::note!(
            "rh-score predict: no price for model {:?} in the price table: its cost counts as $0 (give --price-in/--price-out for a real figure)",
            a.model
        );
    }
    let dataset = resolve_dataset(a.dataset.clone(), a.allow_incomplete)?;
    let ds = Dataset::load(&dataset)?;
    let scenes = rh_prompt::select_scenes(&ds, a.subset, a.limit)?;
    let opts = rh_runner::predict::PredictOptions {
        dataset,
        model: a.model.clone(),
        out: a.out.clone().unwrap_or_default(),
        subset: a.subset,
        limit: a.limit,
        client,
        generation,
        price,
        max_cost: a.max_cost,
        retry_errors: a.retry_errors,
        cache_dir: (!a.no_cache).then(|| {
            a.cache_dir
                .clone()
                .unwrap_or_else(rh_llm::cache::default_dir)
        }),
        sample: a.sample_index,
        prompt,
        progress: !a.quiet && !a.json,
        abort_after_failures: cfg.run.abort_after_failures,
        progress_every_s: cfg.run.progress_every_s,
    };
    if a.dry_run {
        let req = rh_runner::predict::dry_run(&opts, &scenes)?;
        let e = &req["estimate"];
        rh_contract::note!(
            "rh-score predict --dry-run: {} scenes ≈ {} input tokens ({} a scene) + at most {} output tokens; cost {}",
            e["scenes"],
            e["input_tokens"],
            e["input_tokens_per_scene"],
            e["output_tokens_at_most"],
            match (e["cost_usd_at_least"].as_f64(), e["cost_usd_at_most"].as_f64()) {
                (Some(lo), Some(hi)) => format!("≈ ${lo:.4} to ${hi:.4} (estimate)"),
                _ => "unknown: no price for this model (give --price-in/--price-out)".into(),
            }
        );
        return print_out(&(serde_json::to_string_pretty(&req)? + "\n"));
    }
    let s = rh_runner::predict::run(&opts, &scenes)?;
    if a.json {
        print_out(&(serde_json::to_string_pretty(&s)? + "\n"))?;
    } else {
        rh_contract::note!(
            "rh-score predict: {} of {} scenes in {} ({} already there, {} new: {} answered, \
             {} lost as error lines, {} refusals, {} without a parseable plan); {} requests, \
             {} retries, {} rate-limited, {} from the cache; cost ${:.4} (file total ${:.4}); \
             {:.1} decisions/s; prompt {}",
            s.scenes - s.remaining,
            s.scenes,
            s.out,
            s.already_done,
            s.written,
            s.answered,
            s.lost,
            s.refusals,
            s.unparseable,
            s.requests,
            s.retries,
            s.rate_limited,
            s.cache_hits,
            s.cost_usd,
            s.total_cost_usd,
            s.decisions_per_s,
            s.prompt_version
        );
    }
    if s.stopped == "max_cost" {
        rh_contract::note!(
            "rh-score predict: stopped by --max-cost {:.4} USD with {} scene(s) left; run again \
             with a higher --max-cost to resume",
            a.max_cost.unwrap_or(0.0),
            s.remaining
        );
    }
    if s.lost > 0 {
        rh_contract::note!(
            "rh-score predict: {} decision(s) lost; `--retry-errors` asks for them again",
            s.lost
        );
    }
    Ok(())
}
