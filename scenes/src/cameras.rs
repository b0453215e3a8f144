//! Camera framing (specification §7): `ego`, `closeup`, `overhead` — one set per scene group,
//! framed on the union of its speed bands' hazard paths (the bands differ only in
//! speed), placed from the group's "cameras" stream with a retry that keeps the hazard
//! in every camera's frame and visible (`visibility`) through every band's observation
//! window. Cameras never touch physics, so framing after the simulation changes no
//! state hash; the chosen poses are stored in the spec.

use crate::view::{complete_basis, window_steps, View};
use crate::visibility;
use rand::RngExt;
use rh_physics::obstacles::Obstacles;
use rh_physics::simulate::Simulation;
use rh_physics::spec::vec3::{add, cross, dot, norm, scale, sub};
use rh_physics::spec::{CameraSpec, SceneSpec, Vec3};

pub const CAMERA_NAMES: [&str; 3] = ["ego", "closeup", "overhead"];
const FRAMING_ATTEMPTS: u32 = 8;

pub use crate::config::FramingRules;

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
    !cameras.is_empty()
        && cameras.iter().all(|camera| {
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

/// The hazard's path through the checked window of every band of a group: its centres
/// (for aiming) and, per frame, its sample points (for the field of view and sizes).
pub struct GroupPath {
    centres: Vec<Vec3>,
    frames: Vec<Vec<Vec3>>,
    all: Vec<Vec3>,
}

impl GroupPath {
    pub fn of(bands: &[(&SceneSpec, &Simulation)], rules: &FramingRules) -> GroupPath {
        let mut path = GroupPath {
            centres: vec![],
            frames: vec![],
            all: vec![],
        };
        for (spec, sim) in bands {
            for k in window_steps(spec, sim, rules.until_within) {
                path.centres.push(sim.hazard_position(k));
                let points = visibility::hazard_points_at(spec, sim, k);
                path.all.extend_from_slice(&points);
                path.frames.push(points);
            }
        }
        path
    }
}

/// Chooses ONE set of camera poses for a scene group (its speed bands `bands`, which
/// share everything but the speed), framed on the union of the bands' hazard paths:
/// up to eight draws from the group's "cameras" stream; the first whose three views
/// hold the hazard (`hazard_in_frame`) and show it (`visibility`) in every band wins.
/// When none does, the first draw that could be aimed at all is returned (the
/// validators then say which check failed); None when no draw could be aimed.
pub fn frame_group(
    bands: &[(&SceneSpec, &Simulation)],
    rules: &FramingRules,
) -> Option<Vec<CameraSpec>> {
    let spec = bands.first()?.0;
    let path = GroupPath::of(bands, rules);
    let mut fallback = None;
    for k in 0..FRAMING_ATTEMPTS {
        let Some(cameras) = draw(spec, k, &path, rules) else {
            continue;
        };
        let shows = bands.iter().all(|(spec, sim)| {
            hazard_in_frame(spec, sim, &cameras, rules)
                && visibility::assess_cameras(spec, sim, &cameras, rules).passes(rules)
                && crate::ego::ego_pixels_pass(spec, sim, &cameras, rules)
        });
        if shows {
            return Some(cameras);
        }
        fallback.get_or_insert(cameras);
    }
    fallback
}

/// Chooses camera poses for a single simulated scene (a group of one; see `frame_group`).
pub fn frame(spec: &SceneSpec, sim: &Simulation, rules: &FramingRules) -> Option<Vec<CameraSpec>> {
    frame_group(&[(spec, sim)], rules)
}

/// A camera basis looking along `forward` (+z up).
fn basis_along(forward: Vec3) -> Option<(Vec3, Vec3, Vec3)> {
    let r = cross(forward, [0.0, 0.0, 1.0]);
    (norm(r) >= 1e-3).then(|| complete_basis(forward, r))
}

/// Aims a camera at `position` on a group's hazard path: it looks along the bisector of
/// the two most widely separated directions to the path's centres, then at the middle
/// of the box around every sample point in front of it. The vertical field of view
/// holds the path's centres times `slack`, and the hazard's whole extent times `slack`
/// as far as `max_fov_y` allows (a door beside the observer cannot be seen whole); it
/// is widened where needed so that the hazard's projected size stays under
/// `rules.size_band_px[1]`, and narrowed to the least slack that keeps the centres in
/// view where the hazard would be smaller than `size_band_px[0]`. None when the path's
/// centres alone need more than `max_fov_y`.
fn fit_view(
    position: Vec3,
    path: &GroupPath,
    (width, height): (u32, u32),
    slack: f64,
    rules: &FramingRules,
) -> Option<(Vec3, f64)> {
    let aspect = width as f64 / height as f64;
    let mut dirs = Vec::with_capacity(path.centres.len());
    for p in &path.centres {
        let d = sub(*p, position);
        let n = norm(d);
        if n < 0.05 {
            return None;
        }
        dirs.push(scale(d, 1.0 / n));
    }
    let mut widest = (*dirs.first()?, dirs[0], 2.0);
    for (i, a) in dirs.iter().enumerate() {
        for b in &dirs[i..] {
            let cos = dot(*a, *b);
            if cos < widest.2 {
                widest = (*a, *b, cos);
            }
        }
    }
    let bisector = add(widest.0, widest.1);
    if norm(bisector) < 1e-6 {
        return None;
    }
    // Re-aim at the middle of the sample points' box (the path's extent, not its centres).
    let (r, u, f) = basis_along(scale(bisector, 1.0 / norm(bisector)))?;
    let (lo, hi) = tangent_box(position, (r, u, f), &path.all)?;
    let mid = [(lo[0] + hi[0]) / 2.0, (lo[1] + hi[1]) / 2.0];
    let aim = add(f, add(scale(r, mid[0]), scale(u, mid[1])));
    let forward = scale(aim, 1.0 / norm(aim));
    let basis = basis_along(forward)?;
    let need = |points: &[Vec3]| {
        tangent_box(position, basis, points).map(|(lo, hi)| {
            let x = lo[0].abs().max(hi[0].abs()) / aspect;
            x.max(lo[1].abs()).max(hi[1].abs())
        })
    };
    // Every centre must be in front of the camera; sample points behind it are left out.
    if path
        .centres
        .iter()
        .any(|p| dot(sub(*p, position), forward) < 0.05)
    {
        return None;
    }
    let need_path = need(&path.centres)?;
    let need_all = need(&path.all)?;
    // Projected size in px is tangent size × (height / 2) / tan(fov_y / 2).
    let sizes: Vec<f64> = path
        .frames
        .iter()
        .map(|points| visibility::tangent_size(position, basis, points))
        .collect();
    let half_h = height as f64 / 2.0;
    let [band_lo, band_hi] = rules.size_band_px;
    let widest_for_small = sizes.iter().copied().fold(f64::MAX, f64::min) * half_h / band_lo;
    let narrowest_for_large = sizes.iter().copied().fold(0.0, f64::max) * half_h / band_hi;
    let t_max = (rules.max_fov_y / 2.0).tan();
    let mut t = (need_path * slack)
        .max((need_all * slack).max(narrowest_for_large).min(t_max))
        .max(0.2);
    if t > widest_for_small {
        // The hazard would look too small: the least slack that keeps its path in view.
        let least = 1.02 / (1.0 - rules.margin);
        t = widest_for_small.max(need_path * least).max(0.2);
    }
    let fov_y = 2.0 * t.atan();
    (fov_y <= rules.max_fov_y + 1e-9)
        .then_some((add(position, forward), fov_y.min(rules.max_fov_y)))
}

/// The box, in tangent units of the basis (right, up, forward) from `origin`, around the
/// points in front of the camera: (min, max); None when no point is.
fn tangent_box(
    origin: Vec3,
    (r, u, f): (Vec3, Vec3, Vec3),
    points: &[Vec3],
) -> Option<([f64; 2], [f64; 2])> {
    let (mut lo, mut hi) = ([f64::MAX; 2], [f64::MIN; 2]);
    for p in points {
        let d = sub(*p, origin);
        let z = dot(d, f);
        if z < 0.05 {
            continue;
        }
        let t = [dot(d, r) / z, dot(d, u) / z];
        for a in 0..2 {
            lo[a] = lo[a].min(t[a]);
            hi[a] = hi[a].max(t[a]);
        }
    }
    (lo[0] <= hi[0]).then_some((lo, hi))
}

/// Camera draw `k` for a group: positions from the group's "cameras" stream, aims and
/// fields of view fitted to the hazard's path (`fit_view`). The closeup stands outside
/// the sector behind the observer (seen from the path's centroid), the overhead camera
/// on the far side of the path from the observer, so the observer's body does not stand
/// between them and the event.
pub fn draw(
    spec: &SceneSpec,
    k: u32,
    path: &GroupPath,
    rules: &FramingRules,
) -> Option<Vec<CameraSpec>> {
    let mut rng = rh_physics::seeds::stream(spec.seed, spec.attempt * 1000 + k, "cameras");
    let (width, height) = (spec.video.width, spec.video.height);
    let centroid = scale(
        path.centres.iter().fold([0.0; 3], |a, p| add(a, *p)),
        1.0 / path.centres.len().max(1) as f64,
    );
    let extent = path
        .centres
        .iter()
        .map(|p| norm(sub(*p, centroid)))
        .fold(0.0, f64::max);
    // The closeup stands far enough that the path fits a moderate field of view and a
    // large hazard (a door, a bookcase) stays well inside the frame.
    let size = 2.0 * spec.hazard_body().bounding_radius();
    let o = &spec.observer;
    // Always draw every number, so one camera's draws never shift another's.
    let slack: [f64; 3] = [0, 1, 2].map(|_| rng.random_range(1.1..1.35) / (1.0 - rules.margin));
    let sides: [f64; CANDIDATES] = std::array::from_fn(|_| {
        rng.random_range(OBSERVER_SECTOR..std::f64::consts::TAU - OBSERVER_SECTOR)
    });
    let dist: f64 = rng
        .random_range(1.4f64..2.2)
        .max(extent * 1.8)
        .max(size * 1.6);
    let lift: f64 = rng.random_range(0.1..0.6);
    let over: [f64; 3] = [
        rng.random_range(0.3..1.0),
        rng.random_range(-0.5..0.5),
        rng.random_range(0.4..1.1),
    ];
    let place = |name: &str, position: Vec3, slack: f64| {
        fit_view(position, path, (width, height), slack, rules).map(|(look_at, fov_y)| CameraSpec {
            name: name.to_string(),
            position,
            look_at,
            fov_y,
            width,
            height,
        })
    };
    let ego = place("ego", [o.x, o.y, o.height - 0.08], slack[0])?;
    // Horizontal direction from the path's centroid to the observer.
    let to_observer = {
        let d = [o.x - centroid[0], o.y - centroid[1], 0.0];
        if norm(d) < 1e-6 {
            [1.0, 0.0, 0.0]
        } else {
            scale(d, 1.0 / norm(d))
        }
    };
    let toward = to_observer[1].atan2(to_observer[0]);
    let occluders = visibility::Occluders::of(spec, rules.observer_margin);
    // The first candidate with a clear line of sight to the whole path (no wall, shelf or
    // observer in the way), else the first.
    let clear = |candidates: Vec<Vec3>| {
        candidates
            .iter()
            .copied()
            .find(|c| !path.centres.iter().any(|p| occluders.blocks(*c, *p)))
            .unwrap_or(candidates[0])
    };
    let closeup_at = clear(
        sides
            .iter()
            .map(|side| {
                let heading = toward + side;
                [
                    centroid[0] + heading.cos() * dist,
                    centroid[1] + heading.sin() * dist,
                    (centroid[2] + lift).clamp(0.4, spec.room.ceiling_height - 0.1),
                ]
            })
            .collect(),
    );
    let closeup = place("closeup", closeup_at, slack[1])?;
    // A cutaway view from above the ceiling line (the renderer leaves the ceiling out),
    // off to one side of the path so it never looks straight down: preferably beyond the
    // path's far end as seen from the observer (the observer then stands behind the
    // event, and the path is foreshortened, so the hazard looks larger), else beside it.
    let overhead_at = clear(
        OVERHEAD_HEADINGS
            .iter()
            .map(|turn| {
                let heading = toward + std::f64::consts::PI + turn;
                let (c, s) = (heading.cos(), heading.sin());
                let out = extent + over[0];
                [
                    centroid[0] + c * out - s * over[1],
                    centroid[1] + s * out + c * over[1],
                    spec.room.ceiling_height + over[2],
                ]
            })
            .collect(),
    );
    let overhead = place("overhead", overhead_at, slack[2])?;
    Some(vec![ego, closeup, overhead])
}

/// Candidate headings the closeup camera draws per camera draw.
const CANDIDATES: usize = 6;

/// Overhead headings tried in turn, relative to "beyond the path, away from the observer".
const OVERHEAD_HEADINGS: [f64; 5] = [0.0, 1.2, -1.2, 2.2, -2.2];

/// Half-width (rad) of the sector, seen from the path's centroid around the direction to
/// the observer, where the closeup camera is never placed (the observer would stand
/// between it and the event).
const OBSERVER_SECTOR: f64 = 0.9;

#[cfg(test)]
mod tests {
    use crate::config::Config;
    use crate::randomize::{randomize, SceneKey};
    use rh_catalog::Catalog;
    use rh_physics::obstacles::Obstacles;
    use rh_physics::spec::{Selection, ShapeSpec};

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
