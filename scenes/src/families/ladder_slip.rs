//! ladder_slip: a ladder leaning on a wall slips — its foot slides out, or it tips over
//! backwards (specification §4, two regimes).
//!
//! The ladder (a box: length ℓ along local z, thickness t along y) leans on a wall at an
//! angle α from vertical; its underside touches the floor (a mat) at the foot and the
//! wall at the top. Statics of a leaning box with Coulomb friction at both ends (floor
//! μ_f, wall μ_w; rapier's `Average` rule makes each the mean of the two surfaces') give
//! the floor friction it needs to stand:
//!
//! ```text
//!   μ_req(α) = a / (ℓ (cos α + μ_w sin α) − a μ_w),   a = (ℓ/2) sin α − (t/2) cos α
//! ```
//!
//! (`a`: horizontal distance from the foot to the centre of mass, toward the wall; for a
//! thin rod this is the textbook tan α_c = 2μ_f / (1 − μ_f μ_w)). The sampler first draws
//! the regime, then puts the scene on its side of the boundary with a margin:
//! * **slide** (`regime_slide = 1`): a slippery drop cloth under the foot and a lean with
//!   μ_req(α) ≥ 1.3 μ_f, so the foot must slide out; it starts in the sliding motion
//!   (foot moving out at the band's speed, top moving down the wall).
//! * **tip** (`regime_slide = 0`): a rubber mat (μ_req ≤ μ_f / 1.3 — the foot holds) and
//!   a nearly upright lean, so that a push of the top away from the wall at the slowest
//!   band's speed carries the centre of mass over the foot (kinetic energy about the foot
//!   ≥ 1.3 × the potential barrier): the ladder tips over backwards into the room.
//!
//! Gravity sets the pace (`speed_sweep = false`).
//!
//! Timing (label rule v2): the observer stands beyond the foot (never on it, which would
//! strike them at t0), so the falling ladder reaches them late in its fall, after
//! Δ + 0.2 s (measured medians 1.1–1.8 s).

use super::*;

pub struct LadderSlip;

/// How far beyond the ladder's foot the observer's standing point starts: the torso
/// radius and a margin (m).
const TORSO_CLEARANCE: f64 = 0.3;

/// Floor friction a ladder leaning at `alpha` (from vertical) needs to stand (see above).
pub fn required_floor_friction(alpha: f64, length: f64, thickness: f64, mu_wall: f64) -> f64 {
    let a = length / 2.0 * alpha.sin() - thickness / 2.0 * alpha.cos();
    a / (length * (alpha.cos() + mu_wall * alpha.sin()) - a * mu_wall)
}

/// Kinetic energy per unit mass needed (about the foot) to tip the ladder backwards over
/// its foot from lean `alpha`, and the foot-moment of inertia per unit mass.
fn tip_barrier(alpha: f64, length: f64, thickness: f64) -> (f64, f64) {
    let r = ((length / 2.0).powi(2) + (thickness / 2.0).powi(2)).sqrt();
    let h = length / 2.0 * alpha.cos() + thickness / 2.0 * alpha.sin();
    let inertia = (length * length + thickness * thickness) / 12.0 + r * r;
    (GRAVITY * (r - h), inertia)
}

/// Largest `x` in `[lo, hi]` with `ok(x)` true, for `ok` true at `lo` and monotone.
fn bisect(lo: f64, hi: f64, ok: impl Fn(f64) -> bool) -> f64 {
    if ok(hi) {
        return hi;
    }
    let (mut a, mut b) = (lo, hi);
    for _ in 0..60 {
        let m = (a + b) / 2.0;
        if ok(m) {
            a = m;
        } else {
            b = m;
        }
    }
    a
}

const MARGIN: f64 = 1.3;
const MAT_THICKNESS: f64 = 0.006;

impl Family for LadderSlip {
    fn info(&self) -> FamilyInfo {
        FamilyInfo {
            name: "ladder_slip",
            speed_parameter: "kick_speed_mps",
            // Gravity sets the pace of a slipping or toppling ladder.
            speed_sweep: false,
        }
    }

    fn sample(&self, input: &FamilyInput, rng: &mut ChaCha8Rng) -> Layout {
        let object = input.object;
        let room = input.room;
        let site = wall_site(rng, room, 1.0);
        let slide = uniform(rng, 0.0, 1.0) < 0.5;
        let u_angle = uniform(rng, 0.0, 1.0);
        let u_mat = uniform(rng, 0.0, 1.0);
        let n = heading(site.normal_angle);
        let side = left_of(n);

        let he = object.half_extents();
        let (length, thickness) = (2.0 * he[2], 2.0 * he[1]);
        let mu_l = object.friction;
        let wall_friction = 0.0;
        let mu_w = combined_friction(mu_l, wall_friction);
        let mat_friction = if slide {
            0.02 + 0.1 * u_mat
        } else {
            0.7 + 0.25 * u_mat
        };
        let mu_f = combined_friction(mu_l, mat_friction);
        let min_alpha = (thickness / length).atan() + 0.01;
        let slowest = input
            .band_speeds
            .iter()
            .copied()
            .fold(f64::INFINITY, f64::min);
        let alpha = if slide {
            let lo = bisect(min_alpha, 1.25, |a| {
                required_floor_friction(a, length, thickness, mu_w) < MARGIN * mu_f
            });
            lo + u_angle * (1.25f64.min(lo + 0.15) - lo)
        } else {
            let hi = bisect(min_alpha, 0.6, |a| {
                let (barrier, inertia) = tip_barrier(a, length, thickness);
                let omega = slowest / length;
                0.5 * inertia * omega * omega >= MARGIN * barrier
                    && required_floor_friction(a, length, thickness, mu_w) * MARGIN <= mu_f
            });
            min_alpha + u_angle * (hi - min_alpha)
        };

        // Foot corner on the mat, top corner 1 mm off the wall.
        let foot = {
            let p = ahead(site.base, n, length * alpha.sin() + 0.001);
            [p[0], p[1], MAT_THICKNESS + 0.0005]
        };
        let rotation = quat::mul(
            yaw_quat(site.normal_angle - std::f64::consts::FRAC_PI_2),
            quat::from_axis_angle([1.0, 0.0, 0.0], alpha),
        );
        let corner = quat::rotate(rotation, [0.0, -thickness / 2.0, -length / 2.0]);
        let position = [
            foot[0] - corner[0],
            foot[1] - corner[1],
            foot[2] - corner[2],
        ];
        // Spin about the wall-parallel axis ŝ = ẑ × n: ω = −α̇ ŝ.
        let (omega, pivot) = if slide {
            // Sliding between wall and floor: the instantaneous centre is where the
            // normals at the foot and at the top meet; the foot moves out at `speed`.
            let alpha_dot = input.speed / (length * alpha.cos());
            let centre = [foot[0], foot[1], length * alpha.cos() + foot[2]];
            ([side[0], side[1], 0.0].map(|c| -c * alpha_dot), centre)
        } else {
            // Tipping back about the foot: the top moves away from the wall at `speed`.
            let alpha_dot = -input.speed / length;
            ([side[0], side[1], 0.0].map(|c| -c * alpha_dot), foot)
        };
        let linvel = velocity_about(omega, pivot, position);
        let hazard = hazard_body(object, position, rotation, linvel, omega);

        let wall = wall_body(&site, 1.5, room.ceiling_height, wall_friction);
        let mat_len = length + 1.0;
        let mat_xy = ahead(site.base, n, mat_len / 2.0);
        let mat = fixed_box(
            if slide { "drop_cloth" } else { "rubber_mat" },
            [mat_len / 2.0, he[0] + 0.4, MAT_THICKNESS / 2.0],
            [mat_xy[0], mat_xy[1], MAT_THICKNESS / 2.0],
            yaw_quat(site.normal_angle),
            mat_friction,
            0.1,
        );
        // The observer stands beyond the ladder's foot (its torso clear of the foot's
        // corners): a steep slide-regime lean puts the foot well past the ladder's middle,
        // and an observer standing on it would be struck at t0.
        let clear = (length / 2.0).max(length * alpha.sin() + thickness + TORSO_CLEARANCE);
        let middle = ahead(site.base, n, clear);
        let observer = observer_beyond(
            rng,
            middle,
            n,
            (0.3, 1.0),
            (1.8, 2.1),
            0.4,
            input.far_observer,
            [position[0], position[1]],
        );
        Layout {
            bodies: vec![wall, mat, hazard],
            joints: vec![],
            hazard: 2,
            source_support: Some(1),
            observer,
            params: BTreeMap::from([
                ("regime_slide".into(), if slide { 1.0 } else { 0.0 }),
                ("lean_angle_rad".into(), alpha),
                ("mu_floor".into(), mu_f),
                ("mu_wall".into(), mu_w),
                (
                    "mu_required".into(),
                    required_floor_friction(alpha, length, thickness, mu_w),
                ),
                ("ladder_length_m".into(), length),
                ("wall_normal_rad".into(), site.normal_angle),
            ]),
        }
    }

    fn event_happened(&self, _spec: &SceneSpec, sim: &Simulation) -> bool {
        // It came down: by the end it lies within 30° of the floor.
        up_z(sim.hazard_state(sim.steps()).rotation) < 0.5
    }
}

/// Which way the ladder actually went, read from the trajectory: at the first step its
/// axis is more than 45° from vertical, is the top toward the wall (it slid: foot out,
/// top down the wall) or away from it (it tipped over backwards)? None if it never did.
pub fn measured_slide(spec: &SceneSpec, sim: &Simulation) -> Option<bool> {
    let n = heading(spec.family_params["wall_normal_rad"]);
    (0..=sim.steps()).find_map(|k| {
        let s = sim.hazard_state(k);
        let q = s.rotation.map(f64::from);
        let axis = quat::rotate(q, [0.0, 0.0, 1.0]);
        if axis[2] >= std::f64::consts::FRAC_1_SQRT_2 {
            return None;
        }
        // Local +z runs foot → top; its component along the wall normal is negative when
        // the top is nearer the wall than the foot.
        Some(axis[0] * n[0] + axis[1] * n[1] < 0.0)
    })
}
