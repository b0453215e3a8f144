//! The visibility rule over a whole default build (issue 12): the 340 scenes of a
//! default-seed build (17 families × 4 speed bands × 5 groups) are all valid with it,
//! every group's four bands share one set of cameras (they differ only in speed), and
//! visibility is mostly met by camera placement rather than by rejecting layouts.

use rh_catalog::Catalog;
use rh_scenes::config::Config;
use rh_scenes::driver::plan_and_produce;
use rh_scenes::validate::VALIDATOR_COLUMNS;
use rh_scenes::visibility;
use std::collections::BTreeMap;

#[test]
fn a_default_340_scene_build_is_all_valid_and_bands_share_their_cameras() {
    let catalog = Catalog::embedded().unwrap();
    let config = Config::embedded().unwrap();
    let rules = config.validators.framing();
    let families: Vec<String> = config.build.families.clone();
    let visible = VALIDATOR_COLUMNS
        .iter()
        .position(|c| *c == "valid_visible")
        .unwrap();
    let seed = config.build.seed;
    // family → (attempts, attempts rejected by visibility)
    let mut per_family: BTreeMap<String, (u32, u32)> = BTreeMap::new();
    for g in 0..85u64 {
        let (results, rejections) =
            plan_and_produce(&catalog, &families, None, seed, g, 4, &config).unwrap();
        assert_eq!(results.len(), 4);
        let entry = per_family
            .entry(results[0].spec.family.clone())
            .or_default();
        entry.0 += rejections.attempts;
        entry.1 += rejections.rejected_by[visible];
        let first = &results[0].spec;
        assert_eq!(first.cameras.len(), 3, "{}", first.scene_id);
        for r in &results {
            // But a scene of an adversarial probe pair, labelled without resampling.
            assert!(
                r.verdicts.all() || r.spec.family_params.contains_key("twin_scene_index"),
                "{} ({}) fails {:?}",
                r.spec.scene_id,
                r.spec.family,
                r.verdicts.failures()
            );
            assert_eq!(
                r.spec.cameras, first.cameras,
                "{}: the bands of group {} have different cameras",
                r.spec.scene_id, first.group_id
            );
            // The verdict is the rule, measured again on the stored spec.
            let sim = rh_physics::simulate::simulate(&r.spec, Default::default());
            let a = visibility::assess(&r.spec, &sim, &rules);
            assert!(a.passes(&rules), "{}", r.spec.scene_id);
            let worst = a.worst().unwrap();
            assert!(worst.fraction >= rules.visible_fraction);
            assert!(worst.size_px >= rules.min_size_px);
        }
    }
    assert_eq!(per_family.len(), 17);
    let (attempts, rejected) = per_family
        .values()
        .fold((0, 0), |(a, r), (fa, fr)| (a + fa, r + fr));
    // Placement, then rejection: at most one attempt in three rejected by visibility
    // overall. The ego pixel rule (issue 44) rejected most throws and bounces of small
    // balls far from the eye (under 128 estimated px); the catalog no longer lists objects
    // that small for thrown_object and bouncing_object.
    assert!(
        rejected * 3 <= attempts,
        "visibility rejected {rejected} of {attempts} attempts: {per_family:?}"
    );
}
