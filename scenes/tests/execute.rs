//! The executor (specification §12) at the library level: the replay to Δ is the build's
//! simulation bit for bit, forks are independent of order and thread count, and the
//! humanoid standing still is struck by a ball thrown at it, and by a slab flung at its
//! resting forearm exactly as the label's standing body is (one body, one strike test);
//! label rule v4's escape walks clear a slab arriving late and none clears one arriving
//! 0.25 s after Δ.

use rh_catalog::Catalog;
use rh_physics::body::{Geometry, Part};
use rh_physics::execute::{replay, ExecConfig, ExecKeyframe, ExecPlan, OutcomeKind};
use rh_physics::simulate::{simulate, SimOptions};
use rh_physics::spec::{Selection, ShapeSpec};
use rh_scenes::config::Config;
use rh_scenes::driver::counterfactual_options;
use rh_scenes::driver::{produce_group, SceneResult};
use rh_scenes::randomize::{randomize, SceneKey};
use rh_scenes::selection::plan_group;

fn scenes(family: &str, group: u64) -> Vec<SceneResult> {
    let catalog = Catalog::embedded().unwrap();
    let config = Config::embedded().unwrap();
    let sel = plan_group(&catalog, &[family.to_string()], 3, group).unwrap();
    produce_group(&sel, 3, group * 4, 4, &catalog, &config).unwrap()
}

fn plans() -> Vec<ExecPlan> {
    let kf = |t: f64, x: f64, z: f64, knee: f64| ExecKeyframe {
        t,
        left: [x, 0.15, z],
        right: [x, -0.15, z],
        knee_bend: knee,
    };
    vec![
        ExecPlan {
            walking_cmd: [0.0; 3],
            walking_duration: 0.0,
            keyframes: vec![],
        },
        ExecPlan {
            walking_cmd: [0.3, 0.1, 0.5],
            walking_duration: 0.8,
            keyframes: vec![kf(0.3, 0.45, 0.1, 0.3), kf(0.9, 0.5, 0.2, 0.0)],
        },
        ExecPlan {
            walking_cmd: [-1.2, 0.4, 0.0],
            walking_duration: 1.0,
            keyframes: vec![kf(1.0, 0.1, 0.0, 0.0)],
        },
    ]
}

#[test]
fn replay_to_decision_matches_the_build_and_forks_are_deterministic() {
    let cfg = ExecConfig::embedded_default();
    for family in ["object_drop", "thrown_object", "pendulum_swing"] {
        for r in scenes(family, 0).iter().take(2) {
            let rep = replay(&r.spec);
            // The replay's hash at Δ is the stored one, and the full replay's prefix.
            assert_eq!(rep.decision_hash, r.decision_state_hash, "{family}");
            let sim = simulate(&r.spec, SimOptions::default());
            assert_eq!(
                sim.state_hash_through(r.spec.decision_step()),
                rep.decision_hash
            );
            rep.check(&r.decision_state_hash).unwrap();
            assert!(rep.check("0000").is_err());
            let serial: Vec<_> = plans().iter().map(|p| rep.execute(p, &cfg)).collect();
            // Again from a fresh replay, in reverse order, on other threads.
            let other = replay(&r.spec);
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(2)
                .build()
                .unwrap();
            let mut parallel: Vec<_> = pool.install(|| {
                use rayon::prelude::*;
                plans()
                    .par_iter()
                    .rev()
                    .map(|p| other.execute(p, &cfg))
                    .collect()
            });
            parallel.reverse();
            assert_eq!(serial, parallel, "{family}");
        }
    }
}

#[test]
fn standing_still_in_a_throw_gets_struck_and_a_dodge_clears() {
    let cfg = ExecConfig::embedded_default();
    let mut checked = 0;
    for g in 0..3 {
        for r in scenes("thrown_object", g) {
            if !(r.verdicts.all() && r.labels.danger_present) {
                continue;
            }
            let rep = replay(&r.spec);
            let stand = rep.execute(&plans()[0], &cfg);
            assert_eq!(
                stand.outcome,
                OutcomeKind::Struck,
                "{} {stand:?}",
                r.spec.scene_id
            );
            let s = stand.strike.as_ref().unwrap();
            assert!(s.impulse > 0.0 && s.t > 0.0 && !s.part.is_empty(), "{s:?}");
            checked += 1;
        }
    }
    assert!(checked >= 2, "only {checked} danger_present throws");
}

#[test]
fn recording_the_steps_leaves_outcome_and_hash_unchanged() {
    let cfg = ExecConfig::embedded_default();
    for family in ["thrown_object", "rolling_ball"] {
        let r = &scenes(family, 0)[0];
        let rep = replay(&r.spec);
        let sim = simulate(&r.spec, SimOptions::default());
        for plan in plans() {
            let plain = rep.execute(&plan, &cfg);
            let (recorded, frames) = rep.execute_recorded(&plan, &cfg);
            assert_eq!(plain, recorded, "{family}");
            // Frame 0 is the world at Δ, then one frame per executed step.
            assert_eq!(frames.len() as u32, plain.steps + 1, "{family}");
            let d = r.spec.decision_step();
            for (slot, b) in frames[0].bodies.iter().enumerate() {
                assert_eq!(b, sim.state(d, slot), "{family} slot {slot}");
            }
            let last = frames.last().unwrap();
            assert_eq!(last.base, plain.base_end, "{family}");
            // The pelvis link sits over the base.
            assert!((last.links[0].position[0] - last.base[0]).abs() < 1e-9);
        }
    }
}

/// A constructed scene: the observer at the origin facing +x, and one ball of `mass` kg
/// (radius 0.04 m) at `(x, y, z)` moving straight down at `vz` m/s at the decision
/// moment (Δ = 0), nothing else but the floor.
fn ball_scene(mass: f64, at: [f64; 3], vz: f64) -> rh_physics::spec::SceneSpec {
    use rh_physics::spec::{PartSpec, ShapeSpec};
    let mut spec = scenes("thrown_object", 0).remove(0).spec;
    let mut ball = spec.hazard_body().clone();
    ball.parts = vec![PartSpec {
        shape: ShapeSpec::Sphere { radius: 0.04 },
        offset: [0.0; 3],
        rotation: [0.0, 0.0, 0.0, 1.0],
    }];
    ball.position = at;
    ball.rotation = [0.0, 0.0, 0.0, 1.0];
    ball.mass = mass;
    ball.restitution = 0.3;
    ball.friction = 0.8;
    ball.linvel = [0.0, 0.0, vz];
    ball.angvel = [0.0; 3];
    // The velocity as given (not a push scaled to another body's mass), no air drag:
    // the closed forms below are for a ball in vacuum.
    ball.push_mass = None;
    ball.ccd = true;
    spec.physics.drag = None;
    spec.bodies = vec![ball];
    spec.joints.clear();
    spec.hazard = 0;
    spec.source_support = None;
    spec.observation_window_s = 0.0;
    spec.observer.x = 0.0;
    spec.observer.y = 0.0;
    spec.observer.yaw = 0.0;
    spec
}

/// Both palms side by side 0.40 m ahead and 0.10 m above the pelvis from t = 0.2 s on
/// (palm tops at z = pelvis + 0.115), no walking.
fn cupped_hands() -> ExecPlan {
    ExecPlan {
        walking_cmd: [0.0; 3],
        walking_duration: 0.0,
        keyframes: vec![ExecKeyframe {
            t: 0.2,
            left: [0.40, 0.06, 0.10],
            right: [0.40, -0.06, 0.10],
            knee_bend: 0.0,
        }],
    }
}

/// A thrown-object scene (gym, soccer ball) without gravity, its hazard replaced by a box
/// slab of `half` extents and `mass` kg at `position`, turned with the observer and flying
/// at `velocity` from t = 0 without spin or bounce.
fn flung_slab(
    half: [f64; 3],
    mass: f64,
    place: impl FnOnce(&rh_physics::spec::SceneSpec) -> ([f64; 3], [f64; 3]),
) -> rh_physics::spec::SceneSpec {
    let catalog = Catalog::embedded().unwrap();
    let config = Config::embedded().unwrap();
    let selection = Selection {
        family: "thrown_object".into(),
        object_id: "soccer_ball".into(),
        room_id: "gym".into(),
        description: None,
        planner: None,
    };
    let mut spec = randomize(&selection, &SceneKey::new(5, 0, 0), &catalog, &config).unwrap();
    let (position, velocity) = place(&spec);
    let yaw = spec.observer.yaw;
    spec.physics.gravity = [0.0; 3];
    let h = &mut spec.bodies[0];
    h.parts[0].shape = ShapeSpec::Box { half_extents: half };
    h.mass = mass;
    h.position = position;
    h.rotation = [0.0, 0.0, (yaw / 2.0).sin(), (yaw / 2.0).cos()];
    h.linvel = velocity;
    h.angvel = [0.0; 3];
    h.restitution = 0.0;
    // The velocity as given (not a push scaled to another body's mass), no air drag.
    h.push_mass = None;
    spec.physics.drag = None;
    spec
}

#[test]
fn a_slab_flung_at_the_resting_forearm_strikes_label_and_freeze_alike() {
    // A 1.5 kg slab flies sideways (no gravity) at 3 m/s into the left forearm of the
    // body standing at rest, arriving 0.35 s after the decision moment. Rule v3: the
    // forearm is part of the standing body, so it is a strike (≈ 4.5 N·s, under the
    // 6 N·s a *reaching* hand would need); the executor's freeze plan is the same body
    // and the same test, so it is struck on the same part.
    let (speed, half) = (3.0, [0.04, 0.01, 0.03]);
    let mut t_hit = 0.0;
    let spec = flung_slab(half, 1.5, |spec| {
        let o = &spec.observer;
        let g = Geometry::of(o);
        let forearm = g.link_poses(&g.rest_pose([o.x, o.y, o.yaw]))[Part::LeftForearm as usize];
        let left = [-o.yaw.sin(), o.yaw.cos(), 0.0];
        t_hit = spec.observation_window_s + 0.35;
        let d = speed * t_hit + half[1] + 0.035;
        (
            [0, 1, 2].map(|i| forearm.position[i] + d * left[i]),
            left.map(|c| -speed * c),
        )
    });

    let cf = simulate(&spec, counterfactual_options(&spec));
    let s = cf.strike.expect("the slab meets the forearm");
    assert_eq!(s.part, Part::LeftForearm, "{s:?}");
    let t = s.first_touch as f64 * spec.physics.dt;
    assert!((t - t_hit).abs() < 0.02, "{t} vs {t_hit}");
    assert!(s.speed > 2.9 && s.impulse > 3.0 && s.impulse < 6.0, "{s:?}");
    let l = rh_scenes::label::label(&spec, &simulate(&spec, SimOptions::default()), cf.strike);
    assert!(l.danger_present);

    let cfg = ExecConfig::embedded_default();
    let freeze = &plans()[0];
    let out = replay(&spec).execute(freeze, &cfg);
    assert_eq!(out.outcome, OutcomeKind::Struck, "{out:?}");
    let st = out.strike.as_ref().unwrap();
    assert_eq!(st.part, "left_forearm");
    let dt_hit = t_hit - spec.observation_window_s;
    assert!((st.t - dt_hit).abs() < 0.02, "{st:?}");
}

#[test]
fn grasp_catches_a_gentle_drop_and_refuses_a_fast_or_heavy_one() {
    let cfg = ExecConfig::embedded_default();
    let g = 9.81;
    let palm_top = |spec: &rh_physics::spec::SceneSpec| spec.observer.pelvis_z + 0.10 + 0.015;
    // Dropped from rest 0.5 m above the palms: it lands at sqrt(2h/g) = 0.319 s with
    // sqrt(2gh) = 3.1 m/s (< grasp_speed_max), the hand closes, and it is caught.
    let h = 0.5;
    let probe = ball_scene(0.2, [0.0; 3], 0.0);
    let z0 = palm_top(&probe) + 0.04 + h;
    let spec = ball_scene(0.2, [0.40, 0.0, z0], 0.0);
    let out = replay(&spec).execute(&cupped_hands(), &cfg);
    assert_eq!(out.outcome, OutcomeKind::Caught, "{out:?}");
    let t_land = (2.0 * h / g).sqrt();
    let t = out.first_contact_t.unwrap();
    assert!(
        (t - t_land).abs() < 0.02,
        "contact at {t}, closed form {t_land}"
    );
    assert!(out.floor_t.is_none(), "{out:?}");
    // The same plan standing with the hands at rest does not grasp: it is no catch.
    let rest = ExecPlan {
        keyframes: vec![],
        ..cupped_hands()
    };
    let out = replay(&spec).execute(&rest, &cfg);
    assert_ne!(out.outcome, OutcomeKind::Caught, "{out:?}");
    // Arriving at 3x grasp_speed_max (contact at about 0.3 s, the hands in place): the
    // hand does not close and the blow (0.3 kg x 22.5 m/s) is a strike on the hands.
    let v = 3.0 * cfg.grasp_speed_max;
    let (t_hit, v0) = (0.3, v - g * 0.3);
    let drop = v0 * t_hit + 0.5 * g * t_hit * t_hit;
    let spec = ball_scene(0.3, [0.40, 0.0, palm_top(&probe) + 0.04 + drop], -v0);
    let out = replay(&spec).execute(&cupped_hands(), &cfg);
    assert_ne!(out.outcome, OutcomeKind::Caught, "{out:?}");
    assert_eq!(out.outcome, OutcomeKind::Struck, "{out:?}");
    // Too heavy (4 kg > grasp_mass_max), gently dropped: never caught.
    let spec = ball_scene(4.0, [0.40, 0.0, z0], 0.0);
    let out = replay(&spec).execute(&cupped_hands(), &cfg);
    assert_ne!(out.outcome, OutcomeKind::Caught, "{out:?}");
}

#[test]
fn a_ball_that_misses_the_hands_reaches_the_floor_and_is_missed() {
    let cfg = ExecConfig::embedded_default();
    // 0.25 m in front of the palms' centres (0.15 m between their edges and the ball's):
    // the plan reached out and a palm came within attempt_radius, the ball hits the floor.
    let spec = ball_scene(0.2, [0.65, 0.0, 1.5], 0.0);
    let out = replay(&spec).execute(&cupped_hands(), &cfg);
    assert_eq!(out.outcome, OutcomeKind::Missed, "{out:?}");
    assert!(
        out.first_contact_t.is_none() && out.floor_t.is_some(),
        "{out:?}"
    );
    assert!(out.min_hand_distance <= cfg.attempt_radius, "{out:?}");
}

/// A 3 kg slab 0.60 m wide and tall flying level (no gravity) at 4 m/s at the torso of the
/// standing observer from straight ahead, arriving `after` s after the decision moment.
fn slab_at_the_torso(after: f64) -> rh_physics::spec::SceneSpec {
    let (speed, half) = (4.0, [0.05, 0.30, 0.30]);
    flung_slab(half, 3.0, |spec| {
        let o = &spec.observer;
        let ahead = [o.yaw.cos(), o.yaw.sin(), 0.0];
        // The torso box's front is 0.09 m ahead of the axis; the palms at rest 0.16 m.
        let d = speed * (spec.observation_window_s + after) + half[0] + 0.16;
        (
            [o.x + d * ahead[0], o.y + d * ahead[1], o.pelvis_z + 0.25],
            ahead.map(|c| -speed * c),
        )
    })
}

/// The escape walks start from the world at Δ that the plain run kept
/// (`simulate::decision_world`, `execute::replay_reusing`): the same world as a fresh
/// replay — same hash at Δ, same outcomes and per-step hashes of every plan — also for
/// a copy of the spec with the observer moved (what an aimed pose changes), and a spec
/// that changes the world misses it.
#[test]
fn the_kept_world_at_decision_is_the_replay() {
    use rh_physics::execute::replay_reusing;
    use rh_physics::simulate::decision_world;
    let cfg = ExecConfig::embedded_default();
    for family in ["thrown_object", "shelf_slide", "door_swing"] {
        for r in scenes(family, 1).iter().take(2) {
            let mut moved = r.spec.clone();
            moved.observer.x += 0.4;
            moved.observer.yaw += 0.3;
            moved.cameras.clear();
            let sim = simulate(&r.spec, SimOptions::default());
            assert_eq!(sim.state_hash, r.state_hash);
            assert!(decision_world(&moved).is_some(), "{family}: not kept");
            let mut heavier = r.spec.clone();
            heavier.bodies[heavier.hazard].mass *= 2.0;
            assert!(decision_world(&heavier).is_none(), "{family}");
            let kept = replay_reusing(&moved);
            let fresh = replay(&moved);
            assert_eq!(kept.decision_hash, fresh.decision_hash, "{family}");
            assert_eq!(kept.decision_hash, r.decision_state_hash, "{family}");
            for plan in plans() {
                let (a, b) = (kept.execute(&plan, &cfg), fresh.execute(&plan, &cfg));
                assert_eq!(a.state_hash, b.state_hash, "{family}");
                assert_eq!(a.outcome, b.outcome, "{family}");
            }
        }
    }
}

#[test]
fn a_strike_is_escapable_only_when_some_walk_clears_it_in_time() {
    use rh_physics::execute::escape::{escapable, escape_plans, first_unstruck};
    use rh_scenes::label::{label, Action};
    let cfg = ExecConfig::embedded_default();
    let plans_of = |spec: &rh_physics::spec::SceneSpec| {
        let p = escape_plans(spec);
        // Eight 1.6 m walks at 1.45 m/s, the first straight back, the second back-left.
        assert_eq!(p.len(), 8);
        assert!((p[0].walking_cmd[0] + 1.45).abs() < 1e-12 && p[0].walking_cmd[1].abs() < 1e-12);
        assert!(p[1].walking_cmd[0] < 0.0 && p[1].walking_cmd[1] > 0.0);
        assert!((p[0].walking_duration - 1.6 / 1.45).abs() < 1e-12);
        p
    };
    for (after, escapes) in [(1.0, true), (0.25, false)] {
        let spec = slab_at_the_torso(after);
        let cf = simulate(&spec, counterfactual_options(&spec));
        let l = label(&spec, &simulate(&spec, SimOptions::default()), cf.strike);
        // Heavy (3 kg ≥ 2 kg) and striking the standing body: a DODGE with danger present,
        // the scenes the validator judges.
        assert!(l.dangerous && l.danger_present, "{l:?}");
        assert_eq!(l.gt_action, Action::Dodge);
        let plans = plans_of(&spec);
        let first = first_unstruck(&replay(&spec), &plans, &cfg);
        assert_eq!(escapable(&spec), escapes, "arriving {after} s after Δ");
        assert_eq!(
            rh_scenes::validate::escapable(&spec, &l),
            escapes,
            "{after}"
        );
        if escapes {
            // Straight back is run down (4 m/s against 1.45 m/s): a walk to a side clears.
            let i = first.expect("an escape");
            assert!(i >= 1, "{i}");
            assert_eq!(
                replay(&spec).execute(&plans[0], &cfg).outcome,
                OutcomeKind::Struck
            );
            assert_ne!(
                replay(&spec).execute(&plans[i], &cfg).outcome,
                OutcomeKind::Struck
            );
        } else {
            // 0.25 s from rest at 4 m/s² moves the base 0.125 m: the 0.6 m slab hits
            // whichever way it goes.
            assert_eq!(first, None);
        }
    }
}

#[test]
fn a_hazard_still_on_the_floor_from_the_start_ends_the_run_once_it_has_stayed_still() {
    // A 1 kg ball resting on the floor 1.5 m in front of the standing humanoid, as a
    // ladder or a wardrobe comes to rest without ever landing: the run of the `freeze`
    // plan ends `settle_time_s` after it (execution rule e5), not at the horizon, and is
    // clear either way.
    let spec = ball_scene(1.0, [1.5, 0.0, 0.04], 0.0);
    let cfg = ExecConfig::embedded_default();
    let freeze = &plans()[0];
    let out = replay(&spec).execute(freeze, &cfg);
    assert_eq!(out.outcome, OutcomeKind::Clear, "{out:?}");
    let settle = (cfg.settle_time_s / spec.physics.dt).round() as u32;
    assert!(settle > 0);
    assert!(
        out.steps >= settle && out.steps <= settle + 12,
        "{} steps, settle {settle}",
        out.steps
    );
    // Without the rule (settle_time_s 0, configs of e4) it runs to the horizon.
    let e4 = ExecConfig {
        settle_time_s: 0.0,
        ..cfg.clone()
    };
    let long = replay(&spec).execute(freeze, &e4);
    assert_eq!(long.outcome, OutcomeKind::Clear);
    let horizon = (cfg.horizon_s / spec.physics.dt).round() as u32;
    assert!(
        long.steps >= horizon.min(spec.physics.max_steps) - 1,
        "{}",
        long.steps
    );
}
