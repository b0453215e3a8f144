//! The one family behind object_drop and shelf_slide: an object creeps down a tilted
//! board (a tray propped on a table, a sagging shelf) and tips over its lower edge toward
//! an observer standing beyond it. The two families are two [`EdgeCreep`] tables (in
//! their own files): their name, where the board is mounted, the drawn ranges and the
//! names of the recorded parameters.

use super::launch::*;
use super::*;

/// Which of the room's height ranges the board's lower edge is drawn from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mount {
    Table,
    Shelf,
}

/// A table block under the board (object_drop): the board's lower edge lies on the
/// table's front edge.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct UnderTable {
    /// Half depth of the table along the heading (m, drawn).
    pub half_depth: [f64; 2],
    /// How far the table's top lies below the board's lower edge (m).
    pub top_below_edge: f64,
    pub friction: f64,
}

/// A family's ranges (policy) for the shared sampler. Every range is drawn whatever the
/// speed, in the order of the fields, so the four bands differ only in the nudge.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EdgeCreep {
    /// The family's name (its speed is the nudge down the slope, `push_speed_mps`).
    pub name: &'static str,
    /// Name of the board body ("board", "shelf"); also prefixes the recorded friction and
    /// tilt (`<name>_friction`, `<name>_tilt_rad`).
    pub surface_name: &'static str,
    pub mount: Mount,
    /// Name of the recorded mount height (`table_height_m`, `shelf_height_m`).
    pub height_param: &'static str,
    pub table: Option<UnderTable>,
    /// Half width of the board across the slope (m, drawn), capped at `max_half_width`.
    pub half_width: [f64; 2],
    pub max_half_width: f64,
    pub friction: [f64; 2],
    /// Offset of the object across the slope (m).
    pub lateral: [f64; 2],
    /// Yaw of the object relative to the heading (rad).
    pub relative_yaw: [f64; 2],
    /// Acceleration down the slope (m/s²) that sets the board's tilt.
    pub accel: [f64; 2],
    /// Distance of the object's centre up the slope from the lower edge (m).
    pub com_to_edge: [f64; 2],
    /// How far behind the room's centre the event starts (see `event_origin`).
    pub origin_back: f64,
    pub thickness: f64,
    /// Where the object lands, ahead of the lower edge (m).
    pub landing_ahead: f64,
    /// The observer's near distance range beyond the landing point (m).
    pub observer_near: (f64, f64),
}

impl Family for EdgeCreep {
    fn info(&self) -> FamilyInfo {
        FamilyInfo {
            name: self.name,
            speed_parameter: "push_speed_mps",
            speed_sweep: true,
        }
    }

    /// A push (label rule v6): a faster band's object starts farther up the same board.
    fn timed(&self) -> bool {
        true
    }

    fn event_happened(&self, spec: &SceneSpec, sim: &Simulation) -> bool {
        // The object left the board and reached the floor.
        reached_floor(spec, sim)
    }

    fn sample(&self, input: &FamilyInput, rng: &mut ChaCha8Rng) -> Layout {
        let object = input.object;
        let heading_angle = uniform(rng, 0.0, std::f64::consts::TAU);
        let dir = heading(heading_angle);
        let range = match self.mount {
            Mount::Table => input.room.table_height,
            Mount::Shelf => input.room.shelf_height,
        };
        let height = uniform(rng, range[0], range[1]);
        let table_half_depth = self.table.map(|t| draw(rng, t.half_depth));
        let half_width = draw(rng, self.half_width);
        let friction = draw(rng, self.friction);
        let lateral = draw(rng, self.lateral);
        let relative_yaw = draw(rng, self.relative_yaw);
        let accel = draw(rng, self.accel);
        let base_to_edge = draw(rng, self.com_to_edge);
        let (lead, lead_max) = super::launch::push_leads(input);
        let com_to_edge = base_to_edge + lead;
        let origin = event_origin(rng, input.room, dir, self.origin_back);

        let mu = combined_friction(object.friction, friction);
        let tilt = creep_tilt(object, mu, accel);
        let lying = lies_on_slope(object, tilt);
        let (_, half_len) = slope_pose_extents(object, lying, relative_yaw);
        let board_half_len = (base_to_edge + lead_max + half_len + 0.05) / 2.0;
        // The board's lower edge: the table's front edge, or the event's origin.
        let edge_xy = match table_half_depth {
            Some(d) => ahead(origin, dir, d),
            None => origin,
        };
        let launch = TiltedLaunch {
            surface_name: self.surface_name,
            edge: [edge_xy[0], edge_xy[1], height],
            heading_angle,
            tilt,
            board_half: [board_half_len, half_width.min(self.max_half_width)],
            thickness: self.thickness,
            friction,
            com_to_edge,
            lateral,
            relative_yaw,
            lying,
        };
        let (board, hazard) = launch.build(object, input.speed);
        // Where the object starts without the push's lead (the same in every band).
        let start = {
            let p = hazard.position;
            let run = lead * tilt.cos();
            [p[0] + dir[0] * run, p[1] + dir[1] * run]
        };
        let mut bodies = vec![board, hazard];
        if let (Some(t), Some(d)) = (self.table, table_half_depth) {
            let top = height - t.top_below_edge;
            let half = [d, half_width];
            bodies.push(table_block(
                "table",
                origin,
                half,
                top,
                heading_angle,
                t.friction,
            ));
        }
        let landing = ahead(edge_xy, dir, self.landing_ahead);
        let observer = observer_beyond(
            rng,
            landing,
            dir,
            self.observer_near,
            (2.2, 2.8),
            0.35,
            input.far_observer,
            [start[0], start[1]],
        );
        let name = self.surface_name;
        Layout {
            bodies,
            joints: vec![],
            hazard: 1,
            source_support: Some(0),
            observer,
            params: BTreeMap::from([
                (self.height_param.into(), height),
                ("com_behind_edge_m".into(), com_to_edge),
                ("drop_height_m".into(), height),
                (format!("{name}_friction"), friction),
                (format!("{name}_tilt_rad"), tilt),
                ("creep_accel_mps2".into(), accel),
                ("lying".into(), if lying { 1.0 } else { 0.0 }),
            ]),
        }
    }
}

fn draw(rng: &mut ChaCha8Rng, range: [f64; 2]) -> f64 {
    uniform(rng, range[0], range[1])
}
