//! Camera framing (SPEC §7): `ego`, `closeup`, `overhead`, placed from the "cameras/k"
//! stream with a retry that keeps the hazard in every camera's frame through the
//! observation window. Cameras never touch physics, so framing after the simulation
//! changes no state hash; the chosen poses are stored in the spec.

use crate::simulate::{Obstacles, Simulation};
use crate::spec::vec3::{cross, dot, norm, scale, sub};
use crate::spec::{CameraSpec, SceneSpec, Vec3};
use rand::RngExt;

pub const CAMERA_NAMES: [&str; 3] = ["ego", "closeup", "overhead"];
const FRAMING_ATTEMPTS: u32 = 8;

pub use crate::config::FramingRules;

/// The unit vector from a camera's position toward its `look_at`.
fn forward(camera: &CameraSpec) -> Vec3 {
    let f = sub(camera.look_at, camera.position);
    scale(f, 1.0 / norm(f).max(1e-12))
}

/// The right-handed basis (right, up, forward) with the given `right` direction.
fn complete_basis(f: Vec3, r: Vec3) -> (Vec3, Vec3, Vec3) {
    let r = scale(r, 1.0 / norm(r));
    let u = cross(r, f);
    (r, u, f)
}

/// A camera's basis (right, up, forward) with +z up: `None` when it looks (nearly)
/// straight up or down, where "+z up" is undefined.
pub fn basis(camera: &CameraSpec) -> Option<(Vec3, Vec3, Vec3)> {
    let f = forward(camera);
    let r = cross(f, [0.0, 0.0, 1.0]);
    if norm(r) < 1e-3 {
        return None;
    }
    Some(complete_basis(f, r))
}

/// The basis the renderer draws with: [`basis`], and for a camera looking straight up or
/// down (which the validator rejects) +y as the hint, so something sensible is drawn.
pub fn draw_basis(camera: &CameraSpec) -> (Vec3, Vec3, Vec3) {
    basis(camera).unwrap_or_else(|| {
        let f = forward(camera);
        complete_basis(f, cross(f, [0.0, 1.0, 0.0]))
    })
}

/// A pinhole camera looking from `position` to `look_at` with +z up.
pub struct View {
    position: Vec3,
    right: Vec3,
    up: Vec3,
    forward: Vec3,
    tan_half_y: f64,
    tan_half_x: f64,
}

impl View {
    /// None when the camera looks (nearly) straight up or down, where "+z up" is undefined.
    pub fn new(camera: &CameraSpec) -> Option<View> {
        let (r, u, f) = basis(camera)?;
        let tan_half_y = (camera.fov_y / 2.0).tan();
        Some(View {
            position: camera.position,
            right: r,
            up: u,
            forward: f,
            tan_half_y,
            tan_half_x: tan_half_y * camera.width as f64 / camera.height as f64,
        })
    }

    /// Normalised image coordinates in [-1, 1] (x right, y up), or None behind the camera.
    pub fn project(&self, point: Vec3) -> Option<[f64; 2]> {
        let d = sub(point, self.position);
        let z = dot(d, self.forward);
        if z < 0.05 {
            return None;
        }
        Some([
            dot(d, self.right) / z / self.tan_half_x,
            dot(d, self.up) / z / self.tan_half_y,
        ])
    }
}

/// Steps of the observation window sampled at the video rate, up to the moment the
/// hazard comes within `until_within` of the observer's torso axis: from then on the
/// event has reached the observer, and leaving the view (past the head) is natural.
fn window_steps(spec: &SceneSpec, sim: &Simulation, until_within: f64) -> Vec<u32> {
    spec.observation_frame_steps(sim.steps())
        .into_iter()
        .take_while(|&k| {
            k == 0 || spec.observer.torso_axis_distance(sim.hazard_position(k)) > until_within
        })
        .collect()
}

/// Whether the hazard's centre stays inside every camera's frame (with `margin`) and in
/// its line of sight — no fixed body (table, shelf, wall, stairs) between the camera and
/// the hazard — during the observation window (see `window_steps`).
pub fn hazard_in_frame(
    spec: &SceneSpec,
    sim: &Simulation,
    cameras: &[CameraSpec],
    rules: &FramingRules,
) -> bool {
    let limit = 1.0 - rules.margin;
    let steps = window_steps(spec, sim, rules.until_within);
    let obstacles = Obstacles::of(spec);
    cameras.iter().all(|camera| {
        let Some(view) = View::new(camera) else {
            return false;
        };
        steps.iter().all(|&k| {
            let p = sim.hazard_position(k);
            view.project(p)
                .is_some_and(|[x, y]| x.abs() <= limit && y.abs() <= limit)
                && !obstacles.blocks(camera.position, p)
        })
    })
}

/// Aims a camera at `position` so that every point is in view: it looks along the
/// bisector of the two most widely separated directions to the points, with the
/// vertical field of view that holds them all times `slack`. None when that would need
/// more than `max_fov_y`.
fn fit_view(
    position: Vec3,
    points: &[Vec3],
    aspect: f64,
    slack: f64,
    max_fov_y: f64,
) -> Option<(Vec3, f64)> {
    let mut dirs = Vec::with_capacity(points.len());
    for p in points {
        let d = sub(*p, position);
        let n = norm(d);
        if n < 0.05 {
            return None;
        }
        dirs.push(scale(d, 1.0 / n));
    }
    let mut widest = (dirs[0], dirs[0], 2.0);
    for (i, a) in dirs.iter().enumerate() {
        for b in &dirs[i..] {
            let cos = dot(*a, *b);
            if cos < widest.2 {
                widest = (*a, *b, cos);
            }
        }
    }
    let bisector = [
        widest.0[0] + widest.1[0],
        widest.0[1] + widest.1[1],
        widest.0[2] + widest.1[2],
    ];
    if norm(bisector) < 1e-6 {
        return None;
    }
    let forward = scale(bisector, 1.0 / norm(bisector));
    let look_at = [
        position[0] + forward[0],
        position[1] + forward[1],
        position[2] + forward[2],
    ];
    let probe = CameraSpec {
        name: String::new(),
        position,
        look_at,
        fov_y: 1.0,
        width: 1,
        height: 1,
    };
    let view = View::new(&probe)?;
    let mut need = 0.0f64;
    for p in points {
        let d = sub(*p, position);
        let z = dot(d, view.forward);
        if z < 0.05 {
            return None;
        }
        need = need
            .max((dot(d, view.up) / z).abs())
            .max((dot(d, view.right) / z).abs() / aspect);
    }
    let fov_y = 2.0 * (need * slack).max(0.2).atan();
    (fov_y <= max_fov_y).then_some((look_at, fov_y))
}

/// Chooses camera poses for a simulated scene: up to eight draws from the scene's
/// "cameras" stream; the first whose three views hold the hazard wins. None when none do.
pub fn frame(spec: &SceneSpec, sim: &Simulation, rules: &FramingRules) -> Option<Vec<CameraSpec>> {
    let steps = window_steps(spec, sim, rules.until_within);
    let path: Vec<Vec3> = steps.iter().map(|&k| sim.hazard_position(k)).collect();
    (0..FRAMING_ATTEMPTS).find_map(|k| {
        let cameras = draw(spec, k, &path, rules)?;
        hazard_in_frame(spec, sim, &cameras, rules).then_some(cameras)
    })
}

/// Camera draw `k`: positions from the "cameras" stream, aims and fields of view fitted
/// to the hazard's path.
pub fn draw(
    spec: &SceneSpec,
    k: u32,
    path: &[Vec3],
    rules: &FramingRules,
) -> Option<Vec<CameraSpec>> {
    let margin = rules.margin;
    let mut rng = crate::seeds::stream(
        spec.seed,
        spec.attempt * 1000 + k,
        &format!("cameras/{}", spec.speed_band.name()),
    );
    let (width, height) = (spec.video.width, spec.video.height);
    let aspect = width as f64 / height as f64;
    let centroid = scale(
        path.iter()
            .fold([0.0; 3], |a, p| [a[0] + p[0], a[1] + p[1], a[2] + p[2]]),
        1.0 / path.len() as f64,
    );
    let extent = path
        .iter()
        .map(|p| norm(sub(*p, centroid)))
        .fold(0.0, f64::max);
    let start = path[0];
    let o = &spec.observer;
    // Always draw every number, so one camera's draws never shift another's.
    let slack: [f64; 3] = [0, 1, 2].map(|_| rng.random_range(1.1..1.35) / (1.0 - margin));
    let side: f64 = rng.random_range(0.0..std::f64::consts::TAU);
    let dist: f64 = rng.random_range(1.4f64..2.2).max(extent * 1.8);
    let lift: f64 = rng.random_range(0.1..0.6);
    let over: [f64; 3] = [
        rng.random_range(-0.4..0.4),
        rng.random_range(-0.4..0.4),
        rng.random_range(0.9..1.5),
    ];
    let place = |name: &str, position: Vec3, slack: f64| {
        fit_view(position, path, aspect, slack, rules.max_fov_y).map(|(look_at, fov_y)| {
            CameraSpec {
                name: name.to_string(),
                position,
                look_at,
                fov_y,
                width,
                height,
            }
        })
    };
    let ego = place("ego", [o.x, o.y, o.height - 0.08], slack[0])?;
    let closeup = place(
        "closeup",
        [
            centroid[0] + side.cos() * dist,
            centroid[1] + side.sin() * dist,
            (centroid[2] + lift).clamp(0.4, spec.room.ceiling_height - 0.1),
        ],
        slack[1],
    )?;
    // A cutaway view from above the ceiling line (the renderer leaves the ceiling out),
    // offset sideways so it never looks straight down.
    let mid = [(o.x + start[0]) / 2.0, (o.y + start[1]) / 2.0];
    let overhead = place(
        "overhead",
        [
            mid[0] + over[0] - 0.7,
            mid[1] + over[1],
            spec.room.ceiling_height + over[2],
        ],
        slack[2],
    )?;
    Some(vec![ego, closeup, overhead])
}

#[cfg(test)]
mod tests {
    use crate::config::Config;
    use crate::randomize::{randomize, SceneKey};
    use crate::simulate::Obstacles;
    use crate::spec::{Selection, ShapeSpec};
    use rh_catalog::Catalog;

    #[test]
    fn furniture_blocks_the_line_of_sight() {
        let catalog = Catalog::embedded().unwrap();
        let config = Config::embedded().unwrap();
        let selection = Selection {
            family: "object_drop".into(),
            object_id: "apple".into(),
            room_id: "kitchen".into(),
            description: None,
            planner: None,
        };
        let spec = randomize(&selection, &SceneKey::new(0, 0, 0), &catalog, &config).unwrap();
        let table = &spec.bodies[spec.source_support.unwrap()];
        let ShapeSpec::Box { half_extents } = table.parts[0].shape else {
            panic!("the table is a box")
        };
        let [x, y, _] = table.position;
        let top = table.position[2] + half_extents[2];
        let obstacles = Obstacles::of(&spec);
        // Straight through the table's middle, under its top: blocked.
        let low = top / 2.0;
        assert!(obstacles.blocks([x - 3.0, y, low], [x + 3.0, y, low]));
        assert!(obstacles.blocks([x, y - 3.0, low], [x, y + 3.0, low]));
        // Over the top, or beside it: clear.
        assert!(!obstacles.blocks([x - 3.0, y, top + 0.2], [x + 3.0, y, top + 0.2]));
        assert!(!obstacles.blocks([x + 3.0, y + 3.0, low], [x + 3.0, y - 3.0, low]));
        // The hazard itself (a dynamic body) never blocks.
        let h = spec.hazard_body().position;
        assert!(!obstacles.blocks([h[0], h[1], h[2] + 1.0], h));
    }
}
