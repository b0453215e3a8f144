//! The scoring run: stream the predictions, score each decision, fold into aggregates.

use crate::aggregate::ModelAgg;
use crate::aia::AiaMatcher;
use crate::config::Config;
use crate::dataset::Dataset;
use crate::error::InputError;
use crate::fast_map::FastMap;
use crate::metrics::DecisionResult;
use crate::preds::{process_line, LineOutcome, LineReader, RawLine};
use anyhow::Result;
use rayon::prelude::*;
use serde::Serialize;
use std::collections::BTreeMap;
use std::io::{BufRead, BufReader, Write};
use std::path::Path;

/// Lines per parallel batch.
const BATCH_LINES: usize = 8192;
/// Bytes per parallel batch (soft cap).
const BATCH_BYTES: usize = 64 << 20;
/// Line numbers and examples kept per warning kind.
const KEEP_FIRST: usize = 5;

/// Line-number ranges kept per dropped-line kind (beyond them, lines are only counted).
const KEEP_RANGES: usize = 1000;

/// Counted warnings of one kind.
#[derive(Debug, Clone, Default, Serialize)]
pub struct WarningAcc {
    pub count: u64,
    pub first_lines: Vec<u64>,
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub examples: Vec<String>,
    /// The kind drops its lines (not scored).
    #[serde(skip)]
    pub dropped: bool,
    /// Every dropped line, as inclusive ranges in file order (at most [`KEEP_RANGES`]).
    #[serde(skip)]
    pub ranges: Vec<(u64, u64)>,
}

impl WarningAcc {
    /// The dropped lines as text, "3-5, 9" ("…" when more were dropped than kept).
    pub fn lines_text(&self) -> String {
        let mut parts: Vec<String> = self
            .ranges
            .iter()
            .map(|&(a, b)| {
                if a == b {
                    a.to_string()
                } else {
                    format!("{a}-{b}")
                }
            })
            .collect();
        let kept: u64 = self.ranges.iter().map(|(a, b)| b - a + 1).sum();
        if kept < self.count {
            parts.push(format!("… ({} more)", self.count - kept));
        }
        parts.join(", ")
    }
}

/// The state of a scoring run.
pub struct Scoring<'a> {
    pub ds: &'a Dataset,
    pub cfg: &'a Config,
    pub aia: AiaMatcher,
    pub models: Vec<ModelAgg>,
    model_index: FastMap<String, usize>,
    pub warnings: BTreeMap<&'static str, WarningAcc>,
    pub lines: u64,
    pub blank_lines: u64,
    pub scored: u64,
    pub lost: u64,
    pub duplicates: u64,
    /// Lines not scored (skipped kinds, duplicates, scenes outside the expected set).
    pub dropped: u64,
    /// The number of the first line that is not blank.
    pub first_content_line: Option<u64>,
    /// The scenes every model is expected to answer.
    pub expected: crate::coverage::Expected,
    decisions_out: Option<Box<dyn Write + 'a>>,
    /// With `--execute`: the decisions to execute, and the decision lines held back until
    /// their outcomes are known.
    exec: Option<ExecCollect>,
}

/// What `--execute` collects while scoring.
#[derive(Default)]
pub struct ExecCollect {
    /// One per (model, scene): the counted decision (a retry replaces a lost one).
    pub pending: Vec<crate::execution::Pending>,
    index: FastMap<(usize, u32), usize>,
    /// Decision lines (model, scene, JSON), written after execution.
    pub deferred: Vec<(usize, u32, serde_json::Value)>,
}

impl<'a> Scoring<'a> {
    pub fn new(ds: &'a Dataset, cfg: &'a Config) -> Self {
        Scoring {
            ds,
            cfg,
            aia: AiaMatcher::new(&cfg.aia),
            models: Vec::new(),
            model_index: FastMap::default(),
            warnings: BTreeMap::new(),
            lines: 0,
            blank_lines: 0,
            scored: 0,
            lost: 0,
            duplicates: 0,
            dropped: 0,
            first_content_line: None,
            expected: crate::coverage::Expected::all_valid(ds),
            decisions_out: None,
            exec: None,
        }
    }

    /// Scores only decisions on these scenes (others are dropped as `outside_subset`).
    pub fn with_expected(mut self, expected: crate::coverage::Expected) -> Self {
        self.expected = expected;
        self
    }

    /// Also collect every scored decision's plan for `--execute` (decision lines are then
    /// held back: see [`Scoring::take_execution`]).
    pub fn with_execution(mut self) -> Self {
        self.exec = Some(ExecCollect::default());
        self
    }

    /// The collected decisions and the model names (index = `Pending::model`); the held
    /// back decision lines are for the caller to complete and write.
    pub fn take_execution(&mut self) -> Option<(ExecCollect, Vec<String>)> {
        let names = self.models.iter().map(|m| m.name.clone()).collect();
        self.exec.take().map(|c| (c, names))
    }

    /// Where decision lines go (for writing the held-back ones).
    pub fn decisions_output(&mut self) -> Option<&mut (dyn Write + 'a)> {
        self.decisions_out.as_deref_mut()
    }

    /// Also write one JSON line per decision (scored, lost or duplicate) to `w`.
    pub fn with_decisions_output(mut self, w: Box<dyn Write + 'a>) -> Self {
        self.decisions_out = Some(w);
        self
    }

    fn warn(&mut self, kind: &'static str, line: u64, example: Option<String>) {
        let w = self.warnings.entry(kind).or_default();
        w.count += 1;
        if w.first_lines.len() < KEEP_FIRST {
            w.first_lines.push(line);
            if let Some(e) = example {
                w.examples.push(e);
            }
        }
    }

    /// A line that is not scored: counted, and named by its number.
    fn drop_line(&mut self, kind: &'static str, line: u64, example: Option<String>) {
        self.dropped += 1;
        self.warn(kind, line, example);
        let w = self.warnings.get_mut(kind).expect("just counted");
        w.dropped = true;
        if w.ranges.last().is_some_and(|r| r.1 + 1 == line) {
            w.ranges.last_mut().expect("checked").1 = line;
        } else if w.ranges.len() < KEEP_RANGES {
            w.ranges.push((line, line));
        }
    }

    /// Scores a predictions file. An unreadable file is an input error.
    pub fn score_path(&mut self, path: &Path) -> Result<()> {
        let f = std::fs::File::open(path)
            .map_err(|e| InputError(format!("cannot read predictions {}: {e}", path.display())))?;
        if f.metadata().map(|m| m.is_dir()).unwrap_or(false) {
            return Err(InputError(format!(
                "predictions {} is a directory, expected a .jsonl file",
                path.display()
            ))
            .into());
        }
        self.score_reader(BufReader::with_capacity(1 << 20, f))
            .map_err(|e| match e.downcast::<std::io::Error>() {
                // The decision lines' writer failing is not a reading error.
                Ok(io)
                    if io
                        .get_ref()
                        .is_some_and(|i| i.is::<rh_contract::fsio::CannotWrite>()) =>
                {
                    io.into()
                }
                Ok(io) => InputError(format!("error reading {}: {io}", path.display())).into(),
                Err(e) => e,
            })
    }

    /// Scores predictions from any reader, in parallel batches, folding in line order.
    pub fn score_reader<R: BufRead + Send>(&mut self, r: R) -> Result<()> {
        let mut reader = LineReader::new(r, self.cfg.sanity.max_line_bytes);
        let read_batch = |reader: &mut LineReader<R>| -> std::io::Result<Vec<(u64, RawLine)>> {
            let mut batch = Vec::with_capacity(BATCH_LINES);
            let mut bytes = 0usize;
            while batch.len() < BATCH_LINES && bytes < BATCH_BYTES {
                match reader.next_line()? {
                    Some((n, l)) => {
                        bytes += match &l {
                            RawLine::Line(b) => b.len(),
                            RawLine::TooLong(_) => 0,
                        };
                        batch.push((n, l));
                    }
                    None => break,
                }
            }
            Ok(batch)
        };
        let mut batch = read_batch(&mut reader)?;
        while !batch.is_empty() {
            let (ds, cfg, aia) = (self.ds, self.cfg, &self.aia);
            let (outcomes, next) = rayon::join(
                || {
                    batch
                        .par_iter()
                        .map(|(n, l)| {
                            let too_long = match l {
                                RawLine::TooLong(len) => Some(*len),
                                _ => None,
                            };
                            (*n, too_long, process_line(l, ds, cfg, aia))
                        })
                        .collect::<Vec<_>>()
                },
                || read_batch(&mut reader),
            );
            for (n, too_long, o) in outcomes {
                self.fold(n, too_long, o)?;
            }
            batch = next?;
        }
        if let Some(w) = self.decisions_out.as_mut() {
            w.flush()?;
        }
        Ok(())
    }

    fn fold(&mut self, line: u64, too_long: Option<u64>, o: LineOutcome) -> Result<()> {
        self.lines += 1;
        if !matches!(o, LineOutcome::Blank) && self.first_content_line.is_none() {
            self.first_content_line = Some(line);
        }
        match o {
            LineOutcome::Blank => self.blank_lines += 1,
            LineOutcome::Skip { kind, detail } => {
                let example = detail.or(too_long.map(|l| format!("{l} bytes")));
                self.drop_line(kind, line, example);
            }
            LineOutcome::Decision {
                scene,
                model,
                result,
                notes,
                prompt_version,
                plan,
            } => {
                if !self.expected.mask[scene as usize] {
                    let id = self.ds.scenes[scene as usize].scene_id.clone();
                    self.drop_line("outside_subset", line, Some(id));
                    return Ok(());
                }
                for n in notes {
                    self.warn(n, line, None);
                }
                let mi = match self.model_index.get(&model) {
                    Some(&i) => i,
                    None => {
                        self.models.push(ModelAgg::new(model.clone(), self.ds));
                        self.model_index
                            .insert(model.clone(), self.models.len() - 1);
                        self.models.len() - 1
                    }
                };
                let sc = &self.ds.scenes[scene as usize];
                let a = &self.cfg.analyses;
                let m = &mut self.models[mi];
                let lost_before = m.lost;
                let counted = m.add(scene, sc, result.as_ref(), a.miss_radius, a.far_standing);
                if counted {
                    m.prompt_versions
                        .insert(prompt_version.unwrap_or_else(|| "-".to_string()));
                }
                if !counted {
                    self.duplicates += 1;
                    self.drop_line(
                        "duplicate_decision",
                        line,
                        Some(format!("{} / {model}", sc.scene_id)),
                    );
                } else if result.is_some() {
                    self.scored += 1;
                    if m.lost < lost_before {
                        self.lost -= 1;
                        self.warn("retry_after_error", line, None);
                    }
                } else {
                    self.lost += 1;
                }
                if let Some(c) = self.exec.as_mut() {
                    c.collect(counted, mi, scene, line, result.as_ref(), plan.as_deref());
                }
                if let Some(w) = self.decisions_out.as_mut() {
                    let status = match (counted, &result) {
                        (false, _) => "duplicate",
                        (true, None) => "lost",
                        (true, Some(_)) => "scored",
                    };
                    let rec = DecisionLine {
                        line,
                        scene_id: &sc.scene_id,
                        model: &model,
                        status,
                        gt_action: sc.gt_action.as_str(),
                        rules: result.as_ref().map_or_else(Vec::new, |r| {
                            crate::safety_rule::SafetyRule::ALL
                                .into_iter()
                                .filter(|&x| r.fired(x))
                                .map(|x| x.as_str())
                                .collect()
                        }),
                        result: result.as_ref(),
                    };
                    match self.exec.as_mut() {
                        Some(c) => c.deferred.push((mi, scene, serde_json::to_value(&rec)?)),
                        None => {
                            serde_json::to_writer(&mut *w, &rec)?;
                            w.write_all(b"\n")?;
                        }
                    }
                }
            }
        }
        Ok(())
    }
}

#[derive(Serialize)]
struct DecisionLine<'a> {
    line: u64,
    scene_id: &'a str,
    model: &'a str,
    status: &'static str,
    gt_action: &'static str,
    rules: Vec<&'static str>,
    #[serde(flatten, skip_serializing_if = "Option::is_none")]
    result: Option<&'a DecisionResult>,
}

impl ExecCollect {
    fn collect(
        &mut self,
        counted: bool,
        model: usize,
        scene: u32,
        line: u64,
        result: Option<&DecisionResult>,
        plan: Option<&crate::plan::Plan>,
    ) {
        let Some(r) = result.filter(|_| counted) else {
            return;
        };
        let p = crate::execution::Pending {
            line,
            scene,
            model,
            plan: plan.map(crate::execution::exec_plan),
            action: r.action,
            saa: r.saa,
        };
        match self.index.get(&(model, scene)) {
            Some(&i) => self.pending[i] = p,
            None => {
                self.index.insert((model, scene), self.pending.len());
                self.pending.push(p);
            }
        }
    }
}
