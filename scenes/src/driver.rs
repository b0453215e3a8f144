//! The DAG driver: one scene group through every stage, in order —
//! plan → randomize → simulate → frame cameras → (counterfactual) simulate → label →
//! validate → render — with attempt-indexed resampling when any band fails a validator.
//! [`run_group`] is the one place the stages are chained; `build` runs groups in
//! parallel and writes what it returns.

use crate::aim::AimConfig;
use crate::cameras;
use crate::config::{Config, ValidatorConfig};
pub use crate::counterfactual::{
    counterfactual_options, counterfactual_run, first_near_step, full_event_simulation,
    may_touch_observer,
};
use crate::families;
use crate::label::{label, Labels};
use crate::randomize::{randomize_as, RandomizeError, SceneKey, StandIn};
use crate::selection::{plan_group_with, replan_group};
use crate::twins;
use crate::validate::{validate, Verdicts, VALIDATOR_COLUMNS};
use rayon::prelude::*;
use rh_catalog::Catalog;
use rh_physics::simulate::{simulate, SimOptions, Simulation};
use rh_physics::spec::{SceneSpec, Selection};

pub use crate::result::{HazardVisibility, SceneMedia, SceneResult};

/// Stage 4 (render) as the DAG driver sees it: writes a labelled scene's videos and
/// frames and says where (`None`: not rendered, e.g. an invalid scene). Kept behind this
/// signature so the driver needs no GPU code (`render` is a cargo feature).
pub type RenderStage<'a> = dyn Fn(&SceneResult) -> Result<Option<SceneMedia>, String> + Sync + 'a;

/// Why a group could not be produced.
#[derive(Debug)]
pub enum GroupError {
    /// Planning or sampling failed on the build's inputs (families, catalog).
    Input(String),
    /// The render stage failed.
    Render(String),
}

/// The whole DAG for scene group `g` of a build (`count` speed bands, scenes
/// `4g … 4g + count − 1`): plan the group's selection, produce its labelled scenes
/// ([`produce_group_counted`]), then render each (`render`; `None` for a label-only
/// build), the scenes as parallel tasks of the caller's rayon pool (a worker idle at
/// the end of a build takes scenes of another's last group). Also returns the group's
/// family and how its attempts went.
pub fn run_group(
    catalog: &Catalog,
    families: &[String],
    planned: Option<&[Selection]>,
    seed: u64,
    g: u64,
    count: u64,
    config: &Config,
    render: Option<&RenderStage>,
) -> Result<(Vec<SceneResult>, Rejections), GroupError> {
    let (mut results, rejections) =
        plan_and_produce(catalog, families, planned, seed, g, count, config)
            .map_err(GroupError::Input)?;
    if let Some(render) = render {
        results.par_iter_mut().try_for_each(|r| {
            r.media = render(r).map_err(GroupError::Render)?;
            let ego = r.media.as_ref().and_then(|m| m.visibility.get("ego"));
            let px = ego.map(|v| &v.visible_px[..]);
            let (frames, valid) = (&r.ego_checked_frames, r.verdicts.all());
            crate::ego::check_rendered(&r.spec, valid, frames, px, &config.validators)
                .map_err(GroupError::Render)
        })?;
    }
    Ok((results, rejections))
}

/// Plans group `g` and produces its scenes: selections planned from descriptions
/// (`build --descriptions`, group g takes g mod D) as given, else as the embedded planner
/// deals the group ([`produce_planned_group`]). The one planning path of builds, `verify`
/// and `balance`.
pub fn plan_and_produce(
    catalog: &Catalog,
    families: &[String],
    planned: Option<&[Selection]>,
    seed: u64,
    g: u64,
    count: u64,
    config: &Config,
) -> Result<(Vec<SceneResult>, Rejections), String> {
    if let Some(s) = planned.filter(|s| !s.is_empty()) {
        let selection = &s[(g % s.len() as u64) as usize];
        return produce_group_counted(selection, seed, g * 4, count, catalog, config)
            .map_err(|e| e.to_string());
    }
    produce_planned_group(catalog, families, seed, g, count, config).map_err(|e| match e {
        GroupError::Input(m) | GroupError::Render(m) => m,
    })
}

/// Group `g` of a descriptionless build over `families`, as the embedded planner deals
/// it: a group of an adversarial probe pair (`twins::slot`, `[probes]`) — the probe shows
/// the disguised object, never as a near miss; its twin is the probe's final specs with
/// only the object replaced by its look-alike (`twins::twin_spec`), simulated and
/// labelled without resampling — else [`replanned_group`].
pub fn produce_planned_group(
    catalog: &Catalog,
    families: &[String],
    seed: u64,
    g: u64,
    count: u64,
    config: &Config,
) -> Result<(Vec<SceneResult>, Rejections), GroupError> {
    let input = |e: &dyn std::fmt::Display| GroupError::Input(e.to_string());
    let policy = crate::selection::PlanPolicy::of(&config.build, &config.labels);
    let Some(slot) = twins::slot(&config.probes, families, g) else {
        return replanned_group(catalog, families, seed, g, count, config).map_err(|e| input(&e));
    };
    let (adversarial, genuine) = twins::objects(slot.pair, catalog).map_err(|e| input(&e))?;
    let mut selection = plan_group_with(catalog, families, seed, slot.probe_group, &policy)
        .map_err(|e| input(&e))?;
    selection.object_id = adversarial.id.clone();
    let heavy = config.labels.heavy_mass_kg;
    let benign = if crate::selection::intrinsically_dangerous(adversarial, heavy) {
        genuine
    } else {
        adversarial
    };
    let stand_in = StandIn {
        aimed_as: Some(benign.id.clone()),
        pushed_as: slot.pair.twin.then(|| benign.id.clone()),
        never_far: true,
    };
    // Both groups of a pair build the whole pair (deterministic): the probe's four bands
    // and, for a twin pair, the twins labelled — once per process ([`PROBES`]).
    let probe_count = if slot.pair.twin { 4 } else { count };
    let produce = || {
        let bands = Bands {
            build_seed: seed,
            first_index: slot.probe_group * 4,
            count: probe_count,
        };
        let (mut probe, rejections) =
            probe_group_counted(&selection, bands, catalog, config, &stand_in)
                .map_err(|e| e.to_string())?;
        let twins = slot.pair.twin.then(|| {
            let label = |spec, sim| label_scene(spec, sim, config);
            twins::pair_twins(
                &mut probe,
                &slot,
                genuine,
                config.probes.divergence_min,
                &label,
            )
        });
        Ok((probe, rejections, twins.flatten()))
    };
    let produced = if slot.pair.twin {
        let key = ProbeKey {
            seed,
            probe_group: slot.probe_group,
            families: families.to_vec(),
            config: serde_json::to_string(config).expect("a config serializes"),
            catalog: format!("{catalog:?}"),
        };
        PROBES.get(key, 2, produce)
    } else {
        produce()
    };
    let (mut probe, rejections, twins) = produced.map_err(GroupError::Input)?;
    let valid = |r: &[SceneResult]| r.iter().all(|r| r.verdicts.all());
    // N means N: a probe (or twin) group that cannot be made valid gives way to a group
    // planned afresh, unpaired (the pair's other group then names no twin either).
    let replanned =
        || replanned_group(catalog, families, seed, g, count, config).map_err(|e| input(&e));
    if slot.role == twins::Role::Probe {
        probe.truncate(count as usize);
        return if valid(&probe) {
            Ok((probe, rejections))
        } else {
            replanned()
        };
    }
    let Some(mut twin) = twins else {
        return replanned();
    };
    twin.truncate(count as usize);
    let rejected = Rejections {
        attempts: 1,
        ..Rejections::default()
    };
    Ok((twin, rejected))
}

/// What a probe group's bands are a function of (with the driver's code): the build's
/// seed, the group, the families (the planner deals them), the build's configuration and
/// the catalog (its `Debug` text: every field).
#[derive(PartialEq)]
struct ProbeKey {
    seed: u64,
    probe_group: u64,
    families: Vec<String>,
    config: String,
    catalog: String,
}

/// Probe groups produced for their twin group or by it, until both have taken them.
static PROBES: crate::shared::Shared<ProbeKey, Result<ProbePair, String>> =
    crate::shared::Shared::new(64);

/// A probe group's bands, its attempts, and its labelled twins (`None`: no twin pair, or
/// one that could not be made valid).
type ProbePair = (Vec<SceneResult>, Rejections, Option<Vec<SceneResult>>);

/// A group the planner deals (no probe pair): a group none of whose attempts passes
/// every validator (a heavy pillow thrown at the chest that no walk escapes), or whose
/// event cannot be aimed (`[aim] replans`), is planned afresh ([`replan_group`]), up to
/// `validators.replans` times, and the first plan whose bands all pass (aimed, while
/// aim replans are left) is kept. If the last plan fails, the first earlier plan that
/// passes at its family's own pose stands instead; else the last, marked invalid.
fn replanned_group(
    catalog: &Catalog,
    families: &[String],
    seed: u64,
    g: u64,
    count: u64,
    config: &Config,
) -> Result<(Vec<SceneResult>, Rejections), String> {
    let policy = crate::selection::PlanPolicy::of(&config.build, &config.labels);
    let mut total = Rejections::default();
    let aim_replans = config.aim.replans.min(config.validators.replans);
    // The plans tried for an aim are produced again at their own pose if every plan fails
    // (below): their plain runs are kept, not simulated twice.
    let mut memo = SimMemo::default();
    let mut produce = |replan: u32, require_aim: bool, total: &mut Rejections| {
        let selection =
            replan_group(catalog, families, seed, g, &policy, replan).map_err(|e| e.to_string())?;
        let memo = (replan < aim_replans).then_some(&mut memo);
        let bands = Bands {
            build_seed: seed,
            first_index: g * 4,
            count,
        };
        let attempts = Attempts {
            bands,
            require_aim,
            stand_in: &StandIn::default(),
        };
        let produced = produce_attempts(&selection, &attempts, catalog, config, memo)
            .map_err(|e| e.to_string())?;
        match &produced {
            // Planned afresh at once, before any band is labelled.
            None => total.attempts += 1,
            Some((_, rejections)) => {
                total.attempts += rejections.attempts;
                for (t, r) in total.rejected_by.iter_mut().zip(rejections.rejected_by) {
                    *t += r;
                }
            }
        }
        Ok::<_, String>(produced.map(|(results, _)| results))
    };
    let valid = |results: &[SceneResult]| results.iter().all(|r| r.verdicts.all());
    let mut last = Vec::new();
    for replan in 0..=config.validators.replans {
        // While a replan is left for it, a group whose event cannot be aimed is planned
        // afresh.
        let require_aim = replan < aim_replans;
        total.replans = replan;
        let Some(results) = produce(replan, require_aim, &mut total)? else {
            continue;
        };
        let unaimed = require_aim
            && results
                .first()
                .is_some_and(|r| needs_aim(&r.spec, &config.aim));
        if valid(&results) && !unaimed {
            return Ok((results, total));
        }
        last = results;
    }
    for replan in 0..aim_replans {
        if let Some(results) = produce(replan, false, &mut total)?.filter(|r| valid(r)) {
            return Ok((results, total));
        }
    }
    // N means N: plans beyond `replans` (attempt-indexed: replan k is a pure function of
    // the build seed, the group and k) until one passes, up to `replans_max`.
    for replan in config.validators.replans + 1..=config.validators.replans_max {
        total.replans = replan;
        if let Some(results) = produce(replan, false, &mut total)? {
            if valid(&results) {
                return Ok((results, total));
            }
            last = results;
        }
    }
    Ok((last, total))
}

/// Whether a spec's event still waits to be aimed (label rule v5): the driver aims it
/// (`aim::driver_aimed`) at the hands or the body, and no aimed pose (`aim::apply`)
/// stands in it.
fn needs_aim(spec: &SceneSpec, aim: &AimConfig) -> bool {
    use crate::intent::Intent;
    matches!(
        crate::aim::driver_aimed(spec, aim),
        Some(Intent::Hands | Intent::Body)
    ) && !crate::aim::posed_by_aim(spec)
}

/// Frames one set of cameras for a group's bands and labels and validates each band.
fn label_group(
    runs: Vec<(SceneSpec, Simulation)>,
    catalog: &Catalog,
    config: &Config,
) -> Vec<SceneResult> {
    framed_group(runs, catalog, config)
        .map(|(spec, sim)| label_scene(spec, sim, config))
        .collect()
}

/// A group's bands with one set of cameras framed for all of them, then the room
/// furnished clear of the event and of those cameras' sight of it (`decor::furnish`).
fn framed_group(
    mut runs: Vec<(SceneSpec, Simulation)>,
    catalog: &Catalog,
    config: &Config,
) -> impl Iterator<Item = (SceneSpec, Simulation)> {
    let bands: Vec<(&SceneSpec, &Simulation)> = runs.iter().map(|(s, m)| (s, m)).collect();
    let framed = cameras::frame_group(&bands, &config.validators.framing()).unwrap_or_default();
    for (spec, _) in runs.iter_mut() {
        spec.cameras = framed.clone();
    }
    crate::decor::furnish(&mut runs, catalog, &config.decor);
    runs.into_iter()
}

/// Simulates one spec (plain and counterfactual), frames its cameras (as a group of
/// one; a build frames a group's bands together, see `produce_group`), labels and
/// validates.
pub fn run_scene(mut spec: SceneSpec, config: &Config) -> SceneResult {
    let sim = simulate(&spec, SimOptions::default());
    spec.cameras = cameras::frame(&spec, &sim, &config.validators.framing()).unwrap_or_default();
    label_scene(spec, sim, config)
}

/// The stages after framing: the counterfactual run where needed, labels and verdicts
/// of a simulated spec that carries its cameras.
pub fn label_scene(spec: SceneSpec, sim: Simulation, config: &Config) -> SceneResult {
    let family = families::get(&spec.family).expect("randomize only emits implemented families");
    let labels = counterfactual_labels(&spec, &sim);
    let verdicts = validate(&spec, &sim, family, &config.validators, &labels);
    scene_result(spec, sim, labels, verdicts, &config.validators)
}

/// The labels of a simulated spec: the counterfactual run where the hazard may touch
/// the observer ([`counterfactual_run`]), then the label rule.
fn counterfactual_labels(spec: &SceneSpec, sim: &Simulation) -> Labels {
    let strike = counterfactual_run(spec, sim).and_then(|cf| cf.strike);
    label(spec, sim, strike)
}

/// A labelled and validated scene as the dataset takes it.
fn scene_result(
    spec: SceneSpec,
    sim: Simulation,
    labels: Labels,
    verdicts: Verdicts,
    validators: &ValidatorConfig,
) -> SceneResult {
    let until_within = validators.frame_check_until_within;
    let trajectory = hazard_trajectory(&spec, &sim);
    SceneResult {
        ego_motion_px: crate::ego::ego_motion_px(&spec, &sim),
        ego_checked_frames: crate::ego::model_input_frames(&spec, &sim, until_within),
        state_hash: sim.state_hash.clone(),
        decision_state_hash: sim.state_hash_through(spec.decision_step()),
        steps: sim.steps(),
        spec,
        labels,
        verdicts,
        trajectory,
        media: None,
    }
}

fn hazard_trajectory(spec: &SceneSpec, sim: &Simulation) -> Vec<[f32; 4]> {
    (0..)
        .map(|frame| (frame, spec.frame_step(frame)))
        .take_while(|&(_, step)| step <= sim.steps())
        .map(|(frame, step)| {
            let p = sim.hazard_com(step);
            [
                (frame as f64 / spec.video.fps as f64) as f32,
                p[0] as f32,
                p[1] as f32,
                p[2] as f32,
            ]
        })
        .collect()
}

/// Labels a group's simulated bands at the first of `aims` (`aim::aims`) whose bands all
/// pass the validators, else at the family's own pose — there, unless the attempt is the
/// `last` (whose verdicts are kept whatever they are), with [`label_group_counting`].
fn label_aimed(
    runs: Vec<(SceneSpec, Simulation)>,
    aims: Vec<crate::aim::Aim>,
    catalog: &Catalog,
    config: &Config,
    last: bool,
) -> Vec<SceneResult> {
    let debug = std::env::var_os("RH_AIM_DEBUG").is_some();
    for aim in aims {
        let mut posed = runs.clone();
        crate::aim::apply(&mut posed, &aim);
        if !debug {
            match label_group_if_valid(posed, catalog, config) {
                Some(results) => return results,
                None => continue,
            }
        }
        let results = label_group(posed, catalog, config);
        if results.iter().all(|r| r.verdicts.all()) {
            return results;
        }
        let failed: Vec<Vec<&str>> = results.iter().map(|r| r.verdicts.failures()).collect();
        eprintln!(
            "aim {} {} candidate {} rejected: {failed:?}",
            results[0].spec.family, results[0].spec.selection.object_id, aim.candidate
        );
    }
    if last {
        label_group(runs, catalog, config)
    } else {
        label_group_counting(runs, catalog, config)
    }
}

/// [`label_group`] for an attempt that is not the last, checked cheapest first: the
/// validators that need no labels on every band; only if they all pass, each band's
/// counterfactual run and the reaction-time rule; only if those pass too, the escape
/// walks (`validate::escapable`, the costliest check), stopping at the first band they
/// reject. An attempt a cheaper check rejects is discarded whatever the costlier checks
/// would say, so their verdicts stay `true` (and `Rejections` does not count them) and
/// its labels are the plain run's (no strike); an attempt that passes them all gets
/// `label_group`'s results.
fn label_group_counting(
    runs: Vec<(SceneSpec, Simulation)>,
    catalog: &Catalog,
    config: &Config,
) -> Vec<SceneResult> {
    let mut checked = Vec::with_capacity(runs.len());
    for (spec, sim) in framed_group(runs, catalog, config) {
        let family =
            families::get(&spec.family).expect("randomize only emits implemented families");
        let verdicts = crate::validate::unlabelled(&spec, &sim, family, &config.validators);
        checked.push((spec, sim, verdicts));
    }
    let unlabelled_pass = checked.iter().all(|(_, _, v)| v.all());
    let mut labelled = Vec::with_capacity(checked.len());
    for (spec, sim, mut verdicts) in checked {
        let labels = if unlabelled_pass {
            let labels = counterfactual_labels(&spec, &sim);
            verdicts.reaction_time = crate::validate::reaction_time_ok(&spec, &labels);
            labels
        } else {
            label(&spec, &sim, None)
        };
        labelled.push((spec, sim, labels, verdicts));
    }
    if labelled.iter().all(|(_, _, _, v)| v.all()) {
        for (spec, _, labels, verdicts) in labelled.iter_mut() {
            verdicts.escapable = crate::validate::escapable(spec, labels);
            if !verdicts.escapable {
                break;
            }
        }
    }
    labelled
        .into_iter()
        .map(|(spec, sim, labels, verdicts)| {
            scene_result(spec, sim, labels, verdicts, &config.validators)
        })
        .collect()
}

/// [`label_group`] when every band passes every validator, else `None` — found at the
/// first failing check: the validators that need no labels on every band first
/// (`validate::unlabelled`), then each band's counterfactual run and the reaction-time
/// rule, then the escape walks. The results are `label_group`'s (same labels, every
/// verdict true); only a rejected pose costs less.
fn label_group_if_valid(
    runs: Vec<(SceneSpec, Simulation)>,
    catalog: &Catalog,
    config: &Config,
) -> Option<Vec<SceneResult>> {
    let mut framed_runs = Vec::with_capacity(runs.len());
    for (spec, sim) in framed_group(runs, catalog, config) {
        let family =
            families::get(&spec.family).expect("randomize only emits implemented families");
        let verdicts = crate::validate::unlabelled(&spec, &sim, family, &config.validators);
        if !verdicts.all() {
            return None;
        }
        framed_runs.push((spec, sim, verdicts));
    }
    let mut labelled = Vec::with_capacity(framed_runs.len());
    for (spec, sim, mut verdicts) in framed_runs {
        let labels = counterfactual_labels(&spec, &sim);
        verdicts.reaction_time = crate::validate::reaction_time_ok(&spec, &labels);
        if !verdicts.reaction_time {
            return None;
        }
        labelled.push((spec, sim, labels, verdicts));
    }
    for (spec, _, labels, verdicts) in labelled.iter_mut() {
        verdicts.escapable = crate::validate::escapable(spec, labels);
        if !verdicts.escapable {
            return None;
        }
    }
    Some(
        labelled
            .into_iter()
            .map(|(spec, sim, labels, verdicts)| {
                scene_result(spec, sim, labels, verdicts, &config.validators)
            })
            .collect(),
    )
}

/// How a group's attempts went: attempts made, and per validator (in
/// `validate::VALIDATOR_COLUMNS` order) how many attempts it rejected (an attempt is
/// rejected when any band fails; it counts once for each validator that failed — but the
/// escape walks of an attempt at the family's pose run only when every other validator
/// passes or it is the last attempt, [`label_group_counting`], so `valid_escapable`
/// counts the attempts it alone rejected).
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Rejections {
    pub attempts: u32,
    pub rejected_by: [u32; VALIDATOR_COLUMNS.len()],
    /// Times the group was planned afresh (another object or room of its family).
    pub replans: u32,
}

/// Produces scenes `first_index .. first_index + count` (one group, `count` ≤ 4 bands).
/// Tries attempts 0, 1, … until every band passes every validator; if none does within
/// `max_attempts`, the last attempt is kept with `valid = false` so the failure is visible.
pub fn produce_group(
    selection: &Selection,
    build_seed: u64,
    first_index: u64,
    count: u64,
    catalog: &Catalog,
    config: &Config,
) -> Result<Vec<SceneResult>, RandomizeError> {
    produce_group_counted(selection, build_seed, first_index, count, catalog, config)
        .map(|(results, _)| results)
}

/// `produce_group`, also saying which validators rejected which attempts.
///
/// Each attempt simulates every band, frames ONE set of cameras for the group on the
/// union of the bands' hazard paths (`cameras::frame_group`, from the group's "cameras"
/// stream), then labels and validates each band with those cameras: the bands differ
/// only in speed.
pub fn produce_group_counted(
    selection: &Selection,
    build_seed: u64,
    first_index: u64,
    count: u64,
    catalog: &Catalog,
    config: &Config,
) -> Result<(Vec<SceneResult>, Rejections), RandomizeError> {
    let bands = Bands {
        build_seed,
        first_index,
        count,
    };
    let tries = Tries {
        require_aim: &[false],
        stand_in: &StandIn::default(),
    };
    produce_requiring(selection, bands, catalog, config, tries)
}

/// A probe group's bands: attempts whose event cannot be aimed are redrawn (`require_aim`,
/// up to the family's `[aim] attempts_by_family`), since a probe shown at the family's own
/// pose is a near miss for it and its twin alike; only if every such attempt fails does
/// the group stand at the family's pose (as [`produce_group_counted`]), its plain runs kept.
fn probe_group_counted(
    selection: &Selection,
    bands: Bands,
    catalog: &Catalog,
    config: &Config,
    stand_in: &StandIn,
) -> Result<(Vec<SceneResult>, Rejections), RandomizeError> {
    let tries = Tries {
        require_aim: &[true, false],
        stand_in,
    };
    produce_requiring(selection, bands, catalog, config, tries)
}

/// A group's scenes `first_index .. first_index + count` of build `build_seed`.
#[derive(Clone, Copy)]
struct Bands {
    build_seed: u64,
    first_index: u64,
    count: u64,
}

/// How [`produce_requiring`] tries a group: `require_aim` as each of these in turn, the
/// group laid out as `stand_in` says.
#[derive(Clone, Copy)]
struct Tries<'a> {
    require_aim: &'a [bool],
    stand_in: &'a StandIn,
}

/// [`produce_attempts`] with `require_aim` as each of `tries` in turn (sharing plain runs)
/// until one produces the group.
fn produce_requiring(
    selection: &Selection,
    bands: Bands,
    catalog: &Catalog,
    config: &Config,
    tries: Tries,
) -> Result<(Vec<SceneResult>, Rejections), RandomizeError> {
    let mut memo = SimMemo::default();
    for &require_aim in tries.require_aim {
        let attempts = Attempts {
            bands,
            require_aim,
            stand_in: tries.stand_in,
        };
        let memo = (tries.require_aim.len() > 1).then_some(&mut memo);
        if let Some(produced) = produce_attempts(selection, &attempts, catalog, config, memo)? {
            return Ok(produced);
        }
    }
    Ok(Default::default())
}

/// Which scenes [`produce_attempts`] produces: the group's `bands`, laid out as
/// `stand_in` says; with `require_aim`, unaimed attempts are redrawn unlabelled.
struct Attempts<'a> {
    bands: Bands,
    require_aim: bool,
    stand_in: &'a StandIn,
}

/// Plain runs kept by spec (its JSON text), so that a plan produced again simulates
/// nothing twice (`simulate` is pure in the spec, so a kept run is the run). Holds at most
/// [`SimMemo::KEPT`] runs; later ones are simulated and not kept.
#[derive(Default)]
struct SimMemo {
    runs: std::collections::BTreeMap<String, Simulation>,
}

impl SimMemo {
    const KEPT: usize = 64;

    /// The plain run of `spec` (`json` is its JSON text).
    fn simulate(&mut self, json: &str, spec: &SceneSpec) -> Simulation {
        if let Some(sim) = self.runs.get(json) {
            return sim.clone();
        }
        let sim = simulate(spec, SimOptions::default());
        if self.runs.len() < Self::KEPT {
            self.runs.insert(json.to_string(), sim.clone());
        }
        sim
    }
}

/// [`produce_group_counted`]; with `require_aim`, an attempt whose event cannot be aimed
/// ([`needs_aim`] after `aim::aims` found no pose) is redrawn unlabelled, and after
/// `[aim] attempts` such attempts the answer is `None` (the caller replans).
fn produce_attempts(
    selection: &Selection,
    attempts: &Attempts,
    catalog: &Catalog,
    config: &Config,
    mut memo: Option<&mut SimMemo>,
) -> Result<Option<(Vec<SceneResult>, Rejections)>, RandomizeError> {
    let Attempts {
        bands: Bands {
            build_seed,
            first_index,
            count,
        },
        require_aim,
        stand_in,
    } = *attempts;
    let mut results = Vec::new();
    let mut rejections = Rejections::default();
    let mut unaimed = 0;
    for attempt in 0..config.validators.max_attempts {
        rejections.attempts += 1;
        let mut band_run = |index: u64| -> Result<(SceneSpec, Simulation), RandomizeError> {
            let spec = randomize_as(
                selection,
                &SceneKey::new(build_seed, index, attempt),
                catalog,
                &config.randomize(),
                stand_in,
            )?;
            // Simulate what the file will say: a JSON round trip is exact (serde_json
            // float_roundtrip), and this makes "replay equals build" hold by construction.
            let json = spec.to_json();
            let spec = SceneSpec::from_json(&json).expect("a spec parses back");
            let sim = match memo.as_deref_mut() {
                Some(memo) => memo.simulate(&json, &spec),
                None => simulate(&spec, SimOptions::default()),
            };
            Ok((spec, sim))
        };
        // The fastest band (the last) first: with `require_aim`, a layout whose fastest
        // band alone cannot be aimed (no candidate on its path that it meets) is redrawn
        // without simulating the other bands. (Every band must meet the aim, and the
        // fastest band's path strays farthest from the others.)
        let fastest = band_run(first_index + count - 1)?;
        let unaimable = require_aim
            && count > 1
            && needs_aim(&fastest.0, &config.aim)
            && crate::aim::aims(std::slice::from_ref(&fastest), &config.aim).is_empty();
        let mut runs = Vec::with_capacity(count as usize);
        if !unaimable {
            for index in first_index..first_index + count - 1 {
                runs.push(band_run(index)?);
            }
        }
        runs.push(fastest);
        // Label rule v5: the observer stands on the bands' hazard paths (one pose). An
        // aimed pose the validators reject (the hazard out of a camera's view, too early
        // to react) gives way to the next aimed pose, then to the family's own pose,
        // before a new attempt is drawn.
        let aims = if unaimable {
            Vec::new()
        } else {
            crate::aim::aims(&runs, &config.aim)
        };
        if require_aim
            && aims.is_empty()
            && runs.first().is_some_and(|(s, _)| needs_aim(s, &config.aim))
        {
            unaimed += 1;
            // Also when the attempts run out first: no scene was labelled.
            if unaimed >= config.aim.attempts_for(&selection.family)
                || attempt + 1 == config.validators.max_attempts
            {
                return Ok(None);
            }
            continue;
        }
        let last = attempt + 1 == config.validators.max_attempts;
        results = label_aimed(runs, aims, catalog, config, last);
        if results.iter().all(|r| r.verdicts.all()) {
            break;
        }
        for (v, count) in rejections.rejected_by.iter_mut().enumerate() {
            if results.iter().any(|r| !r.verdicts.as_array()[v]) {
                *count += 1;
            }
        }
    }
    Ok(Some((results, rejections)))
}
