//! What the model sees (specification §6, "answerable items"): the head (`ego`) camera's
//! model-input frames — the observation times `FRAME_TIMES` — must show the hazard, and
//! the event must be under way between t = 0 and Δ. Pure geometry (no GPU), so a
//! label-only build and a rendered one have the same verdicts; the renderer's measured
//! pixels are checked against the same rule afterwards ([`check_measured`]).
//!
//! * [`ego_pixels_pass`] (part of `valid_visible`): at every model-input frame before
//!   the hazard reaches the observer (`view::window_steps`), rays through a grid of
//!   pixel centres over the hazard's screen box are cast at its collision shapes shrunk
//!   to `px_inset` of their size; a ray that meets them with no fixed body, no other
//!   moving body and (for a camera outside it) not the observer's capsule in front
//!   counts for its cell's pixels (for a camera inside the room only where it meets them
//!   inside the room's shell: walls, floor and ceiling hide what lies beyond). The
//!   estimate must reach `ego_px_min` (`visible_px_min` × `visible_px_safety`):
//!   shrinking and the factor keep it below what the renderer draws.
//! * [`motion_px`] (column `ego_motion_px`, validator `valid_motion`): the largest image
//!   displacement between t = 0 and Δ of a point sampled on the hazard's or a moving
//!   prop's (a chain's trigger, a neighbour) collision shapes.

use crate::config::FramingRules;
use crate::view::{window_steps, View};
use crate::visibility::shape_points;
use rh_contract::FRAME_TIMES;
use rh_physics::obstacles::Obstacles;
use rh_physics::simulate::Simulation;
use rh_physics::spec::vec3::{add, dot, scale, sub};
use rh_physics::spec::{quat, BodyRole, CameraSpec, PartSpec, SceneSpec, ShapeSpec, Vec3};

/// At most about this many rays per frame (the grid's stride grows with the box).
const MAX_SAMPLES: f64 = 256.0;

/// The ego camera of a set of cameras.
pub fn ego_camera(cameras: &[CameraSpec]) -> Option<&CameraSpec> {
    cameras.iter().find(|c| c.name == "ego")
}

/// The physics steps of the model-input frames (`FRAME_TIMES`, as the renderer maps
/// them) before the hazard reaches the observer: those within `view::window_steps`.
pub fn model_input_steps(
    spec: &SceneSpec,
    sim: &Simulation,
    until_within: f64,
) -> Vec<(usize, u32)> {
    let steps = spec.observation_frame_steps(sim.steps());
    let window = window_steps(spec, sim, until_within).len();
    FRAME_TIMES
        .iter()
        .enumerate()
        .filter_map(|(i, &t)| {
            let k = ((t * spec.video.fps as f64).round() as usize).min(steps.len() - 1);
            (k < window).then_some((i, steps[k]))
        })
        .collect()
}

/// Whether every model-input ego frame before the hazard reaches the observer shows it
/// with at least `rules.ego_px_min` estimated pixels (true when that is 0; false without
/// an ego camera).
pub fn ego_pixels_pass(
    spec: &SceneSpec,
    sim: &Simulation,
    cameras: &[CameraSpec],
    rules: &FramingRules,
) -> bool {
    if rules.ego_px_min <= 0.0 {
        return true;
    }
    let Some(camera) = ego_camera(cameras) else {
        return false;
    };
    model_input_steps(spec, sim, rules.until_within)
        .into_iter()
        .all(|(_, k)| visible_px(spec, sim, camera, k, rules, rules.ego_px_min) >= rules.ego_px_min)
}

/// A shape shrunk about its centre to `s` of its size.
fn shrunk(shape: &ShapeSpec, s: f64) -> ShapeSpec {
    match *shape {
        ShapeSpec::Box { half_extents } => ShapeSpec::Box {
            half_extents: half_extents.map(|e| e * s),
        },
        ShapeSpec::Sphere { radius } => ShapeSpec::Sphere { radius: radius * s },
        ShapeSpec::Cylinder {
            half_height,
            radius,
        } => ShapeSpec::Cylinder {
            half_height: half_height * s,
            radius: radius * s,
        },
        ShapeSpec::Capsule {
            half_height,
            radius,
        } => ShapeSpec::Capsule {
            half_height: half_height * s,
            radius: radius * s,
        },
    }
}

/// The corners of a box around a shape in its own frame (cylinders and capsules along z).
fn bound_corners(shape: &ShapeSpec) -> [Vec3; 8] {
    let e = match *shape {
        ShapeSpec::Box { half_extents } => half_extents,
        ShapeSpec::Sphere { radius } => [radius; 3],
        ShapeSpec::Cylinder {
            half_height,
            radius,
        } => [radius, radius, half_height],
        ShapeSpec::Capsule {
            half_height,
            radius,
        } => [radius, radius, half_height + radius],
    };
    std::array::from_fn(|i| {
        let sg = |b: usize| if i >> b & 1 == 1 { 1.0 } else { -1.0 };
        [sg(0) * e[0], sg(1) * e[1], sg(2) * e[2]]
    })
}

/// The estimated pixels of `camera`'s image showing the hazard at step `k` (see the
/// module's text); counting stops once it reaches `enough`.
pub fn visible_px(
    spec: &SceneSpec,
    sim: &Simulation,
    camera: &CameraSpec,
    k: u32,
    rules: &FramingRules,
    enough: f64,
) -> f64 {
    let Some((r, u, f)) = crate::view::basis(camera) else {
        return 0.0;
    };
    let body = spec.hazard_body();
    let state = sim.hazard_state(k);
    let (position, rotation) = (state.position.map(f64::from), state.rotation.map(f64::from));
    let parts: Vec<PartSpec> = body
        .parts
        .iter()
        .map(|p| PartSpec {
            shape: shrunk(&p.shape, rules.px_inset),
            ..p.clone()
        })
        .collect();
    let hazard = Obstacles::none().with_body(&parts, position, rotation);
    let (w, h) = (camera.width as f64, camera.height as f64);
    let ty = (camera.fov_y / 2.0).tan();
    let tx = ty * w / h;
    // The hazard's box on the screen (px, x right, y down), clipped to the image; the
    // whole image when a corner is behind the camera.
    let (mut lo, mut hi) = ([f64::MAX; 2], [f64::MIN; 2]);
    let mut behind = false;
    for part in &parts {
        for c in bound_corners(&part.shape) {
            let p = add(
                position,
                quat::rotate(rotation, add(part.offset, quat::rotate(part.rotation, c))),
            );
            let d = sub(p, camera.position);
            let z = dot(d, f);
            if z < 0.05 {
                behind = true;
                continue;
            }
            let px = [
                (1.0 + dot(d, r) / z / tx) * w / 2.0,
                (1.0 - dot(d, u) / z / ty) * h / 2.0,
            ];
            for a in 0..2 {
                lo[a] = lo[a].min(px[a]);
                hi[a] = hi[a].max(px[a]);
            }
        }
    }
    if behind {
        (lo, hi) = ([0.0, 0.0], [w, h]);
    }
    let (x0, y0) = (lo[0].max(0.0).floor(), lo[1].max(0.0).floor());
    let (x1, y1) = (hi[0].min(w).ceil(), hi[1].min(h).ceil());
    if x1 <= x0 || y1 <= y0 {
        return 0.0;
    }
    let stride = ((x1 - x0) * (y1 - y0) / MAX_SAMPLES).sqrt().ceil().max(1.0);
    let occluders = occluders(spec, sim, camera, k, rules);
    // The room's walls, floor and ceiling hide what lies beyond them from a camera inside
    // the room (the renderer leaves out a surface only for a camera outside it).
    let inside = in_room(spec, camera.position);
    let mut count = 0.0;
    let mut y = y0;
    while y < y1 {
        let mut x = x0;
        while x < x1 {
            // The centre of the cell's middle pixel (cells at the box's far edges are cut).
            let (cw, ch) = (stride.min(x1 - x), stride.min(y1 - y));
            let (px, py) = (x + (cw / 2.0).floor() + 0.5, y + (ch / 2.0).floor() + 0.5);
            let (nx, ny) = ((px / w * 2.0 - 1.0) * tx, (1.0 - py / h * 2.0) * ty);
            let dir = add(f, add(scale(r, nx), scale(u, ny)));
            let dir = scale(dir, 1.0 / dot(dir, dir).sqrt());
            if let Some(t) = hazard.first_hit(camera.position, dir, 100.0) {
                let hit = add(camera.position, scale(dir, t));
                if !(inside && !in_room(spec, hit)) && !occluders.blocks(camera.position, hit) {
                    count += cw * ch;
                    if count >= enough {
                        return count;
                    }
                }
            }
            x += stride;
        }
        y += stride;
    }
    count
}

/// Whether `p` lies inside the room's shell (centred on the origin, floor at z = 0).
fn in_room(spec: &SceneSpec, p: Vec3) -> bool {
    let [sx, sy] = spec.room.size;
    p[0].abs() <= sx / 2.0
        && p[1].abs() <= sy / 2.0
        && (0.0..=spec.room.ceiling_height).contains(&p[2])
}

/// What can stand between `camera` and the hazard at step `k`: the fixed bodies, the
/// observer's capsule (widened) for a camera outside it, and every other moving body.
fn occluders(
    spec: &SceneSpec,
    sim: &Simulation,
    camera: &CameraSpec,
    k: u32,
    rules: &FramingRules,
) -> Obstacles {
    let fixed = Obstacles::of(spec);
    let with_observer = fixed
        .clone()
        .with_observer(&spec.observer, rules.observer_margin);
    let mut o = if with_observer.contains(camera.position) && !fixed.contains(camera.position) {
        fixed
    } else {
        with_observer
    };
    for (slot, &i) in sim.dynamic_bodies.iter().enumerate() {
        if slot == sim.hazard_slot {
            continue;
        }
        let s = sim.state(k, slot);
        o = o.with_body(
            &spec.bodies[i].parts,
            s.position.map(f64::from),
            s.rotation.map(f64::from),
        );
    }
    o
}

/// Points sampled on the collision shapes of body `i` of `spec` at step `k`.
fn body_points(spec: &SceneSpec, sim: &Simulation, slot: usize, k: u32) -> Vec<Vec3> {
    let body = &spec.bodies[sim.dynamic_bodies[slot]];
    let s = sim.state(k, slot);
    let (position, rotation) = (s.position.map(f64::from), s.rotation.map(f64::from));
    body.parts
        .iter()
        .flat_map(|part| {
            shape_points(&part.shape).into_iter().map(move |p| {
                add(
                    position,
                    quat::rotate(rotation, add(part.offset, quat::rotate(part.rotation, p))),
                )
            })
        })
        .collect()
}

/// How far the event moves in `camera`'s image between t = 0 and Δ (px at its
/// resolution): the largest displacement of a sample point of the hazard or of a moving
/// prop (role `Prop`) that is in front of the camera at both times.
pub fn motion_px(spec: &SceneSpec, sim: &Simulation, camera: &CameraSpec) -> f64 {
    let Some(view) = View::new(camera) else {
        return 0.0;
    };
    let decision = spec.decision_step().min(sim.steps());
    let (w, h) = (camera.width as f64 / 2.0, camera.height as f64 / 2.0);
    let mut most = 0.0f64;
    for (slot, &i) in sim.dynamic_bodies.iter().enumerate() {
        if slot != sim.hazard_slot && spec.bodies[i].role != BodyRole::Prop {
            continue;
        }
        let start = body_points(spec, sim, slot, 0);
        let end = body_points(spec, sim, slot, decision);
        for (a, b) in start.iter().zip(&end) {
            if let (Some(a), Some(b)) = (view.project(*a), view.project(*b)) {
                most = most.max(((a[0] - b[0]) * w).hypot((a[1] - b[1]) * h));
            }
        }
    }
    most
}

/// [`motion_px`] of a spec's ego camera; None without one.
pub fn ego_motion_px(spec: &SceneSpec, sim: &Simulation) -> Option<f64> {
    ego_camera(&spec.cameras).map(|c| motion_px(spec, sim, c))
}

/// The renderer's check of the rule (specification §6: the renderer's measurement gates
/// validity): a valid scene's measured ego pixels (`visible_px`, one per `FRAME_TIMES`)
/// must reach `visible_px_min` at each of its model-input frames before the hazard
/// reaches the observer (`frames`: indices into `FRAME_TIMES`, [`model_input_frames`]).
/// An error names the scene, the frame and the pixels: the geometric estimate passed a
/// frame the renderer does not show — the build stops rather than ship it.
pub fn check_measured(
    spec: &SceneSpec,
    frames: &[usize],
    visible_px: &[u32],
    visible_px_min: u32,
) -> Result<(), String> {
    for &i in frames {
        let px = visible_px.get(i).copied().unwrap_or(0);
        if px < visible_px_min {
            return Err(format!(
                "scene {} ({} {}): the ego frame at t = {:.2} s shows the hazard in {px} px, \
                 under validators.visible_px_min = {visible_px_min}, though the geometric \
                 visibility rule passed it (measured ego pixels {visible_px:?}); raise \
                 validators.visible_px_safety",
                spec.scene_id, spec.family, spec.selection.object_id, FRAME_TIMES[i]
            ));
        }
    }
    Ok(())
}

/// [`check_measured`] for a rendered scene: only a valid one with measured ego pixels
/// (`visible_px`), and only where the configuration has the pixel rule
/// (`visible_px_safety` > 0).
pub fn check_rendered(
    spec: &SceneSpec,
    valid: bool,
    frames: &[usize],
    visible_px: Option<&[u32]>,
    cfg: &crate::config::ValidatorConfig,
) -> Result<(), String> {
    match visible_px {
        Some(px) if valid && cfg.visible_px_safety > 0.0 => {
            check_measured(spec, frames, px, cfg.visible_px_min)
        }
        _ => Ok(()),
    }
}

/// The indices (into `FRAME_TIMES`) of the model-input frames before the hazard reaches
/// the observer ([`model_input_steps`]).
pub fn model_input_frames(spec: &SceneSpec, sim: &Simulation, until_within: f64) -> Vec<usize> {
    model_input_steps(spec, sim, until_within)
        .into_iter()
        .map(|(i, _)| i)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::Config;
    use crate::randomize::{randomize, SceneKey};
    use rh_catalog::Catalog;
    use rh_physics::simulate::{simulate, SimOptions};
    use rh_physics::spec::{BodyKind, BodySpec, Selection};

    fn body(role: BodyRole, kind: BodyKind, shape: ShapeSpec, position: Vec3) -> BodySpec {
        BodySpec {
            name: "b".into(),
            role,
            kind,
            catalog_id: None,
            parts: vec![PartSpec {
                shape,
                offset: [0.0; 3],
                rotation: [0.0, 0.0, 0.0, 1.0],
            }],
            position,
            rotation: [0.0, 0.0, 0.0, 1.0],
            mass: 1.0,
            friction: 0.5,
            restitution: 0.1,
            linvel: [0.0; 3],
            angvel: [0.0; 3],
            push_mass: None,
            ccd: false,
        }
    }

    fn ball(radius: f64, position: Vec3) -> BodySpec {
        body(
            BodyRole::Hazard,
            BodyKind::Dynamic,
            ShapeSpec::Sphere { radius },
            position,
        )
    }

    /// A constructed scene: the hazard (body 0) then `others`; the observer at the origin
    /// facing +x, its ego camera at head height looking along +x with `fov_y` (720p).
    fn scene(hazard: BodySpec, others: Vec<BodySpec>, fov_y: f64) -> (SceneSpec, CameraSpec) {
        let catalog = Catalog::embedded().unwrap();
        let config = Config::embedded().unwrap();
        let selection = Selection {
            family: "object_drop".into(),
            object_id: "apple".into(),
            room_id: "kitchen".into(),
            description: None,
            planner: None,
        };
        let mut spec = randomize(&selection, &SceneKey::new(0, 0, 0), &catalog, &config).unwrap();
        spec.bodies = std::iter::once(hazard).chain(others).collect();
        spec.hazard = 0;
        spec.source_support = None;
        spec.joints.clear();
        spec.observer.x = 0.0;
        spec.observer.y = 0.0;
        spec.observer.yaw = 0.0;
        spec.room.size = [20.0, 20.0];
        let eye = [0.0, 0.0, spec.observer.height - 0.08];
        let camera = CameraSpec {
            name: "ego".into(),
            position: eye,
            look_at: [1.0, 0.0, eye[2]],
            fov_y,
            width: 1280,
            height: 720,
        };
        spec.cameras = vec![camera.clone()];
        (spec, camera)
    }

    fn rules() -> FramingRules {
        Config::embedded().unwrap().validators.framing()
    }

    /// A ball straight ahead covers π ρ² pixels, ρ = f · inset · r / d (its silhouette's
    /// radius, d ≫ r); the estimate matches that, finely sampled (small ball: every pixel
    /// centre) and coarsely (a large one: one ray per cell), and is 0 behind a panel or
    /// behind another moving body.
    #[test]
    fn a_ball_ahead_shows_its_silhouettes_pixels_unless_something_is_in_front() {
        let rules = rules();
        let fov = 1.2f64;
        let focal = 360.0 / (fov / 2.0).tan();
        for (r, tol) in [(0.05, 0.10), (0.2, 0.06)] {
            let d = 3.0;
            let (spec, cam) = scene(ball(r, [d, 0.0, 1.24]), vec![], fov);
            let sim = simulate(&spec, SimOptions::default());
            let s = rules.px_inset * r;
            let rho = focal * s / (d * d - s * s).sqrt();
            let expected = std::f64::consts::PI * rho * rho;
            let px = visible_px(&spec, &sim, &cam, 0, &rules, f64::MAX);
            assert!(
                (px - expected).abs() < tol * expected,
                "r {r}: {px} vs {expected}"
            );
            // Counting stops once enough is seen.
            assert!(visible_px(&spec, &sim, &cam, 0, &rules, 50.0) < expected);
        }
        let panel = |kind, role| {
            body(
                role,
                kind,
                ShapeSpec::Box {
                    half_extents: [0.02, 0.5, 0.5],
                },
                [1.5, 0.0, 1.24],
            )
        };
        for (kind, role) in [
            (BodyKind::Fixed, BodyRole::Support),
            (BodyKind::Dynamic, BodyRole::Prop),
        ] {
            let (spec, cam) = scene(ball(0.2, [3.0, 0.0, 1.24]), vec![panel(kind, role)], fov);
            let sim = simulate(&spec, SimOptions::default());
            assert_eq!(
                visible_px(&spec, &sim, &cam, 0, &rules, f64::MAX),
                0.0,
                "{kind:?}"
            );
            let mut open = rules;
            open.ego_px_min = 64.0;
            assert!(!ego_pixels_pass(&spec, &sim, &spec.cameras, &open));
        }
        // Beyond the room's wall: hidden (issue 44: a brick on a ramp poking through the
        // wall showed 0 px while its shapes projected inside the image).
        let (mut spec, cam) = scene(ball(0.2, [3.0, 0.0, 1.24]), vec![], fov);
        let sim = simulate(&spec, SimOptions::default());
        assert!(visible_px(&spec, &sim, &cam, 0, &rules, f64::MAX) > 1000.0);
        spec.room.size = [5.0, 20.0];
        assert_eq!(visible_px(&spec, &sim, &cam, 0, &rules, f64::MAX), 0.0);
        // Out of the picture (behind the observer): nothing.
        let (spec, cam) = scene(ball(0.2, [-3.0, 0.0, 1.24]), vec![], fov);
        let sim = simulate(&spec, SimOptions::default());
        assert_eq!(visible_px(&spec, &sim, &cam, 0, &rules, f64::MAX), 0.0);
    }

    /// A ball falling freely 3 m in front of the camera, across its view: a sample point
    /// at depth d moves by f · Δz / d px in the image (pinhole, motion parallel to the
    /// image plane), Δz ≈ ½ g Δ²; the validator compares it with `motion_px_min`.
    #[test]
    fn a_falling_ball_moves_by_focal_times_drop_over_depth() {
        let fov = 1.2f64;
        let focal = 360.0 / (fov / 2.0).tan();
        let d = 3.0;
        let (spec, cam) = scene(ball(0.1, [d, 0.0, 2.3]), vec![], fov);
        let sim = simulate(&spec, SimOptions::default());
        let k = spec.decision_step();
        let drop = sim.hazard_position(0)[2] - sim.hazard_position(k)[2];
        let window = spec.observation_window_s;
        assert!((drop - 0.5 * 9.81 * window * window).abs() < 0.02, "{drop}");
        // The sample point nearest the camera (0.9 r in front of the centre) moves most.
        let expected = focal * drop / (d - 0.9 * 0.1);
        let m = motion_px(&spec, &sim, &cam);
        assert!((m - expected).abs() < 1e-3 * m, "{m} vs {expected}");
        assert_eq!(ego_motion_px(&spec, &sim), Some(m));
        let family = crate::families::get("object_drop").unwrap();
        let mut cfg = Config::embedded().unwrap().validators;
        cfg.motion_px_min = m - 1.0;
        assert!(crate::validate::unlabelled(&spec, &sim, family, &cfg).motion);
        cfg.motion_px_min = m + 1.0;
        assert!(!crate::validate::unlabelled(&spec, &sim, family, &cfg).motion);
        // A ball at rest on the floor does not move.
        let (spec, cam) = scene(ball(0.1, [d, 0.0, 0.1]), vec![], fov);
        let sim = simulate(&spec, SimOptions::default());
        assert!(motion_px(&spec, &sim, &cam) < 0.5);
    }

    /// The renderer's count is checked at the model-input frames before the hazard
    /// reaches the observer, and only there; a shortfall is an error naming the frame.
    #[test]
    fn measured_pixels_below_the_minimum_are_an_error() {
        let (spec, _) = scene(ball(0.1, [3.0, 0.0, 1.2]), vec![], 1.0);
        assert!(check_measured(&spec, &[0, 1, 2], &[500, 80, 64, 0, 0], 64).is_ok());
        let err = check_measured(&spec, &[0, 1, 2, 3], &[500, 80, 64, 10, 0], 64).unwrap_err();
        assert!(err.contains("t = 0.45 s") && err.contains("10 px"), "{err}");
    }
}
