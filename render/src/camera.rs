//! Camera matrices for the GPU, built on the basis of `view::View` (the in-frame
//! validator's camera model), and the full-event video's outside camera.

use super::FULL_EVENT;
use rh_physics::simulate::Simulation;
use rh_physics::spec::vec3::{add, dot, norm, scale, sub};
use rh_physics::spec::{CameraSpec, SceneSpec, Vec3};
use rh_scenes::view;

/// Column-major view-projection matrix agreeing with `view::View::project`:
/// clip x/w and y/w are exactly its normalised coordinates; depth maps [near, far] to [0, 1].
pub fn view_proj(cam: &CameraSpec) -> [[f32; 4]; 4] {
    to_cols(view_proj_rows(cam))
}

/// [`view_proj`] in f64, row-major.
fn view_proj_rows(cam: &CameraSpec) -> [[f64; 4]; 4] {
    let (r, u, f) = view::draw_basis(cam);
    let e = cam.position;
    let ty = (cam.fov_y / 2.0).tan();
    let tx = ty * cam.width as f64 / cam.height as f64;
    let (near, far) = (0.05, 60.0);
    let a = far / (far - near);
    let b = -near * far / (far - near);
    [
        [r[0] / tx, r[1] / tx, r[2] / tx, -dot(r, e) / tx],
        [u[0] / ty, u[1] / ty, u[2] / ty, -dot(u, e) / ty],
        [a * f[0], a * f[1], a * f[2], -a * dot(f, e) + b],
        [f[0], f[1], f[2], -dot(f, e)],
    ]
}

/// Inverse of [`view_proj`] in f64, row-major: (NDC x, y, depth, 1) to homogeneous
/// world coordinates (Gauss-Jordan elimination with partial pivoting).
pub(super) fn inverse_view_proj_rows(cam: &CameraSpec) -> [[f64; 4]; 4] {
    let mut a = view_proj_rows(cam);
    let mut inv = [[0.0f64; 4]; 4];
    for (i, row) in inv.iter_mut().enumerate() {
        row[i] = 1.0;
    }
    for c in 0..4 {
        let p = (c..4)
            .max_by(|&i, &j| a[i][c].abs().total_cmp(&a[j][c].abs()))
            .unwrap_or(c);
        a.swap(c, p);
        inv.swap(c, p);
        let d = a[c][c];
        for j in 0..4 {
            a[c][j] /= d;
            inv[c][j] /= d;
        }
        for r in (0..4).filter(|&r| r != c) {
            let f = a[r][c];
            for j in 0..4 {
                a[r][j] -= f * a[c][j];
                inv[r][j] -= f * inv[c][j];
            }
        }
    }
    inv
}

pub(super) fn to_cols(rows: [[f64; 4]; 4]) -> [[f32; 4]; 4] {
    let mut m = [[0.0f32; 4]; 4];
    for (i, row) in rows.iter().enumerate() {
        for (j, v) in row.iter().enumerate() {
            m[j][i] = *v as f32;
        }
    }
    m
}

/// The outside camera of the full-event video: beside the line from the observer to the
/// hazard's start, raised, aimed at everything that moves, with a field of view that
/// holds the observer and the hazard's whole path.
pub fn full_event_camera(
    spec: &SceneSpec,
    sim: &Simulation,
    width: u32,
    height: u32,
) -> CameraSpec {
    let o = &spec.observer;
    let mut pts: Vec<Vec3> = vec![[o.x, o.y, 0.0], [o.x, o.y, o.height]];
    let stride = (sim.steps() / 60).max(1);
    let mut k = 0;
    while k <= sim.steps() {
        pts.push(sim.hazard_position(k));
        k += stride;
    }
    pts.push(sim.hazard_position(sim.steps()));
    outside_camera(spec, sim.hazard_position(0), &pts, width, height)
}

/// The outside camera for a set of points to hold in view (`full_event_camera`'s
/// placement): beside the line from the observer to `start`, raised, aimed at the
/// points' centre, with a field of view that holds them all.
pub(super) fn outside_camera(
    spec: &SceneSpec,
    start: Vec3,
    pts: &[Vec3],
    width: u32,
    height: u32,
) -> CameraSpec {
    let o = &spec.observer;
    let n = pts.len() as f64;
    let c = scale(pts.iter().fold([0.0; 3], |a, p| add(a, *p)), 1.0 / n);
    let mut d = [start[0] - o.x, start[1] - o.y, 0.0];
    if norm(d) < 1e-3 {
        d = [o.yaw.cos(), o.yaw.sin(), 0.0];
    }
    let d = scale(d, 1.0 / norm(d));
    // Perpendicular, pulled back a little behind the observer.
    let side = [-d[1] * 0.87 - d[0] * 0.5, d[0] * 0.87 - d[1] * 0.5, 0.0];
    let aspect = width as f64 / height as f64;
    let mut dist = 3.0;
    let mut best = None;
    for _ in 0..8 {
        let position = [
            c[0] + side[0] * dist,
            c[1] + side[1] * dist,
            (c[2] + 0.9).max(1.7),
        ];
        let mut cam = CameraSpec {
            name: FULL_EVENT.into(),
            position,
            look_at: c,
            fov_y: 1.0,
            width,
            height,
        };
        let (r, u, f) = view::draw_basis(&cam);
        let mut need = 0.0f64;
        let mut behind = false;
        for p in pts {
            let v = sub(*p, position);
            let z = dot(v, f);
            if z < 0.3 {
                behind = true;
                break;
            }
            need = need
                .max((dot(v, u) / z).abs())
                .max((dot(v, r) / z).abs() / aspect);
        }
        if !behind {
            cam.fov_y = 2.0 * (need * 1.2).max(0.25).atan();
            let ok = cam.fov_y <= 1.4;
            best = Some(cam);
            if ok {
                break;
            }
        }
        dist *= 1.3;
    }
    best.unwrap_or(CameraSpec {
        name: FULL_EVENT.into(),
        position: [c[0] + side[0] * 6.0, c[1] + side[1] * 6.0, 2.5],
        look_at: c,
        fov_y: 1.2,
        width,
        height,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use rh_scenes::view::View;

    #[test]
    fn projection_matrix_agrees_with_the_validator_camera_model() {
        let cam = CameraSpec {
            name: "t".into(),
            position: [0.3, -2.0, 1.4],
            look_at: [0.5, 0.6, 0.8],
            fov_y: 0.9,
            width: 1280,
            height: 720,
        };
        let m = view_proj(&cam);
        let view = View::new(&cam).unwrap();
        for p in [
            [0.5, 0.6, 0.8],
            [1.0, 1.0, 0.2],
            [-0.4, 0.9, 1.9],
            [0.2, -0.5, 1.0],
        ] {
            let [x, y] = view.project(p).unwrap();
            let v = [p[0] as f32, p[1] as f32, p[2] as f32, 1.0];
            let clip: Vec<f32> = (0..4)
                .map(|r| (0..4).map(|c| m[c][r] * v[c]).sum())
                .collect();
            assert!((clip[0] / clip[3] - x as f32).abs() < 1e-4, "{p:?}");
            assert!((clip[1] / clip[3] - y as f32).abs() < 1e-4, "{p:?}");
            let z = clip[2] / clip[3];
            assert!((0.0..=1.0).contains(&z));
        }
    }
}
