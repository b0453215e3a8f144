//! The head camera's calibration (specification §7, "the ego camera is calibrated"): a pinhole
//! camera without lens distortion, its intrinsics in pixels and its pose in the world
//! and in the observer's body frame. Plain numbers, defined once: the dataset writer
//! fills the `ego_*` camera columns from it, the canonical prompt states it, and any
//! user can project a point with the stored columns ([`HeadCamera::project_world`] is
//! the formula the columns' descriptions give).
//!
//! Conventions (OpenCV's): pixel `(u, v)` has u to the right and v down, measured from
//! the top-left corner of the image (the centre of pixel (i, j) is (i + 0.5, j + 0.5));
//! the camera frame has x right, y down, z along the optical axis. A rotation is stored
//! row-major as the 3 × 3 matrix whose columns are the camera's x, y, z axes in the
//! frame named (world or body): a point `p` of that frame is at `Rᵀ (p − position)` in
//! camera coordinates. The camera never rolls: its x axis is horizontal.

type Vec3 = [f64; 3];

fn sub(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn dot(a: Vec3, b: Vec3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross(a: Vec3, b: Vec3) -> Vec3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn unit(a: Vec3) -> Option<Vec3> {
    let n = dot(a, a).sqrt();
    (n > 1e-12).then(|| a.map(|c| c / n))
}

/// A camera's calibration as the dataset stores it.
#[derive(Debug, Clone, PartialEq)]
pub struct HeadCamera {
    /// Image size (px).
    pub width: u32,
    pub height: u32,
    /// Vertical and horizontal field of view (rad).
    pub fov_y: f64,
    pub fov_x: f64,
    /// `[fx, fy, cx, cy]` (px): u = fx·x/z + cx, v = fy·y/z + cy.
    pub intrinsics: [f64; 4],
    /// Optical centre in the world frame (m).
    pub position_world: Vec3,
    /// Row-major rotation, columns = the camera's axes in the world frame.
    pub rotation_world: [f64; 9],
    /// Optical centre in the body frame (origin at the pelvis, x forward, y left, z up).
    pub position_body: Vec3,
    /// Row-major rotation, columns = the camera's axes in the body frame.
    pub rotation_body: [f64; 9],
    /// Where the optical axis points in the body frame: yaw about z from body +x (rad,
    /// positive to the left) and pitch above the horizontal (rad, negative looking down).
    pub yaw_body: f64,
    pub pitch_body: f64,
}

/// The observer's body frame in the world: pelvis position and heading.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodyFrame {
    pub x: f64,
    pub y: f64,
    pub yaw: f64,
    pub pelvis_z: f64,
}

impl BodyFrame {
    /// The body's axes (x forward, y left, z up) in the world.
    fn axes(&self) -> [Vec3; 3] {
        let (s, c) = self.yaw.sin_cos();
        [[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]]
    }

    /// A world point in body coordinates.
    pub fn to_body(&self, p: Vec3) -> Vec3 {
        let d = sub(p, [self.x, self.y, self.pelvis_z]);
        self.axes().map(|a| dot(a, d))
    }

    /// A world direction in body coordinates.
    fn dir_to_body(&self, d: Vec3) -> Vec3 {
        self.axes().map(|a| dot(a, d))
    }
}

/// Row-major matrix with the given columns.
fn from_columns(c: [Vec3; 3]) -> [f64; 9] {
    [
        c[0][0], c[1][0], c[2][0], c[0][1], c[1][1], c[2][1], c[0][2], c[1][2], c[2][2],
    ]
}

impl HeadCamera {
    /// The calibration of a camera at `position` looking at `look_at` with +z up (no
    /// roll) and vertical field of view `fov_y`, for an observer whose body frame is
    /// `body`. None when it looks (nearly) straight up or down.
    pub fn new(
        position: Vec3,
        look_at: Vec3,
        fov_y: f64,
        (width, height): (u32, u32),
        body: BodyFrame,
    ) -> Option<HeadCamera> {
        let f = unit(sub(look_at, position))?;
        let r = cross(f, [0.0, 0.0, 1.0]);
        if dot(r, r).sqrt() < 1e-3 {
            return None;
        }
        let r = unit(r)?;
        // Image up is r × f; the camera's y axis (image down) is its opposite.
        let down = cross(f, r);
        let t = (fov_y / 2.0).tan();
        let aspect = width as f64 / height as f64;
        let focal = height as f64 / 2.0 / t;
        let axes_body = [r, down, f].map(|a| body.dir_to_body(a));
        let fb = axes_body[2];
        Some(HeadCamera {
            width,
            height,
            fov_y,
            fov_x: 2.0 * (t * aspect).atan(),
            intrinsics: [focal, focal, width as f64 / 2.0, height as f64 / 2.0],
            position_world: position,
            rotation_world: from_columns([r, down, f]),
            position_body: body.to_body(position),
            rotation_body: from_columns(axes_body),
            yaw_body: fb[1].atan2(fb[0]),
            pitch_body: fb[2].clamp(-1.0, 1.0).asin(),
        })
    }

    /// Pixel `(u, v)` of a point given in the frame of `(position, rotation)`; None
    /// behind the camera (or in its plane).
    fn project(position: Vec3, rotation: &[f64; 9], k: [f64; 4], p: Vec3) -> Option<[f64; 2]> {
        let d = sub(p, position);
        let col = |j: usize| [rotation[j], rotation[3 + j], rotation[6 + j]];
        let [x, y, z] = [0, 1, 2].map(|j| dot(col(j), d));
        (z > 1e-9).then(|| [k[0] * x / z + k[2], k[1] * y / z + k[3]])
    }

    /// Pixel `(u, v)` of a world point (None behind the camera): with the stored columns,
    /// `[x, y, z] = Rᵀ (p − position)` and `u = fx·x/z + cx`, `v = fy·y/z + cy`.
    pub fn project_world(&self, p: Vec3) -> Option<[f64; 2]> {
        Self::project(
            self.position_world,
            &self.rotation_world,
            self.intrinsics,
            p,
        )
    }

    /// Pixel `(u, v)` of a point in the body frame (None behind the camera).
    pub fn project_body(&self, p: Vec3) -> Option<[f64; 2]> {
        Self::project(self.position_body, &self.rotation_body, self.intrinsics, p)
    }

    /// The intrinsics of the image scaled to `width` × `height` (as the prompt sends it).
    pub fn intrinsics_at(&self, width: u32, height: u32) -> [f64; 4] {
        let (sx, sy) = (
            width as f64 / self.width as f64,
            height as f64 / self.height as f64,
        );
        let k = self.intrinsics;
        [k[0] * sx, k[1] * sy, k[2] * sx, k[3] * sy]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const BODY: BodyFrame = BodyFrame {
        x: 2.0,
        y: -1.0,
        yaw: 0.5,
        pelvis_z: 0.79,
    };

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() < 1e-9
    }

    /// A camera 0.45 m above the pelvis looking 30° left and 20° down of the body's
    /// forward axis: its stated pose, and points on its axis and off it project where
    /// the pinhole model with the stored numbers puts them.
    #[test]
    fn a_constructed_camera_projects_points_to_the_stated_pixels() {
        let (yaw, pitch) = (30f64.to_radians(), -20f64.to_radians());
        let heading = BODY.yaw + yaw;
        let position = [BODY.x, BODY.y, BODY.pelvis_z + 0.45];
        let dir = [
            pitch.cos() * heading.cos(),
            pitch.cos() * heading.sin(),
            pitch.sin(),
        ];
        let look_at = [0, 1, 2].map(|i| position[i] + 2.0 * dir[i]);
        let fov_y = 60f64.to_radians();
        let cam = HeadCamera::new(position, look_at, fov_y, (1280, 720), BODY).unwrap();
        assert!(
            close(cam.yaw_body, yaw) && close(cam.pitch_body, pitch),
            "{cam:?}"
        );
        assert!(cam
            .position_body
            .iter()
            .zip([0.0, 0.0, 0.45])
            .all(|(a, b)| close(*a, b)));
        let f = 360.0 / (30f64.to_radians()).tan();
        assert!(close(cam.intrinsics[0], f) && close(cam.intrinsics[1], f));
        assert_eq!([cam.intrinsics[2], cam.intrinsics[3]], [640.0, 360.0]);
        assert!(close(
            (cam.fov_x / 2.0).tan(),
            (fov_y / 2.0).tan() * 1280.0 / 720.0
        ));
        // A point on the optical axis is at the principal point, in both frames.
        let on_axis = [0, 1, 2].map(|i| position[i] + 3.0 * dir[i]);
        let [u, v] = cam.project_world(on_axis).unwrap();
        assert!(close(u, 640.0) && close(v, 360.0), "{u} {v}");
        let [u, v] = cam.project_body(BODY.to_body(on_axis)).unwrap();
        assert!(close(u, 640.0) && close(v, 360.0), "{u} {v}");
        // 0.5 m to the camera's right and 0.25 m up at 3 m depth: (fx/6, −fy/12) from it.
        let r = [heading.sin(), -heading.cos(), 0.0];
        let up = cross(r, dir);
        let p = [0, 1, 2].map(|i| on_axis[i] + 0.5 * r[i] + 0.25 * up[i]);
        let [u, v] = cam.project_world(p).unwrap();
        assert!(
            close(u, 640.0 + f / 6.0) && close(v, 360.0 - f / 12.0),
            "{u} {v}"
        );
        let [ub, vb] = cam.project_body(BODY.to_body(p)).unwrap();
        assert!(close(u, ub) && close(v, vb));
        // Behind the camera: no pixel.
        let behind = [0, 1, 2].map(|i| position[i] - dir[i]);
        assert!(cam.project_world(behind).is_none());
        // Scaled to 768 × 432, every intrinsic scales by 0.6.
        let k = cam.intrinsics_at(768, 432);
        assert!(close(k[0], 0.6 * f) && close(k[2], 384.0) && close(k[3], 216.0));
    }

    #[test]
    fn a_camera_looking_straight_down_has_no_upright_calibration() {
        let p = [0.0, 0.0, 1.2];
        assert!(HeadCamera::new(p, [0.0, 0.0, 0.0], 1.0, (640, 480), BODY).is_none());
    }
}
