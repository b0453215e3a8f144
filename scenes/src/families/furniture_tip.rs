//! furniture_tip: tall furniture tips over like an inverted pendulum (specification §4).
//!
//! The piece stands on the floor, already rocked forward onto its front bottom edge just
//! past its balance angle (the angle at which its centre of mass is over that edge), so
//! it falls forward whatever the band. The band's value is the speed of its top at t0
//! (the push that rocked it), as a rotation about the front edge, which rests on the
//! floor. Gravity sets the pace of the fall (`speed_sweep = false`).
//!
//! Timing (label rule v2): the piece starts only 0.006–0.02 rad past balance with a gentle
//! push (a heavy, tall piece starts just far enough past it that even the slowest band's
//! top travels 0.1 m in the observation window), so its fall starts slowly (an inverted
//! pendulum grows like `e^{λt}`), and the observer stands where only the late part of the
//! fall reaches: beyond the front face's reach at the angle the fastest band's piece has
//! fallen to 1 s after t0 (integrated from the rigid body's equation of motion about its
//! edge, `φ'' = (g r_c / k²) sin φ`).
//!
//! Labels: nearly always DODGE. Every catalog piece but the styrofoam TV is heavy
//! (bookcases, wardrobes, fridges, mirrors: 5–80 kg), and a toppling one must be dodged;
//! only the styrofoam TV gives CATCH.

use super::*;

pub struct FurnitureTip;

/// Where the object tips about: the front bottom edge (local +y) of the parts that reach
/// its bottom, and the balance angle there (rad from upright).
pub fn front_edge(object: &Object) -> (Vec3, f64) {
    let bottom = bottom_offset(object);
    let front = object
        .parts
        .iter()
        .filter(|p| (p.offset[2] - p.half_extents()[2] + bottom).abs() < 1e-3)
        .map(|p| p.offset[1] + p.half_extents()[1])
        .fold(0.0, f64::max);
    let com = com_offset(object);
    let balance = (front - com[1]).atan2(com[2] + bottom);
    ([0.0, front, -bottom], balance)
}

/// The observer's torso: radius and the height of the top of the capsule's straight part.
const TORSO_RADIUS: f64 = 0.18;
const TORSO_STRAIGHT_TOP: f64 = 1.14;
/// The fastest band's piece may strike no earlier than this after t0 (Δ + 0.2 s and a margin).
const LATEST_REACH_S: f64 = 1.0;

/// Tipping about the front edge: the distance from the edge to the centre of mass `r_c`
/// and the squared radius of gyration `k²` about the edge (I = m k²), from the parts
/// (mass spread by volume, as the simulator does).
pub fn edge_pendulum(object: &Object) -> (f64, f64) {
    let (edge, _) = front_edge(object);
    let com = com_offset(object);
    let total: f64 = object.parts.iter().map(|p| p.volume()).sum();
    let mut k2 = 0.0;
    for p in &object.parts {
        let w = p.volume() / total;
        let h = p.half_extents();
        // Moment about the part's own x axis through its centre, per unit mass.
        let own = match p.shape {
            ShapeKind::Cylinder => (3.0 * h[0] * h[0] + 4.0 * h[2] * h[2]) / 12.0,
            ShapeKind::Sphere => 0.4 * h[0] * h[0],
            _ => (h[1] * h[1] + h[2] * h[2]) / 3.0,
        };
        let dy = p.offset[1] - edge[1];
        let dz = p.offset[2] - edge[2];
        k2 += w * (own + dy * dy + dz * dz);
    }
    let r_c = ((com[1] - edge[1]).powi(2) + (com[2] - edge[2]).powi(2)).sqrt();
    (r_c, k2)
}

/// The tilt from upright (rad) a piece reaches `t` seconds after starting `past` rad past
/// its balance angle with angular speed `omega0`, rocking on its edge: `φ'' = (g r_c / k²)
/// sin φ` (RK4, 1 ms steps), stopped at lying flat.
pub fn tilt_after(object: &Object, past: f64, omega0: f64, t: f64) -> f64 {
    let (_, balance) = front_edge(object);
    let (r_c, k2) = edge_pendulum(object);
    let lambda2 = GRAVITY * r_c / k2;
    let f = |phi: f64| lambda2 * phi.sin();
    let (mut phi, mut w) = (past, omega0);
    let h = 1e-3;
    let flat = std::f64::consts::FRAC_PI_2;
    for _ in 0..(t / h).round() as usize {
        let (k1p, k1w) = (w, f(phi));
        let (k2p, k2w) = (w + 0.5 * h * k1w, f(phi + 0.5 * h * k1p));
        let (k3p, k3w) = (w + 0.5 * h * k2w, f(phi + 0.5 * h * k2p));
        let (k4p, k4w) = (w + h * k3w, f(phi + h * k3p));
        phi += h / 6.0 * (k1p + 2.0 * k2p + 2.0 * k3p + k4p);
        w += h / 6.0 * (k1w + 2.0 * k2w + 2.0 * k3w + k4w);
        if balance + phi >= flat {
            return flat;
        }
    }
    balance + phi
}

/// The observation window Δ of the default configuration (s).
const WINDOW_S: f64 = 0.6;
/// How far the top of the slowest band's piece travels at least in the window (m): about
/// 25 ego pixels at the observer's distance, twice the motion rule's minimum.
pub const MIN_TOP_TRAVEL_M: f64 = 0.1;

/// The least angle past balance (rad, at most 0.2) at which a piece pushed so that its top
/// moves at `speed` tilts far enough in the window for its top to travel
/// [`MIN_TOP_TRAVEL_M`] (bisection on [`tilt_after`]).
pub fn least_past_balance(object: &Object, speed: f64) -> f64 {
    let height = top_offset(object) + bottom_offset(object);
    let (_, balance) = front_edge(object);
    let travel =
        |past: f64| (tilt_after(object, past, speed / height, WINDOW_S) - balance - past) * height;
    if travel(0.0) >= MIN_TOP_TRAVEL_M {
        return 0.0;
    }
    let (mut lo, mut hi) = (0.0, 0.2);
    for _ in 0..30 {
        let mid = 0.5 * (lo + hi);
        if travel(mid) >= MIN_TOP_TRAVEL_M {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    hi
}

/// How far in front of the edge (horizontally) the front face of a piece of height
/// `height` tilted `tilt` from upright reaches at torso heights (up to the top of the
/// torso capsule's straight part).
pub fn face_reach(height: f64, tilt: f64) -> f64 {
    (height * tilt.sin()).min(TORSO_STRAIGHT_TOP * tilt.tan())
}

impl Family for FurnitureTip {
    fn info(&self) -> FamilyInfo {
        FamilyInfo {
            name: "furniture_tip",
            speed_parameter: "push_speed_mps",
            // Gravity sets the pace of a toppling piece of furniture.
            speed_sweep: false,
        }
    }

    fn sample(&self, input: &FamilyInput, rng: &mut ChaCha8Rng) -> Layout {
        let object = input.object;
        let heading_angle = uniform(rng, 0.0, std::f64::consts::TAU);
        let dir = heading(heading_angle);
        // Past balance by 0.006–0.02 rad, or, for a piece so heavy and tall that the
        // slowest band would hardly stir in the observation window, by the least angle at
        // which its top travels `MIN_TOP_TRAVEL_M` in it (and up to 0.014 rad more).
        let slowest = input
            .band_speeds
            .iter()
            .fold(f64::INFINITY, |a: f64, &b| a.min(b));
        let least = least_past_balance(object, slowest);
        let past_balance = least.max(0.006) + uniform(rng, 0.0, 0.014);
        let origin = event_origin(rng, input.room, dir, 0.9 + far_shift(input));

        let (edge, balance) = front_edge(object);
        let tilt = balance + past_balance;
        let height = top_offset(object) + bottom_offset(object);
        // The observer stands just beyond what the fastest band's piece reaches by
        // LATEST_REACH_S: only the rest of the fall reaches them.
        let fastest = input.band_speeds.iter().fold(0.0, |a: f64, &b| a.max(b));
        let tilt_late = tilt_after(object, past_balance, fastest / height, LATEST_REACH_S);
        let clear = face_reach(height, tilt_late) + TORSO_RADIUS;
        // Local +y faces the fall; tilting about local x by −tilt brings the top forward.
        let rotation = quat::mul(
            yaw_quat(heading_angle - std::f64::consts::FRAC_PI_2),
            quat::from_axis_angle([1.0, 0.0, 0.0], -tilt),
        );
        let pivot = [origin[0], origin[1], 0.0005];
        let e = quat::rotate(rotation, edge);
        let position = [pivot[0] - e[0], pivot[1] - e[1], pivot[2] - e[2]];
        // Spin about the edge axis (ẑ × dir) so that the top moves forward at `speed`.
        let axis = left_of(dir);
        let omega = [axis[0], axis[1], 0.0].map(|c| c * input.speed / height);
        let com = quat::rotate(rotation, com_offset(object));
        let com_world = [
            position[0] + com[0],
            position[1] + com[1],
            position[2] + com[2],
        ];
        let linvel = velocity_about(omega, pivot, com_world);
        let hazard = hazard_body(object, position, rotation, linvel, omega);
        let observer = observer_beyond(
            rng,
            [pivot[0], pivot[1]],
            dir,
            (clear + 0.05, clear + 0.3),
            (height / 2.0 + 2.0, height / 2.0 + 2.4),
            // Sideways offset within half the piece's width, so a thin one (a coat
            // stand's pole) still falls onto the observer rather than past them.
            (0.5 * object.half_extents()[0]).min(0.35),
            input.far_observer,
            [com_world[0], com_world[1]],
        );
        Layout {
            bodies: vec![hazard],
            joints: vec![],
            hazard: 0,
            source_support: None,
            observer,
            params: BTreeMap::from([
                ("balance_angle_rad".into(), balance),
                ("initial_tilt_rad".into(), tilt),
                ("height_m".into(), height),
                ("observer_clear_m".into(), clear),
            ]),
        }
    }

    fn event_happened(&self, spec: &SceneSpec, sim: &Simulation) -> bool {
        // It toppled: its up axis turned more than 45° from vertical (past its balance
        // angle) and its top came down to the floor.
        (0..=sim.steps())
            .any(|k| up_z(sim.hazard_state(k).rotation) < std::f64::consts::FRAC_1_SQRT_2)
            && crate::label::time_to_floor(spec, sim).is_some()
    }
}
