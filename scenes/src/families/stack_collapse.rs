//! stack_collapse: a leaning stack of items on a table collapses (specification §4).
//!
//! N copies of the object are stacked near a table edge, each shifted toward the edge by
//! the same step `2(L + e)/N` (L: the item's half-length along the lean, e: a millimetre
//! or few), so the centre of mass of the items above the bottom one lies e beyond the
//! bottom item's front edge while every smaller sub-stack is still supported: the stack
//! cannot stand, and its upper part topples over that edge and off the table. The items
//! are placed exactly on one another (no overlap). The band's value is a nudge: the items
//! above the bottom one start moving toward the edge at up to that speed (top item).
//! Gravity sets the pace (`speed_sweep = false`). The hazard is the top item.
//!
//! Timing (label rule v2): e is only 1–3 mm past the tipping point and the nudges are a
//! few centimetres per second, so the tall stack leans over slowly (an inverted
//! pendulum starting near balance) before it buckles and its top item falls toward the
//! observer, who stands 0.7–1.2 m beyond where it lands (its path leaves the reach
//! envelope low and late), after Δ + 0.2 s = 0.8 s. Stacks of wide flat pans still
//! buckle in about 0.7 s.

use super::*;

pub struct StackCollapse;

/// Gap left between stacked items (m), so float rounding never makes them overlap.
const LAYER_GAP: f64 = 1e-4;

impl Family for StackCollapse {
    fn info(&self) -> FamilyInfo {
        FamilyInfo {
            name: "stack_collapse",
            speed_parameter: "nudge_speed_mps",
            // Gravity sets the pace of a collapsing stack.
            speed_sweep: false,
        }
    }

    fn sample(&self, input: &FamilyInput, rng: &mut ChaCha8Rng) -> Layout {
        let object = input.object;
        let heading_angle = uniform(rng, 0.0, std::f64::consts::TAU);
        let dir = heading(heading_angle);
        let side = left_of(dir);
        let height = uniform(rng, input.room.table_height[0], input.room.table_height[1]);
        let surface_half = [uniform(rng, 0.3, 0.45), uniform(rng, 0.35, 0.6)];
        let surface_friction = uniform(rng, 0.35, 0.6);
        let overhang = uniform(rng, 0.001, 0.003);
        let base_back = uniform(rng, 0.0, 0.05);
        let lateral = uniform(rng, -0.15, 0.15);
        let origin = event_origin(rng, input.room, dir, 0.6 + far_shift(input));

        let item_h = top_offset(object) + bottom_offset(object);
        let count = (0.45 / item_h).round().clamp(3.0, 7.0) as usize;
        let half_len = footprint_half_length(object, 0.0);
        // The upper items' mean offset from the bottom one is `step·N/2`: `overhang` past
        // the bottom item's front edge.
        let step = (2.0 * (half_len + overhang) / count as f64).min(0.95 * half_len);

        let table = fixed_box(
            "table",
            [surface_half[0], surface_half[1], height / 2.0],
            [origin[0], origin[1], height / 2.0],
            yaw_quat(heading_angle),
            surface_friction,
            0.2,
        );
        let edge = ahead(origin, dir, surface_half[0]);
        // Bottom item: its front face `base_back` behind the edge.
        let base = ahead(ahead(edge, dir, -(half_len + base_back)), side, lateral);
        let mut bodies = vec![table];
        for i in 0..count {
            let xy = ahead(base, dir, step * i as f64);
            let z = height + bottom_offset(object) + (item_h + LAYER_GAP) * i as f64;
            let v = if count > 1 {
                input.speed * i as f64 / (count - 1) as f64
            } else {
                0.0
            };
            let linvel = [dir[0] * v, dir[1] * v, 0.0];
            let rotation = yaw_quat(heading_angle);
            if i + 1 == count {
                bodies.push(hazard_body(
                    object,
                    [xy[0], xy[1], z],
                    rotation,
                    linvel,
                    [0.0; 3],
                ));
            } else {
                bodies.push(prop_copy(
                    object,
                    &format!("{}_{i}", object.id),
                    [xy[0], xy[1], z],
                    rotation,
                    linvel,
                ));
            }
        }
        let top = bodies.last().expect("a stack").position;
        let landing = ahead(edge, dir, 0.2);
        let observer = observer_beyond(
            rng,
            landing,
            dir,
            (0.7, 1.2),
            (2.3, 2.8),
            0.35,
            input.far_observer,
            [top[0], top[1]],
        );
        Layout {
            hazard: bodies.len() - 1,
            bodies,
            joints: vec![],
            source_support: Some(0),
            observer,
            params: BTreeMap::from([
                ("table_height_m".into(), height),
                ("stack_count".into(), count as f64),
                ("item_height_m".into(), item_h),
                ("lean_step_m".into(), step),
                ("drop_height_m".into(), top[2] - bottom_offset(object)),
            ]),
        }
    }

    fn event_happened(&self, spec: &SceneSpec, sim: &Simulation) -> bool {
        // The stack collapsed: its top item ends at least one item height lower.
        let h = spec
            .family_params
            .get("item_height_m")
            .copied()
            .unwrap_or(0.0);
        let start = sim.hazard_position(0)[2];
        let end = sim.hazard_position(sim.steps())[2];
        end <= start - h
    }
}
