//! object_drop: an object on a table creeps off the edge and falls (specification §4).
//!
//! Timing (label rule v2): the object rests on a smooth board propped on the table (a tray,
//! a drawing board) that slopes gently toward the table's front edge, just steeper than
//! the friction angle (a rolling ball: a few degrees). Nudged down the slope at the band's
//! speed it creeps 0.24–0.32 m, accelerating at 0.35–0.6 m/s², before it tips over the
//! edge: even the fastest nudge takes about 0.55 s to get there, so the fall reaches the
//! observer standing beyond the edge after Δ + 0.2 s = 0.8 s.

use super::edge_creep::{EdgeCreep, Mount, UnderTable};

/// The family's ranges: a board on a table, its lower edge on the table's front edge.
pub static OBJECT_DROP: EdgeCreep = EdgeCreep {
    name: "object_drop",
    surface_name: "board",
    mount: Mount::Table,
    height_param: "table_height_m",
    table: Some(UnderTable {
        half_depth: [0.3, 0.45],
        top_below_edge: 0.025,
        friction: 0.5,
    }),
    half_width: [0.35, 0.7],
    max_half_width: 0.35,
    friction: [0.1, 0.3],
    lateral: [-0.12, 0.12],
    relative_yaw: [-0.25, 0.25],
    accel: [0.35, 0.6],
    com_to_edge: [0.24, 0.32],
    origin_back: 0.6,
    thickness: 0.02,
    landing_ahead: 0.15,
    observer_near: (0.35, 0.85),
};
