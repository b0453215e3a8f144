//! `rh-pipeline build`: the build options from the arguments, the build
//! ([`crate::build::build`]) and its summary.

use super::args::{parse_shard, BuildArgs, PlannerKind};
use super::failure::{build_failure, input, print_json, println, Failure};
use super::llm_planner::llm_planner;
use super::release_command;
use crate::build::{build, BuildOptions};
use rh_catalog::Catalog;
use rh_scenes::config::Config;
use rh_scenes::selection::{LexiconPlanner, Planner};

/// `rh-pipeline build`: the scene groups (round-robin families, or planned from
/// `--descriptions`), the build, and its summary.
pub fn run(args: BuildArgs, catalog: &Catalog, config: &Config) -> Result<(), Failure> {
    let BuildArgs {
        n,
        release,
        release_config,
        descriptions,
        planner,
        llm,
        out,
        seed,
        families,
        no_render,
        masks,
        shard,
        jobs,
        json,
        quiet,
        progress_every,
    } = args;
    if !(progress_every.is_finite() && progress_every > 0.0 && progress_every <= 86_400.0) {
        return Err(input(format!(
            "--progress-every {progress_every}: must be a positive number of seconds, at most 86400"
        )));
    }
    // The bounds of the numbers are checked before anything is planned or written.
    if let Some(n) = n.filter(|&n| n > crate::build::MAX_SCENES) {
        return Err(input(format!(
            "--n {n}: at most {} scenes in one build (shard a larger one with --shard i/N, then merge)",
            crate::build::MAX_SCENES
        )));
    }
    let release = match release {
        true => Some(release_command::prepare(
            release_config.as_deref(),
            catalog,
            config,
        )?),
        false => None,
    };
    let r = release.as_ref().map(|(r, _)| r);
    let seed = r.map_or(seed.unwrap_or(config.build.seed), |r| r.seed);
    let n = r.map(|r| r.n).or(n);
    let families = r.map_or(families, |r| r.families.clone());
    let (no_render, masks) = r.map_or((no_render, masks), |r| {
        (no_render || !r.render, r.masks && !no_render)
    });
    let selections = match &descriptions {
        None => None,
        Some(path) => {
            let texts = read_descriptions(path)?;
            let sel = match planner {
                PlannerKind::Lexicon => {
                    plan_descriptions(&LexiconPlanner::new(catalog), &texts, path, seed)?
                }
                PlannerKind::Llm => {
                    plan_descriptions(&llm_planner(catalog, &llm)?, &texts, path, seed)?
                }
            };
            Some(sel)
        }
    };
    let n = match (n, &selections) {
        (Some(n), _) => n,
        (None, Some(s)) => 4 * s.len() as u64,
        (None, None) => unreachable!("clap requires --n without --descriptions or --release"),
    };
    let families = match &selections {
        Some(s) => {
            let mut f: Vec<String> = Vec::new();
            for x in s {
                if !f.contains(&x.family) {
                    f.push(x.family.clone());
                }
            }
            f
        }
        None => families.unwrap_or_else(|| config.build.families.clone()),
    };
    let opts = BuildOptions {
        n,
        out,
        seed,
        families,
        selections,
        jobs: jobs.unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get())),
        shard: match shard {
            Some(s) => parse_shard(&s)?,
            None => (0, 1),
        },
        render: !no_render,
        masks,
        progress: !quiet,
        progress_every_s: progress_every,
        release: r.map(|r| r.id.clone()),
    };
    build_and_print(&opts, catalog, config, json, release.as_ref())
}

/// Reads a descriptions file: one a line; blank lines and `#` comments skipped.
fn read_descriptions(path: &std::path::Path) -> Result<Vec<String>, Failure> {
    let text = std::fs::read_to_string(path).map_err(|e| {
        input(format!(
            "cannot read --descriptions {}: {e}",
            path.display()
        ))
    })?;
    let lines: Vec<String> = text
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty() && !l.starts_with('#'))
        .map(str::to_string)
        .collect();
    if lines.is_empty() {
        return Err(input(format!("{}: no descriptions", path.display())));
    }
    Ok(lines)
}

/// One selection per description; description `i` plans with group `i`'s seed.
fn plan_descriptions(
    planner: &dyn Planner,
    descriptions: &[String],
    path: &std::path::Path,
    build_seed: u64,
) -> Result<Vec<rh_physics::spec::Selection>, Failure> {
    descriptions
        .iter()
        .enumerate()
        .map(|(i, d)| {
            planner
                .plan(d, rh_physics::seeds::group_seed(build_seed, i as u64))
                .map_err(|e| input(format!("{}: description {}: {e}", path.display(), i + 1)))
        })
        .collect()
}

/// `rh-pipeline build`: builds, then prints the summary.
fn build_and_print(
    opts: &BuildOptions,
    catalog: &Catalog,
    config: &Config,
    json: bool,
    release: Option<&(rh_dataset::release::Release, String)>,
) -> Result<(), Failure> {
    let summary = build(opts, catalog, config).map_err(build_failure)?;
    if let Some((release, origin)) = release {
        release_command::check_built(opts, release, origin)?;
    }
    if json {
        print_json(&summary)?;
    } else {
        println(&format!(
            "built {} scenes ({} valid) into {} — {}{}",
            summary.scenes,
            summary.valid,
            summary.out,
            summary.data_file,
            if summary.resumed_groups > 0 {
                format!(" (resumed {} groups)", summary.resumed_groups)
            } else {
                String::new()
            }
        ))?;
        let actions: Vec<String> = summary
            .per_action
            .iter()
            .map(|(a, c)| format!("{a} {c}"))
            .collect();
        println(&format!("labels: {}", actions.join(", ")))?;
        if let Some(rejections) = &summary.rejections {
            let attempts: u32 = rejections.values().map(|f| f.attempts).sum();
            let by_family: Vec<String> = rejections
                .iter()
                .filter_map(|(family, f)| {
                    let n = f.rejected_by.get("valid_visible").copied().unwrap_or(0);
                    (n > 0).then(|| format!("{family} {n}/{}", f.attempts))
                })
                .collect();
            println(&format!(
                "visibility rejected {} of {attempts} group attempts{}",
                rejections
                    .values()
                    .map(|f| f.rejected_by.get("valid_visible").copied().unwrap_or(0))
                    .sum::<u32>(),
                if by_family.is_empty() {
                    String::new()
                } else {
                    format!(" ({})", by_family.join(", "))
                }
            ))?;
        }
        if let Some(rejections) = &summary.rejections {
            let replans: u32 = rejections.values().map(|f| f.replans).sum();
            println!("replans: {replans} (scene groups planned afresh, another object or room of their family: unaimable or invalid plans)");
        }
        if !summary.invalid_scene_ids.is_empty() {
            println(&format!(
                "warning: {} scene(s) failed validation after every attempt: {}",
                summary.invalid_scene_ids.len(),
                summary.invalid_scene_ids.join(", ")
            ))?;
        }
    }
    Ok(())
}
