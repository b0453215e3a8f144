//! `rh-pipeline plan`: one description mapped to a selection (lexicon or LLM), as JSON.

use super::args::LlmArgs;
use super::failure::{input, print_json, Failure};
use super::llm_planner::llm_planner;
use rh_catalog::Catalog;
use rh_scenes::selection::{LexiconPlanner, Planner};

/// Plans `description` with `seed` and prints the selection and what the lexicon matched.
pub fn run(
    catalog: &Catalog,
    description: &str,
    seed: u64,
    llm: bool,
    llm_args: &LlmArgs,
) -> Result<(), Failure> {
    let lexicon = LexiconPlanner::new(catalog);
    let selection = if llm {
        llm_planner(catalog, llm_args)?.plan(description, seed)
    } else {
        lexicon.plan(description, seed)
    }
    .map_err(|e| input(e.to_string()))?;
    let matches = lexicon.matches(description);
    let out = serde_json::json!({ "selection": selection, "matched": matches });
    print_json(&out)?;
    Ok(())
}
