//! The evaluation subset (specification §6, §8): which valid scenes of a build form the `eval`
//! config — `per_family` (18) of each family, 17 × 18 = 306 scenes.
//!
//! Label rule v5 keeps the paper's label shape in the subset by stratifying it: per
//! family, `[eval]` of `configs/default.toml` asks for `catch_share` of the family's
//! scenes as CATCH and at most `no_action_per_family` NO_ACTION scenes, the rest DODGE;
//! a family short of CATCH gives more DODGE and the other way round, but never more
//! NO_ACTION than that: a family without enough real decisions (CATCH or DODGE) stays
//! short of `per_family`, and the card names it. Within a kind, scenes are taken in scene-index order, so the subset is a
//! pure function of the build's rows. The labels themselves are untouched: the subset
//! only chooses among them, and the card prints the whole build's shares beside the
//! subset's. Builds before v5 (no `catch_share`) take whole speed-band groups first,
//! then single scenes, in scene-index order, whatever their labels.

use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// `[eval]` of `configs/default.toml`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EvalConfig {
    pub per_family: usize,
    /// The share of each family's subset asked to be CATCH (`None`: label-blind, whole
    /// groups first — builds before label rule v5).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub catch_share: Option<f64>,
    /// At most this many NO_ACTION scenes per family (with `catch_share`).
    #[serde(default)]
    pub no_action_per_family: usize,
    /// Adversarial twin pairs (`twins`) taken first, whole, per family (with
    /// `catch_share`): both scenes valid, in the probe's scene-index order. Their labels
    /// count toward the family's CATCH and NO_ACTION targets.
    #[serde(default)]
    pub twin_pairs_per_family: usize,
    /// The NO_ACTION scenes a family's twin pairs may bring (with `catch_share`), where
    /// more than `no_action_per_family` (0: that cap — builds before it): a disguised
    /// object caught whose genuine look-alike passes the standing body harmlessly is a
    /// probe like any other. Further NO_ACTION scenes stay within `no_action_per_family`.
    #[serde(default, skip_serializing_if = "is_zero_usize")]
    pub twin_no_action_per_family: usize,
    /// Probe pairs without a NO_ACTION scene are taken before those with one (each in the
    /// probe's order), so the NO_ACTION caps keep the most pairs (false: the probe's order
    /// alone — builds before it).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub decisive_pairs_first: bool,
    /// With `catch_share`: families still short of `per_family` take further NO_ACTION
    /// scenes of their own, one family at a time in name order, while the subset's
    /// NO_ACTION scenes stay within this share of `per_family` × families (0: never —
    /// builds before the fill).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub no_action_fill_share: f64,
}

fn is_zero(v: &f64) -> bool {
    *v == 0.0
}

fn is_zero_usize(v: &usize) -> bool {
    *v == 0
}

impl Default for EvalConfig {
    /// What builds before label rule v5 used (their manifests have no `[eval]`).
    fn default() -> Self {
        EvalConfig {
            per_family: 18,
            catch_share: None,
            no_action_per_family: 0,
            twin_pairs_per_family: 0,
            twin_no_action_per_family: 0,
            decisive_pairs_first: false,
            no_action_fill_share: 0.0,
        }
    }
}

/// One scene as the selection sees it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EvalRow<'a> {
    pub family: &'a str,
    pub scene_index: u64,
    pub valid: bool,
    /// `gt_action` as written in the dataset ("CATCH", "DODGE", "NO_ACTION").
    pub action: &'a str,
    /// The scene index of its adversarial twin (`twin_scene_id`), if in a probe pair.
    pub twin: Option<u64>,
}

/// The chosen rows (indices into `rows`, in scene-index order) and how many scenes
/// each family got.
pub fn select(rows: &[EvalRow], cfg: &EvalConfig) -> (Vec<usize>, BTreeMap<String, usize>) {
    let mut by_family: BTreeMap<&str, Vec<usize>> = BTreeMap::new();
    for (i, r) in rows.iter().enumerate() {
        if r.valid {
            by_family.entry(r.family).or_default().push(i);
        }
    }
    let mut picked: Vec<(&str, Vec<usize>, Vec<usize>)> = Vec::new();
    for (family, mut members) in by_family {
        members.sort_by_key(|&r| rows[r].scene_index);
        let taken = match cfg.catch_share {
            Some(share) => stratified(rows, &members, cfg, share),
            None => whole_groups_first(rows, &members, cfg.per_family),
        };
        picked.push((family, members, taken));
    }
    if cfg.catch_share.is_some() && cfg.no_action_fill_share > 0.0 {
        fill_with_no_action(rows, &mut picked, cfg);
    }
    let mut chosen = Vec::new();
    let mut counts = BTreeMap::new();
    for (family, _, taken) in picked {
        counts.insert(family.to_string(), taken.len());
        chosen.extend(taken);
    }
    chosen.sort_by_key(|&r| rows[r].scene_index);
    (chosen, counts)
}

/// Families short of `per_family` take their next NO_ACTION scene (scene-index order),
/// one family at a time in name order, round after round, while the subset's NO_ACTION
/// scenes stay within `no_action_fill_share` of `per_family` × families.
fn fill_with_no_action(
    rows: &[EvalRow],
    picked: &mut [(&str, Vec<usize>, Vec<usize>)],
    cfg: &EvalConfig,
) {
    let cap = (cfg.no_action_fill_share * (cfg.per_family * picked.len()) as f64).floor() as usize;
    let mut none = picked
        .iter()
        .flat_map(|(_, _, taken)| taken)
        .filter(|&&r| rows[r].action == "NO_ACTION")
        .count();
    let mut progress = true;
    while progress && none < cap {
        progress = false;
        for (_, members, taken) in picked.iter_mut() {
            if none >= cap || taken.len() >= cfg.per_family {
                continue;
            }
            let next = members
                .iter()
                .copied()
                .find(|&r| rows[r].action == "NO_ACTION" && !taken.contains(&r));
            if let Some(r) = next {
                taken.push(r);
                none += 1;
                progress = true;
            }
        }
    }
}

/// Up to `twin_pairs_per_family` probe pairs whose scenes are both valid members and not
/// both NO_ACTION, in the probe's (the lower index's) order, as long as their NO_ACTION
/// scenes stay within `twin_no_action_per_family`; then per kind, the first remaining scenes in index
/// order: CATCH up to its target, NO_ACTION up to its cap (both less what the pairs
/// gave), DODGE for the rest; then whatever is left of CATCH and DODGE, in that order,
/// until `per_family`.
fn stratified(rows: &[EvalRow], members: &[usize], cfg: &EvalConfig, share: f64) -> Vec<usize> {
    let n = cfg.per_family;
    let by_index: BTreeMap<u64, usize> =
        members.iter().map(|&r| (rows[r].scene_index, r)).collect();
    let pair_none_cap = cfg.no_action_per_family.max(cfg.twin_no_action_per_family);
    let mut taken: Vec<usize> = Vec::new();
    for (r, q) in probe_pairs(rows, members, &by_index, cfg) {
        if taken.len() + 2 > n.min(2 * cfg.twin_pairs_per_family) {
            break;
        }
        // Within the family's NO_ACTION cap, like every other scene.
        let none = [r, q]
            .iter()
            .chain(&taken)
            .filter(|&&x| rows[x].action == "NO_ACTION")
            .count();
        if none <= pair_none_cap {
            taken.extend([r, q]);
        }
    }
    let count = |action: &str| taken.iter().filter(|&&r| rows[r].action == action).count();
    let (pair_catch, pair_none) = (count("CATCH"), count("NO_ACTION"));
    let left = n - taken.len();
    let of = |action: &str| -> Vec<usize> {
        members
            .iter()
            .copied()
            .filter(|&r| rows[r].action == action && !taken.contains(&r))
            .collect()
    };
    let (catch, dodge, none) = (of("CATCH"), of("DODGE"), of("NO_ACTION"));
    let c = ((n as f64 * share).round() as usize)
        .saturating_sub(pair_catch)
        .min(catch.len())
        .min(left);
    let na = cfg
        .no_action_per_family
        .saturating_sub(pair_none)
        .min(none.len())
        .min(left - c);
    let d = (left - c - na).min(dodge.len());
    taken.extend(catch[..c].iter().chain(&dodge[..d]).chain(&none[..na]));
    for (kind, from) in [(&catch, c), (&dodge, d)] {
        for &r in &kind[from..] {
            if taken.len() >= n {
                break;
            }
            taken.push(r);
        }
    }
    taken
}

/// A family's probe pairs (both scenes valid members, not both NO_ACTION: nothing reaches
/// the observer with either object, so no decision tells them apart) in the probe's (the
/// lower index's) order; with `decisive_pairs_first`, the pairs without a NO_ACTION scene
/// come first (each kind in that order), so the NO_ACTION cap keeps the most pairs.
fn probe_pairs(
    rows: &[EvalRow],
    members: &[usize],
    by_index: &BTreeMap<u64, usize>,
    cfg: &EvalConfig,
) -> Vec<(usize, usize)> {
    let mut pairs: Vec<(usize, usize)> = members
        .iter()
        .filter_map(|&r| {
            let twin = rows[r].twin.filter(|&t| t > rows[r].scene_index)?;
            by_index.get(&twin).map(|&q| (r, q))
        })
        .filter(|&(r, q)| !(rows[r].action == "NO_ACTION" && rows[q].action == "NO_ACTION"))
        .collect();
    if cfg.decisive_pairs_first {
        // Stable: within each kind, the probe's order.
        pairs.sort_by_key(|&(r, q)| {
            usize::from(rows[r].action == "NO_ACTION") + usize::from(rows[q].action == "NO_ACTION")
        });
    }
    pairs
}

/// Whole speed-band groups (all four bands valid) in index order while they fit, then
/// single valid scenes in index order.
fn whole_groups_first(rows: &[EvalRow], members: &[usize], n: usize) -> Vec<usize> {
    let mut groups: BTreeMap<u64, Vec<usize>> = BTreeMap::new();
    for &r in members {
        groups.entry(rows[r].scene_index / 4).or_default().push(r);
    }
    let mut taken: Vec<usize> = Vec::new();
    for group in groups.values() {
        if group.len() == 4 && taken.len() + 4 <= n {
            taken.extend(group);
        }
    }
    for &r in members {
        if taken.len() >= n {
            break;
        }
        if !taken.contains(&r) {
            taken.push(r);
        }
    }
    taken
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row<'a>(family: &'a str, i: u64, action: &'static str) -> EvalRow<'a> {
        EvalRow {
            family,
            scene_index: i,
            valid: true,
            action,
            twin: None,
        }
    }

    /// Scene `i` of family "a", the probe pair's member whose twin is scene `twin`.
    fn paired(i: u64, twin: u64, action: &'static str) -> EvalRow<'static> {
        EvalRow {
            twin: Some(twin),
            ..row("a", i, action)
        }
    }

    /// Both scenes of the probe pair `i`–`j` of family "a" (labels `a`, `b`).
    fn pair(i: u64, j: u64, a: &'static str, b: &'static str) -> [EvalRow<'static>; 2] {
        [paired(i, j, a), paired(j, i, b)]
    }

    #[test]
    fn stratified_subset_asks_for_the_configured_shares_and_fills_from_the_rest() {
        let cfg = EvalConfig {
            per_family: 10,
            catch_share: Some(0.5),
            no_action_per_family: 1,
            twin_pairs_per_family: 0,
            twin_no_action_per_family: 0,
            decisive_pairs_first: false,
            no_action_fill_share: 0.0,
        };
        // Family a: 3 CATCH, 12 DODGE, 4 NO_ACTION: CATCH short, DODGE fills.
        // Family c: 1 CATCH, 1 DODGE, 5 NO_ACTION: short, one NO_ACTION only.
        let mut rows = Vec::new();
        for i in 0..19u64 {
            let a = match i {
                0 | 5 | 9 => "CATCH",
                1 | 2 | 3 | 4 => "NO_ACTION",
                _ => "DODGE",
            };
            rows.push(row("a", i, a));
        }
        // Family b: 20 CATCH, 20 DODGE, no NO_ACTION; one invalid CATCH is never taken.
        for i in 100..140u64 {
            rows.push(row("b", i, if i % 2 == 0 { "CATCH" } else { "DODGE" }));
        }
        rows[19].valid = false;
        for i in 200..207u64 {
            rows.push(row(
                "c",
                i,
                ["CATCH", "DODGE", "NO_ACTION"][(i as usize).saturating_sub(200).min(2)],
            ));
        }
        let (chosen, counts) = select(&rows, &cfg);
        assert_eq!(counts["a"], 10);
        assert_eq!(counts["b"], 10);
        assert_eq!(counts["c"], 3, "CATCH, DODGE and one NO_ACTION");
        let kinds = |f: &str, k: &str| {
            chosen
                .iter()
                .filter(|&&r| rows[r].family == f && rows[r].action == k)
                .count()
        };
        assert_eq!(
            (
                kinds("a", "CATCH"),
                kinds("a", "DODGE"),
                kinds("a", "NO_ACTION")
            ),
            (3, 6, 1)
        );
        assert_eq!((kinds("b", "CATCH"), kinds("b", "DODGE")), (5, 5));
        assert!(!chosen.contains(&19));
        assert!(chosen
            .windows(2)
            .all(|w| rows[w[0]].scene_index < rows[w[1]].scene_index));
    }

    #[test]
    fn short_families_fill_with_no_action_within_the_subset_share() {
        let cfg = EvalConfig {
            per_family: 4,
            catch_share: Some(0.5),
            no_action_per_family: 1,
            twin_pairs_per_family: 0,
            twin_no_action_per_family: 0,
            decisive_pairs_first: false,
            // 3 families × 4 = 12 scenes: at most floor(0.34 × 12) = 4 NO_ACTION.
            no_action_fill_share: 0.34,
        };
        let mut rows = Vec::new();
        // a: 2 CATCH, 2 DODGE: full, no NO_ACTION. b: 1 DODGE, 5 NO_ACTION: short by 2
        // after its one NO_ACTION. c: 1 CATCH, 4 NO_ACTION: short by 2 too.
        for (i, k) in ["CATCH", "CATCH", "DODGE", "DODGE"].iter().enumerate() {
            rows.push(row("a", i as u64, k));
        }
        rows.push(row("b", 10, "DODGE"));
        for i in 11..16u64 {
            rows.push(row("b", i, "NO_ACTION"));
        }
        rows.push(row("c", 20, "CATCH"));
        for i in 21..25u64 {
            rows.push(row("c", i, "NO_ACTION"));
        }
        let (chosen, counts) = select(&rows, &cfg);
        // Before the fill: b and c one NO_ACTION each (2 of 4 allowed); the fill gives b
        // one more (its next by index, 12), then c one more (22), and stops at the cap.
        assert_eq!((counts["a"], counts["b"], counts["c"]), (4, 3, 3));
        let none: Vec<u64> = chosen
            .iter()
            .filter(|&&r| rows[r].action == "NO_ACTION")
            .map(|&r| rows[r].scene_index)
            .collect();
        assert_eq!(none, vec![11, 12, 21, 22]);
        // Without the fill the short families stay short.
        let off = EvalConfig {
            no_action_fill_share: 0.0,
            ..cfg.clone()
        };
        let (_, counts) = select(&rows, &off);
        assert_eq!((counts["b"], counts["c"]), (2, 2));
    }

    #[test]
    fn twin_pairs_come_first_whole_and_within_the_no_action_cap() {
        let cfg = EvalConfig {
            per_family: 6,
            catch_share: Some(0.5),
            no_action_per_family: 1,
            twin_pairs_per_family: 2,
            twin_no_action_per_family: 0,
            decisive_pairs_first: false,
            no_action_fill_share: 0.0,
        };
        // Pair 0–4: NO_ACTION / NO_ACTION, left out (no probe, and over the cap of one);
        // pair 1–5: CATCH / DODGE, taken; pair 2–6: CATCH / NO_ACTION, taken (the one
        // NO_ACTION); pair 3–7: the twin is invalid: not a pair.
        let mut rows: Vec<EvalRow> = [
            pair(0, 4, "NO_ACTION", "NO_ACTION"),
            pair(1, 5, "CATCH", "DODGE"),
            pair(2, 6, "CATCH", "NO_ACTION"),
            pair(3, 7, "CATCH", "DODGE"),
        ]
        .concat();
        rows[7].valid = false;
        rows.extend([8, 9, 10].map(|i| row("a", i, if i == 8 { "CATCH" } else { "DODGE" })));
        let (chosen, _) = select(&rows, &cfg);
        let indices: Vec<u64> = chosen.iter().map(|&r| rows[r].scene_index).collect();
        // Pairs 1–5 and 2–6; CATCH target 3 less the pairs' 2: one more (3); DODGE for
        // the rest (9); no further NO_ACTION (the pair used the cap).
        assert_eq!(indices, vec![1, 2, 3, 5, 6, 9]);
    }

    #[test]
    fn twin_pairs_may_bring_more_no_action_but_never_two_in_one_pair() {
        let cfg = EvalConfig {
            per_family: 8,
            catch_share: Some(0.5),
            no_action_per_family: 1,
            twin_pairs_per_family: 3,
            twin_no_action_per_family: 2,
            decisive_pairs_first: false,
            ..EvalConfig::default()
        };
        // NO_ACTION / NO_ACTION: no probe, left out although the cap is two; CATCH /
        // NO_ACTION twice: both taken (two NO_ACTION, the pairs' cap); a third would
        // exceed it: left out.
        let mut rows: Vec<EvalRow> = [
            pair(0, 10, "NO_ACTION", "NO_ACTION"),
            pair(1, 11, "CATCH", "NO_ACTION"),
            pair(2, 12, "CATCH", "NO_ACTION"),
            pair(3, 13, "CATCH", "NO_ACTION"),
        ]
        .concat();
        rows.extend(
            [
                (20, "CATCH"),
                (21, "DODGE"),
                (22, "DODGE"),
                (23, "NO_ACTION"),
            ]
            .map(|(i, action)| row("a", i, action)),
        );
        let (chosen, _) = select(&rows, &cfg);
        let indices: Vec<u64> = chosen.iter().map(|&r| rows[r].scene_index).collect();
        // Pairs 1–11 and 2–12; CATCH target 4 less the pairs' 2: 3 and 20; the rest
        // DODGE (21, 22); no single NO_ACTION (the pairs already hold two).
        assert_eq!(indices, vec![1, 2, 3, 11, 12, 20, 21, 22]);
    }

    #[test]
    fn decisive_pairs_are_taken_before_pairs_with_a_no_action_scene() {
        let cfg = EvalConfig {
            per_family: 6,
            catch_share: Some(0.5),
            no_action_per_family: 1,
            twin_pairs_per_family: 2,
            twin_no_action_per_family: 1,
            decisive_pairs_first: true,
            ..EvalConfig::default()
        };
        let rows: Vec<EvalRow> = [
            pair(0, 10, "CATCH", "NO_ACTION"),
            pair(1, 11, "CATCH", "NO_ACTION"),
            pair(2, 12, "CATCH", "DODGE"),
            pair(3, 13, "DODGE", "CATCH"),
        ]
        .concat();
        let pick = |cfg: &EvalConfig| -> Vec<u64> {
            let (chosen, _) = select(&rows, cfg);
            chosen.iter().map(|&r| rows[r].scene_index).collect()
        };
        // Decisive first: pairs 2–12 and 3–13; CATCH target 3 less their 2: scene 0; the
        // NO_ACTION cap of one: scene 10.
        assert_eq!(pick(&cfg), vec![0, 2, 3, 10, 12, 13]);
        // The probe's order alone: pair 0–10 uses the cap, 1–11 is left out, then 2–12;
        // one more CATCH (1) and a DODGE (3): one probe pair fewer.
        let ordered = EvalConfig {
            decisive_pairs_first: false,
            ..cfg.clone()
        };
        assert_eq!(pick(&ordered), vec![0, 1, 2, 3, 10, 12]);
    }

    #[test]
    fn label_blind_subset_prefers_whole_groups_then_fills_by_index() {
        // Family a: groups 0..6 (scenes 0..24); group 1 has an invalid scene.
        let mut rows: Vec<EvalRow> = (0..24)
            .map(|i| EvalRow {
                valid: i != 5,
                ..row("a", i, "DODGE")
            })
            .collect();
        rows.extend((24..30).map(|i| row("b", i, "CATCH")));
        let (chosen, counts) = select(&rows, &EvalConfig::default());
        assert_eq!(counts["a"], 18);
        assert_eq!(counts["b"], 6);
        let a: Vec<u64> = chosen
            .iter()
            .filter(|&&r| rows[r].family == "a")
            .map(|&r| rows[r].scene_index)
            .collect();
        // Whole groups 0, 2, 3, 4 (16 scenes), then the first two valid leftovers: 4, 6.
        let mut expected: Vec<u64> = (0..4).chain(8..20).collect();
        expected.extend([4, 6]);
        expected.sort();
        assert_eq!(a, expected);
    }
}
