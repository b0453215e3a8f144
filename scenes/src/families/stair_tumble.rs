//! stair_tumble: an object tumbles down a flight of stairs (specification §4).
//!
//! A real staircase of fixed boxes: a top landing and `n − 1` steps below it (rise and
//! run drawn), descending toward the observer who stands beyond the bottom step. The
//! object is pushed (a ball: rolled) toward the top edge at the band's speed, from where
//! even the slowest band goes over the edge still sliding at 0.8 m/s.
//!
//! Timing (label rule v2): the stairs descend along the room's diagonal and the observer
//! stands `OBSERVER_GAP_M` or more beyond the bottom step, outside the reach of anything
//! still on the stairs: what reaches them rolls or slides that gap across the floor after
//! Δ + 0.2 s, and what the floor's friction stops first never does.
//!
//! Timed (label rule v5): a ball aimed at the hands rolls over a longer landing, starting
//! `v·t` behind its top edge, so every band goes over the edge after the same drawn time
//! `t` (`EDGE_S`, 0.85–1.0 s): even the fastest band then bounds over the lower steps,
//! within the hands' reach, after Δ plus the reaction time. `aim` stands the observer
//! where it comes off the bottom step (`[aim.meet_height_by_family]`), and the label
//! rule's interception finds where the hands take it.

use super::launch::*;
use super::*;

pub struct StairTumble;

/// The slowest band still moves this fast as it goes over the top edge (m/s).
const LEAVE_SPEED: f64 = 0.8;
/// Timed groups: when every band's ball goes over the top edge (s after t0): late enough
/// that even the fastest band, flying over the flight, is still above the lower steps
/// within the hands' reach after Δ plus the reaction time.
pub const EDGE_S: [f64; 2] = [0.85, 1.0];
/// Least floor distance between the bottom step and the observer (m).
pub const OBSERVER_GAP_M: f64 = 2.1;

impl Family for StairTumble {
    fn info(&self) -> FamilyInfo {
        FamilyInfo {
            name: "stair_tumble",
            speed_parameter: "push_speed_mps",
            speed_sweep: true,
        }
    }

    fn timed(&self) -> bool {
        true
    }

    fn sample(&self, input: &FamilyInput, rng: &mut ChaCha8Rng) -> Layout {
        let object = input.object;
        let room = input.room;
        let heading_angle = diagonal_heading(rng, room, 0.2);
        let dir = heading(heading_angle);
        let steps = uniform(rng, 3.0, 6.0).floor().min(5.0) as usize;
        let rise = uniform(rng, 0.16, 0.2);
        let run = uniform(rng, 0.22, 0.27);
        let half_width = uniform(rng, 0.45, 0.6);
        let friction = uniform(rng, 0.25, 0.45);
        let lateral = uniform(rng, -0.15, 0.15);
        let relative_yaw = uniform(rng, -0.2, 0.2);
        let rolling = is_single_sphere(object);
        let overshoot = uniform(rng, 0.8, 1.2);
        let mu = combined_friction(object.friction, friction);
        let slowest = input
            .band_speeds
            .iter()
            .copied()
            .fold(f64::INFINITY, f64::min);
        let half_len = footprint_half_length(object, 0.0);
        let untimed_com_to_edge = if rolling {
            0.05 + 0.15 * (overshoot - 0.8) / 0.4
        } else {
            // Where the slowest band, sliding, would still move at LEAVE_SPEED with its
            // centre `overshoot` half-lengths past the edge: it goes over with momentum.
            let run_up =
                (slowest * slowest - LEAVE_SPEED * LEAVE_SPEED).max(0.0) / (2.0 * mu * GRAVITY);
            (run_up - overshoot * half_len).clamp(-0.4 * half_len, 0.25)
        };
        let flight = (steps - 1) as f64 * run;
        let gap_near = uniform(rng, OBSERVER_GAP_M, OBSERVER_GAP_M + 0.4);
        let gap_far = uniform(rng, OBSERVER_GAP_M + 1.4, OBSERVER_GAP_M + 1.8);
        let side = uniform(rng, -0.3, 0.3);
        let t_edge = uniform(rng, EDGE_S[0], EDGE_S[1]);
        // Timed (label rule v5, see the module doc): a ball aimed at the hands keeps its
        // push over the landing (it rolls), so it starts `v·t_edge` back from the top
        // edge and every band goes over it at the drawn time.
        let timed = rolling && input.intent == crate::intent::Intent::Hands && !input.far_observer;
        let com_to_edge = if timed {
            input.speed * t_edge
        } else {
            untimed_com_to_edge
        };
        let longest_run_up = if timed {
            input.band_speeds.iter().copied().fold(0.0, f64::max) * t_edge
        } else {
            0.0
        };
        let landing_half = (0.5 * (longest_run_up + half_len + 0.05)).max(0.35);
        let gap = if input.far_observer {
            gap_far
        } else {
            gap_near
        };
        let length = (2.0 * landing_half + flight + gap).min(room_span(room, dir, 0.55));
        let origin = ahead(span_start(rng, room, dir, length, 0.55), dir, landing_half);

        let top_height = steps as f64 * rise;
        let landing = EdgeLaunch {
            surface_name: "landing",
            surface_height: top_height,
            surface_half: [landing_half, half_width],
            surface_friction: friction,
            heading_angle,
            com_to_edge,
            lateral,
            relative_yaw: if rolling { 0.0 } else { relative_yaw },
            origin,
            board_thickness: None,
            rolling,
        };
        let (mut bodies, edge, start) = landing.build(object, input.speed);
        for j in 1..steps {
            let h = (steps - j) as f64 * rise;
            let c = ahead(edge, dir, (j as f64 - 0.5) * run);
            bodies.insert(
                j,
                fixed_box(
                    &format!("step_{j}"),
                    [run / 2.0, half_width, h / 2.0],
                    [c[0], c[1], h / 2.0],
                    yaw_quat(heading_angle),
                    friction,
                    0.2,
                ),
            );
        }
        let hazard = bodies.len() - 1;
        let foot = ahead(edge, dir, flight);
        let obs = ahead(
            ahead(foot, dir, length - 2.0 * landing_half - flight),
            left_of(dir),
            side,
        );
        let observer = ObserverPose {
            x: obs[0],
            y: obs[1],
            // Facing the hazard's start; a timed ball's start follows from the speed, so
            // facing the top edge.
            yaw: if timed {
                (edge[1] - obs[1]).atan2(edge[0] - obs[0])
            } else {
                (start[1] - obs[1]).atan2(start[0] - obs[0])
            },
        };
        Layout {
            bodies,
            joints: vec![],
            hazard,
            source_support: Some(0),
            observer,
            params: BTreeMap::from([
                ("steps".into(), steps as f64),
                ("rise_m".into(), rise),
                ("run_m".into(), run),
                ("top_height_m".into(), top_height),
                ("com_behind_edge_m".into(), com_to_edge),
                ("heading_rad".into(), heading_angle),
                ("landing_half_m".into(), landing_half),
                ("edge_time_s".into(), if timed { t_edge } else { 0.0 }),
            ]),
        }
    }

    fn event_happened(&self, spec: &SceneSpec, sim: &Simulation) -> bool {
        // It tumbled down at least two steps.
        let p = &spec.family_params;
        let (top, rise) = (p["top_height_m"], p["rise_m"]);
        let bottom = sim.hazard_lowest_z[sim.steps() as usize];
        bottom <= top - 2.0 * rise + 0.01
    }
}

/// The hazard centre's height where it first crosses each step edge (distance
/// `k · run` past the top edge along the stairs, k = 0 … steps − 1), in order.
pub fn step_crossing_heights(spec: &SceneSpec, sim: &Simulation) -> Vec<f64> {
    let p = &spec.family_params;
    let dir = heading(p["heading_rad"]);
    let landing = &spec.bodies[0];
    let half = p.get("landing_half_m").copied().unwrap_or(0.35);
    let edge = ahead([landing.position[0], landing.position[1]], dir, half);
    let along = |q: [f64; 3]| (q[0] - edge[0]) * dir[0] + (q[1] - edge[1]) * dir[1];
    let mut out = Vec::new();
    let steps = p["steps"] as usize;
    // Edges the centre already starts beyond (an object overhanging the top edge) are not
    // crossings.
    let mut k = ((along(sim.hazard_position(0)) / p["run_m"]).floor() + 1.0).max(0.0) as usize;
    for j in 1..=sim.steps() {
        if k >= steps {
            break;
        }
        let line = k as f64 * p["run_m"];
        let (a, b) = (sim.hazard_position(j - 1), sim.hazard_position(j));
        if along(a) < line && along(b) >= line {
            let f = (line - along(a)) / (along(b) - along(a));
            out.push(a[2] + f * (b[2] - a[2]));
            k += 1;
        }
    }
    out
}
