//! Launch building blocks shared by several families: an object pushed off the edge of a
//! horizontal surface ([`EdgeLaunch`]) or creeping down a tilted board or shelf
//! ([`TiltedLaunch`], [`creep_tilt`]), and the room spans that straight-line events run
//! along ([`room_span`], [`span_start`]).

use super::*;

/// Shared layout for "pushed off the edge of a horizontal surface" families
/// (object_drop from a table, shelf_slide from a high shelf, rolling_ball).
pub struct EdgeLaunch {
    pub surface_name: &'static str,
    pub surface_height: f64,
    pub surface_half: [f64; 2],
    pub surface_friction: f64,
    pub heading_angle: f64,
    /// Distance of the hazard's centre behind the surface edge (m); its front may overhang.
    pub com_to_edge: f64,
    /// Lateral position of the hazard along the edge (m, from the edge's centre).
    pub lateral: f64,
    /// Yaw of the object relative to the heading (rad).
    pub relative_yaw: f64,
    pub origin: [f64; 2],
    /// A solid block from the floor (table, cabinet) or a thin board (shelf).
    pub board_thickness: Option<f64>,
    pub rolling: bool,
}

impl EdgeLaunch {
    /// Builds the surface and the hazard on it, moving toward the edge at `speed`.
    pub fn build(&self, object: &Object, speed: f64) -> (Vec<BodySpec>, [f64; 2], Vec3) {
        let dir = heading(self.heading_angle);
        let perp = [-dir[1], dir[0]];
        let h = self.surface_height;
        let (thickness, centre_z) = match self.board_thickness {
            Some(t) => (t, h - t / 2.0),
            None => (h, h / 2.0),
        };
        // The surface's local x axis points along the heading, so its front edge is at
        // +surface_half[0] from its centre.
        let surface_centre = [self.origin[0], self.origin[1]];
        let surface = fixed_box(
            self.surface_name,
            [self.surface_half[0], self.surface_half[1], thickness / 2.0],
            [surface_centre[0], surface_centre[1], centre_z],
            yaw_quat(self.heading_angle),
            self.surface_friction,
            0.2,
        );
        let edge = [
            surface_centre[0] + dir[0] * self.surface_half[0],
            surface_centre[1] + dir[1] * self.surface_half[0],
        ];
        let back = self.com_to_edge;
        let pos = [
            edge[0] - dir[0] * back + perp[0] * self.lateral,
            edge[1] - dir[1] * back + perp[1] * self.lateral,
            h + bottom_offset(object),
        ];
        let linvel = [dir[0] * speed, dir[1] * speed, 0.0];
        let angvel = if self.rolling {
            // Rolling without slipping on a +z surface: v + ω × (−r ẑ) = 0 gives
            // ω = (−v_y, v_x, 0) / r.
            let r = bottom_offset(object).max(1e-3);
            [-dir[1] * speed / r, dir[0] * speed / r, 0.0]
        } else {
            [0.0; 3]
        };
        let hazard = hazard_body(
            object,
            pos,
            yaw_quat(self.heading_angle + self.relative_yaw),
            linvel,
            angvel,
        );
        (vec![surface, hazard], edge, pos)
    }
}

/// A heading along one of the room's four diagonal directions (drawn uniformly), turned by
/// up to `jitter` rad: the longest straight run the room offers, for hazards that travel
/// toward the observer from afar. Always makes two draws.
pub fn diagonal_heading(rng: &mut ChaCha8Rng, room: &Room, jitter: f64) -> f64 {
    let which = uniform(rng, 0.0, 4.0).floor().min(3.0) as usize;
    let turn = uniform(rng, -jitter, jitter);
    let base = room.size[1].atan2(room.size[0]);
    let pi = std::f64::consts::PI;
    [base, pi - base, pi + base, -base][which] + turn
}

/// Length of the longest segment along `dir` through the room's centre that keeps
/// `margin` from every wall (the room is centred on the origin).
pub fn room_span(room: &Room, dir: [f64; 2], margin: f64) -> f64 {
    let half = [
        (room.size[0] / 2.0 - margin).max(0.0),
        (room.size[1] / 2.0 - margin).max(0.0),
    ];
    (0..2)
        .map(|k| {
            if dir[k].abs() < 1e-9 {
                f64::INFINITY
            } else {
                2.0 * half[k] / dir[k].abs()
            }
        })
        .fold(f64::INFINITY, f64::min)
}

/// Start of a segment of `length` along `dir` centred in the room, slid along `dir` by a
/// drawn share of whatever room is left over (`room_span` with `margin`). Always makes
/// one draw.
pub fn span_start(
    rng: &mut ChaCha8Rng,
    room: &Room,
    dir: [f64; 2],
    length: f64,
    margin: f64,
) -> [f64; 2] {
    let slack = (room_span(room, dir, margin) - length).max(0.0);
    let s = uniform(rng, -0.5, 0.5) * slack - length / 2.0;
    [dir[0] * s, dir[1] * s]
}

/// Tilt (rad) of a board on which `object` accelerates down the slope at `accel` (m/s²)
/// from rest: an object resting on a ball (a single sphere, a kettlebell) rolls without
/// slipping (`a = 5/7·g·sin β`, a solid ball),
/// anything else slides against the combined friction `mu` (`a = g (sin β − μ cos β)`).
/// A slope just steeper than the friction angle makes a slow creep that always goes on.
pub fn creep_tilt(object: &Object, mu: f64, accel: f64) -> f64 {
    if rests_on_a_ball(object) {
        (7.0 * accel / (5.0 * GRAVITY)).clamp(0.0, 1.0).asin()
    } else {
        let phi = mu.atan();
        phi + (accel / (GRAVITY * (1.0 + mu * mu).sqrt()))
            .clamp(0.0, 1.0)
            .asin()
    }
}

/// Whether the object's lowest point is on a sphere part (it rolls rather than slides).
pub fn rests_on_a_ball(object: &Object) -> bool {
    let bottom = bottom_offset(object);
    object
        .parts
        .iter()
        .any(|p| p.shape == ShapeKind::Sphere && p.half_extents()[2] - p.offset[2] >= bottom - 1e-9)
}

/// A creeping launch is a push (label rule v6): the board is longer by the distance the
/// band's push carries the object in this time (s), so the object a layout is drawn for
/// reaches the edge about when rule v5's slower nudge brought it there, and a much
/// heavier look-alike, which the same push barely moves, creeps from rest behind it — at
/// least `0.6 · v` apart by Δ (0.12 m at the slowest band's 0.2 m/s).
pub const PUSH_LEAD_S: f64 = 0.6;

/// The push lead of the band at `speed` and of the group's fastest band (m): the board is
/// as long as the fastest band needs, the same in every band, and a faster band's object
/// starts farther up it (a timed family, `Family::timed`).
pub fn push_leads(input: &FamilyInput) -> (f64, f64) {
    let fastest = input.band_speeds.iter().copied().fold(0.0, f64::max);
    (input.speed * PUSH_LEAD_S, fastest * PUSH_LEAD_S)
}

/// Shared layout for "creeps down a tilted board and off its lower edge" (a tray propped
/// on a table, a sagging shelf board, a bent ceiling mount plate): a thin fixed board
/// sloping down along `heading_angle` by `tilt`, and the hazard resting on it, its centre
/// `com_to_edge` up the slope from the lower edge, moving down the slope at `speed`.
pub struct TiltedLaunch {
    pub surface_name: &'static str,
    /// Centre of the board's lower (front) top edge.
    pub edge: Vec3,
    pub heading_angle: f64,
    pub tilt: f64,
    /// Half length along the slope and half width of the board (m).
    pub board_half: [f64; 2],
    pub thickness: f64,
    pub friction: f64,
    pub com_to_edge: f64,
    /// Offset of the hazard across the slope (m).
    pub lateral: f64,
    /// Yaw of the object relative to the heading (rad).
    pub relative_yaw: f64,
    /// Laid on its side, its own z axis down the slope (see `lies_on_slope`).
    pub lying: bool,
}

/// Whether `object` should lie on its side, its own z axis down a slope of `tilt`: a
/// capsule (which would roll across the slope) or a tall object that would topple on the
/// slope (its centre's height times `tan(tilt)` near its narrowest half-width).
pub fn lies_on_slope(object: &Object, tilt: f64) -> bool {
    if object.parts.iter().any(|p| p.shape == ShapeKind::Capsule) {
        return true;
    }
    if is_single_sphere(object) || object.parts.len() > 1 {
        return false;
    }
    let h = object.half_extents();
    h[2] * tilt.tan() > 0.8 * h[0].min(h[1])
}

/// Distance from the object's origin down to the slope and its half-length along the
/// slope (relative yaw `rel`), standing or lying (see `TiltedLaunch::lying`).
pub fn slope_pose_extents(object: &Object, lying: bool, rel: f64) -> (f64, f64) {
    if lying {
        // Turned +90° about its own y axis: its +x points down onto the slope.
        let bottom = object
            .parts
            .iter()
            .map(|p| p.half_extents()[0] + p.offset[0])
            .fold(0.0, f64::max);
        (bottom, object.half_extents()[2])
    } else {
        (bottom_offset(object), footprint_half_length(object, rel))
    }
}

impl TiltedLaunch {
    /// Unit vector down the slope, and the board's upward normal.
    pub fn axes(&self) -> (Vec3, Vec3) {
        let d = heading(self.heading_angle);
        let (s, c) = self.tilt.sin_cos();
        ([d[0] * c, d[1] * c, -s], [d[0] * s, d[1] * s, c])
    }

    /// Height of the board's top at its upper (back) edge.
    pub fn top_height(&self) -> f64 {
        self.edge[2] + 2.0 * self.board_half[0] * self.tilt.sin()
    }

    /// Two rails instead of the board: copies of `board` (built with a rail's half-width)
    /// `offset` to either side of the slope's centre line, named `<name>_0` and `_1`.
    /// From below, the hazard's middle is seen between them.
    pub fn rails(&self, board: &BodySpec, offset: f64) -> [BodySpec; 2] {
        let side = left_of(heading(self.heading_angle));
        [-1.0, 1.0].map(|sign| {
            let mut r = board.clone();
            r.name = format!("{}_{}", board.name, if sign < 0.0 { 0 } else { 1 });
            r.position[0] += side[0] * sign * offset;
            r.position[1] += side[1] * sign * offset;
            r
        })
    }

    /// The board and the hazard on it (`speed` down the slope).
    pub fn build(&self, object: &Object, speed: f64) -> (BodySpec, BodySpec) {
        let (down, normal) = self.axes();
        let dir = heading(self.heading_angle);
        let side = left_of(dir);
        let tilt_q = quat::from_axis_angle([side[0], side[1], 0.0], self.tilt);
        let at = |along: f64, across: f64, up: f64| -> Vec3 {
            [0, 1, 2].map(|k| {
                let s = [side[0], side[1], 0.0][k];
                self.edge[k] - down[k] * along + s * across + normal[k] * up
            })
        };
        let board = fixed_box(
            self.surface_name,
            [self.board_half[0], self.board_half[1], self.thickness / 2.0],
            at(self.board_half[0], 0.0, -self.thickness / 2.0),
            quat::mul(tilt_q, yaw_quat(self.heading_angle)),
            self.friction,
            0.2,
        );
        let (bottom, _) = slope_pose_extents(object, self.lying, self.relative_yaw);
        let position = at(self.com_to_edge, self.lateral, bottom);
        let mut rotation = quat::mul(tilt_q, yaw_quat(self.heading_angle + self.relative_yaw));
        if self.lying {
            let lay = quat::from_axis_angle([0.0, 1.0, 0.0], std::f64::consts::FRAC_PI_2);
            rotation = quat::mul(rotation, lay);
        }
        let linvel = down.map(|c| c * speed);
        let angvel = if is_single_sphere(object) {
            // Rolling without slipping down the slope: ω = n × v / r.
            let r = bottom_offset(object).max(1e-3);
            cross3(normal, linvel).map(|c| c / r)
        } else {
            [0.0; 3]
        };
        let hazard = hazard_body(object, position, rotation, linvel, angvel);
        (board, hazard)
    }
}
