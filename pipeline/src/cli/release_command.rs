//! The benchmark's canonical release (`rh_dataset::release`): `build --release` checks
//! the release's pins before it builds ([`prepare`]) and the finished build's fingerprint
//! after ([`check_built`]); `rh-pipeline fingerprint DIR` prints a dataset's fingerprint
//! and checks a build of the release against its pins ([`fingerprint`]).

use super::failure::{input, print_json, println, Failure};
use crate::build::BuildOptions;
use rh_catalog::Catalog;
use rh_dataset::manifest::{catalog_sha256, config_sha256, Manifest};
use rh_dataset::release::{
    identity_differences, prompt_version, Fingerprint, Release, EMBEDDED_PROMPT,
};
use rh_scenes::config::Config;
use std::path::Path;

/// The release of `build --release` (`path`, else `$RH_RELEASE_CONFIG`, else the embedded
/// one) with the name it was read from, once the configuration, catalog, label rule and
/// prompt of this build are the ones it pins; otherwise exit 2 naming each difference.
pub fn prepare(
    path: Option<&Path>,
    catalog: &Catalog,
    config: &Config,
) -> Result<(Release, String), Failure> {
    let (release, origin) = Release::load(path).map_err(input)?;
    let pins = &release.pins;
    let mut differs = Vec::new();
    let mut cmp = |what: &str, found: String, pinned: &str| {
        if found != pinned {
            differs.push(format!("{what} is {found} where the release pins {pinned}"));
        }
    };
    cmp(
        "the configuration's SHA-256 (configs/default.toml with configs/labels.toml, or --config)",
        config_sha256(config),
        &pins.config_sha256,
    );
    cmp(
        "the catalog's SHA-256 (catalog/, or --catalog)",
        catalog_sha256(catalog),
        &pins.catalog_sha256,
    );
    cmp(
        "the label rule (configs/labels.toml rule_version)",
        config.labels.rule_version.clone(),
        &pins.label_rule,
    );
    cmp(
        "the prompt (configs/prompt.toml version)",
        prompt_version(EMBEDDED_PROMPT).unwrap_or_else(|| "none".into()),
        &pins.prompt_version,
    );
    if !differs.is_empty() {
        return Err(input(format!(
            "release {} ({origin}) cannot be built here: {}. Build it from the commit that defined it, or define a new release (a new id and its pins: `rh-pipeline fingerprint DIR` prints the fingerprint of a build)",
            release.id,
            differs.join("; ")
        )));
    }
    Ok((release, origin))
}

/// After `build --release`: the whole build's fingerprint must be the release's (exit 1
/// naming each part that differs: the build does not reproduce it). A shard is checked
/// once merged (`rh-pipeline fingerprint` of the merged directory).
pub fn check_built(opts: &BuildOptions, release: &Release, origin: &str) -> Result<(), Failure> {
    let out = opts.out.display();
    if opts.shard.1 > 1 {
        if opts.progress {
            rh_contract::note!(
                "shard {}/{} of release {}: merge all shards, then `rh-pipeline fingerprint {}` checks the release's fingerprint",
                opts.shard.0,
                opts.shard.1,
                release.id,
                "MERGED_DIR"
            );
        }
        return Ok(());
    }
    let found = Fingerprint::of(&opts.out).map_err(|e| Failure {
        code: 1,
        message: format!("the fingerprint of {out}: {e}"),
    })?;
    let differs = found.differences(&release.fingerprint);
    if !differs.is_empty() {
        return Err(Failure {
            code: 1,
            message: format!(
                "the build in {out} does not reproduce release {} ({origin}): {}",
                release.id,
                differs.join("; ")
            ),
        });
    }
    if opts.progress {
        rh_contract::note!(
            "{out} is release {}: its fingerprint matches {origin}{}",
            release.id,
            if opts.render {
                ""
            } else {
                " (label-only: build without --no-render for the release to upload)"
            }
        );
    }
    Ok(())
}

/// `rh-pipeline fingerprint DIR [--json]`.
pub fn fingerprint(dir: &Path, json: bool) -> Result<(), Failure> {
    let found = Fingerprint::of(dir).map_err(input)?;
    let manifest = Manifest::read(dir).map_err(input)?;
    let claimed = manifest.as_ref().and_then(|m| m.release.clone());
    // A build of a release is checked against the release this program pins.
    let check = match &claimed {
        None => None,
        Some(id) => {
            let (release, origin) = Release::load(None).map_err(input)?;
            (&release.id == id).then(|| {
                let mut d = manifest
                    .as_ref()
                    .map(|m| identity_differences(m, &release))
                    .unwrap_or_default();
                d.extend(found.differences(&release.fingerprint));
                (origin, d)
            })
        }
    };
    if json {
        print_json(&serde_json::json!({
            "dir": dir.display().to_string(),
            "fingerprint": found,
            "release": claimed,
            "matches_release": check.as_ref().map(|(_, d)| d.is_empty()),
            "differences": check.as_ref().map(|(_, d)| d.clone()),
        }))?;
    } else {
        println(&format!(
            "[fingerprint]\nscenes_sha256 = \"{}\"\neval_sha256 = \"{}\"\nspecs_sha256 = \"{}\"",
            found.scenes_sha256, found.eval_sha256, found.specs_sha256
        ))?;
    }
    match (&claimed, &check) {
        (Some(id), Some((origin, d))) if !d.is_empty() => Err(input(format!(
            "{} is not release {id} as {origin} pins it: {}",
            dir.display(),
            d.join("; ")
        ))),
        (Some(id), Some((origin, _))) => {
            rh_contract::note!("{} is release {id}: it matches {origin}", dir.display());
            Ok(())
        }
        (Some(id), None) => {
            rh_contract::note!(
                "{} is a build of release {id}, which this rh-pipeline does not pin (configs/release.toml or $RH_RELEASE_CONFIG): not compared",
                dir.display()
            );
            Ok(())
        }
        (None, _) => Ok(()),
    }
}
