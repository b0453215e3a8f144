//! The humanoid's ego camera during a closed-loop episode (issue 26): the image
//! observation of the Python package's Gymnasium environment. One [`EgoCamera`] per
//! environment, reused across episodes; [`EgoCamera::set_scene`] at each reset builds the
//! scene's meshes, [`EgoCamera::draw`] draws one executed step (`ExecFrame`, from
//! `rh_physics::control::Session::frame`) as a tightly packed RGB image.
//!
//! It is the ego view of the execution videos (`execution`): the spec's `ego` camera
//! carried along by the base (position, yaw) and the pelvis drop, the dataset's lit
//! shading with shadows, the standing observer left out and the executing humanoid's
//! links drawn at their poses (all casting shadows; the head not drawn in this view, the
//! camera sits inside it). Only the image size differs (any `width` × `height`, the
//! spec camera's vertical field of view). Needs no video encoder: it works in a build
//! without the crate's `video` feature.
//!
//! Deterministic: the pixels are a function of the scene, the frame and the size on a
//! given adapter (no clock, no randomness; the same GPU commands every time).

use super::execution::{carried, moving_vertices, stage_humanoid_scene};
use super::geometry::SceneGeometry;
use super::gpu::Gpu;
use super::mesh::Mesh;
use super::{RenderError, RenderOptions, Shading};
use rh_catalog::Catalog;
use rh_physics::execute::ExecFrame;
use rh_physics::simulate::Simulation;
use rh_physics::spec::{BodyKind, CameraSpec, SceneSpec, Vec3};

/// Largest image side accepted (pixels).
pub const MAX_SIDE: u32 = 4096;

/// The ego camera of one environment (see the module docs).
pub struct EgoCamera {
    gpu: Gpu,
    width: u32,
    height: u32,
    stage: Option<EgoScene>,
}

/// What stays put during an episode.
struct EgoScene {
    scene_id: String,
    scene: SceneGeometry,
    links: Vec<Mesh>,
    ego: CameraSpec,
    observer: Vec3,
    bodies: usize,
}

impl EgoCamera {
    /// Opens the GPU (`RenderError::NoAdapter` when there is none: no Vulkan driver, not
    /// even lavapipe) with the anti-aliasing of `opts`, for `width` × `height` images.
    pub fn new(width: u32, height: u32, opts: &RenderOptions) -> Result<EgoCamera, RenderError> {
        if !(1..=MAX_SIDE).contains(&width) || !(1..=MAX_SIDE).contains(&height) {
            return Err(RenderError::Io(format!(
                "ego camera image size {width}x{height}: each side must be 1..={MAX_SIDE} pixels"
            )));
        }
        crate::models::set_config(&opts.models);
        Ok(EgoCamera {
            gpu: Gpu::new(opts.msaa, opts.msaa_cpu, opts.fxaa)?,
            width,
            height,
            stage: None,
        })
    }

    /// The adapter's name (`llvmpipe …` for lavapipe).
    pub fn adapter_name(&self) -> &str {
        &self.gpu.adapter_name
    }

    /// `(width, height)` of the images.
    pub fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    /// Builds `spec`'s meshes for the episodes that follow (the whole scene is rebuilt on
    /// every call: cheap next to the replay, and never stale).
    pub fn set_scene(&mut self, spec: &SceneSpec, catalog: &Catalog) -> Result<(), RenderError> {
        let fail = |m: &str| RenderError::Scene(spec.scene_id.clone(), m.to_string());
        let ego = spec
            .cameras
            .iter()
            .find(|c| c.name == "ego")
            .ok_or_else(|| fail("no 'ego' camera in the spec"))?
            .clone();
        let slots = slots_of(spec);
        let (scene, links) = stage_humanoid_scene(&mut self.gpu, spec, &slots, catalog);
        self.gpu
            .cache_static_shadow(scene.light_vp, &scene.static_casters())?;
        let o = &spec.observer;
        self.stage = Some(EgoScene {
            scene_id: spec.scene_id.clone(),
            scene,
            links,
            ego,
            observer: [o.x, o.y, o.yaw],
            bodies: slots.dynamic_bodies.len(),
        });
        Ok(())
    }

    /// The ego view of one executed step of the scene last set: `height` rows of `width`
    /// RGB pixels (sRGB, 8 bits), top row first.
    pub fn draw(&mut self, frame: &ExecFrame) -> Result<Vec<u8>, RenderError> {
        let Some(s) = self.stage.as_ref() else {
            return Err(RenderError::Io(
                "ego camera: no scene set (call set_scene first)".into(),
            ));
        };
        if frame.bodies.len() != s.bodies {
            return Err(RenderError::Scene(
                s.scene_id.clone(),
                format!(
                    "the frame has {} moving bodies, the scene {}",
                    frame.bodies.len(),
                    s.bodies
                ),
            ));
        }
        let (verts, without_head) = moving_vertices(&s.scene, &frame.bodies, &s.links, frame);
        let all = self.gpu.set_dynamic(&verts)?;
        let cam = carried(&s.ego, s.observer, frame, self.width, self.height);
        let view = s.scene.view_job(
            0,
            &cam,
            Shading::Lit,
            s.scene.ranges_for(&cam),
            all.start..all.start + without_head,
        );
        // The fixed casters' shadow map is cached (`set_scene`); the moving ones (the
        // scene's bodies and the humanoid, head included) are added to it.
        let rgba = self
            .gpu
            .draw_over_static_shadow(s.scene.light_vp, &[all], &[view])?
            .pop()
            .unwrap_or_default();
        let want = (self.width * self.height * 4) as usize;
        if rgba.len() != want {
            return Err(RenderError::Gpu(format!(
                "ego camera: read back {} bytes, expected {want}",
                rgba.len()
            )));
        }
        let rgb = rgba
            .chunks_exact(4)
            .flat_map(|p| [p[0], p[1], p[2]])
            .collect();
        self.gpu.frames.give(rgba);
        Ok(rgb)
    }
}

/// The scene's moving-body slots (`Simulation::dynamic_bodies`: the spec's dynamic bodies
/// in spec order, as `rh_physics::simulate` numbers them and `ExecFrame::bodies` holds
/// them), without simulating anything: all `SceneGeometry::build` reads of a simulation.
fn slots_of(spec: &SceneSpec) -> Simulation {
    let dynamic_bodies: Vec<usize> = (0..spec.bodies.len())
        .filter(|&i| spec.bodies[i].kind == BodyKind::Dynamic)
        .collect();
    Simulation {
        dt: spec.physics.dt,
        hazard_slot: dynamic_bodies
            .iter()
            .position(|&b| b == spec.hazard)
            .unwrap_or(0),
        dynamic_bodies,
        states: Vec::new(),
        hazard_lowest_z: Vec::new(),
        hazard_com: Vec::new(),
        hazard_contacts: Vec::new(),
        energy: Vec::new(),
        initial_penetration: 0.0,
        strike: None,
        state_hash: String::new(),
        snapshots: Default::default(),
    }
}
