//! Adversarial twins (label rule v5, issue #23, `rh_scenes::twins`): a twin pair differs
//! only in the object, and where a throw meets the chest the physics decides the label.

use rh_catalog::Catalog;
use rh_physics::spec::Selection;
use rh_scenes::config::Config;
use rh_scenes::driver::{produce_planned_group, run_scene};
use rh_scenes::label::Action;
use rh_scenes::randomize::{randomize, SceneKey};
use rh_scenes::twins::{self, Role};
use serde_json::Value;

/// The JSON paths where `a` and `b` differ (an array of another length differs as a whole).
fn diff(a: &Value, b: &Value, path: &str, out: &mut Vec<String>) {
    match (a, b) {
        (Value::Object(x), Value::Object(y)) => {
            let keys: std::collections::BTreeSet<&String> = x.keys().chain(y.keys()).collect();
            for k in keys {
                let (p, q) = (x.get(k), y.get(k));
                match (p, q) {
                    (Some(p), Some(q)) => diff(p, q, &format!("{path}.{k}"), out),
                    _ => out.push(format!("{path}.{k}")),
                }
            }
        }
        (Value::Array(x), Value::Array(y)) if x.len() == y.len() => {
            for (i, (p, q)) in x.iter().zip(y).enumerate() {
                diff(p, q, &format!("{path}[{i}]"), out);
            }
        }
        _ if a != b => out.push(path.to_string()),
        _ => {}
    }
}

#[test]
fn a_twin_pair_differs_only_in_the_object() {
    let config = Config::embedded().unwrap();
    let catalog = Catalog::embedded().unwrap();
    let families = &config.build.families;
    let pairs: Vec<(u64, u64)> = (0..170)
        .filter_map(|g| twins::slot(&config.probes, families, g))
        .filter(|s| s.pair.twin && s.role == Role::Probe)
        .map(|s| (s.probe_group, s.twin_group))
        .collect();
    assert!(pairs.len() >= 10, "{pairs:?}");
    // The first pair (a throw) and one more family.
    for &(probe_group, twin_group) in [pairs[0], pairs[pairs.len() / 2]].iter() {
        let (probe, _) = produce_planned_group(&catalog, families, 5, probe_group, 4, &config)
            .unwrap_or_else(|_| panic!("group {probe_group}"));
        let (twin, _) = produce_planned_group(&catalog, families, 5, twin_group, 4, &config)
            .unwrap_or_else(|_| panic!("group {twin_group}"));
        assert_eq!((probe.len(), twin.len()), (4, 4));
        for (p, t) in probe.iter().zip(&twin) {
            assert_eq!(twins::twin_of(&p.spec), Some(t.spec.scene_index));
            assert_eq!(twins::twin_of(&t.spec), Some(p.spec.scene_index));
            assert_eq!(
                p.spec.scene_index + 4 * (twin_group - probe_group),
                t.spec.scene_index
            );
            let disguised = catalog.object(&p.spec.selection.object_id).unwrap();
            assert_eq!(
                disguised.looks_like.as_deref(),
                Some(t.spec.selection.object_id.as_str())
            );
            let genuine = catalog.object(&t.spec.selection.object_id).unwrap();
            let mut paths = Vec::new();
            let json =
                |s: &rh_physics::spec::SceneSpec| serde_json::from_str(&s.to_json()).unwrap();
            diff(&json(&p.spec), &json(&t.spec), "", &mut paths);
            let object_bodies: Vec<usize> = (0..p.spec.bodies.len())
                .filter(|&i| p.spec.bodies[i].catalog_id.as_deref() == Some(disguised.id.as_str()))
                .collect();
            assert!(object_bodies.contains(&p.spec.hazard));
            let allowed = |path: &str| {
                [
                    ".scene_id",
                    ".scene_index",
                    ".group_id",
                    ".selection.object_id",
                    ".family_params.twin_scene_index",
                ]
                .contains(&path)
                    || path.starts_with(".hazard_flags")
                    || object_bodies.iter().any(|i| {
                        ["name", "catalog_id", "mass", "friction", "restitution"]
                            .iter()
                            .any(|f| path == format!(".bodies[{i}].{f}"))
                    })
            };
            let other: Vec<&String> = paths.iter().filter(|q| !allowed(q)).collect();
            assert!(
                other.is_empty(),
                "{} / {}: differ beyond the object at {other:?}",
                disguised.id,
                genuine.id
            );
            // The object really changed, and only into its look-alike's catalog values.
            let (hp, ht) = (p.spec.hazard_body(), t.spec.hazard_body());
            assert_eq!((hp.mass, ht.mass), (disguised.mass, genuine.mass));
            assert_ne!(hp.mass, ht.mass);
            assert_eq!(hp.parts, ht.parts, "look-alikes share their parts");
            let flags: Vec<String> = genuine.hazards.iter().cloned().collect();
            assert_eq!(t.spec.hazard_flags, flags);
            // Cameras, observer pose and lighting are the probe's.
            assert_eq!(p.spec.cameras, t.spec.cameras);
        }
    }
}

/// Closed form: a 2.1 kg steel apple and the 0.21 kg apple it looks like, thrown from the
/// same spot so that the centre reaches the observer's torso axis at chest height
/// (1.1 m) 0.9 s after the release: the apple is caught in front of the chest (CATCH),
/// the steel apple cannot be (heavy) and harms the standing body (DODGE).
#[test]
fn a_chest_aimed_throw_is_caught_when_light_and_dodged_when_heavy() {
    let config = Config::embedded().unwrap();
    let catalog = Catalog::embedded().unwrap();
    let room = catalog.rooms_for_family("thrown_object").next().unwrap();
    let selection = Selection {
        family: "thrown_object".into(),
        object_id: "steel_apple".into(),
        room_id: room.id.clone(),
        description: None,
        planner: None,
    };
    let mut spec = randomize(&selection, &SceneKey::new(11, 0, 0), &catalog, &config).unwrap();
    let (t, chest) = (0.9, 1.1);
    let g = spec.physics.gravity;
    let target = [spec.observer.x, spec.observer.y, chest];
    let h = spec.hazard;
    let p0 = spec.bodies[h].position;
    spec.bodies[h].linvel = [0, 1, 2].map(|i| (target[i] - p0[i] - 0.5 * g[i] * t * t) / t);
    spec.bodies[h].angvel = [0.0; 3];
    // The centre passes the chest at 0.9 s (closed form, before any contact).
    let at = |i: usize| p0[i] + spec.bodies[h].linvel[i] * t + 0.5 * g[i] * t * t;
    assert!((0..3).all(|i| (at(i) - target[i]).abs() < 1e-9));
    let apple = catalog.object("apple").unwrap();
    let twin = twins::twin_spec(&mut spec, apple, 1, 0);
    let heavy = run_scene(spec, &config);
    let light = run_scene(twin, &config);
    assert_eq!(light.labels.gt_action, Action::Catch, "{:?}", light.labels);
    assert_eq!(heavy.labels.gt_action, Action::Dodge, "{:?}", heavy.labels);
    assert!(heavy.labels.dangerous && heavy.labels.danger_present);
    assert!(!light.labels.dangerous);
}
