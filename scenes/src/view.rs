//! Camera geometry shared by framing (`cameras`), the visibility rule (`visibility`) and
//! the renderer: a camera's basis with +z up, a pinhole projection, and the steps of
//! the observation window that the framing and visibility rules check.

use rh_physics::simulate::Simulation;
use rh_physics::spec::vec3::{cross, dot, norm, scale, sub};
use rh_physics::spec::{CameraSpec, SceneSpec, Vec3};

/// The unit vector from a camera's position toward its `look_at`.
fn forward(camera: &CameraSpec) -> Vec3 {
    let f = sub(camera.look_at, camera.position);
    scale(f, 1.0 / norm(f).max(1e-12))
}

/// The right-handed basis (right, up, forward) with the given `right` direction.
pub(crate) fn complete_basis(f: Vec3, r: Vec3) -> (Vec3, Vec3, Vec3) {
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
pub fn window_steps(spec: &SceneSpec, sim: &Simulation, until_within: f64) -> Vec<u32> {
    spec.observation_frame_steps(sim.steps())
        .into_iter()
        .take_while(|&k| {
            k == 0 || spec.observer.torso_axis_distance(sim.hazard_position(k)) > until_within
        })
        .collect()
}
