//! Execution videos (`rh-score --execute-videos`, specification §12): one scene's executed
//! decisions, recorded step by step by `execute::Replay::execute_recorded`, drawn with
//! the dataset's renderer from an outside camera and from the humanoid's ego camera, and
//! all of them tiled side by side ("one scene, N brains").
//!
//! * Time: video frame `j` shows physics step `start + round(j / fps / dt)`, where
//!   `start` is 0 (the observation window first, the humanoid standing in its starting
//!   pose) or Δ ([`ExecVideoOptions::include_observation`]); a decision's videos end at
//!   its last executed step. Steps up to Δ are the scene's own simulation (bit for bit
//!   the replay's), later ones the execution's.
//! * The standing observer of the dataset's videos is left out; the humanoid's thirteen
//!   links are drawn at their executed poses with the shapes the physics uses.
//! * Outside camera: `full_event_camera`'s placement holding the observer, the hazard's
//!   path in every execution and every executed base position, the same for all the
//!   scene's decisions (so tiles compare). Ego camera: the spec's `ego` camera carried
//!   along by the base (position, yaw) and the pelvis drop; the head link is not drawn
//!   in it (the camera sits inside it).
//! * Tiled: the outside views side by side (at most `tile_columns` a row, then further
//!   rows), each labelled `model: outcome` in its top-left corner; a decision that ended
//!   earlier holds its last frame; a place left over in the last row stays dark.

use super::camera::outside_camera;
use super::encode::{EncodeSettings, VideoJob};
use super::geometry::SceneGeometry;
use super::gpu::{Gpu, ViewJob};
use super::mesh::{Mesh, Xf};
use super::observer::link_meshes;
use super::renderer::Renderer;
use super::{font, RenderError, Shading};
use rh_catalog::Catalog;
use rh_physics::body::{Geometry, LinkPose, Part};
use rh_physics::execute::ExecFrame;
use rh_physics::simulate::{BodyState, Simulation};
use rh_physics::spec::{quat, CameraSpec, SceneSpec, Vec3};
use std::path::{Path, PathBuf};

/// How execution videos look (`[execution_video]` of `configs/scoring.toml`).
#[derive(Debug, Clone)]
pub struct ExecVideoOptions {
    /// Size of each view (outside, ego, and each tile).
    pub width: u32,
    pub height: u32,
    /// Frames per second; 0: the dataset's (`spec.video.fps`).
    pub fps: u32,
    /// Start at t = 0 (the observation window) rather than at the decision moment Δ.
    pub include_observation: bool,
    /// Most tiles in a row of the tiled video.
    pub tile_columns: u32,
    pub encode: EncodeSettings,
}

/// One decision to draw: its recording and where its two videos go.
pub struct ExecTrack<'a> {
    /// The tile's label (`model: outcome`).
    pub label: String,
    /// `execute_recorded`'s frames (frame 0: the world at Δ).
    pub frames: &'a [ExecFrame],
    pub outside: PathBuf,
    pub ego: PathBuf,
}

/// What was written for one scene.
#[derive(Debug, Clone, PartialEq)]
pub struct ExecVideos {
    pub fps: u32,
    /// Physics step of the first frame (0 or Δ) and of Δ.
    pub start_step: u32,
    pub decision_step: u32,
    /// Frames of each track's two videos, in track order.
    pub frames: Vec<u32>,
    /// The tiled video's frames, size and grid (columns, rows), when asked for.
    pub tiled: Option<TiledVideo>,
}

#[derive(Debug, Clone, PartialEq)]
pub struct TiledVideo {
    pub frames: u32,
    pub width: u32,
    pub height: u32,
    pub columns: u32,
    pub rows: u32,
}

/// Everything per scene that stays put while the frames are drawn.
struct Stage<'a> {
    scene: SceneGeometry,
    links: Vec<Mesh>,
    outside: CameraSpec,
    ego: &'a CameraSpec,
    observer: Vec3,
    sim: &'a Simulation,
    decision: u32,
}

impl Renderer {
    /// Renders the executions of one scene (see the module docs): for each track its
    /// outside and ego videos, and with `tiled` the tracks' outside views side by side.
    pub fn render_executions(
        &mut self,
        spec: &SceneSpec,
        sim: &Simulation,
        catalog: &Catalog,
        tracks: &[ExecTrack],
        tiled: Option<&Path>,
        opts: &ExecVideoOptions,
    ) -> Result<ExecVideos, RenderError> {
        let fail = |m: String| RenderError::Scene(spec.scene_id.clone(), m);
        if tracks.iter().any(|t| t.frames.is_empty()) {
            return Err(fail("an execution without recorded steps".into()));
        }
        let ego = spec
            .cameras
            .iter()
            .find(|c| c.name == "ego")
            .ok_or_else(|| fail("no 'ego' camera in the spec".into()))?;
        let decision = spec.decision_step().min(sim.steps());
        let fps = if opts.fps == 0 {
            spec.video.fps
        } else {
            opts.fps
        }
        .max(1);
        let start = if opts.include_observation {
            0
        } else {
            decision
        };
        let last_step = |t: &ExecTrack| decision + t.frames.len() as u32 - 1;
        let end = tracks.iter().map(last_step).max().unwrap_or(decision);
        let dt = spec.physics.dt;
        let steps: Vec<u32> = (0u32..)
            .map(|j| start + (j as f64 / fps as f64 / dt).round() as u32)
            .take_while(|&s| s <= end)
            .collect();
        let (scene, links) = stage_humanoid_scene(&mut self.gpu, spec, sim, catalog);
        let o = &spec.observer;
        let stage = Stage {
            outside: execution_camera(spec, sim, decision, tracks, opts),
            scene,
            links,
            ego,
            observer: [o.x, o.y, o.yaw],
            sim,
            decision,
        };
        let (w, h) = (opts.width, opts.height);
        let spawn = |path: &Path| {
            VideoJob::spawn(
                path.to_path_buf(),
                w,
                h,
                fps,
                opts.encode.clone(),
                self.gpu.frames.clone(),
            )
        };
        let jobs: Vec<(VideoJob, VideoJob)> = tracks
            .iter()
            .map(|t| (spawn(&t.outside), spawn(&t.ego)))
            .collect();
        let grid = tiled.map(|path| Grid::new(tracks.len() as u32, w, h, opts.tile_columns, path));
        let tiled_job = grid.as_ref().map(|g| {
            VideoJob::spawn(
                g.path.clone(),
                g.width(),
                g.height(),
                fps,
                opts.encode.clone(),
                Default::default(),
            )
        });
        let mut last_tiles: Vec<Vec<u8>> = vec![Vec::new(); tracks.len()];
        let mut stopped = false;
        for &step in &steps {
            for (i, t) in tracks.iter().enumerate() {
                if step > last_step(t) {
                    continue;
                }
                let [outside, ego] = self.draw_execution(&stage, t.frames, step)?;
                if grid.is_some() {
                    last_tiles[i] = outside.clone();
                }
                stopped |= !jobs[i].0.send(outside) || !jobs[i].1.send(ego);
            }
            if let (Some(g), Some(job)) = (&grid, &tiled_job) {
                stopped |= !job.send(g.compose(&last_tiles, tracks));
            }
            if stopped {
                break;
            }
        }
        let mut errors = Vec::new();
        let mut frames = Vec::new();
        for ((a, b), t) in jobs.into_iter().zip(tracks) {
            let want = steps.iter().filter(|&&s| s <= last_step(t)).count() as u32;
            for (job, path) in [(a, &t.outside), (b, &t.ego)] {
                check(job.finish(), want, path, &mut errors);
            }
            frames.push(want);
        }
        let tiled = match (grid, tiled_job) {
            (Some(g), Some(job)) => {
                check(job.finish(), steps.len() as u32, &g.path, &mut errors);
                Some(TiledVideo {
                    frames: steps.len() as u32,
                    width: g.width(),
                    height: g.height(),
                    columns: g.columns,
                    rows: g.rows,
                })
            }
            _ => None,
        };
        if !errors.is_empty() {
            return Err(RenderError::Encode(errors.join("; ")));
        }
        Ok(ExecVideos {
            fps,
            start_step: start,
            decision_step: decision,
            frames,
            tiled,
        })
    }

    /// One track at one physics step: the outside and ego images (RGBA).
    fn draw_execution(
        &mut self,
        stage: &Stage,
        frames: &[ExecFrame],
        step: u32,
    ) -> Result<[Vec<u8>; 2], RenderError> {
        // Before Δ: the scene's own run, the humanoid in its starting pose.
        let (states, frame): (&[BodyState], &ExecFrame) = if step <= stage.decision {
            let n = stage.sim.dynamic_bodies.len();
            let at = step as usize * n;
            (&stage.sim.states[at..at + n], &frames[0])
        } else {
            let f = &frames[(step - stage.decision) as usize];
            (&f.bodies, f)
        };
        let (verts, without_head) = moving_vertices(&stage.scene, states, &stage.links, frame);
        let all = self.gpu.set_dynamic(&verts)?;
        let ego_cam = carried(
            stage.ego,
            stage.observer,
            frame,
            stage.outside.width,
            stage.outside.height,
        );
        let scene = &stage.scene;
        let views: Vec<ViewJob> = [
            (&stage.outside, all.clone()),
            (&ego_cam, all.start..all.start + without_head),
        ]
        .into_iter()
        .enumerate()
        .map(|(slot, (cam, dynamic))| {
            scene.view_job(slot, cam, Shading::Lit, scene.ranges_for(cam), dynamic)
        })
        .collect();
        let mut casters = scene.static_casters();
        casters.push(all);
        let mut images = self.gpu.draw(scene.light_vp, &casters, &views)?;
        let ego = images.pop().unwrap_or_default();
        let outside = images.pop().unwrap_or_default();
        Ok([outside, ego])
    }
}

/// The scene's geometry with its observer hidden (the executing humanoid is drawn from
/// its links instead) and the humanoid's link meshes; `gpu`'s buffers are sized for both
/// and the static vertices uploaded.
pub(super) fn stage_humanoid_scene(
    gpu: &mut Gpu,
    spec: &SceneSpec,
    sim: &Simulation,
    catalog: &Catalog,
) -> (SceneGeometry, Vec<Mesh>) {
    let mut scene = SceneGeometry::build(spec, sim, catalog);
    scene.hide_observer();
    let links = link_meshes(&Geometry::of(&spec.observer).shapes());
    let link_verts: usize = links.iter().map(|m| m.verts.len()).sum();
    gpu.reserve(scene.statics.len() + scene.max_dynamic + link_verts + 1024);
    gpu.set_static(&scene.statics);
    (scene, links)
}

/// The vertices of the scene's moving bodies at `states` and of the humanoid posed as in
/// `frame`, its head last, and how many come before the head (the ego camera, carried in
/// the head, draws without it).
pub(super) fn moving_vertices(
    scene: &SceneGeometry,
    states: &[BodyState],
    links: &[Mesh],
    frame: &ExecFrame,
) -> (Vec<super::mesh::Vertex>, u32) {
    let mut verts = scene.dynamic_from(states, false);
    let head = Part::Head as usize;
    for (i, (mesh, pose)) in links.iter().zip(&frame.links).enumerate() {
        if i != head {
            mesh.transformed_into(&link_xf(pose), &mut verts);
        }
    }
    let without_head = verts.len() as u32;
    links[head].transformed_into(&link_xf(&frame.links[head]), &mut verts);
    (verts, without_head)
}

pub(super) fn link_xf(p: &LinkPose) -> Xf {
    Xf::from_quat(p.rotation, p.position)
}

/// Waits for an encoder and notes an error unless it wrote exactly `want` frames.
fn check(done: Result<u32, String>, want: u32, path: &Path, errors: &mut Vec<String>) {
    match done {
        Ok(n) if n == want => {}
        Ok(n) => errors.push(format!("{}: {n} of {want} frames written", path.display())),
        Err(e) => errors.push(format!("{}: {e}", path.display())),
    }
}

/// The spec's ego camera moved with the body: the base's displacement and turn from the
/// observer's `(x, y, yaw)`, and the pelvis drop.
pub(super) fn carried(
    ego: &CameraSpec,
    observer: Vec3,
    f: &ExecFrame,
    width: u32,
    height: u32,
) -> CameraSpec {
    let turn = quat::from_axis_angle([0.0, 0.0, 1.0], f.base[2] - observer[2]);
    let carry = |p: Vec3| {
        let local = [p[0] - observer[0], p[1] - observer[1], p[2]];
        let r = quat::rotate(turn, local);
        [r[0] + f.base[0], r[1] + f.base[1], r[2] - f.drop]
    };
    CameraSpec {
        name: ego.name.clone(),
        position: carry(ego.position),
        look_at: carry(ego.look_at),
        fov_y: ego.fov_y,
        width,
        height,
    }
}

/// The outside camera of a scene's execution videos: it holds the observer, the hazard
/// up to Δ and in every execution, and every executed base position (feet and head).
fn execution_camera(
    spec: &SceneSpec,
    sim: &Simulation,
    decision: u32,
    tracks: &[ExecTrack],
    opts: &ExecVideoOptions,
) -> CameraSpec {
    let o = &spec.observer;
    let mut pts: Vec<Vec3> = vec![[o.x, o.y, 0.0], [o.x, o.y, o.height]];
    let stride = (decision / 30).max(1) as usize;
    let hazard_slot = sim.hazard_slot;
    pts.extend(
        (0..=decision)
            .step_by(stride)
            .map(|k| sim.hazard_position(k)),
    );
    for t in tracks {
        let stride = (t.frames.len() / 30).max(1);
        for f in t.frames.iter().step_by(stride).chain(t.frames.last()) {
            pts.push(f.bodies[hazard_slot].position.map(f64::from));
            pts.push([f.base[0], f.base[1], 0.0]);
            pts.push([f.base[0], f.base[1], o.height]);
        }
    }
    let mut cam = outside_camera(spec, sim.hazard_position(0), &pts, opts.width, opts.height);
    cam.name = "execution".into();
    cam
}

/// The tiled video's layout.
struct Grid {
    n: u32,
    columns: u32,
    rows: u32,
    tile_w: u32,
    tile_h: u32,
    path: PathBuf,
}

impl Grid {
    fn new(n: u32, tile_w: u32, tile_h: u32, max_columns: u32, path: &Path) -> Grid {
        let columns = n.clamp(1, max_columns.max(1));
        Grid {
            n,
            columns,
            rows: n.div_ceil(columns).max(1),
            tile_w,
            tile_h,
            path: path.to_path_buf(),
        }
    }

    fn width(&self) -> u32 {
        self.columns * self.tile_w
    }

    fn height(&self) -> u32 {
        self.rows * self.tile_h
    }

    /// The tiles (RGBA, `tile_w` × `tile_h`; empty: not drawn yet) in one RGBA frame,
    /// each labelled.
    fn compose(&self, tiles: &[Vec<u8>], tracks: &[ExecTrack]) -> Vec<u8> {
        let (tw, th) = (self.tile_w, self.tile_h);
        let mut img =
            image::RgbImage::from_pixel(self.width(), self.height(), image::Rgb([10, 11, 13]));
        let scale = if tw >= 480 { 2 } else { 1 };
        for i in 0..self.n {
            let (x0, y0) = ((i % self.columns) * tw, (i / self.columns) * th);
            let tile = &tiles[i as usize];
            if tile.len() == (tw * th * 4) as usize {
                for (k, px) in tile.chunks_exact(4).enumerate() {
                    let (x, y) = (k as u32 % tw, k as u32 / tw);
                    img.put_pixel(x0 + x, y0 + y, image::Rgb([px[0], px[1], px[2]]));
                }
            }
            // The label on a dark strip.
            let label = &tracks[i as usize].label;
            let strip_w = ((label.chars().count() as u32 * 6 + 3) * scale).min(tw);
            let strip_h = (font::ROWS + 3) * scale;
            for y in y0..(y0 + strip_h).min(y0 + th) {
                for x in x0..x0 + strip_w {
                    let p = img.get_pixel_mut(x, y);
                    p.0 = p.0.map(|c| c / 4);
                }
            }
            font::draw_text(
                &mut img,
                x0 + 2 * scale,
                y0 + scale,
                label,
                scale,
                [240, 240, 240],
            );
        }
        img.pixels().flat_map(|p| [p[0], p[1], p[2], 255]).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rh_physics::spec::vec3;

    #[test]
    fn the_ego_camera_follows_the_base() {
        let ego = CameraSpec {
            name: "ego".into(),
            position: [1.1, 2.0, 1.2],
            look_at: [2.0, 2.0, 1.0],
            fov_y: 1.0,
            width: 64,
            height: 36,
        };
        let f = ExecFrame {
            bodies: vec![],
            links: [LinkPose {
                position: [0.0; 3],
                rotation: rh_physics::spec::IDENTITY,
            }; 13],
            base: [1.0, 3.0, std::f64::consts::FRAC_PI_2],
            drop: 0.2,
        };
        let c = carried(&ego, [1.0, 2.0, 0.0], &f, 32, 18);
        // 0.1 m ahead of the pelvis, turned a quarter to the left: +y; 1 m up, lowered.
        assert!(
            vec3::norm(vec3::sub(c.position, [1.0, 3.1, 1.0])) < 1e-9,
            "{c:?}"
        );
        assert!(
            vec3::norm(vec3::sub(c.look_at, [1.0, 4.0, 0.8])) < 1e-9,
            "{c:?}"
        );
        assert_eq!((c.width, c.height), (32, 18));
    }

    #[test]
    fn tiles_fill_rows_of_at_most_the_column_count() {
        let g = Grid::new(5, 100, 60, 4, Path::new("t.mp4"));
        assert_eq!((g.columns, g.rows, g.width(), g.height()), (4, 2, 400, 120));
        let g = Grid::new(3, 100, 60, 4, Path::new("t.mp4"));
        assert_eq!((g.columns, g.rows, g.width(), g.height()), (3, 1, 300, 60));
    }
}
