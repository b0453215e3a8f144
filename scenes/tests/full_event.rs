//! The full-event video tells the truth (issue 12, item 5): it shows the counterfactual
//! run of specification §6 — the standing observer as a static collider, what the labels mean —
//! over the whole event, so a hazard that strikes the observer stops at its body instead
//! of passing through it as in the plain run (where the observer is no body).
//! Label-only (no GPU): the renderer draws exactly `scene::full_event_simulation`
//! (checked in `tests/render.rs`).

use rh_catalog::Catalog;
use rh_physics::simulate::{observer_penetration, simulate, SimOptions};
use rh_physics::spec::SceneSpec;
use rh_scenes::config::Config;
use rh_scenes::driver::{counterfactual_options, full_event_simulation, produce_group};
use rh_scenes::selection::plan_group;

/// Among the valid scenes of `family` (build seed 3, two groups of four speed bands)
/// whose counterfactual run strikes the observer, the one whose plain run passes
/// deepest into the observer's body.
fn striking_scene(family: &str, config: &Config, catalog: &Catalog) -> SceneSpec {
    let families = vec![family.to_string()];
    let mut best: Option<(f64, SceneSpec)> = None;
    for g in 0..2u64 {
        let selection = plan_group(catalog, &families, 3, g).unwrap();
        let results = produce_group(&selection, 3, g * 4, 4, catalog, config).unwrap();
        for r in results {
            if !r.verdicts.all() || !r.labels.danger_present {
                continue;
            }
            let depth = observer_penetration(&r.spec, &simulate(&r.spec, SimOptions::default()));
            if best.as_ref().is_none_or(|(d, _)| depth > *d) {
                best = Some((depth, r.spec));
            }
        }
    }
    best.unwrap_or_else(|| panic!("{family}: no striking scene in 2 groups of seed 3"))
        .1
}

#[test]
fn the_full_event_run_keeps_the_hazard_out_of_the_observer_and_covers_the_whole_event() {
    let config = Config::embedded().unwrap();
    let catalog = Catalog::embedded().unwrap();
    for family in ["furniture_tip", "door_swing"] {
        let spec = striking_scene(family, &config, &catalog);
        let id = &spec.scene_id;
        let plain = simulate(&spec, SimOptions::default());
        let labelled = simulate(&spec, counterfactual_options(&spec));
        let full = full_event_simulation(&spec, &plain)
            .unwrap_or_else(|| panic!("{family} {id}: a striking scene needs its own run"));

        // The bug this fixes: in the plain run the hazard passes into the observer.
        let plain_depth = observer_penetration(&spec, &plain);
        assert!(
            plain_depth > 0.03,
            "{family} {id}: the plain run should pass into the observer ({plain_depth:.3} m)"
        );
        // What the full-event video shows: the observer is a body; the hazard stays out
        // of it (up to the solver's contact tolerance).
        let full_depth = observer_penetration(&spec, &full);
        assert!(
            full_depth < 0.015,
            "{family} {id}: the full-event run sinks {full_depth:.3} m into the observer"
        );

        // It is the labels' counterfactual, step for step, with the same strike ...
        assert_eq!(full.strike, labelled.strike, "{family} {id}");
        assert!(full.strike.is_some(), "{family} {id}");
        let n = labelled.dynamic_bodies.len() * (labelled.steps() as usize + 1);
        assert_eq!(full.states[..n], labelled.states[..], "{family} {id}");
        // ... but not stopped after the strike window: it runs on to the end of the
        // event (settled, or the horizon).
        assert!(
            full.steps() > labelled.steps(),
            "{family} {id}: the full-event run stopped at step {} like the label run",
            full.steps()
        );
        let last = full.steps();
        let settled = full.dynamic_bodies.iter().enumerate().all(|(slot, _)| {
            let s = full.state(last, slot);
            let v = s.linvel.iter().map(|x| x * x).sum::<f32>().sqrt() as f64;
            v < spec.physics.settle_speed
        });
        assert!(
            settled || last == spec.physics.max_steps,
            "{family} {id}: the full-event run ends at step {last} mid-event"
        );
        // Deterministic: the same run again is the same run.
        let again = full_event_simulation(&spec, &plain).unwrap();
        assert_eq!(again.state_hash, full.state_hash, "{family} {id}");
    }
}
