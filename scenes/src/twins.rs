//! Adversarial twins (label rule v5, SPEC §6, issue #23): matched probe pairs.
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

use rh_catalog::{Catalog, Object};
use rh_physics::seeds;
use rh_physics::spec::SceneSpec;
use serde::{Deserialize, Serialize};

/// The `family_params` key holding the other scene's index of a twin pair.
pub const TWIN_PARAM: &str = "twin_scene_index";

/// `[probes]` of `configs/default.toml` (absent: no twins, builds before label rule v5).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProbeConfig {
    #[serde(default)]
    pub pairs: Vec<ProbePair>,
}

/// One probe pair: the disguised object and the family that shows it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProbePair {
    pub adversarial: String,
    pub family: String,
    /// `false`: the object only needs to appear (one probe group, no twin) — for objects
    /// whose look-alike the physics cannot tell apart in any family that shows them.
    #[serde(default = "yes")]
    pub twin: bool,
}

fn yes() -> bool {
    true
}

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

/// The other scene's index of a twin pair, if `spec` is in one.
pub fn twin_of(spec: &SceneSpec) -> Option<u64> {
    spec.family_params.get(TWIN_PARAM).map(|&i| i as u64)
}
