//! Physics acceptance checks for the foundation families: the simulation agrees with
//! closed-form mechanics, labels follow physics rather than appearance, and replays are
//! bit-for-bit identical.

use rh_catalog::Catalog;
use rh_physics::simulate::{simulate, SimOptions, Simulation, TOUCH_FLOOR, TOUCH_SOURCE};
use rh_physics::spec::{quat, Selection, ShapeSpec};
use rh_scenes::config::Config;
use rh_scenes::driver::{plan_and_produce, produce_group, run_scene, SceneResult};
use rh_scenes::label::Action;
use rh_scenes::selection::plan_group;

const G: f64 = 9.81;

fn setup() -> (Catalog, Config) {
    (Catalog::embedded().unwrap(), Config::embedded().unwrap())
}

/// All four bands of `groups` groups of one family; every scene must be valid.
fn scenes(family: &str, groups: u64, seed: u64) -> Vec<SceneResult> {
    let (catalog, config) = setup();
    let families = vec![family.to_string()];
    let results: Vec<SceneResult> = (0..groups)
        .flat_map(|g| {
            plan_and_produce(&catalog, &families, None, seed, g, 4, &config)
                .unwrap()
                .0
        })
        .collect();
    for r in &results {
        // A scene of an adversarial probe pair (label rule v5) is labelled without
        // resampling; every other scene passes every validator.
        assert!(
            r.verdicts.all() || r.spec.family_params.contains_key("twin_scene_index"),
            "{} invalid: {:?}",
            r.spec.scene_id,
            r.verdicts.failures()
        );
    }
    results
}

fn plain(r: &SceneResult) -> Simulation {
    simulate(&r.spec, SimOptions::default())
}

#[test]
fn ceiling_drop_falls_freely_once_off_its_mount() {
    // Label rule v2 layout: the fixture creeps down its bent mount rails (checked against
    // the designed acceleration in tests/families.rs), then falls: from the last mount
    // contact to the floor its centre of mass follows free fall exactly, and its
    // `time_to_floor` lies within the step of its first floor contact.
    let results = scenes("ceiling_drop", 6, 3);
    assert_eq!(results.len(), 24);
    for r in &results {
        // Free fall: without the air drag a foam panel feels (label rule v6; its own
        // closed form is in tests/twins.rs).
        let mut undragged = r.clone();
        undragged.spec.physics.drag = None;
        let sim = plain(&undragged);
        let contacts = &sim.hazard_contacts;
        let floor = (1..=sim.steps())
            .find(|&k| contacts[k as usize] & TOUCH_FLOOR != 0)
            .expect("reaches the floor");
        // The last contact with the mount (either rail) before the floor.
        let left = (1..floor)
            .rev()
            .find(|&k| contacts[k as usize] != 0)
            .map_or(0, |k| k + 1);
        let (z0, vz0, dt) = (
            sim.hazard_com(left)[2],
            sim.hazard_velocity(left)[2],
            sim.dt,
        );
        // rapier's substeps: z_k = z0 + v0 k dt − g dt² k (k + 1/n) / 2.
        let n = r.spec.physics.solver_iterations as f64;
        let mut checked = 0;
        for k in (left + 1..floor).take_while(|&k| sim.hazard_lowest_z[k as usize] > 0.03) {
            if contacts[k as usize] != 0 {
                break;
            }
            let kf = (k - left) as f64;
            let expected = z0 + vz0 * kf * dt - G * dt * dt * kf * (kf + 1.0 / n) / 2.0;
            let z = sim.hazard_com(k)[2];
            assert!(
                (z - expected).abs() < 5e-4,
                "{} step {k}: z {z} vs free fall {expected}",
                r.spec.scene_id
            );
            checked += 1;
        }
        assert!(
            checked > 20,
            "{}: only {checked} free-fall steps",
            r.spec.scene_id
        );
        // The label's floor time is the scene's own (drag included).
        let real = plain(r);
        let floor = (1..=real.steps())
            .find(|&k| real.hazard_contacts[k as usize] & TOUCH_FLOOR != 0)
            .expect("reaches the floor");
        let t = r.labels.time_to_floor.expect("a floor time");
        // The label times the lowest point's own arrival, which may come up to one step
        // after the solver first reports the contact (`label::time_to_floor`: a body
        // slowed by drag is still a few millimetres up at its contact step).
        assert!(
            t > (floor as f64 - 2.0) * dt && t <= (floor + 1) as f64 * dt + 1e-9,
            "{}: time_to_floor {t} vs first floor contact at step {floor}",
            r.spec.scene_id
        );
    }
}

#[test]
fn object_drop_falls_ballistically_once_clear_of_the_table() {
    // Pushed off the board (label rule v6), most objects tumble as they leave it; enough
    // groups to find those that fall clear.
    let results = scenes("object_drop", 40, 5);
    let mut clear_falls = 0;
    for r in &results {
        // Free fall: without the air drag a light body feels (its own closed form is in
        // tests/twins.rs).
        let mut undragged = r.clone();
        undragged.spec.physics.drag = None;
        let sim = plain(&undragged);
        let floor = sim
            .time_to_floor_step(r.spec.labels.floor_contact_eps)
            .expect("reaches the floor");
        // Release: the step after the last contact with the table before the floor.
        let Some(last_table) = (0..floor)
            .rev()
            .find(|&k| sim.hazard_contacts[k as usize] & TOUCH_SOURCE != 0)
        else {
            continue;
        };
        let release = last_table + 1;
        if (release..floor).any(|k| sim.hazard_contacts[k as usize] != 0) || floor - release < 20 {
            continue;
        }
        // The centre of mass follows z(t) = z_r + v_r t − g t²/2 in flight.
        // (The centre of mass, not the body origin: a spinning body's origin circles it.)
        let z_r = sim.hazard_com(release)[2];
        let v_r = sim.hazard_velocity(release)[2];
        let drop = z_r - sim.hazard_com(floor - 1)[2];
        for k in release..floor {
            let t = (k - release) as f64 * sim.dt;
            let expected = z_r + v_r * t - 0.5 * G * t * t;
            let z = sim.hazard_com(k)[2];
            assert!(
                (z - expected).abs() < 0.01 * drop.max(0.05),
                "{}: step {k} z {z:.4} vs {expected:.4}",
                r.spec.scene_id
            );
        }
        // "Falls clear": the body hardly turns in flight, so its lowest point falls like its
        // centre and time_to_floor has a closed form from the release height.
        let offset = |k: u32| sim.hazard_position(k)[2] - sim.hazard_lowest_z[k as usize];
        if (offset(release) - offset(floor - 1)).abs() > 0.002 {
            continue;
        }
        let h = sim.hazard_lowest_z[release as usize];
        let expected = release as f64 * sim.dt + (v_r + (v_r * v_r + 2.0 * G * h).sqrt()) / G;
        let measured = r.labels.time_to_floor.unwrap();
        assert!(
            (measured - expected).abs() / expected < 0.01,
            "{}: {measured} vs {expected}",
            r.spec.scene_id
        );
        clear_falls += 1;
    }
    assert!(
        clear_falls >= 3,
        "only {clear_falls} object_drop scenes fell clear; the check needs examples"
    );
}

#[test]
fn ramp_sliding_acceleration_matches_incline_formula() {
    let results = scenes("sliding_object", 8, 7);
    let mut checked = 0;
    for r in &results {
        let body = r.spec.hazard_body();
        if !body
            .parts
            .iter()
            .all(|p| matches!(p.shape, ShapeSpec::Box { .. }))
        {
            continue; // upright cylinders slide too, but the formula below is for boxes
        }
        let theta = r.spec.family_params["ramp_angle_rad"];
        let mu = r.spec.family_params["mu_effective"];
        assert!(
            theta.tan() > mu,
            "ramp angle must be above the friction cone"
        );
        let expected = G * (theta.sin() - mu * theta.cos());
        let sim = plain(r);
        let ramp = &r.spec.bodies[r.spec.source_support.unwrap()];
        let downhill = quat::rotate(ramp.rotation, [1.0, 0.0, 0.0]);
        // Sliding phase: on the ramp only, after a short settling of the contact, and
        // while the whole footprint is still on the incline (past that the front
        // overhangs the lower end and the box pivots over it).
        let ShapeSpec::Box { half_extents } = body.parts[0].shape else {
            unreachable!()
        };
        let on_ramp = r.spec.family_params["slide_distance_m"] - half_extents[0];
        let p0 = sim.hazard_position(0);
        let along = |k: u32| {
            let p = sim.hazard_position(k);
            (p[0] - p0[0]) * downhill[0]
                + (p[1] - p0[1]) * downhill[1]
                + (p[2] - p0[2]) * downhill[2]
        };
        let steps: Vec<u32> = (12..=sim.steps())
            .take_while(|&k| sim.hazard_contacts[k as usize] == TOUCH_SOURCE && along(k) < on_ramp)
            .collect();
        assert!(steps.len() > 20, "{}: too short a slide", r.spec.scene_id);
        // Least-squares fit of s(t) = s0 + v0 t + a t²/2 along the slope.
        let s: Vec<(f64, f64)> = steps
            .iter()
            .map(|&k| {
                let p = sim.hazard_position(k);
                (
                    k as f64 * sim.dt,
                    p[0] * downhill[0] + p[1] * downhill[1] + p[2] * downhill[2],
                )
            })
            .collect();
        let a = fit_quadratic(&s) * 2.0;
        let err = (a - expected).abs() / expected;
        assert!(
            err < 0.03,
            "{} ({}, {} m/s): a {a:.4} vs g(sinθ−μcosθ) {expected:.4} ({:.2}%)",
            r.spec.scene_id,
            r.spec.selection.object_id,
            r.spec.speed_value,
            err * 100.0
        );
        checked += 1;
    }
    assert!(checked >= 8, "only {checked} box slides checked");
}

/// Coefficient of t² of the least-squares quadratic through the points.
fn fit_quadratic(points: &[(f64, f64)]) -> f64 {
    // Normal equations for y = c0 + c1 t + c2 t², solved by Cramer's rule on centred t.
    let n = points.len() as f64;
    let mean_t = points.iter().map(|p| p.0).sum::<f64>() / n;
    let mut m = [[0.0f64; 3]; 3];
    let mut rhs = [0.0f64; 3];
    for &(t, y) in points {
        let t = t - mean_t;
        let basis = [1.0, t, t * t];
        for i in 0..3 {
            for j in 0..3 {
                m[i][j] += basis[i] * basis[j];
            }
            rhs[i] += basis[i] * y;
        }
    }
    let det = |m: [[f64; 3]; 3]| {
        m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
            - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
    };
    let mut m2 = m;
    for i in 0..3 {
        m2[i][2] = rhs[i];
    }
    det(m2) / det(m)
}

#[test]
fn thrown_object_apex_and_range_are_ballistic() {
    let results = scenes("thrown_object", 8, 11);
    let mut apexes = 0;
    for r in &results {
        let sim = plain(r);
        let contact = sim.first_contact_step().expect("lands somewhere");
        // The centre of mass flies ballistically (the body origin of a spinning
        // object with an off-centre mass circles around it).
        let p0 = sim.hazard_com(0);
        let v0 = r.spec.hazard_body().linvel;
        // Range: horizontal distance covered before the first contact.
        let t = contact as f64 * sim.dt;
        let p = sim.hazard_com(contact);
        let range = ((p[0] - p0[0]).powi(2) + (p[1] - p0[1]).powi(2)).sqrt();
        let expected_range = (v0[0] * v0[0] + v0[1] * v0[1]).sqrt() * t;
        assert!(
            (range - expected_range).abs() / expected_range < 0.02,
            "{}: range {range} vs {expected_range}",
            r.spec.scene_id
        );
        // Apex: z0 + vz²/2g when thrown upward.
        if v0[2] > 0.5 {
            let apex = (0..contact)
                .map(|k| sim.hazard_position(k)[2])
                .fold(f64::MIN, f64::max);
            let expected_apex = p0[2] + v0[2] * v0[2] / (2.0 * G);
            // 2% of the rise, but never below the integrator's own resolution: a fixed
            // step moves the apex by up to half a step's travel (v_z·dt/2).
            let rise = expected_apex - p0[2];
            let tolerance = (0.02 * rise).max(0.5 * v0[2] * sim.dt);
            assert!(
                (apex - expected_apex).abs() <= tolerance,
                "{}: apex {apex} vs {expected_apex} (tolerance {tolerance})",
                r.spec.scene_id
            );
            apexes += 1;
        }
    }
    assert!(apexes >= 4, "only {apexes} upward throws");
}

/// Runs the same group layout with the object swapped for its look-alike twin, in every
/// speed band, until the light one is a CATCH and the heavy one would harm the standing
/// body (rule v5: a dangerous object that never harms it is NO_ACTION) — or, without
/// `need_harm`, whatever the heavy one does.
fn twin_labels(
    family: &str,
    real: &str,
    twin: &str,
    need_harm: bool,
) -> Option<(SceneResult, SceneResult)> {
    let (catalog, config) = setup();
    for seed in 0..40u64 {
        let room = plan_group(&catalog, &[family.to_string()], seed, 0)
            .unwrap()
            .room_id;
        let pick = |object: &str| {
            let selection = Selection {
                family: family.into(),
                object_id: object.into(),
                room_id: room.clone(),
                description: None,
                planner: None,
            };
            produce_group(&selection, seed, 0, 4, &catalog, &config).unwrap()
        };
        for (a, b) in pick(real).into_iter().zip(pick(twin)) {
            let (light, heavy) = if a.spec.hazard_body().mass < b.spec.hazard_body().mass {
                (&a, &b)
            } else {
                (&b, &a)
            };
            if a.spec.attempt == b.spec.attempt
                && light.labels.reachable
                && light.labels.gt_action == Action::Catch
                && (heavy.labels.danger_present || !need_harm)
            {
                return Some((a, b));
            }
        }
    }
    None
}

#[test]
fn labels_follow_physics_not_appearance() {
    let catalog = Catalog::embedded().unwrap();
    // A foam twin of a heavy object is safe to catch; the real one, landing on the
    // standing body, must be dodged.
    let anvil = catalog.object("anvil").unwrap();
    let foam = catalog.object("foam_anvil").unwrap();
    assert_eq!(catalog.appearance_source(foam).appearance, anvil.appearance);
    let (real, twin) =
        twin_labels("object_drop", "anvil", "foam_anvil", true).expect("a reachable layout");
    assert_eq!(
        real.spec.hazard_body().parts,
        twin.spec.hazard_body().parts,
        "twins share their shape"
    );
    assert_eq!(real.labels.gt_action, Action::Dodge);
    assert!(
        real.labels.dangerous
            && real
                .labels
                .danger_reasons
                .contains(&"heavy_mass".to_string())
    );
    assert_eq!(twin.labels.gt_action, Action::Catch);
    assert!(!twin.labels.dangerous);

    // A steel twin of a light object is dangerous; the real apple is caught. Rule v5: the
    // steel one is dodged only where it would harm the standing body — in object_drop's
    // layouts (4 bands × 40 seeds) a steel apple that would be caught as an apple never
    // does: it falls in front of the body (issue 23's aimed twins are still to come).
    let (apple, steel) =
        twin_labels("object_drop", "apple", "steel_apple", false).expect("a reachable layout");
    assert_eq!(apple.labels.gt_action, Action::Catch);
    assert!(!apple.labels.dangerous);
    assert!(steel.labels.dangerous);
    let expected = if steel.labels.danger_present {
        Action::Dodge
    } else {
        Action::NoAction
    };
    assert_eq!(steel.labels.gt_action, expected, "{:?}", steel.labels);
}

#[test]
fn replay_is_identical_across_runs_and_thread_counts() {
    let results = scenes("thrown_object", 2, 1)
        .into_iter()
        .chain(scenes("rolling_ball", 2, 1))
        .chain(scenes("object_drop", 2, 1))
        .collect::<Vec<_>>();
    let hashes_with = |threads: usize| -> Vec<String> {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            use rayon::prelude::*;
            results.par_iter().map(|r| plain(r).state_hash).collect()
        })
    };
    let stored: Vec<String> = results.iter().map(|r| r.state_hash.clone()).collect();
    assert_eq!(hashes_with(1), stored);
    assert_eq!(hashes_with(2), stored);
    // A changed spec changes the hash.
    let mut spec = results[0].spec.clone();
    spec.bodies[spec.hazard].mass *= 1.5;
    spec.bodies[spec.hazard].linvel[2] += 0.01;
    assert_ne!(simulate(&spec, SimOptions::default()).state_hash, stored[0]);
}

#[test]
fn counterfactual_strike_matches_a_full_counterfactual_run() {
    // The shortcuts of `driver::counterfactual_run` (none where nothing comes near the
    // observer, else resumed from the plain run's kept world) must agree with simulating
    // the counterfactual from t0 for every scene.
    let (_, config) = setup();
    for family in ["thrown_object", "ceiling_drop", "rolling_ball"] {
        for r in scenes(family, 3, 21) {
            let full = simulate(&r.spec, rh_scenes::driver::counterfactual_options(&r.spec));
            let rerun = run_scene(r.spec.clone(), &config);
            assert_eq!(
                (rerun.labels.strike_speed, rerun.labels.strike_impulse),
                (full.strike.map(|s| s.speed), full.strike.map(|s| s.impulse)),
                "{}",
                r.spec.scene_id
            );
            // Floor contacts happen in every scene's plain run.
            assert!(plain(&r)
                .hazard_contacts
                .iter()
                .any(|c| c & TOUCH_FLOOR != 0));
        }
    }
}

#[test]
fn the_counterfactual_resumed_from_a_kept_world_is_the_run_from_t0_bit_for_bit() {
    // `driver::counterfactual_run` starts the observer's body at the plain run's last
    // kept world before anything comes near it (`simulate::counterfactual`): static
    // colliders that nothing has come near change nothing, so it is the counterfactual
    // simulated from t0, state for state, in every family; and it is the same run
    // whether the plain run kept that world or it is replayed.
    let mut resumed_runs = 0;
    for family in rh_catalog::FAMILIES {
        for r in scenes(family, 1, 21) {
            let plain = simulate(&r.spec, SimOptions::default());
            let Some(resumed) = rh_scenes::driver::counterfactual_run(&r.spec, &plain) else {
                continue;
            };
            let full = simulate(&r.spec, rh_scenes::driver::counterfactual_options(&r.spec));
            let id = &r.spec.scene_id;
            assert_eq!(resumed.state_hash, full.state_hash, "{family} {id}");
            assert_eq!(resumed.strike, full.strike, "{family} {id}");
            let near = rh_scenes::driver::first_near_step(&r.spec, &plain).unwrap();
            let start = rh_physics::simulate::resume_step(near);
            if start > 0 && start < plain.steps() {
                resumed_runs += 1;
                let mut bare = plain.clone();
                bare.snapshots = Default::default();
                let replayed = rh_scenes::driver::counterfactual_run(&r.spec, &bare).unwrap();
                assert_eq!(replayed.state_hash, full.state_hash, "{family} {id}");
            }
        }
    }
    assert!(
        resumed_runs >= 20,
        "only {resumed_runs} runs resumed from a kept world"
    );
}
