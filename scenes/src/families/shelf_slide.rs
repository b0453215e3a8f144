//! shelf_slide: an object slides off a high shelf (specification §4).
//!
//! Timing (label rule v2): the shelf sags forward, sloping toward its front edge just
//! steeper than the friction angle (a ball: a few degrees). Nudged down the slope at the
//! band's speed, the object creeps 0.2–0.28 m, accelerating at 0.4–0.65 m/s², before it
//! tips over the edge (about 0.45 s even for the fastest nudge), and then falls from
//! shelf height, so it reaches the observer in front of the shelf after Δ + 0.2 s = 0.8 s.

use super::edge_creep::{EdgeCreep, Mount};

/// The family's ranges: a shelf board alone, its lower edge at the event's origin.
pub static SHELF_SLIDE: EdgeCreep = EdgeCreep {
    name: "shelf_slide",
    surface_name: "shelf",
    mount: Mount::Shelf,
    height_param: "shelf_height_m",
    table: None,
    half_width: [0.4, 0.6],
    max_half_width: f64::INFINITY,
    friction: [0.1, 0.3],
    lateral: [-0.15, 0.15],
    relative_yaw: [-0.15, 0.15],
    accel: [0.4, 0.65],
    com_to_edge: [0.2, 0.28],
    origin_back: 0.7,
    thickness: 0.03,
    landing_ahead: 0.25,
    observer_near: (0.3, 0.9),
};
