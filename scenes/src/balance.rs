//! Label balance over the evaluation-sized subset (SPEC §8: 18 scenes per family).
//!
//! `label_balance` builds, for each family, the first five scene groups that a full
//! build with the same seed would give that family (the embedded planner deals groups to
//! families round-robin), takes 18 of their 20 scenes, and counts the ground-truth
//! actions. `rh-pipeline balance` prints the table.
//!
//! Families whose label is (almost) always one action, and why the physics demands it:
//! * `furniture_tip`, `ladder_slip`, `door_swing`: nearly every catalog entry is a heavy
//!   (≥ 2 kg) piece of furniture, ladder or door, so an event that reaches the observer
//!   is DODGE; CATCH comes only from the light props (styrofoam TV, prop ladder, hollow
//!   prop door) when they are slow enough.
//! * `pendulum_swing`: the swinging masses are heavy or large-and-fragile except the
//!   foam wrecking ball and the glass pendant lamp at low speed, so DODGE dominates.
//!
//! Every family also has far-observer groups (about 4%), which are NO_ACTION.

use crate::config::Config;
use crate::driver::produce_group_counted;
use crate::families;
use crate::label::Action;
use crate::selection::plan_group_with;
use rh_catalog::Catalog;
use serde::Serialize;

/// Counts of ground-truth actions among one family's scenes.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct FamilyBalance {
    pub family: String,
    pub catch: usize,
    pub dodge: usize,
    pub no_action: usize,
    /// Scenes that failed a validator after every resampling attempt.
    pub invalid: usize,
    /// Group attempts made (one per group when nothing is rejected).
    pub attempts: u32,
    /// Attempts rejected by each validator (`validate::VALIDATOR_COLUMNS` order).
    pub rejected_by: Vec<u32>,
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
}

impl FamilyBalance {
    pub fn total(&self) -> usize {
        self.catch + self.dodge + self.no_action
    }
}

/// Builds `per_family` scenes (18 for the evaluation subset) of each family in
/// `families` (canonical names; all implemented families if empty) with `build_seed`,
/// and counts their labels. Groups are those a full build over all families would give
/// each family, so the counts match what the dataset holds.
pub fn label_balance(
    catalog: &Catalog,
    config: &Config,
    build_seed: u64,
    families: &[String],
    per_family: usize,
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
    let groups_per_family = per_family.div_ceil(4) as u64;
    let mut out = Vec::new();
    for family in &wanted {
        let index = all
            .iter()
            .position(|f| f == family)
            .ok_or_else(|| anyhow::anyhow!("unknown or unimplemented family '{family}'"))?;
        let mut balance = FamilyBalance {
            family: family.clone(),
            catch: 0,
            dodge: 0,
            no_action: 0,
            invalid: 0,
            attempts: 0,
            rejected_by: vec![0; crate::validate::VALIDATOR_COLUMNS.len()],
        };
        let mut taken = 0;
        for j in 0..groups_per_family {
            let group = index as u64 + all.len() as u64 * j;
            let selection = plan_group_with(catalog, &all, build_seed, group, &config.plan_policy())?;
            let (results, rejections) =
                produce_group_counted(&selection, build_seed, group * 4, 4, catalog, config)?;
            balance.attempts += rejections.attempts;
            for (total, n) in balance.rejected_by.iter_mut().zip(rejections.rejected_by) {
                *total += n;
            }
            for r in results {
                if taken == per_family {
                    break;
                }
                taken += 1;
                if !r.verdicts.all() {
                    balance.invalid += 1;
                }
                match r.labels.gt_action {
                    Action::Catch => balance.catch += 1,
                    Action::Dodge => balance.dodge += 1,
                    Action::NoAction => balance.no_action += 1,
                }
            }
        }
        out.push(balance);
    }
    Ok(out)
}

/// The balance as a plain-text table: label counts, then the group attempts made and
/// the share of them each validator rejected (`reaction`: the reaction-time rule of
/// label rule v2; `other`: any other validator).
pub fn format_table(rows: &[FamilyBalance]) -> String {
    let header = format!(
        "{:<16} {:>6} {:>6} {:>9} {:>7} {:>8} {:>9} {:>7}\n",
        "family", "CATCH", "DODGE", "NO_ACTION", "invalid", "attempts", "reaction", "other"
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
        invalid: 0,
        attempts: 0,
        rejected_by: vec![0; crate::validate::VALIDATOR_COLUMNS.len()],
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
            "{:<16} {:>6} {:>6} {:>9} {:>7} {:>8} {:>9} {:>7}\n",
            r.family,
            r.catch,
            r.dodge,
            r.no_action,
            r.invalid,
            r.attempts,
            pct(r.rejected_by[reaction]),
            pct(other)
        )
    };
    for r in rows {
        s.push_str(&line(r));
        total.catch += r.catch;
        total.dodge += r.dodge;
        total.no_action += r.no_action;
        total.invalid += r.invalid;
        total.attempts += r.attempts;
        for (t, n) in total.rejected_by.iter_mut().zip(&r.rejected_by) {
            *t += n;
        }
    }
    s.push_str(&line(&total));
    s
}
