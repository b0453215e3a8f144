//! `--execute-videos DIR` (specification §12, issue 14 item 4): every executed decision drawn by
//! the dataset's renderer (`rh_render::Renderer::render_executions`) from an
//! outside camera and from the humanoid's ego camera, and for one scene all models'
//! executions tiled side by side ("one scene, N brains"):
//!
//! ```text
//! DIR/<scene_id>/<model>__outside.mp4   outside view (the same camera for every model)
//! DIR/<scene_id>/<model>__ego.mp4       ego camera, carried by the executed base
//! DIR/<tiled scene>/tiled.mp4           the outside views side by side, labelled
//! DIR/index.json                        every file with its model, outcome and frames
//! ```
//!
//! Each decision is executed again with recording on (`Replay::execute_recorded`, a side
//! output); its outcome and run hash must be the scored one's, else the run fails. Model
//! names are made file-safe (anything but letters, digits, `.`, `-`, `_` becomes `_`).

use anyhow::{anyhow, bail, Result};
use rh_execute::VideoRequest;
use rh_execute::{checked_replay, replay_key, Pending};
use rh_grade::config::ExecVideoConfig;
use rh_grade::dataset::{read_replay_keys, Dataset};
use rh_grade::error::InputError;
use rh_physics::execute::{ExecConfig, ExecFrame, Outcome};
use rh_physics::simulate::{simulate, SimOptions};
use rh_render::encode::EncodeSettings;
use rh_render::{ExecTrack, ExecVideoOptions, RenderOptions, Renderer};
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

#[derive(Debug, Serialize)]
pub struct VideoIndex {
    pub width: u32,
    pub height: u32,
    pub include_observation: bool,
    pub scenes: Vec<SceneVideos>,
}

#[derive(Debug, Serialize)]
pub struct SceneVideos {
    pub scene_id: String,
    pub fps: u32,
    /// Physics steps (dt = `dt` s) of the first frame and of the decision moment Δ:
    /// frame `j` shows step `start_step + round(j / fps / dt)`.
    pub start_step: u32,
    pub decision_step: u32,
    pub dt: f64,
    pub decisions: Vec<DecisionVideos>,
    pub tiled: Option<Tiled>,
}

#[derive(Debug, Serialize)]
pub struct DecisionVideos {
    pub model: String,
    pub outcome: String,
    /// Paths relative to DIR.
    pub outside: String,
    pub ego: String,
    pub frames: u32,
}

#[derive(Debug, Serialize)]
pub struct Tiled {
    pub file: String,
    pub width: u32,
    pub height: u32,
    pub columns: u32,
    pub rows: u32,
    pub frames: u32,
    /// Tile `i` is at column `i % columns`, row `i / columns`.
    pub tiles: Vec<Tile>,
}

#[derive(Debug, Serialize)]
pub struct Tile {
    pub model: String,
    pub outcome: String,
    pub column: u32,
    pub row: u32,
}

/// A model name as a file name.
pub fn file_safe(name: &str) -> String {
    let s: String = name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || matches!(c, '.' | '-' | '_') {
                c
            } else {
                '_'
            }
        })
        .collect();
    match s.trim_start_matches('.') {
        "" => "model".into(),
        t => t.to_string(),
    }
}

/// Draws the videos of the executed decisions (outcomes aligned with `pending`; model
/// names indexed by `Pending::model`) and writes `DIR/index.json`.
#[allow(clippy::too_many_arguments)]
pub fn write_videos(
    ds: &Dataset,
    pending: &[Pending],
    outcomes: &[Option<Outcome>],
    names: &[String],
    cfg: &ExecConfig,
    vcfg: &ExecVideoConfig,
    req: &VideoRequest,
) -> Result<VideoIndex> {
    // Executed decisions by scene (dataset order), then by model name.
    let mut by_scene: BTreeMap<u32, Vec<usize>> = BTreeMap::new();
    for (i, p) in pending.iter().enumerate() {
        if p.plan.is_some() && outcomes[i].is_some() {
            by_scene.entry(p.scene).or_default().push(i);
        }
    }
    for list in by_scene.values_mut() {
        list.sort_by(|&a, &b| names[pending[a].model].cmp(&names[pending[b].model]));
    }
    let id_of = |scene: u32| ds.scenes[scene as usize].scene_id.as_str();
    let tiled = match req.tiled_scene {
        Some(id) => by_scene
            .keys()
            .copied()
            .find(|&s| id_of(s) == id)
            .ok_or_else(|| {
                InputError(format!(
                    "--tiled-scene {id}: no executed decision on that scene"
                ))
            })?,
        None => match by_scene
            .iter()
            .max_by_key(|(s, l)| (l.len(), std::cmp::Reverse(**s)))
        {
            Some((s, _)) => *s,
            None => bail!(InputError(
                "--execute-videos: no decision was executed (every plan was R1 or lost)".into()
            )),
        },
    };
    if let Some(wanted) = req.scenes {
        for id in wanted {
            if !by_scene.keys().any(|&s| id_of(s) == id) {
                bail!(InputError(format!(
                    "--video-scenes: {id} has no executed decision (unknown scene, or only R1/lost decisions)"
                )));
            }
        }
        by_scene.retain(|&s, _| s == tiled || wanted.iter().any(|w| w == id_of(s)));
    }
    std::fs::create_dir_all(req.dir)
        .map_err(|e| InputError(format!("cannot create {}: {e}", req.dir.display())))?;
    let keys = read_replay_keys(&ds.dir)?;
    let catalog =
        rh_catalog::Catalog::embedded().map_err(|e| anyhow!("the embedded catalog: {e}"))?;
    let mut renderer = Renderer::new(RenderOptions::default()).map_err(|e| {
        InputError(format!(
            "--execute-videos cannot render on this machine: {e} (needs Vulkan — a GPU or Mesa's lavapipe — and FFmpeg with libx264; scripts/setup.sh installs them)"
        ))
    })?;
    let opts = ExecVideoOptions {
        width: vcfg.width,
        height: vcfg.height,
        fps: vcfg.fps,
        include_observation: vcfg.include_observation,
        tile_columns: vcfg.tile_columns,
        encode: EncodeSettings {
            preset: vcfg.preset.clone(),
            bframes: vcfg.bframes,
            crf: vcfg.crf,
            threads: 1,
        },
    };
    let total: usize = by_scene.values().map(Vec::len).sum();
    let bar = if req.progress {
        indicatif::ProgressBar::new(total as u64)
    } else {
        indicatif::ProgressBar::hidden()
    };
    bar.set_style(
        indicatif::ProgressStyle::with_template(
            "{msg} {bar:30} {pos}/{len} decisions · {elapsed} · ETA {eta}",
        )
        .expect("valid template"),
    );
    bar.set_message("execution videos");
    // Off a terminal the bar is silent: a line every 10 s instead.
    let log = rh_contract::progress::ProgressLog::start(
        req.progress,
        "rh-score: execution videos",
        "decisions",
        total as u64,
        std::time::Duration::from_secs_f64(rh_contract::progress::LOG_EVERY_S),
    );
    let mut index = VideoIndex {
        width: vcfg.width,
        height: vcfg.height,
        include_observation: vcfg.include_observation,
        scenes: Vec::new(),
    };
    for (&scene, list) in &by_scene {
        let sv = scene_videos(
            ds,
            &keys,
            pending,
            outcomes,
            names,
            cfg,
            &opts,
            req.dir,
            scene,
            list,
            scene == tiled,
            &catalog,
            &mut renderer,
        )?;
        bar.inc(list.len() as u64);
        log.add(list.len() as u64);
        index.scenes.push(sv);
    }
    drop(log);
    bar.finish_and_clear();
    let text = serde_json::to_string_pretty(&index)? + "\n";
    let path = req.dir.join("index.json");
    rh_contract::fsio::write_file(&path, "the video index", text.as_bytes())?;
    Ok(index)
}

/// One scene: re-executes its decisions with recording, checks them against the scored
/// outcomes and renders them.
#[allow(clippy::too_many_arguments)]
fn scene_videos(
    ds: &Dataset,
    keys: &rh_grade::fast_map::FastMap<String, rh_grade::dataset::ReplayKey>,
    pending: &[Pending],
    outcomes: &[Option<Outcome>],
    names: &[String],
    cfg: &ExecConfig,
    opts: &ExecVideoOptions,
    dir: &Path,
    scene: u32,
    list: &[usize],
    tiled: bool,
    catalog: &rh_catalog::Catalog,
    renderer: &mut Renderer,
) -> Result<SceneVideos> {
    let scene_id = ds.scenes[scene as usize].scene_id.clone();
    let key = replay_key(keys, &scene_id)?;
    let (replay, _) = checked_replay(&ds.dir, key, &scene_id)?;
    let spec = replay.spec();
    let sim = simulate(spec, SimOptions::default());
    let mut recordings: Vec<(String, String, Vec<ExecFrame>)> = Vec::new();
    let mut used = std::collections::BTreeSet::new();
    for &i in list {
        let plan = pending[i]
            .plan
            .as_ref()
            .expect("executed decisions have a plan");
        let scored = outcomes[i]
            .as_ref()
            .expect("executed decisions have an outcome");
        let (o, frames) = replay.execute_recorded(plan, cfg);
        if o.outcome != scored.outcome || o.state_hash != scored.state_hash {
            bail!(
                "scene {scene_id}, model {}: the recorded execution ({}, run hash {}) is not the scored one ({}, {}); stale execution cache? rerun with --no-exec-cache",
                names[pending[i].model],
                o.outcome.name(),
                o.state_hash,
                scored.outcome.name(),
                scored.state_hash
            );
        }
        let model = names[pending[i].model].clone();
        let mut stem = file_safe(&model);
        while !used.insert(stem.clone()) {
            stem.push('_');
        }
        recordings.push((model, stem, frames));
    }
    let rel = |f: &str| format!("{scene_id}/{f}");
    let tracks: Vec<ExecTrack> = recordings
        .iter()
        .zip(list)
        .map(|((model, stem, frames), &i)| ExecTrack {
            label: format!("{model}: {}", outcome_name(outcomes, i)),
            frames,
            outside: dir.join(rel(&format!("{stem}__outside.mp4"))),
            ego: dir.join(rel(&format!("{stem}__ego.mp4"))),
        })
        .collect();
    let tiled_path: Option<PathBuf> = tiled.then(|| dir.join(rel("tiled.mp4")));
    let out = renderer
        .render_executions(spec, &sim, catalog, &tracks, tiled_path.as_deref(), opts)
        .map_err(|e| anyhow!("execution videos of scene {scene_id}: {e}"))?;
    let decisions: Vec<DecisionVideos> = recordings
        .iter()
        .zip(list)
        .zip(&out.frames)
        .map(|(((model, stem, _), &i), &frames)| DecisionVideos {
            model: model.clone(),
            outcome: outcome_name(outcomes, i).into(),
            outside: rel(&format!("{stem}__outside.mp4")),
            ego: rel(&format!("{stem}__ego.mp4")),
            frames,
        })
        .collect();
    let tiled = out.tiled.map(|t| Tiled {
        file: rel("tiled.mp4"),
        width: t.width,
        height: t.height,
        columns: t.columns,
        rows: t.rows,
        frames: t.frames,
        tiles: decisions
            .iter()
            .enumerate()
            .map(|(k, d)| Tile {
                model: d.model.clone(),
                outcome: d.outcome.clone(),
                column: k as u32 % t.columns,
                row: k as u32 / t.columns,
            })
            .collect(),
    });
    Ok(SceneVideos {
        scene_id,
        fps: out.fps,
        start_step: out.start_step,
        decision_step: out.decision_step,
        dt: spec.physics.dt,
        decisions,
        tiled,
    })
}

fn outcome_name(outcomes: &[Option<Outcome>], i: usize) -> &'static str {
    outcomes[i].as_ref().map_or("-", |o| o.outcome.name())
}

/// [`write_videos`] with the scoring configuration's executor and video settings, then
/// one line on stderr saying what was written (`rh-score --execute-videos`).
pub fn draw_and_note(
    ds: &Dataset,
    pending: &[Pending],
    outcomes: &[Option<Outcome>],
    names: &[String],
    cfg: &rh_grade::config::Config,
    req: &VideoRequest,
) -> Result<()> {
    let started = std::time::Instant::now();
    let index = write_videos(
        ds,
        pending,
        outcomes,
        names,
        &cfg.execution,
        &cfg.execution_video,
        req,
    )?;
    let decisions: usize = index.scenes.iter().map(|s| s.decisions.len()).sum();
    let secs = started.elapsed().as_secs_f64();
    rh_contract::note!(
        "rh-score: execution videos of {decisions} decisions in {} scenes ({:.2} s per decision) in {}; see {}",
        index.scenes.len(),
        secs / decisions.max(1) as f64,
        req.dir.display(),
        req.dir.join("index.json").display()
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn model_names_become_file_safe() {
        assert_eq!(file_safe("gpt-4o"), "gpt-4o");
        assert_eq!(file_safe("Qwen/Qwen2.5-VL 7B"), "Qwen_Qwen2.5-VL_7B");
        assert_eq!(file_safe("../x"), "_x");
        assert_eq!(file_safe(""), "model");
    }
}
