//! Geometric visibility of the hazard (validator `valid_visible`, specification §6): pure — no
//! GPU — so label-only and rendered builds agree and stay byte-stable.
//!
//! At every frame the in-frame check covers (the observation window until the hazard
//! reaches the observer, see `view::window_steps`), for every camera:
//! * **line of sight over the hazard's extent**: points sampled on the hazard's collision
//!   shapes at its pose ([`hazard_points`]) count as seen when they lie inside the image
//!   and no fixed body and no part of the observer's collision capsule (widened by
//!   `observer_margin`; a camera inside it — the ego camera in the head — is excepted
//!   for its own body) lies between the camera and the point; at least
//!   `visible_fraction` of the points must be seen;
//! * **size**: the hazard's projected size — the largest side of its sample points'
//!   box in the image, in pixels at the camera's resolution — is at least `min_size_px`.
//!
//! [`assess`] is the one entry point: it measures every camera of a spec over a
//! simulation; [`Assessment::passes`] is the verdict.

use crate::config::FramingRules;
use crate::view::View;
use rh_physics::obstacles::Obstacles;
use rh_physics::simulate::Simulation;
use rh_physics::spec::vec3::{add, dot, sub};
use rh_physics::spec::{quat, CameraSpec, Quat, SceneSpec, ShapeSpec, Vec3};

/// Points are sampled this far in from the shape's surface (as a share of its size), so
/// that a hazard resting on a table does not have its sample points inside the table.
const INSET: f64 = 0.9;

/// How one camera sees the hazard at one moment.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sight {
    /// Share of the hazard's sample points inside the image and in the line of sight.
    pub fraction: f64,
    /// Largest side (px) of the box around the hazard's sample points in the image.
    pub size_px: f64,
}

impl Sight {
    pub fn passes(&self, rules: &FramingRules) -> bool {
        self.fraction >= rules.visible_fraction && self.size_px >= rules.min_size_px
    }
}

/// One camera's sights at each checked step.
#[derive(Debug, Clone, PartialEq)]
pub struct CameraSights {
    pub camera: String,
    /// (physics step, sight) for each frame checked.
    pub sights: Vec<(u32, Sight)>,
}

/// Every camera's sights of the hazard over a scene's checked frames.
#[derive(Debug, Clone, PartialEq)]
pub struct Assessment {
    pub cameras: Vec<CameraSights>,
}

impl Assessment {
    /// The verdict: at least one camera, and every camera sees enough of the hazard, large
    /// enough, at every checked frame.
    pub fn passes(&self, rules: &FramingRules) -> bool {
        !self.cameras.is_empty()
            && self
                .cameras
                .iter()
                .all(|c| c.sights.iter().all(|(_, s)| s.passes(rules)))
    }

    /// The worst sight over cameras and frames: least fraction, least size.
    pub fn worst(&self) -> Option<Sight> {
        self.cameras
            .iter()
            .flat_map(|c| c.sights.iter().map(|(_, s)| *s))
            .reduce(|a, b| Sight {
                fraction: a.fraction.min(b.fraction),
                size_px: a.size_px.min(b.size_px),
            })
    }
}

/// The entry point: how each of the spec's cameras sees the hazard at each frame of the
/// in-frame check's window.
pub fn assess(spec: &SceneSpec, sim: &Simulation, rules: &FramingRules) -> Assessment {
    assess_cameras(spec, sim, &spec.cameras, rules)
}

/// [`assess`] for other cameras than the spec's own (placement tries candidates).
pub fn assess_cameras(
    spec: &SceneSpec,
    sim: &Simulation,
    cameras: &[CameraSpec],
    rules: &FramingRules,
) -> Assessment {
    let steps = crate::view::window_steps(spec, sim, rules.until_within);
    let points: Vec<(u32, Vec<Vec3>)> = steps
        .iter()
        .map(|&k| (k, hazard_points_at(spec, sim, k)))
        .collect();
    let occluders = Occluders::of(spec, rules.observer_margin);
    let cameras = cameras
        .iter()
        .map(|camera| CameraSights {
            camera: camera.name.clone(),
            sights: points
                .iter()
                .map(|(k, p)| (*k, sight(camera, p, &occluders)))
                .collect(),
        })
        .collect();
    Assessment { cameras }
}

/// What can hide the hazard: the fixed bodies, and the observer's body (its collision
/// capsule, widened) for cameras outside it.
pub struct Occluders {
    fixed: Obstacles,
    with_observer: Obstacles,
}

impl Occluders {
    pub fn of(spec: &SceneSpec, observer_margin: f64) -> Occluders {
        Occluders {
            fixed: Obstacles::of(spec),
            with_observer: Obstacles::of(spec).with_observer(&spec.observer, observer_margin),
        }
    }

    /// Whether something stands between a camera at `camera` and the point `p`.
    pub fn blocks(&self, camera: Vec3, p: Vec3) -> bool {
        self.for_camera(camera).blocks(camera, p)
    }

    /// The obstacles for a camera at `position`: a camera inside the observer's body
    /// (the ego camera) does not see its own body.
    fn for_camera(&self, position: Vec3) -> &Obstacles {
        if self.with_observer.contains(position) && !self.fixed.contains(position) {
            &self.fixed
        } else {
            &self.with_observer
        }
    }
}

/// How `camera` sees a hazard given by its sample `points`.
pub fn sight(camera: &CameraSpec, points: &[Vec3], occluders: &Occluders) -> Sight {
    let Some(view) = View::new(camera) else {
        return Sight {
            fraction: 0.0,
            size_px: 0.0,
        };
    };
    let obstacles = occluders.for_camera(camera.position);
    let (w, h) = (camera.width as f64 / 2.0, camera.height as f64 / 2.0);
    let mut seen = 0usize;
    let (mut lo, mut hi) = ([f64::MAX; 2], [f64::MIN; 2]);
    for p in points {
        let Some([x, y]) = view.project(*p) else {
            continue;
        };
        let px = [x * w, y * h];
        for a in 0..2 {
            lo[a] = lo[a].min(px[a]);
            hi[a] = hi[a].max(px[a]);
        }
        if x.abs() <= 1.0 && y.abs() <= 1.0 && !obstacles.blocks(camera.position, *p) {
            seen += 1;
        }
    }
    let size_px = if lo[0] <= hi[0] {
        (hi[0] - lo[0]).max(hi[1] - lo[1])
    } else {
        0.0
    };
    Sight {
        fraction: seen as f64 / points.len().max(1) as f64,
        size_px,
    }
}

/// The hazard's sample points (world frame) at physics step `k`.
pub fn hazard_points_at(spec: &SceneSpec, sim: &Simulation, k: u32) -> Vec<Vec3> {
    let state = sim.hazard_state(k);
    hazard_points(
        spec,
        state.position.map(f64::from),
        state.rotation.map(f64::from),
    )
}

/// Points sampled on and in the hazard's collision shapes (see [`shape_points`]) with
/// its body at `position`, `rotation`.
pub fn hazard_points(spec: &SceneSpec, position: Vec3, rotation: Quat) -> Vec<Vec3> {
    spec.hazard_body()
        .parts
        .iter()
        .flat_map(|part| {
            shape_points(&part.shape).into_iter().map(move |p| {
                let in_body = add(part.offset, quat::rotate(part.rotation, p));
                add(position, quat::rotate(rotation, in_body))
            })
        })
        .collect()
}

/// Fifteen points of a shape in its own frame (cylinders and capsules along z): its
/// centre and points just inside its surface — a box's corners and face centres, a
/// sphere's axis and diagonal points, a cylinder's or capsule's end centres and rims.
pub fn shape_points(shape: &ShapeSpec) -> Vec<Vec3> {
    let s = INSET;
    let mut p = vec![[0.0; 3]];
    match *shape {
        ShapeSpec::Box { half_extents: e } => {
            let e = e.map(|c| c * s);
            for a in 0..3 {
                for sign in [-1.0, 1.0] {
                    let mut q = [0.0; 3];
                    q[a] = sign * e[a];
                    p.push(q);
                }
            }
            for i in 0..8 {
                let sg = |b: usize| if i >> b & 1 == 1 { 1.0 } else { -1.0 };
                p.push([sg(0) * e[0], sg(1) * e[1], sg(2) * e[2]]);
            }
        }
        ShapeSpec::Sphere { radius } => {
            let r = radius * s;
            for a in 0..3 {
                for sign in [-1.0, 1.0] {
                    let mut q = [0.0; 3];
                    q[a] = sign * r;
                    p.push(q);
                }
            }
            let d = r / 3f64.sqrt();
            for i in 0..8 {
                let sg = |b: usize| if i >> b & 1 == 1 { d } else { -d };
                p.push([sg(0), sg(1), sg(2)]);
            }
        }
        ShapeSpec::Cylinder {
            half_height,
            radius,
        }
        | ShapeSpec::Capsule {
            half_height,
            radius,
        } => {
            let capsule = matches!(shape, ShapeSpec::Capsule { .. });
            let (hh, r) = (half_height * s, radius * s);
            let tip = if capsule { hh + r } else { hh };
            p.push([0.0, 0.0, tip]);
            p.push([0.0, 0.0, -tip]);
            for z in [-hh, hh] {
                for a in 0..4 {
                    let t = a as f64 * std::f64::consts::FRAC_PI_2;
                    p.push([r * t.cos(), r * t.sin(), z]);
                }
            }
            for a in 0..4 {
                let t = (a as f64 + 0.5) * std::f64::consts::FRAC_PI_2;
                p.push([r * t.cos(), r * t.sin(), 0.0]);
            }
        }
    }
    p
}

/// The box around `points` as seen from `origin` along the camera basis (right, up,
/// forward), in tangent units (image-plane coordinates at unit depth): its largest side.
/// Times `height / 2 / tan(fov_y / 2)` it is the hazard's projected size in pixels, so
/// placement can choose a field of view for a band of sizes.
pub fn tangent_size(origin: Vec3, basis: (Vec3, Vec3, Vec3), points: &[Vec3]) -> f64 {
    let (r, u, f) = basis;
    let (mut lo, mut hi) = ([f64::MAX; 2], [f64::MIN; 2]);
    for p in points {
        let d = sub(*p, origin);
        let z = dot(d, f).max(1e-3);
        let t = [dot(d, r) / z, dot(d, u) / z];
        for a in 0..2 {
            lo[a] = lo[a].min(t[a]);
            hi[a] = hi[a].max(t[a]);
        }
    }
    if lo[0] > hi[0] {
        return 0.0;
    }
    (hi[0] - lo[0]).max(hi[1] - lo[1])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::Config;
    use crate::randomize::{randomize, SceneKey};
    use rh_catalog::Catalog;
    use rh_physics::spec::{BodyKind, BodyRole, BodySpec, PartSpec, Selection};

    const MARGIN: f64 = 0.08;

    fn body(kind: BodyKind, shape: ShapeSpec, position: Vec3) -> BodySpec {
        BodySpec {
            name: "b".into(),
            role: if kind == BodyKind::Fixed {
                BodyRole::Support
            } else {
                BodyRole::Hazard
            },
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
            ccd: false,
            push_mass: None,
        }
    }

    /// A constructed scene: the hazard (body 0) and the given fixed bodies, the observer
    /// standing at `observer` (x, y); everything else from a sampled spec.
    fn scene(hazard: BodySpec, fixed: Vec<BodySpec>, observer: [f64; 2]) -> SceneSpec {
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
        spec.bodies = std::iter::once(hazard).chain(fixed).collect();
        spec.hazard = 0;
        spec.source_support = None;
        spec.joints.clear();
        spec.observer.x = observer[0];
        spec.observer.y = observer[1];
        spec
    }

    /// A 1280 × 720 camera at `position` looking at `look_at`.
    fn camera(position: Vec3, look_at: Vec3, fov_y: f64) -> CameraSpec {
        CameraSpec {
            name: "test".into(),
            position,
            look_at,
            fov_y,
            width: 1280,
            height: 720,
        }
    }

    fn sight_of(spec: &SceneSpec, cam: &CameraSpec) -> Sight {
        let h = spec.hazard_body();
        let points = hazard_points(spec, h.position, h.rotation);
        sight(cam, &points, &Occluders::of(spec, MARGIN))
    }

    #[test]
    fn the_observer_between_camera_and_hazard_hides_it() {
        let ball = body(
            BodyKind::Dynamic,
            ShapeSpec::Sphere { radius: 0.1 },
            [3.0, 0.0, 1.0],
        );
        let cam = camera([-3.0, 0.0, 1.0], [3.0, 0.0, 1.0], 0.8);
        // The observer's capsule stands on the line of sight: nothing of the ball is seen.
        let behind = scene(ball.clone(), vec![], [0.0, 0.0]);
        assert_eq!(sight_of(&behind, &cam).fraction, 0.0);
        // 0.2 m beside the line: the bare capsule (torso radius 0.18) would leave the
        // centre in sight; the widened one (+ 0.08 m, the drawn arms) hides every ray.
        let beside = scene(ball.clone(), vec![], [0.0, 0.2]);
        assert_eq!(sight_of(&beside, &cam).fraction, 0.0);
        // Two metres aside: all of it.
        let clear = scene(ball.clone(), vec![], [0.0, 2.0]);
        assert_eq!(sight_of(&clear, &cam).fraction, 1.0);
        // The ego camera, inside the observer's head, is not blocked by its own body.
        let o = &behind.observer;
        let ego = camera([o.x, o.y, o.height - 0.08], [3.0, 0.0, 1.0], 0.8);
        assert_eq!(sight_of(&behind, &ego).fraction, 1.0);
    }

    #[test]
    fn a_tiny_far_hazard_is_too_small() {
        let rules = Config::embedded().unwrap().validators.framing();
        let (r, d, fov) = (0.02, 10.0, 1.0);
        let pebble = body(
            BodyKind::Dynamic,
            ShapeSpec::Sphere { radius: r },
            [d, 0.0, 1.0],
        );
        let spec = scene(pebble, vec![], [0.0, 5.0]);
        let s = sight_of(&spec, &camera([0.0, 0.0, 1.0], [d, 0.0, 1.0], fov));
        // Fully in sight, but its projected size is 2 · 0.9 r / d · (720 / 2) / tan(fov / 2).
        let expected = 2.0 * INSET * r / d * 360.0 / (fov / 2.0).tan();
        assert!(
            (s.size_px - expected).abs() < 0.02 * expected,
            "{s:?} vs {expected}"
        );
        assert_eq!(s.fraction, 1.0);
        assert!(s.size_px < rules.min_size_px && !s.passes(&rules), "{s:?}");
        // Ten times closer, the same pebble is large enough.
        let near = body(
            BodyKind::Dynamic,
            ShapeSpec::Sphere { radius: r },
            [d / 10.0, 0.0, 1.0],
        );
        let spec = scene(near, vec![], [0.0, 5.0]);
        let s = sight_of(&spec, &camera([0.0, 0.0, 1.0], [d, 0.0, 1.0], fov));
        assert!(s.passes(&rules), "{s:?}");
    }

    #[test]
    fn a_hazard_whose_centre_is_seen_but_most_of_it_hidden_fails() {
        let rules = Config::embedded().unwrap().validators.framing();
        // A 2 m bar across the view; two fixed panels hide all of it but a 0.3 m gap
        // around its middle.
        let bar = body(
            BodyKind::Dynamic,
            ShapeSpec::Box {
                half_extents: [0.05, 1.0, 0.05],
            },
            [3.0, 0.0, 1.0],
        );
        let panel = |y: f64| {
            body(
                BodyKind::Fixed,
                ShapeSpec::Box {
                    half_extents: [0.02, 0.5, 1.0],
                },
                [1.0, y, 1.0],
            )
        };
        let spec = scene(bar, vec![panel(-0.65), panel(0.65)], [0.0, 4.0]);
        let cam = camera([-3.0, 0.0, 1.0], [3.0, 0.0, 1.0], 0.8);
        // The old centre-only test sees it ...
        assert!(!Obstacles::of(&spec).blocks(cam.position, [3.0, 0.0, 1.0]));
        // ... but only the points along the bar's middle are in sight: 5 of 15.
        let s = sight_of(&spec, &cam);
        assert!((s.fraction - 5.0 / 15.0).abs() < 1e-9, "{s:?}");
        assert!(!s.passes(&rules));
        // Without the panels the same view passes.
        let open = scene(spec.bodies[0].clone(), vec![], [0.0, 4.0]);
        assert!(sight_of(&open, &cam).passes(&rules));
    }

    #[test]
    fn a_hazard_partly_outside_the_image_counts_only_its_inside() {
        let ball = body(
            BodyKind::Dynamic,
            ShapeSpec::Sphere { radius: 0.2 },
            [3.0, 0.0, 1.0],
        );
        let spec = scene(ball, vec![], [0.0, 4.0]);
        // Aimed so that the ball's centre sits on the image's right border.
        let (fov, aspect) = (0.6f64, 1280.0 / 720.0);
        let side = 3.0 * (fov / 2.0).tan() * aspect;
        let cam = camera([0.0, side, 1.0], [3.0, side, 1.0], fov);
        let s = sight_of(&spec, &cam);
        assert!(s.fraction > 0.3 && s.fraction < 0.7, "{s:?}");
    }

    #[test]
    fn every_shape_gives_fifteen_points_inside_it() {
        for shape in [
            ShapeSpec::Box {
                half_extents: [0.1, 0.2, 0.3],
            },
            ShapeSpec::Sphere { radius: 0.2 },
            ShapeSpec::Cylinder {
                half_height: 0.3,
                radius: 0.1,
            },
            ShapeSpec::Capsule {
                half_height: 0.3,
                radius: 0.1,
            },
        ] {
            let points = shape_points(&shape);
            assert_eq!(points.len(), 15, "{shape:?}");
            let reach = shape.bounding_radius();
            assert!(points
                .iter()
                .all(|p| (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt() < reach));
        }
    }
}
