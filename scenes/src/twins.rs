//! Adversarial twins (label rule v5, specification §6, issue #23): matched probe pairs.
//!
//! `[probes]` of `configs/default.toml` lists pairs (an adversarial object — a catalog
//! entry with `looks_like` — and the family that shows it). Each pair takes two scene
//! groups of its family, in the order the embedded planner deals that family's groups
//! (family `f`'s k-th group is build group `k·F + f`, `F` families): the pairs of a
//! family take its groups 0 and 1, 2 and 3, … — so every listed pair is in any build
//! with at least twice as many groups per family as the family has pairs (a 680-scene
//! build has 10 groups per family).
//!
//! * The **probe** group (even k) shows the adversarial object: planned, randomized,
//!   aimed, framed, labelled and resampled like any group (its intent comes from the
//!   disguised object's own properties), but never as a near miss.
//! * The **twin** group (odd k) is the probe group's final specs band by band with only
//!   the object replaced by its look-alike ([`twin_spec`]: the hazard's catalog id,
//!   parts, mass, friction, restitution and hazard flags, and the scene's identity) —
//!   the same room, layout, launch, observer pose, intent, lighting and cameras — then
//!   simulated and labelled afresh. It is never resampled: a twin that fails a
//!   validator stays invalid, and its pair is then left out of the evaluation subset.
//!
//! Both specs record the other's scene index in `family_params.twin_scene_index` (the
//! dataset's `twin_scene_id`). The driver (`driver::produce_planned_group`) asks
//! [`slot`] which role a group plays.

use crate::result::SceneResult;
use rh_catalog::{Catalog, Object};
use rh_physics::seeds;
use rh_physics::spec::SceneSpec;

/// The `family_params` key holding the other scene's index of a twin pair.
pub const TWIN_PARAM: &str = "twin_scene_index";

/// The `family_params` key holding how far apart the pair's hazards get within the
/// observation window (m, [`divergence`]); kept on both scenes also when the pair is
/// dropped for showing too little.
pub const DIVERGENCE_PARAM: &str = "twin_divergence_m";

pub use crate::config::{ProbeConfig, ProbePair};

/// Which side of a pair a group is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Role {
    /// Shows the adversarial object.
    Probe,
    /// The probe's specs with the object replaced by its look-alike.
    Twin,
}

/// A group's place in a probe pair.
#[derive(Debug, Clone, PartialEq)]
pub struct Slot<'a> {
    pub pair: &'a ProbePair,
    pub role: Role,
    pub probe_group: u64,
    pub twin_group: u64,
}

/// The probe pair group `group` of a build over `families` belongs to, if any: the
/// family's pairs take its groups in their order, two each (one for a pair without a
/// twin).
pub fn slot<'a>(probes: &'a ProbeConfig, families: &[String], group: u64) -> Option<Slot<'a>> {
    let n = families.len() as u64;
    if n == 0 {
        return None;
    }
    let (index, k) = (group % n, group / n);
    let family = &families[index as usize];
    let mut first = 0;
    for pair in probes.pairs.iter().filter(|p| &p.family == family) {
        let taken = if pair.twin { 2 } else { 1 };
        if k < first + taken {
            let probe_group = first * n + index;
            return Some(Slot {
                pair,
                role: if k == first { Role::Probe } else { Role::Twin },
                probe_group,
                twin_group: probe_group + n,
            });
        }
        first += taken;
    }
    None
}

/// Why a probe pair cannot be built.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum ProbeError {
    #[error("[probes] pair '{0}': no such catalog object")]
    UnknownObject(String),
    #[error("[probes] pair '{0}': the object is not adversarial (its catalog entry has no `looks_like`)")]
    NotAdversarial(String),
    #[error("[probes] pair '{object}': the object is not listed for family '{family}'")]
    NotInFamily { object: String, family: String },
}

/// The pair's adversarial object and its genuine look-alike, checked against the catalog.
pub fn objects<'c>(
    pair: &ProbePair,
    catalog: &'c Catalog,
) -> Result<(&'c Object, &'c Object), ProbeError> {
    let unknown = |id: &str| ProbeError::UnknownObject(id.to_string());
    let adversarial = catalog
        .object(&pair.adversarial)
        .ok_or_else(|| unknown(&pair.adversarial))?;
    let genuine_id = adversarial
        .looks_like
        .as_deref()
        .ok_or_else(|| ProbeError::NotAdversarial(pair.adversarial.clone()))?;
    let genuine = catalog
        .object(genuine_id)
        .ok_or_else(|| unknown(genuine_id))?;
    for o in [adversarial, genuine] {
        if !o.families.contains(&pair.family) {
            return Err(ProbeError::NotInFamily {
                object: o.id.clone(),
                family: pair.family.clone(),
            });
        }
    }
    Ok((adversarial, genuine))
}

/// The twin of one probe scene: `probe` with every body showing the probe's object
/// (the hazard; the rows and stacks of families that repeat it) made `other` — its
/// catalog id, parts, mass, friction and restitution — the hazard flags `other`'s, and
/// the scene's identity (`scene_index`, `scene_id`, `group_id`, `selection.object_id`)
/// the twin's. Nothing else changes; both specs name each other in [`TWIN_PARAM`].
pub fn twin_spec(
    probe: &mut SceneSpec,
    other: &Object,
    scene_index: u64,
    group_index: u64,
) -> SceneSpec {
    probe
        .family_params
        .insert(TWIN_PARAM.into(), scene_index as f64);
    let mut twin = probe.clone();
    let original = probe.selection.object_id.clone();
    twin.scene_index = scene_index;
    twin.scene_id = seeds::scene_id(probe.build_seed, scene_index);
    twin.group_id = seeds::group_id(probe.build_seed, group_index);
    twin.selection.object_id = other.id.clone();
    for body in twin
        .bodies
        .iter_mut()
        .filter(|b| b.catalog_id.as_deref() == Some(original.as_str()))
    {
        body.name = body.name.replacen(&original, &other.id, 1);
        body.catalog_id = Some(other.id.clone());
        body.parts = crate::families::object_parts(other);
        body.mass = other.mass;
        body.friction = other.friction;
        body.restitution = other.restitution;
    }
    twin.hazard_flags = other.hazards.iter().cloned().collect();
    twin.family_params
        .insert(TWIN_PARAM.into(), probe.scene_index as f64);
    twin
}

/// The hazard's centre of mass at every physics step of the observation window
/// `0..=Δ` of `spec`'s plain run (no observer), stepped exactly as the build's run.
pub fn window_path(spec: &SceneSpec) -> Vec<[f64; 3]> {
    let mut sw = rh_physics::world::build_world(spec);
    let hazard = sw.body_handles[spec.hazard];
    let com = |sw: &rh_physics::world::SceneWorld| {
        let c = sw.world.bodies[hazard].center_of_mass();
        [c.x as f64, c.y as f64, c.z as f64]
    };
    let mut path = vec![com(&sw)];
    for _ in 0..spec.decision_step() {
        sw.step();
        path.push(com(&sw));
    }
    path
}

/// Label rule v6: how far apart two scenes' hazards get within the observation window —
/// the largest distance between their centres of mass at one physics step of `0..=Δ`.
pub fn divergence(a: &SceneSpec, b: &SceneSpec) -> f64 {
    window_path(a)
        .iter()
        .zip(window_path(b))
        .map(|(p, q)| {
            ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt()
        })
        .fold(0.0, f64::max)
}

/// Records a pair's divergence on both scenes and, below `divergence_min`, unpairs them
/// (neither names the other): the pair's physics does not show in the window.
pub fn keep_if_divergent(probe: &mut SceneSpec, twin: &mut SceneSpec, divergence_min: f64) -> f64 {
    let d = divergence(probe, twin);
    for s in [&mut *probe, &mut *twin] {
        s.family_params.insert(DIVERGENCE_PARAM.into(), d);
        if d < divergence_min {
            s.family_params.remove(TWIN_PARAM);
        }
    }
    d
}

/// The twins of a twin pair's probe bands, labelled by `label` (the build's labelling,
/// not the probe's), each pair kept only where its hazards come `divergence_min` apart in
/// the window ([`keep_if_divergent`]). `None` — and every probe band unpaired — when a
/// probe or twin band fails a validator: then the twin group is planned afresh.
pub(crate) fn pair_twins(
    probe: &mut [SceneResult],
    slot: &Slot,
    genuine: &rh_catalog::Object,
    divergence_min: f64,
    label: &dyn Fn(SceneSpec, rh_physics::simulate::Simulation) -> SceneResult,
) -> Option<Vec<SceneResult>> {
    let mut twin = Vec::with_capacity(probe.len());
    for (band, r) in probe.iter_mut().enumerate() {
        let index = slot.twin_group * 4 + band as u64;
        let mut spec = twin_spec(&mut r.spec, genuine, index, slot.twin_group);
        spec = SceneSpec::from_json(&spec.to_json()).expect("a spec parses back");
        keep_if_divergent(&mut r.spec, &mut spec, divergence_min);
        let sim =
            rh_physics::simulate::simulate(&spec, rh_physics::simulate::SimOptions::default());
        twin.push(label(spec, sim));
    }
    if std::env::var_os("RH_TWIN_DEBUG").is_some() {
        for (p, t) in probe.iter().zip(&twin) {
            eprintln!(
                "twin {} {} {:?} {}/{} valid {}/{} {:?} d {:.3}",
                p.spec.family,
                p.spec.selection.object_id,
                crate::intent::Intent::of(&p.spec),
                p.labels.gt_action.as_str(),
                t.labels.gt_action.as_str(),
                p.verdicts.all(),
                t.verdicts.all(),
                t.verdicts.as_array(),
                t.spec
                    .family_params
                    .get(DIVERGENCE_PARAM)
                    .copied()
                    .unwrap_or(0.0)
            );
        }
    }
    let all_valid = probe.iter().chain(&twin).all(|r| r.verdicts.all());
    if !all_valid {
        for r in probe.iter_mut() {
            r.spec.family_params.remove(TWIN_PARAM);
            r.spec.family_params.remove(DIVERGENCE_PARAM);
        }
        return None;
    }
    Some(twin)
}

/// The other scene's index of a twin pair, if `spec` is in one.
pub fn twin_of(spec: &SceneSpec) -> Option<u64> {
    spec.family_params.get(TWIN_PARAM).map(|&i| i as u64)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::Config;

    fn pair(adversarial: &str, family: &str, twin: bool) -> ProbePair {
        ProbePair {
            adversarial: adversarial.into(),
            family: family.into(),
            twin,
        }
    }

    #[test]
    fn pairs_take_their_family_groups_in_order() {
        let families: Vec<String> = ["a", "b", "c"].map(String::from).to_vec();
        let probes = ProbeConfig {
            pairs: vec![
                pair("x", "b", true),
                pair("y", "b", false),
                pair("z", "b", true),
            ],
            divergence_min: 0.1,
        };
        // Family b owns groups 1, 4, 7, 10, 13, 16, …: x takes 1 and 4, y 7, z 10 and 13.
        let roles: Vec<(u64, &str, Role, u64)> = (0..20)
            .filter_map(|g| {
                slot(&probes, &families, g)
                    .map(|s| (g, s.pair.adversarial.as_str(), s.role, s.probe_group))
            })
            .collect();
        assert_eq!(
            roles,
            vec![
                (1, "x", Role::Probe, 1),
                (4, "x", Role::Twin, 1),
                (7, "y", Role::Probe, 7),
                (10, "z", Role::Probe, 10),
                (13, "z", Role::Twin, 10),
            ]
        );
        assert_eq!(slot(&probes, &families, 4).unwrap().twin_group, 4);
        assert_eq!(slot(&probes, &[], 4), None);
    }

    #[test]
    fn every_adversarial_object_is_in_every_680_scene_build() {
        let config = Config::embedded().unwrap();
        let catalog = Catalog::embedded().unwrap();
        let families = &config.build.families;
        let groups = 680 / 4;
        let mut shown = std::collections::BTreeSet::new();
        for g in 0..groups {
            if let Some(s) = slot(&config.probes, families, g) {
                let (adversarial, genuine) = objects(s.pair, &catalog).unwrap();
                assert_eq!(genuine.id, adversarial.looks_like.clone().unwrap());
                if s.pair.twin {
                    // Both groups of a twin pair are in the build.
                    assert!(s.twin_group < groups, "{:?}", s.pair);
                }
                shown.insert(adversarial.id.clone());
            }
        }
        let all: std::collections::BTreeSet<String> = catalog
            .objects
            .iter()
            .filter(|o| o.is_adversarial())
            .map(|o| o.id.clone())
            .collect();
        assert_eq!(shown, all);
        assert!(config.probes.pairs.iter().filter(|p| p.twin).count() >= 10);
    }

    #[test]
    fn a_pair_naming_a_genuine_or_unknown_object_is_a_clear_error() {
        let catalog = Catalog::embedded().unwrap();
        let e = objects(&pair("apple", "object_drop", true), &catalog).unwrap_err();
        assert_eq!(e, ProbeError::NotAdversarial("apple".into()));
        let e = objects(&pair("ghost", "object_drop", true), &catalog).unwrap_err();
        assert!(e.to_string().contains("'ghost'"), "{e}");
        let e = objects(&pair("steel_apple", "door_swing", true), &catalog).unwrap_err();
        assert!(matches!(e, ProbeError::NotInFamily { .. }), "{e}");
    }
}
