//! `rh-pipeline balance`: label counts per family, built in memory.

use super::failure::{input, print, print_json, Failure};
use rh_catalog::Catalog;
use rh_scenes::config::Config;

/// `balance`: label counts per family over `per_family` scenes each, built in memory.
pub fn run(
    catalog: &Catalog,
    config: &Config,
    seed: Option<u64>,
    per_family: usize,
    pool: u64,
    families: Option<Vec<String>>,
    json: bool,
) -> Result<(), Failure> {
    if per_family == 0 {
        return Err(input("--per-family must be at least 1"));
    }
    if pool == 0 {
        return Err(input("--pool must be at least 1"));
    }
    if per_family > 100_000 {
        return Err(input(format!("--per-family {per_family}: at most 100000")));
    }
    if pool > crate::build::MAX_SCENES {
        return Err(input(format!(
            "--pool {pool}: at most {} scenes (the bound of one build)",
            crate::build::MAX_SCENES
        )));
    }
    let families = families.unwrap_or_default();
    for f in &families {
        if rh_scenes::families::get(f).is_none() {
            return Err(input(format!(
                "unknown or unimplemented family '{f}' (implemented: {})",
                rh_scenes::randomize::implemented_families()
            )));
        }
    }
    let seed = seed.unwrap_or(config.build.seed);
    let rows =
        rh_scenes::balance::label_balance(catalog, config, seed, &families, per_family, pool)
            .map_err(|e| Failure {
                code: 1,
                message: format!("{e:#}"),
            })?;
    if json {
        print_json(&rh_scenes::balance::Balance::of(
            catalog, seed, pool, per_family, rows,
        ))?;
    } else {
        print(&rh_scenes::balance::format_table(&rows))?;
    }
    Ok(())
}
