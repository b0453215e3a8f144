//! The event families of specification §4, in canonical order. Each is implemented in
//! `pipeline/src/families/<name>.rs`; a build's config chooses which of them it uses.

/// The seventeen families, in canonical order.
pub const FAMILIES: [&str; 17] = [
    "object_drop",
    "shelf_slide",
    "hanging_fall",
    "ceiling_drop",
    "sliding_object",
    "rolling_ball",
    "surface_cascade",
    "furniture_tip",
    "stack_collapse",
    "ladder_slip",
    "door_swing",
    "pendulum_swing",
    "thrown_object",
    "bouncing_object",
    "stair_tumble",
    "chain_reaction",
    "multi_object",
];

/// Whether `name` is a family of the contract.
pub fn is_family(name: &str) -> bool {
    FAMILIES.contains(&name)
}

/// Position of a family in the canonical order.
pub fn index(name: &str) -> Option<usize> {
    FAMILIES.iter().position(|f| *f == name)
}
