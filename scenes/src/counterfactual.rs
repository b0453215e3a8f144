//! The counterfactual run of specification §6 — the observer's body (the humanoid standing at
//! rest) as static colliders — behind a scene's `danger_present` and its full-event
//! video: where it is needed at all ([`first_near_step`]) and where it starts (the plain
//! run's world kept just before anything comes near the body,
//! `rh_physics::simulate::counterfactual`).

use rh_physics::simulate::{SimOptions, Simulation};
use rh_physics::spec::SceneSpec;

/// The counterfactual run of specification §6 behind the labels of `spec`, whose plain run is
/// `sim`: `None` when no body ever comes near the observer's body ([`first_near_step`]:
/// that run would be the plain run); else the plain run up to the last snapshot before
/// that step, the observer's body standing from there (`simulate::counterfactual`).
pub fn counterfactual_run(spec: &SceneSpec, sim: &Simulation) -> Option<Simulation> {
    resumed(spec, sim, counterfactual_options(spec))
}

/// The counterfactual run with `options` from the plain run `sim`'s world kept before
/// any body comes near the observer (`simulate::counterfactual`); `None` if none ever does.
fn resumed(spec: &SceneSpec, sim: &Simulation, options: SimOptions) -> Option<Simulation> {
    let near = first_near_step(spec, sim)?;
    Some(rh_physics::simulate::counterfactual(
        spec, sim, near, options,
    ))
}

/// The counterfactual run of specification §6: the observer's body (the humanoid standing at
/// rest, `simulate::observer_links`) as fixed colliders, followed by the strike test.
pub fn counterfactual_options(_spec: &SceneSpec) -> SimOptions {
    SimOptions {
        observer_collider: true,
        run_past_strike: false,
    }
}

/// What the full-event video (`videos/full/<id>.mp4`) shows: the counterfactual of
/// specification §6 — the standing observer as a static collider, what the labels mean — run to
/// the end of the event rather than stopped after the strike window. `None` when no
/// body ever comes near the observer: that run is then the plain run (see
/// [`may_touch_observer`]), which the caller already has. The observation videos and
/// frames always show the plain run (they end at Δ; in a valid scene nothing reaches the
/// observer before Δ plus a reaction time). Labels, specs and hashes never depend on this run.
pub fn full_event_simulation(spec: &SceneSpec, sim: &Simulation) -> Option<Simulation> {
    let options = SimOptions {
        run_past_strike: true,
        ..counterfactual_options(spec)
    };
    resumed(spec, sim, options)
}

/// Clearance kept beyond the bounding spheres before a body could touch the observer
/// (covers the solver's speculative-contact distance with a wide margin).
const OBSERVER_CLEARANCE: f64 = 0.1;

/// Whether any dynamic body ever comes near enough to the observer's body to touch it.
/// If none does, the counterfactual run (observer as a static collider) is step for step
/// the plain run — a static collider changes nothing until something touches it — so
/// it cannot strike and need not be simulated.
pub fn may_touch_observer(spec: &SceneSpec, sim: &Simulation) -> bool {
    first_near_step(spec, sim).is_some()
}

/// The first step at which some dynamic body of the plain run `sim` comes within its
/// bounding radius, the standing body's reach and [`OBSERVER_CLEARANCE`] of the
/// observer's axis; `None`: never ([`may_touch_observer`]).
pub fn first_near_step(spec: &SceneSpec, sim: &Simulation) -> Option<u32> {
    let o = &spec.observer;
    // The standing body's links reach this far from its axis (arms, hands).
    let body = rh_physics::body::Geometry::of(o).rest_extent();
    let reach: Vec<f64> = sim
        .dynamic_bodies
        .iter()
        .map(|&b| spec.bodies[b].bounding_radius() + body.max(o.torso_radius) + OBSERVER_CLEARANCE)
        .collect();
    (0..=sim.steps()).find(|&k| {
        reach.iter().enumerate().any(|(slot, &r)| {
            o.torso_axis_distance(sim.state(k, slot).position.map(f64::from)) <= r
        })
    })
}
