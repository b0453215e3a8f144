//! Streaming aggregation: per-decision results are folded into per-model accumulators as
//! they arrive. Cross-model analyses keep one compact record per (scene, model) — 12 bytes,
//! so memory is bounded by scenes × models, never by the size of the predictions file.

use crate::dataset::{Dataset, Scene};
use crate::metrics::DecisionResult;
use crate::safety_rule::SafetyRule;
use rh_contract::Action;

/// A running mean that counts missing values.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Mean {
    pub sum: f64,
    pub n: u64,
    pub missing: u64,
}

impl Mean {
    pub fn add(&mut self, v: Option<f64>) {
        match v {
            Some(x) => {
                self.sum += x;
                self.n += 1;
            }
            None => self.missing += 1,
        }
    }

    pub fn merge(&mut self, o: &Mean) {
        self.sum += o.sum;
        self.n += o.n;
        self.missing += o.missing;
    }

    pub fn value(&self) -> Option<f64> {
        (self.n > 0).then(|| self.sum / self.n as f64)
    }
}

/// Accumulated metrics over a set of scored decisions.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Acc {
    pub n: u64,
    pub saa: u64,
    pub safe: u64,
    pub first: [u64; 4],
    pub fired: [u64; 4],
    /// Predicted CATCH, DODGE, NO_ACTION, and no parseable plan.
    pub predicted: [u64; 4],
    pub d_end: Mean,
    pub aia: Mean,
    pub d_min: Mean,
    pub closing: Mean,
}

impl Acc {
    pub fn add(&mut self, r: &DecisionResult) {
        self.n += 1;
        self.saa += r.saa as u64;
        self.safe += r.safe() as u64;
        if let Some(f) = r.first_rule {
            self.first[f.index()] += 1;
        }
        for rule in SafetyRule::ALL {
            self.fired[rule.index()] += r.fired(rule) as u64;
        }
        self.predicted[r.action.map_or(3, |a| a.index())] += 1;
        self.d_end.add(r.d_end);
        self.aia.add(Some(r.aia));
        self.d_min.add(r.d_min);
        self.closing.add(r.closing);
    }

    pub fn merge(&mut self, o: &Acc) {
        self.n += o.n;
        self.saa += o.saa;
        self.safe += o.safe;
        for i in 0..4 {
            self.first[i] += o.first[i];
            self.fired[i] += o.fired[i];
            self.predicted[i] += o.predicted[i];
        }
        self.d_end.merge(&o.d_end);
        self.aia.merge(&o.aia);
        self.d_min.merge(&o.d_min);
        self.closing.merge(&o.closing);
    }

    pub fn rate(&self, k: u64) -> Option<f64> {
        (self.n > 0).then(|| k as f64 / self.n as f64)
    }
}

/// Record state codes.
pub const REC_ABSENT: u8 = 0;
pub const REC_LOST: u8 = 1;
pub const REC_SCORED: u8 = 2;
/// Action code for "no parseable plan".
pub const ACT_NONE: u8 = 3;

/// The compact per-(scene, model) record used by cross-model analyses.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rec {
    pub state: u8,
    /// 0 CATCH, 1 DODGE, 2 NO_ACTION, 3 no parseable plan.
    pub action: u8,
    pub questions_material: bool,
    /// AIA × 2 (0, 1 or 2).
    pub aia2: u8,
    /// d_end, NaN when missing.
    pub d_end: f32,
    /// HDE d_min, NaN when missing.
    pub d_min: f32,
}

impl Rec {
    /// Whether a decision was scored for this (scene, model).
    pub fn is_scored(&self) -> bool {
        self.state == REC_SCORED
    }

    /// The scored decision's action (`Some(None)`: no parseable plan); `None` when no
    /// decision was scored.
    pub fn decision(&self) -> Option<Option<Action>> {
        self.is_scored()
            .then(|| Action::from_index(self.action as usize))
    }

    /// The scored decision's end distance `d_end`, when it has one.
    pub fn end_distance(&self) -> Option<f64> {
        (self.is_scored() && !self.d_end.is_nan()).then_some(self.d_end as f64)
    }

    /// The scored decision's HDE `d_min`, when it has one.
    pub fn min_distance(&self) -> Option<f64> {
        (self.is_scored() && !self.d_min.is_nan()).then_some(self.d_min as f64)
    }

    /// The scored decision's AIA.
    pub fn aia(&self) -> Option<f64> {
        self.is_scored().then_some(self.aia2 as f64 / 2.0)
    }
}

impl Default for Rec {
    fn default() -> Self {
        Rec {
            state: REC_ABSENT,
            action: ACT_NONE,
            questions_material: false,
            aia2: 0,
            d_end: f32::NAN,
            d_min: f32::NAN,
        }
    }
}

/// "Correct but out of reach" counters (correct CATCH decisions with an impact point).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct ReachAcc {
    pub correct_catch: u64,
    pub misses: u64,
    pub misses_short: u64,
    pub standing_far: u64,
}

impl ReachAcc {
    pub fn merge(&mut self, o: &ReachAcc) {
        self.correct_catch += o.correct_catch;
        self.misses += o.misses;
        self.misses_short += o.misses_short;
        self.standing_far += o.standing_far;
    }
}

/// Everything accumulated for one model.
#[derive(Debug, Clone)]
pub struct ModelAgg {
    pub name: String,
    pub overall: Acc,
    pub by_family: Vec<Acc>,
    /// slow, normal, fast, very_fast, other.
    pub by_band: [Acc; 5],
    pub by_gt: [Acc; 3],
    /// not adversarial, adversarial.
    pub by_adv: [Acc; 2],
    pub lost: u64,
    pub duplicates: u64,
    pub retried_after_error: u64,
    pub reach: ReachAcc,
    pub adv_decisions: u64,
    pub adv_questions: u64,
    pub records: Vec<Rec>,
    /// Prompt versions of the model's lines (`-` for lines without one).
    pub prompt_versions: std::collections::BTreeSet<String>,
}

impl ModelAgg {
    pub fn new(name: String, ds: &Dataset) -> ModelAgg {
        ModelAgg {
            name,
            overall: Acc::default(),
            by_family: vec![Acc::default(); ds.families.len()],
            by_band: Default::default(),
            by_gt: Default::default(),
            by_adv: Default::default(),
            lost: 0,
            duplicates: 0,
            retried_after_error: 0,
            reach: ReachAcc::default(),
            adv_decisions: 0,
            adv_questions: 0,
            records: vec![Rec::default(); ds.scenes.len()],
            prompt_versions: Default::default(),
        }
    }

    /// Folds one line's decision. Returns false when it was a duplicate (not counted).
    /// Policy: the first line for a (scene, model) pair wins; a scored line after a lost
    /// one (a retry after an API error) replaces it.
    pub fn add(
        &mut self,
        scene_idx: u32,
        scene: &Scene,
        result: Option<&DecisionResult>,
        miss_radius: f64,
        far_standing: f64,
    ) -> bool {
        let rec = &mut self.records[scene_idx as usize];
        match (rec.state, result) {
            (REC_SCORED, _) | (REC_LOST, None) => {
                self.duplicates += 1;
                return false;
            }
            (REC_LOST, Some(_)) => {
                self.lost -= 1;
                self.retried_after_error += 1;
            }
            _ => {}
        }
        let Some(r) = result else {
            rec.state = REC_LOST;
            self.lost += 1;
            return true;
        };
        rec.state = REC_SCORED;
        rec.action = r.action.map_or(ACT_NONE, |a| a.index() as u8);
        rec.questions_material = r.questions_material;
        rec.d_end = r.d_end.map_or(f32::NAN, |d| d as f32);
        rec.d_min = r.d_min.map_or(f32::NAN, |d| d as f32);
        rec.aia2 = (r.aia * 2.0).round() as u8;
        self.overall.add(r);
        self.by_family[scene.family as usize].add(r);
        self.by_band[scene.speed_band.map_or(4, |b| b as usize)].add(r);
        self.by_gt[scene.gt_action.index()].add(r);
        self.by_adv[scene.adversarial as usize].add(r);
        if scene.adversarial {
            self.adv_decisions += 1;
            self.adv_questions += r.questions_material as u64;
        }
        if r.saa && scene.gt_action == Action::Catch {
            if let (Some(d), Some(short), Some(b2i)) = (r.d_end, r.falls_short, r.base_to_impact) {
                self.reach.correct_catch += 1;
                if d > miss_radius {
                    self.reach.misses += 1;
                    self.reach.misses_short += short as u64;
                }
                self.reach.standing_far += (b2i > far_standing) as u64;
            }
        }
        true
    }
}
