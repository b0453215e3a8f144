//! Pinned reference physics: one checked-in spec per family (`tests/pinned/specs/`)
//! must replay to the state hash and step count recorded in `tests/pinned/hashes.json`.
//! Two builds of the same binary agreeing proves determinism; this proves the physics
//! did not change — a new rapier3d, compiler or simulation change that moves one body
//! by one bit fails here, and updating the pins is a visible, deliberate decision.
//!
//! The specs are fixed files, not freshly sampled scenes, so changes to the family
//! samplers or labels do not touch them. To re-pin after a deliberate physics change:
//! `RH_UPDATE_PINNED=1 cargo test --release -p rh-pipeline --test pinned` (and say why in
//! the commit). To regenerate the specs themselves (e.g. after a spec schema change):
//! `cargo test --release -p rh-pipeline --test pinned -- --ignored regenerate`.

use rh_catalog::Catalog;
use rh_physics::simulate::{simulate, SimOptions};
use rh_physics::spec::SceneSpec;
use rh_scenes::config::Config;
use rh_scenes::driver::produce_group;
use rh_scenes::selection::plan_group;
use std::collections::BTreeMap;
use std::path::PathBuf;

fn pinned_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/pinned")
}

#[derive(serde::Serialize, serde::Deserialize, PartialEq, Debug)]
struct Pin {
    state_hash: String,
    steps: u32,
}

#[test]
fn pinned_specs_replay_to_their_pinned_state_hashes() {
    let dir = pinned_dir();
    let mut actual: BTreeMap<String, Pin> = BTreeMap::new();
    for family in rh_catalog::FAMILIES {
        let path = dir.join("specs").join(format!("{family}.json"));
        let text =
            std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let spec = SceneSpec::from_json(&text)
            .unwrap_or_else(|e| panic!("{}: not a spec of this schema: {e}", path.display()));
        assert_eq!(spec.family, *family, "{}", path.display());
        let sim = simulate(&spec, SimOptions::default());
        actual.insert(
            family.to_string(),
            Pin {
                state_hash: sim.state_hash.clone(),
                steps: sim.steps(),
            },
        );
    }
    let hashes = dir.join("hashes.json");
    if std::env::var_os("RH_UPDATE_PINNED").is_some() {
        std::fs::write(
            &hashes,
            serde_json::to_string_pretty(&actual).unwrap() + "\n",
        )
        .unwrap();
        return;
    }
    let expected: BTreeMap<String, Pin> =
        serde_json::from_str(&std::fs::read_to_string(&hashes).unwrap()).unwrap();
    assert_eq!(expected.len(), 17, "one pin per family");
    let changed: Vec<String> = expected
        .iter()
        .filter(|(f, pin)| actual.get(*f) != Some(pin))
        .map(|(f, pin)| format!("{f}: pinned {pin:?}, now {:?}", actual.get(f)))
        .collect();
    assert!(
        changed.is_empty(),
        "the physics changed for {} famil(ies):\n{}\n(re-pin deliberately with RH_UPDATE_PINNED=1)",
        changed.len(),
        changed.join("\n")
    );
}

/// Writes one spec per family (seed 2026, the family's first group, slow band).
#[test]
#[ignore]
fn regenerate_pinned_specs() {
    let catalog = Catalog::embedded().unwrap();
    let config = Config::embedded().unwrap();
    let dir = pinned_dir().join("specs");
    std::fs::create_dir_all(&dir).unwrap();
    let families: Vec<String> = rh_catalog::FAMILIES.iter().map(|s| s.to_string()).collect();
    for (g, family) in families.iter().enumerate() {
        let selection = plan_group(&catalog, &families, 2026, g as u64).unwrap();
        let results = produce_group(&selection, 2026, g as u64 * 4, 1, &catalog, &config).unwrap();
        assert_eq!(&results[0].spec.family, family);
        std::fs::write(
            dir.join(format!("{family}.json")),
            results[0].spec.to_json(),
        )
        .unwrap();
    }
}
