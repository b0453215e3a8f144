//! Bootstrap intervals of a report row's means (d_end, HDE d_min, AIA), from the compact
//! per-(scene, model) records: over the row's scenes, resampled (seeded by the model, row
//! and metric names) or, for large rows, in closed form (see [`crate::stats`]).

use crate::aggregate::Rec;
use crate::dataset::Dataset;
use crate::stats::{mean_interval, seed_for, StatsConfig};
use rh_contract::Action;

/// The intervals `[d_end, d_min, aia]` of row `group` of model `name` over the
/// expected scenes of `recs` (one slice per model; several for the pooled row) whose
/// ground truth is `gt` (all with `None`). An unanswered scene has AIA 0 unless
/// `answered_only`; it has no distance.
#[allow(clippy::too_many_arguments)]
pub fn mean_intervals(
    group: &str,
    name: &str,
    recs: &[&[Rec]],
    ds: &Dataset,
    expected: &[bool],
    gt: Option<Action>,
    answered_only: bool,
    cfg: &StatsConfig,
) -> [Option<[f64; 2]>; 3] {
    let (mut d_end, mut d_min, mut aia) = (Vec::new(), Vec::new(), Vec::new());
    for r in recs {
        for ((rec, sc), &exp) in r.iter().zip(&ds.scenes).zip(expected) {
            if !exp || gt.is_some_and(|g| g != sc.gt_action) {
                continue;
            }
            d_end.extend(rec.end_distance());
            d_min.extend(rec.min_distance());
            match rec.aia() {
                Some(a) => aia.push(a),
                None if !answered_only => aia.push(0.0),
                None => {}
            }
        }
    }
    let seed = |metric: &str| seed_for(cfg.seed, &[name, group, metric]);
    [
        mean_interval(&d_end, cfg, seed("d_end")),
        mean_interval(&d_min, cfg, seed("d_min")),
        mean_interval(&aia, cfg, seed("aia")),
    ]
}
