//! Label balance of the evaluation subset (specification §6, §8: 18 scenes per family).
//!
//! `label_balance` builds, for each family, the scene groups that a full build of `pool`
//! scenes (680 by default) with the same seed would give that family (the embedded
//! planner deals groups to families round-robin), chooses that family's evaluation
//! subset exactly as the dataset's `eval` config does (`eval_subset::select`), and counts
//! the ground-truth actions of the subset and of the whole pool. `rh-pipeline balance`
//! prints the table (or JSON with the shares).
//!
//! Families that cannot give a CATCH, and why the physics demands it: `furniture_tip`
//! (every catalog entry is heavy furniture), `ladder_slip` and `door_swing` (the light
//! props — a prop ladder, a hollow prop door — are longer than the arms can hold:
//! `catch_radius_max`).

use crate::config::Config;
use crate::driver::plan_and_produce;
use crate::eval_subset::{EvalConfig, EvalRow};
use crate::families;
use crate::label::Action;
use rayon::prelude::*;
use rh_catalog::Catalog;
use serde::Serialize;
use std::fmt::Write;

/// Counts of ground-truth actions among one family's evaluation subset and pool.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FamilyBalance {
    pub family: String,
    /// The evaluation subset's labels.
    pub catch: usize,
    pub dodge: usize,
    pub no_action: usize,
    /// The pool's (every scene of the family's groups, valid or not).
    pub pool_catch: usize,
    pub pool_dodge: usize,
    pub pool_no_action: usize,
    /// Pool scenes that failed a validator after every resampling attempt.
    pub invalid: usize,
    /// Group attempts made (one per group when nothing is rejected).
    pub attempts: u32,
    /// Attempts rejected by each validator (`validate::VALIDATOR_COLUMNS` order).
    pub rejected_by: Vec<u32>,
    /// Adversarial twin pairs (`twins`) with both scenes in the evaluation subset, and
    /// how many of them have different labels; the same over the pool (both valid).
    pub twin_pairs: usize,
    pub twin_pairs_differing: usize,
    pub pool_twin_pairs: usize,
    pub pool_twin_pairs_differing: usize,
    /// Candidate pairs of the pool left unpaired because their hazards did not diverge
    /// in the window (label rule v6, `[probes] divergence_min`).
    pub pool_unpaired: usize,
    /// Every twin pair of the pool (both valid), with its divergence in the window.
    pub pairs: Vec<PairReport>,
    /// The adversarial objects the pool shows (valid scenes or not).
    pub adversarial_objects: Vec<String>,
}

impl FamilyBalance {
    /// Share of this family's attempts that the reaction-time validator rejected.
    pub fn reaction_rejection_rate(&self) -> f64 {
        let i = crate::validate::VALIDATOR_COLUMNS
            .iter()
            .position(|c| *c == "valid_reaction_time")
            .expect("a validator column");
        self.rejected_by[i] as f64 / self.attempts.max(1) as f64
    }

    /// Scenes in the evaluation subset.
    pub fn total(&self) -> usize {
        self.catch + self.dodge + self.no_action
    }
}

/// Label counts and shares (`share_*` = count / total).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Shares {
    pub scenes: usize,
    pub catch: usize,
    pub dodge: usize,
    pub no_action: usize,
    pub share_catch: f64,
    pub share_dodge: f64,
    pub share_no_action: f64,
}

impl Shares {
    pub fn of(catch: usize, dodge: usize, no_action: usize) -> Shares {
        let scenes = catch + dodge + no_action;
        let share = |n: usize| n as f64 / scenes.max(1) as f64;
        Shares {
            scenes,
            catch,
            dodge,
            no_action,
            share_catch: share(catch),
            share_dodge: share(dodge),
            share_no_action: share(no_action),
        }
    }
}

/// One twin pair of the pool: its scenes, objects and labels, how far apart its hazards
/// get in the observation window (m, `twins::divergence`), and whether the evaluation
/// subset holds both scenes.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PairReport {
    pub probe_scene: u64,
    pub twin_scene: u64,
    pub probe_object: String,
    pub twin_object: String,
    pub probe_label: String,
    pub twin_label: String,
    pub divergence_m: f64,
    pub in_eval: bool,
}

/// What `balance --json` prints.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Balance {
    pub seed: u64,
    /// The full build whose groups form the pool (scenes).
    pub pool: u64,
    pub per_family: usize,
    /// The evaluation subset's labels, and the pool's.
    pub eval: Shares,
    pub pool_labels: Shares,
    /// Families with at least 3 CATCH (and 3 DODGE) in the subset.
    pub families_with_3_catch: usize,
    pub families_with_3_dodge: usize,
    /// Adversarial twin pairs in the subset and in the pool, and their differing labels.
    pub twins: TwinShares,
    /// Adversarial catalog objects that no pool scene shows.
    pub adversarial_missing: Vec<String>,
    pub families: Vec<FamilyBalance>,
}

/// Twin pairs (both scenes valid) and the share whose two labels differ.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct TwinShares {
    /// Subset pairs whose hazards come at least 0.10 m apart in the window (rule v6).
    pub eval_diverging: usize,
    pub eval_share_diverging: f64,
    pub pool_unpaired: usize,
    pub eval_pairs: usize,
    pub eval_differing: usize,
    pub eval_share_differing: f64,
    pub pool_pairs: usize,
    pub pool_differing: usize,
    pub pool_share_differing: f64,
}

impl Balance {
    /// `catalog`: to name the adversarial objects missing from the pool.
    pub fn of(
        catalog: &Catalog,
        seed: u64,
        pool: u64,
        per_family: usize,
        families: Vec<FamilyBalance>,
    ) -> Balance {
        let sum = |f: fn(&FamilyBalance) -> usize| families.iter().map(f).sum::<usize>();
        let share = |n: usize, of: usize| n as f64 / of.max(1) as f64;
        let (pairs, differing) = (sum(|f| f.twin_pairs), sum(|f| f.twin_pairs_differing));
        let (pool_pairs, pool_differing) = (
            sum(|f| f.pool_twin_pairs),
            sum(|f| f.pool_twin_pairs_differing),
        );
        let diverging = families
            .iter()
            .flat_map(|f| &f.pairs)
            .filter(|p| p.in_eval && p.divergence_m >= DIVERGING_M)
            .count();
        let seen: std::collections::BTreeSet<&String> = families
            .iter()
            .flat_map(|f| &f.adversarial_objects)
            .collect();
        Balance {
            twins: TwinShares {
                eval_diverging: diverging,
                eval_share_diverging: share(diverging, pairs),
                pool_unpaired: sum(|f| f.pool_unpaired),
                eval_pairs: pairs,
                eval_differing: differing,
                eval_share_differing: share(differing, pairs),
                pool_pairs,
                pool_differing,
                pool_share_differing: share(pool_differing, pool_pairs),
            },
            adversarial_missing: catalog
                .objects
                .iter()
                .filter(|o| o.is_adversarial() && !seen.contains(&o.id))
                .map(|o| o.id.clone())
                .collect(),
            seed,
            pool,
            per_family,
            eval: Shares::of(sum(|f| f.catch), sum(|f| f.dodge), sum(|f| f.no_action)),
            pool_labels: Shares::of(
                sum(|f| f.pool_catch),
                sum(|f| f.pool_dodge),
                sum(|f| f.pool_no_action),
            ),
            families_with_3_catch: families.iter().filter(|f| f.catch >= 3).count(),
            families_with_3_dodge: families.iter().filter(|f| f.dodge >= 3).count(),
            families,
        }
    }
}

/// The window divergence a probe pair must show (label rule v6, specification §6): 0.10 m.
pub const DIVERGING_M: f64 = 0.10;

/// Builds the pool of each family in `families` (canonical names; all implemented
/// families if empty) — the groups a full build of `pool` scenes over all families gives
/// it, with `build_seed` — and counts the labels of its evaluation subset of
/// `per_family` scenes (`eval_subset::select` under `[eval]`) and of the whole pool.
pub fn label_balance(
    catalog: &Catalog,
    config: &Config,
    build_seed: u64,
    families: &[String],
    per_family: usize,
    pool: u64,
) -> anyhow::Result<Vec<FamilyBalance>> {
    let all: Vec<String> = families::all()
        .iter()
        .map(|f| f.name().to_string())
        .collect();
    let wanted: Vec<String> = if families.is_empty() {
        all.clone()
    } else {
        families.to_vec()
    };
    let n_groups = pool.div_ceil(4).max(all.len() as u64);
    let eval_cfg = EvalConfig {
        per_family,
        ..config.eval.clone()
    };
    let mut out = Vec::new();
    let mut built_families: Vec<(FamilyBalance, Vec<PoolScene>)> = Vec::new();
    for family in &wanted {
        let index = all
            .iter()
            .position(|f| f == family)
            .ok_or_else(|| anyhow::anyhow!("unknown or unimplemented family '{family}'"))?;
        let groups: Vec<u64> = (index as u64..n_groups).step_by(all.len()).collect();
        let built: Vec<anyhow::Result<_>> = groups
            .par_iter()
            .map(|&group| {
                plan_and_produce(catalog, &all, None, build_seed, group, 4, config)
                    .map_err(anyhow::Error::msg)
            })
            .collect();
        let mut balance = FamilyBalance {
            family: family.clone(),
            catch: 0,
            dodge: 0,
            no_action: 0,
            pool_catch: 0,
            pool_dodge: 0,
            pool_no_action: 0,
            invalid: 0,
            attempts: 0,
            rejected_by: vec![0; crate::validate::VALIDATOR_COLUMNS.len()],
            twin_pairs: 0,
            twin_pairs_differing: 0,
            pool_twin_pairs: 0,
            pool_twin_pairs_differing: 0,
            pool_unpaired: 0,
            pairs: Vec::new(),
            adversarial_objects: Vec::new(),
        };
        let mut scenes: Vec<PoolScene> = Vec::new();
        for result in built {
            let (results, rejections) = result?;
            balance.attempts += rejections.attempts;
            for (total, n) in balance.rejected_by.iter_mut().zip(rejections.rejected_by) {
                *total += n;
            }
            for r in results {
                if !r.verdicts.all() {
                    balance.invalid += 1;
                }
                match r.labels.gt_action {
                    Action::Catch => balance.pool_catch += 1,
                    Action::Dodge => balance.pool_dodge += 1,
                    Action::NoAction => balance.pool_no_action += 1,
                }
                let object = &r.spec.selection.object_id;
                if catalog.object(object).is_some_and(|o| o.is_adversarial())
                    && !balance.adversarial_objects.contains(object)
                {
                    balance.adversarial_objects.push(object.clone());
                }
                let divergence = r.spec.family_params.get(crate::twins::DIVERGENCE_PARAM);
                let twin = crate::twins::twin_of(&r.spec);
                balance.pool_unpaired += usize::from(divergence.is_some() && twin.is_none());
                scenes.push(PoolScene {
                    index: r.spec.scene_index,
                    valid: r.verdicts.all(),
                    action: r.labels.gt_action,
                    twin,
                    object: object.clone(),
                    divergence: divergence.copied().unwrap_or(0.0),
                });
            }
        }
        balance.adversarial_objects.sort();
        built_families.push((balance, scenes));
    }
    // One subset over every family (the NO_ACTION fill is a share of the whole subset),
    // exactly as the dataset's `eval` config chooses it.
    let rows: Vec<EvalRow> = built_families
        .iter()
        .flat_map(|(balance, scenes)| {
            scenes.iter().map(|p| EvalRow {
                family: balance.family.as_str(),
                scene_index: p.index,
                valid: p.valid,
                action: p.action.as_str(),
                twin: p.twin,
            })
        })
        .collect();
    let chosen_rows = crate::eval_subset::select(&rows, &eval_cfg).0;
    let mut start = 0;
    for (mut balance, scenes) in built_families {
        let end = start + scenes.len();
        let chosen: Vec<usize> = chosen_rows
            .iter()
            .filter(|&&r| (start..end).contains(&r))
            .map(|&r| r - start)
            .collect();
        start = end;
        count_subset(&mut balance, &scenes, &chosen);
        out.push(balance);
    }
    Ok(out)
}

/// One pool scene of a family, as the subset and the pair counts need it.
struct PoolScene {
    index: u64,
    valid: bool,
    action: Action,
    twin: Option<u64>,
    object: String,
    divergence: f64,
}

/// Counts the labels and twin pairs of a family's chosen scenes (indices into `scenes`).
fn count_subset(balance: &mut FamilyBalance, scenes: &[PoolScene], chosen: &[usize]) {
    for &i in chosen {
        match scenes[i].action {
            Action::Catch => balance.catch += 1,
            Action::Dodge => balance.dodge += 1,
            Action::NoAction => balance.no_action += 1,
        }
    }
    // Twin pairs, counted once (from the lower index), both scenes valid.
    let at: std::collections::BTreeMap<u64, usize> = scenes
        .iter()
        .enumerate()
        .map(|(i, s)| (s.index, i))
        .collect();
    for (i, p) in scenes.iter().enumerate() {
        let Some(&j) = p.twin.filter(|&t| t > p.index).and_then(|t| at.get(&t)) else {
            continue;
        };
        let q = &scenes[j];
        if !(p.valid && q.valid) {
            continue;
        }
        let differ = usize::from(p.action != q.action);
        let in_eval = chosen.contains(&i) && chosen.contains(&j);
        balance.pool_twin_pairs += 1;
        balance.pool_twin_pairs_differing += differ;
        if in_eval {
            balance.twin_pairs += 1;
            balance.twin_pairs_differing += differ;
        }
        balance.pairs.push(PairReport {
            probe_scene: p.index,
            twin_scene: q.index,
            probe_object: p.object.clone(),
            twin_object: q.object.clone(),
            probe_label: p.action.as_str().to_string(),
            twin_label: q.action.as_str().to_string(),
            divergence_m: p.divergence,
            in_eval,
        });
    }
}

/// The balance as a plain-text table: label counts, then the group attempts made and
/// the share of them each validator rejected (`reaction`: the reaction-time rule of
/// label rule v2, a share of the attempts); `other n`: how many rejections the other
/// validators made, a count (one attempt can fail several of them, so no share of the
/// attempts).
pub fn format_table(rows: &[FamilyBalance]) -> String {
    let header = format!(
        "{:<16} {:>6} {:>6} {:>9}   {:>15} {:>7} {:>8} {:>9} {:>7}\n",
        "family",
        "CATCH",
        "DODGE",
        "NO_ACTION",
        "pool C/D/N",
        "invalid",
        "attempts",
        "reaction",
        "other n"
    );
    let mut s = header;
    let reaction = crate::validate::VALIDATOR_COLUMNS
        .iter()
        .position(|c| *c == "valid_reaction_time")
        .expect("a validator column");
    let mut total = FamilyBalance {
        family: "total".into(),
        catch: 0,
        dodge: 0,
        no_action: 0,
        pool_catch: 0,
        pool_dodge: 0,
        pool_no_action: 0,
        invalid: 0,
        attempts: 0,
        rejected_by: vec![0; crate::validate::VALIDATOR_COLUMNS.len()],
        twin_pairs: 0,
        twin_pairs_differing: 0,
        pool_twin_pairs: 0,
        pool_twin_pairs_differing: 0,
        pool_unpaired: 0,
        pairs: Vec::new(),
        adversarial_objects: Vec::new(),
    };
    let line = |r: &FamilyBalance| {
        let other: u32 = r
            .rejected_by
            .iter()
            .enumerate()
            .filter(|(i, _)| *i != reaction)
            .map(|(_, n)| n)
            .sum();
        let pct = |n: u32| format!("{:.0}%", 100.0 * n as f64 / r.attempts.max(1) as f64);
        format!(
            "{:<16} {:>6} {:>6} {:>9}   {:>15} {:>7} {:>8} {:>9} {:>7}\n",
            r.family,
            r.catch,
            r.dodge,
            r.no_action,
            format!("{}/{}/{}", r.pool_catch, r.pool_dodge, r.pool_no_action),
            r.invalid,
            r.attempts,
            pct(r.rejected_by[reaction]),
            other
        )
    };
    for r in rows {
        s.push_str(&line(r));
        total.catch += r.catch;
        total.dodge += r.dodge;
        total.no_action += r.no_action;
        total.pool_catch += r.pool_catch;
        total.pool_dodge += r.pool_dodge;
        total.pool_no_action += r.pool_no_action;
        total.invalid += r.invalid;
        total.attempts += r.attempts;
        total.twin_pairs += r.twin_pairs;
        total.twin_pairs_differing += r.twin_pairs_differing;
        total.pool_twin_pairs += r.pool_twin_pairs;
        total.pool_twin_pairs_differing += r.pool_twin_pairs_differing;
        total.pool_unpaired += r.pool_unpaired;
        total.pairs.extend(r.pairs.iter().cloned());
        for (t, n) in total.rejected_by.iter_mut().zip(&r.rejected_by) {
            *t += n;
        }
    }
    s.push_str(&line(&total));
    let share = |n: usize, of: usize| 100.0 * n as f64 / of.max(1) as f64;
    let (e, p) = (
        total.total(),
        total.pool_catch + total.pool_dodge + total.pool_no_action,
    );
    let _ = writeln!(
        s,
        "shares: evaluation subset CATCH {:.1}%, DODGE {:.1}%, NO_ACTION {:.1}% of {e}; pool CATCH {:.1}%, DODGE {:.1}%, NO_ACTION {:.1}% of {p}",
        share(total.catch, e),
        share(total.dodge, e),
        share(total.no_action, e),
        share(total.pool_catch, p),
        share(total.pool_dodge, p),
        share(total.pool_no_action, p)
    );
    let _ = writeln!(
        s,
        "adversarial twin pairs: {} in the evaluation subset, {} of them with different labels; {} in the pool, {} differing",
        total.twin_pairs, total.twin_pairs_differing, total.pool_twin_pairs, total.pool_twin_pairs_differing
    );
    let diverging = total
        .pairs
        .iter()
        .filter(|p| p.in_eval && p.divergence_m >= DIVERGING_M)
        .count();
    let _ = writeln!(
        s,
        "twin pairs in the subset whose hazards come >= {DIVERGING_M} m apart in the window: {diverging} of {}; candidate pairs left unpaired (no divergence): {}",
        total.twin_pairs, total.pool_unpaired / 2
    );
    s
}
