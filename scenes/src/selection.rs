//! Stage 1 — plan, the scene-selection planner: choose *what* happens (family, object,
//! room), never a number. (Not a model's reaction plan: that is `rh-score`'s `plan`.)
//!
//! Two planners share the `Planner` trait's output type, `Selection`:
//! * `plan_group` is the embedded planner of `build --n N`: a pure function of the
//!   build seed and group index, balanced round-robin across the requested families.
//! * `LexiconPlanner` maps a free-text description to a validated selection with a
//!   deterministic phrase lexicon. An LLM-backed planner can implement `Planner` later.

use rand::RngExt;
use rh_catalog::{Catalog, Object, Room};
use rh_physics::seeds;
use rh_physics::spec::{LabelConfig, Selection};

#[derive(Debug, thiserror::Error, PartialEq)]
pub enum PlanError {
    #[error("the description matches no catalogue object, room or event; close catalogue names: {suggestions}")]
    NothingMatched { suggestions: String },
    #[error("no catalogue object fits family '{family}'")]
    NoObjectForFamily { family: String },
    #[error("no room hosts family '{family}'")]
    NoRoomForFamily { family: String },
    #[error("'{object}' cannot take part in '{family}' events; it appears in: {allowed}. Objects for '{family}' include: {examples}")]
    ObjectNotInFamily {
        object: String,
        family: String,
        allowed: String,
        examples: String,
    },
    #[error("the description is empty")]
    Empty,
}

/// Maps a description to a selection. Implementations must be deterministic in
/// `(description, seed)`.
pub trait Planner: Sync {
    fn plan(&self, description: &str, seed: u64) -> Result<Selection, PlanError>;
}

/// What the embedded planner balances (label rule v5, `[plan]` of `configs/default.toml`).
#[derive(Debug, Clone, PartialEq)]
pub struct PlanPolicy {
    /// Share of a family's groups that show a benign object (one no property makes
    /// dangerous: see [`intrinsically_dangerous`]) when the family has both kinds;
    /// `None`: the object is drawn among all the family's objects (builds before v5).
    pub benign_share: Option<f64>,
    /// Per family, instead of `benign_share` (with it set).
    pub benign_share_by_family: std::collections::BTreeMap<String, f64>,
    /// `heavy_mass_kg` of the label rule: an object this heavy is dangerous.
    pub heavy_mass_kg: f64,
}

impl PlanPolicy {
    /// What a build configuration's planner balances (`[build]`, the label rule's
    /// `heavy_mass_kg`).
    pub fn of(build: &crate::config::BuildSection, labels: &LabelConfig) -> PlanPolicy {
        PlanPolicy {
            benign_share: build.benign_share,
            benign_share_by_family: build.benign_share_by_family.clone(),
            heavy_mass_kg: labels.heavy_mass_kg,
        }
    }
}

/// Whether an object is dangerous by its properties alone (the label rule's `dangerous`
/// before any impact momentum): sharp, hot, large and fragile, or heavy.
pub fn intrinsically_dangerous(object: &Object, heavy_mass_kg: f64) -> bool {
    object.has_hazard("sharp")
        || object.has_hazard("hot")
        || (object.has_hazard("fragile") && object.has_hazard("large"))
        || object.mass >= heavy_mass_kg
}

/// The embedded planner for descriptionless builds: group `g` gets family
/// `families[g mod F]`; from the group's "plan" stream, whether its object is benign
/// (`policy.benign_share`, when the family has benign and dangerous objects), then the
/// object among those of that kind, then the room. `plan_group_with` under the embedded
/// configuration's policy.
pub fn plan_group(
    catalog: &Catalog,
    families: &[String],
    build_seed: u64,
    group: u64,
) -> Result<Selection, PlanError> {
    static EMBEDDED: std::sync::OnceLock<PlanPolicy> = std::sync::OnceLock::new();
    let policy = EMBEDDED.get_or_init(|| {
        let config =
            crate::config::Config::embedded().expect("the embedded configuration is valid");
        PlanPolicy::of(&config.build, &config.labels)
    });
    plan_group_with(catalog, families, build_seed, group, policy)
}

/// [`plan_group`] under a build configuration's policy (`PlanPolicy::of`).
pub fn plan_group_with(
    catalog: &Catalog,
    families: &[String],
    build_seed: u64,
    group: u64,
    policy: &PlanPolicy,
) -> Result<Selection, PlanError> {
    replan_group(catalog, families, build_seed, group, policy, 0)
}

/// [`plan_group_with`]'s plan number `replan` (0: the group's plan): the same family, the
/// object and room drawn again from the "plan" stream's `replan`-th index, the object
/// kind (benign or dangerous) kept from plan 0.
/// The driver replans a group none of whose attempts passes the validators, or whose
/// event could not be aimed (`[aim] replans`).
pub fn replan_group(
    catalog: &Catalog,
    families: &[String],
    build_seed: u64,
    group: u64,
    policy: &PlanPolicy,
    replan: u32,
) -> Result<Selection, PlanError> {
    let family = &families[(group % families.len() as u64) as usize];
    let mut rng = seeds::stream(seeds::group_seed(build_seed, group), replan, "plan");
    let all: Vec<&Object> = catalog.objects_for_family(family).collect();
    let candidates = match policy.benign_share {
        None => all,
        Some(share) => {
            let share = policy
                .benign_share_by_family
                .get(family)
                .copied()
                .unwrap_or(share);
            let share = share.clamp(0.0, 1.0);
            // A replan keeps its group's first draw of the kind (benign or dangerous): it
            // changes the object and room, never the kind of decision the group asks.
            let first = rng.random_bool(share);
            let benign = if replan == 0 {
                first
            } else {
                seeds::stream(seeds::group_seed(build_seed, group), 0, "plan").random_bool(share)
            };
            let kind: Vec<&Object> = all
                .iter()
                .copied()
                .filter(|o| intrinsically_dangerous(o, policy.heavy_mass_kg) != benign)
                .collect();
            if kind.is_empty() {
                all
            } else {
                kind
            }
        }
    };
    let object = pick(&mut rng, candidates).ok_or_else(|| PlanError::NoObjectForFamily {
        family: family.clone(),
    })?;
    let room = pick(&mut rng, catalog.rooms_for_family(family).collect()).ok_or_else(|| {
        PlanError::NoRoomForFamily {
            family: family.clone(),
        }
    })?;
    Ok(Selection {
        family: family.clone(),
        object_id: object.id.clone(),
        room_id: room.id.clone(),
        description: None,
        planner: None,
    })
}

fn pick<'a, T>(rng: &mut impl rand::Rng, items: Vec<&'a T>) -> Option<&'a T> {
    if items.is_empty() {
        None
    } else {
        Some(items[rng.random_range(0..items.len())])
    }
}

/// Phrases that name an event family. The longest phrase found in a description wins.
const FAMILY_PHRASES: &[(&str, &str)] = &[
    ("falls off the table", "object_drop"),
    ("falls off the counter", "object_drop"),
    ("slides off the counter", "object_drop"),
    ("slides off the table", "object_drop"),
    ("tips off", "object_drop"),
    ("knocked off", "object_drop"),
    ("falls off", "object_drop"),
    ("drops off", "object_drop"),
    ("off the edge", "object_drop"),
    ("off the table", "object_drop"),
    ("off the counter", "object_drop"),
    ("drops", "object_drop"),
    ("slides off the shelf", "shelf_slide"),
    ("slides off a shelf", "shelf_slide"),
    ("slides off a high shelf", "shelf_slide"),
    ("off the shelf", "shelf_slide"),
    ("off a shelf", "shelf_slide"),
    ("from the shelf", "shelf_slide"),
    ("falls off the wall", "hanging_fall"),
    ("comes off the wall", "hanging_fall"),
    ("falls from the wall", "hanging_fall"),
    ("detaches", "hanging_fall"),
    ("falls from the ceiling", "ceiling_drop"),
    ("drops from the ceiling", "ceiling_drop"),
    ("from the ceiling", "ceiling_drop"),
    ("comes loose from the ceiling", "ceiling_drop"),
    ("slides down", "sliding_object"),
    ("down a ramp", "sliding_object"),
    ("down the ramp", "sliding_object"),
    ("ramp", "sliding_object"),
    ("incline", "sliding_object"),
    ("slope", "sliding_object"),
    ("rolls off the counter", "rolling_ball"),
    ("rolls off the table", "rolling_ball"),
    ("rolls off the edge", "rolling_ball"),
    ("rolls off", "rolling_ball"),
    ("rolls across", "rolling_ball"),
    ("rolls toward", "rolling_ball"),
    ("rolls towards", "rolling_ball"),
    ("rolls", "rolling_ball"),
    ("rolling", "rolling_ball"),
    ("hops", "surface_cascade"),
    ("onto the stool", "surface_cascade"),
    ("cascades", "surface_cascade"),
    ("tips over", "furniture_tip"),
    ("topples", "furniture_tip"),
    ("falls over", "furniture_tip"),
    ("stack collapses", "stack_collapse"),
    ("collapses", "stack_collapse"),
    ("stack of", "stack_collapse"),
    ("pile of", "stack_collapse"),
    ("ladder slips", "ladder_slip"),
    ("slips", "ladder_slip"),
    ("swings open", "door_swing"),
    ("slams", "door_swing"),
    ("swings shut", "door_swing"),
    ("swings", "pendulum_swing"),
    ("swinging", "pendulum_swing"),
    ("thrown at", "thrown_object"),
    ("thrown toward", "thrown_object"),
    ("thrown towards", "thrown_object"),
    ("tossed at", "thrown_object"),
    ("hurled at", "thrown_object"),
    ("throws", "thrown_object"),
    ("thrown", "thrown_object"),
    ("tossed", "thrown_object"),
    ("bounces", "bouncing_object"),
    ("bouncing", "bouncing_object"),
    ("down the stairs", "stair_tumble"),
    ("tumbles", "stair_tumble"),
    ("stairs", "stair_tumble"),
    ("knocks into", "chain_reaction"),
    ("strikes", "chain_reaction"),
    ("launches", "chain_reaction"),
    ("row of", "multi_object"),
    ("dominoes", "multi_object"),
    ("domino", "multi_object"),
];

/// The deterministic phrase-lexicon planner (`rh-pipeline plan "<description>"`).
pub struct LexiconPlanner<'a> {
    catalog: &'a Catalog,
}

/// What the lexicon recognised, for people reading `plan` output.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Matches {
    pub object: Option<String>,
    pub family: Option<String>,
    pub room: Option<String>,
}

impl<'a> LexiconPlanner<'a> {
    pub fn new(catalog: &'a Catalog) -> Self {
        LexiconPlanner { catalog }
    }

    /// The phrases recognised in a description.
    pub fn matches(&self, description: &str) -> Matches {
        let text = normalize(description);
        let object = longest_match(&text, self.catalog.objects.iter().flat_map(object_phrases));
        let family = longest_match(
            &text,
            FAMILY_PHRASES.iter().map(|&(p, f)| (p.to_string(), f)),
        );
        let room = longest_match(&text, self.catalog.rooms.iter().flat_map(room_phrases));
        Matches {
            object: object.map(|(p, _)| p),
            family: family.map(|(p, _)| p),
            room: room.map(|(p, _)| p),
        }
    }

    fn find_object(&self, text: &str) -> Option<&'a Object> {
        longest_match(text, self.catalog.objects.iter().flat_map(object_phrases))
            .and_then(|(_, id)| self.catalog.object(id))
    }

    fn find_room(&self, text: &str) -> Option<&'a Room> {
        longest_match(text, self.catalog.rooms.iter().flat_map(room_phrases))
            .and_then(|(_, id)| self.catalog.room(id))
    }

    fn suggestions(&self, text: &str) -> String {
        let words: Vec<&str> = text.split_whitespace().collect();
        let mut candidates: Vec<(usize, String)> = Vec::new();
        let names = self
            .catalog
            .objects
            .iter()
            .map(|o| o.name.to_lowercase())
            .chain(self.catalog.rooms.iter().map(|r| r.name.to_lowercase()));
        for name in names {
            let n_words = name.split_whitespace().count().max(1);
            let best = (0..words.len())
                .flat_map(|i| (1..=n_words.min(words.len() - i)).map(move |len| (i, len)))
                .map(|(i, len)| edit_distance(&words[i..i + len].join(" "), &name))
                .min()
                .unwrap_or(usize::MAX);
            candidates.push((best, name));
        }
        candidates.sort();
        candidates.dedup_by(|a, b| a.1 == b.1);
        candidates
            .into_iter()
            .take(5)
            .map(|(_, n)| n)
            .collect::<Vec<_>>()
            .join(", ")
    }
}

impl Planner for LexiconPlanner<'_> {
    fn plan(&self, description: &str, seed: u64) -> Result<Selection, PlanError> {
        let text = normalize(description);
        if text.trim().is_empty() {
            return Err(PlanError::Empty);
        }
        let object = self.find_object(&text);
        let family = longest_match(
            &text,
            FAMILY_PHRASES.iter().map(|&(p, f)| (p.to_string(), f)),
        )
        .map(|(_, f)| f);
        let room = self.find_room(&text);
        if object.is_none() && family.is_none() && room.is_none() {
            return Err(PlanError::NothingMatched {
                suggestions: self.suggestions(&text),
            });
        }
        let mut rng = seeds::stream(seed, 0, "plan");
        let family: String = match (family, object) {
            (Some(f), _) => f.to_string(),
            (None, Some(o)) => o.families[rng.random_range(0..o.families.len())].clone(),
            (None, None) => {
                let r = room.expect("checked above");
                let hosted: Vec<&str> = rh_contract::FAMILIES
                    .iter()
                    .copied()
                    .filter(|f| r.hosts(f))
                    .collect();
                hosted[rng.random_range(0..hosted.len())].to_string()
            }
        };
        let object = match object {
            Some(o) if o.families.contains(&family) => o,
            Some(o) => {
                return Err(PlanError::ObjectNotInFamily {
                    object: o.name.clone(),
                    family: family.clone(),
                    allowed: o.families.join(", "),
                    examples: self
                        .catalog
                        .objects_for_family(&family)
                        .take(6)
                        .map(|x| x.name.as_str())
                        .collect::<Vec<_>>()
                        .join(", "),
                })
            }
            None => pick(&mut rng, self.catalog.objects_for_family(&family).collect()).ok_or_else(
                || PlanError::NoObjectForFamily {
                    family: family.clone(),
                },
            )?,
        };
        let room = match room {
            Some(r) if r.hosts(&family) => r,
            _ => pick(&mut rng, self.catalog.rooms_for_family(&family).collect()).ok_or_else(
                || PlanError::NoRoomForFamily {
                    family: family.clone(),
                },
            )?,
        };
        Ok(Selection {
            object_id: object.id.clone(),
            room_id: room.id.clone(),
            family,
            description: Some(description.to_string()),
            planner: None,
        })
    }
}

fn object_phrases(o: &Object) -> impl Iterator<Item = (String, &str)> {
    std::iter::once(o.name.clone())
        .chain(std::iter::once(o.id.replace('_', " ")))
        .chain(o.synonyms.iter().cloned())
        .map(|p| normalize(&p))
        .map(move |p| (p, o.id.as_str()))
}

fn room_phrases(r: &Room) -> impl Iterator<Item = (String, &str)> {
    std::iter::once(r.name.clone())
        .chain(std::iter::once(r.id.replace('_', " ")))
        .chain(r.synonyms.iter().cloned())
        .map(|p| normalize(&p))
        .map(move |p| (p, r.id.as_str()))
}

/// Lowercase, punctuation to spaces (keeping hyphens inside words as spaces too), one
/// space between words, padded so whole-word matching is a substring test.
fn normalize(text: &str) -> String {
    let cleaned: String = text
        .to_lowercase()
        .chars()
        .map(|c| {
            if c.is_alphanumeric() || c == '\'' {
                c
            } else {
                ' '
            }
        })
        .collect();
    let words: Vec<&str> = cleaned.split_whitespace().collect();
    format!(" {} ", words.join(" "))
}

/// The longest phrase (by characters) occurring as whole words in `text`; ties keep
/// the first in iteration order, so results are deterministic.
fn longest_match<'b, I>(text: &str, phrases: I) -> Option<(String, &'b str)>
where
    I: Iterator<Item = (String, &'b str)>,
{
    let mut best: Option<(String, &'b str)> = None;
    for (phrase, value) in phrases {
        let phrase = phrase.trim().to_string();
        if phrase.is_empty() {
            continue;
        }
        let padded = format!(" {phrase} ");
        if text.contains(&padded) && best.as_ref().is_none_or(|(b, _)| phrase.len() > b.len()) {
            best = Some((phrase, value));
        }
    }
    best
}

fn edit_distance(a: &str, b: &str) -> usize {
    let a: Vec<char> = a.chars().collect();
    let b: Vec<char> = b.chars().collect();
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    for i in 1..=a.len() {
        let mut cur = vec![i; b.len() + 1];
        for j in 1..=b.len() {
            let cost = usize::from(a[i - 1] != b[j - 1]);
            cur[j] = (prev[j] + 1).min(cur[j - 1] + 1).min(prev[j - 1] + cost);
        }
        prev = cur;
    }
    prev[b.len()]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn catalog() -> Catalog {
        Catalog::embedded().unwrap()
    }

    #[test]
    fn group_plan_is_balanced_and_deterministic() {
        let c = catalog();
        let families: Vec<String> = ["object_drop", "ceiling_drop", "thrown_object"]
            .map(String::from)
            .to_vec();
        let plans: Vec<Selection> = (0..30)
            .map(|g| plan_group(&c, &families, 9, g).unwrap())
            .collect();
        for f in &families {
            assert_eq!(plans.iter().filter(|p| &p.family == f).count(), 10);
        }
        for (g, p) in plans.iter().enumerate() {
            assert_eq!(p, &plan_group(&c, &families, 9, g as u64).unwrap());
            let o = c.object(&p.object_id).unwrap();
            assert!(o.families.contains(&p.family));
        }
    }

    #[test]
    fn a_replan_keeps_the_groups_object_kind() {
        let c = catalog();
        let policy = PlanPolicy {
            benign_share: Some(0.5),
            benign_share_by_family: Default::default(),
            heavy_mass_kg: 2.0,
        };
        let families = vec!["multi_object".to_string()];
        let mut kinds = [0u32; 2];
        let mut changed = 0;
        for g in 0..40 {
            let first = replan_group(&c, &families, 3, g, &policy, 0).unwrap();
            let kind =
                |s: &Selection| intrinsically_dangerous(c.object(&s.object_id).unwrap(), 2.0);
            kinds[kind(&first) as usize] += 1;
            for replan in 1..4 {
                let again = replan_group(&c, &families, 3, g, &policy, replan).unwrap();
                assert_eq!(kind(&again), kind(&first), "group {g} replan {replan}");
                changed += u32::from(again.object_id != first.object_id);
            }
        }
        // Both kinds occur, and replans do draw other objects.
        assert!(kinds[0] > 5 && kinds[1] > 5, "{kinds:?}");
        assert!(changed > 60, "{changed} of 120 replans changed the object");
    }

    #[test]
    fn lexicon_maps_object_family_and_room() {
        let c = catalog();
        let p = LexiconPlanner::new(&c);
        let s = p
            .plan("A steel apple bounces toward the robot in the kitchen", 1)
            .unwrap();
        assert_eq!(
            (s.object_id.as_str(), s.family.as_str(), s.room_id.as_str()),
            ("steel_apple", "bouncing_object", "kitchen")
        );
        // The longest name wins: "steel apple" over "apple".
        let s = p.plan("an apple rolls off the counter", 1).unwrap();
        assert_eq!(s.object_id, "apple");
        assert_eq!(s.family, "rolling_ball");
        assert_eq!(
            s.description.as_deref(),
            Some("an apple rolls off the counter")
        );
    }

    #[test]
    fn unmatched_text_lists_close_names() {
        let c = catalog();
        let err = LexiconPlanner::new(&c)
            .plan("a purple xylophone does nothing", 0)
            .unwrap_err();
        match err {
            PlanError::NothingMatched { suggestions } => assert!(!suggestions.is_empty()),
            other => panic!("unexpected {other:?}"),
        }
        let err = LexiconPlanner::new(&c)
            .plan("an appel", 0)
            .unwrap_err()
            .to_string();
        assert!(err.contains("apple"), "{err}");
    }

    #[test]
    fn edit_distance_counts_edits() {
        assert_eq!(edit_distance("kitten", "sitting"), 3);
        assert_eq!(edit_distance("", "abc"), 3);
        assert_eq!(edit_distance("same", "same"), 0);
    }
}
