//! ReactHuman physics: everything that decides what happens in a scene.
//!
//! * [`spec`] — `SceneSpec`, the JSON document that fully determines a scene (with the
//!   label rule's thresholds it was labelled under, `LabelConfig`);
//! * [`simulate`] — the deterministic rapier world built from a spec (dt 1/240,
//!   enhanced determinism) and its per-step state hash;
//! * [`world`] — the rapier world a spec builds (floor, bodies, joints) and its forks;
//! * [`drag`] — quadratic air drag on large light bodies (label rule v6);
//! * [`shapes`] — the spec's shapes and the humanoid's links as rapier shapes;
//! * [`obstacles`] — line-of-sight queries against the fixed bodies (cameras, visibility);
//! * [`body`] — the humanoid observer's links (pure geometry);
//! * [`strike`] — the strike test shared by the label's counterfactual and the executor;
//! * [`execute`] — replay to the decision moment and execution of a plan by the humanoid;
//! * [`control`] — closed-loop control of the same humanoid from Δ: whole-body commands at
//!   a control rate over the executor's physics, limits and outcome rule;
//! * [`seeds`] — the named `rand_chacha` sub-streams.
//!
//! Module graph (`A → B`: A uses B): `control → execute → simulate → world, shapes, body,
//! strike → spec`; `world → drag, shapes`; `drag → shapes`; `obstacles → shapes`;
//! `seeds` and `spec` use nothing in the crate.

pub mod body;
pub mod control;
pub mod drag;
pub mod execute;
pub mod obstacles;
pub mod seeds;
pub mod shapes;
pub mod simulate;
pub mod spec;
pub mod strike;
pub mod world;
