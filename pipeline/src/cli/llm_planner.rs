//! The LLM scene planner ([`crate::llm_plan`]) from the command line's `LlmArgs`.

use super::args::LlmArgs;
use super::failure::{input, Failure};
use rh_catalog::Catalog;

/// The LLM planner of `--model`, `--base-url` and `--api-key-env`.
pub fn llm_planner<'a>(
    catalog: &'a Catalog,
    args: &LlmArgs,
) -> Result<crate::llm_plan::LlmPlanner<'a>, Failure> {
    let model = args
        .model
        .as_deref()
        .ok_or_else(|| input("the LLM planner needs --model ID"))?;
    let cfg = crate::llm_plan::PlannerConfig::embedded();
    let client = cfg
        .client
        .clone()
        .with_endpoint(args.base_url.clone(), &args.api_key_env);
    let cache = (!args.no_cache).then(|| rh_llm::cache::Cache::new(rh_llm::cache::default_dir()));
    crate::llm_plan::LlmPlanner::new(catalog, client, cache, model, cfg).map_err(|m| Failure {
        code: 1,
        message: m,
    })
}
