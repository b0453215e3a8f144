//! The wgpu side: device, pipelines (shadow + lit MSAA), render targets per output slot,
//! and one call that draws a set of views of the current geometry and reads them back.

mod copy;
mod readback;
use readback::StaticImage;
mod ids;
mod moving;
mod setup;
mod textures;

use super::cells::{rect_area, rect_union, rects_meet};
use super::mesh::Vertex;
use super::RenderError;
pub use ids::{IdImage, IdPass, IdView};
use readback::Finish;
pub use setup::probe_adapter;
use std::ops::Range;

pub const COLOR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8UnormSrgb;
const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
pub const SHADOW_SIZE: u32 = 1024;

/// Per-view uniforms (matches `U` in shader.wgsl).
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct Uniforms {
    pub view_proj: [[f32; 4]; 4],
    pub light_vp: [[f32; 4]; 4],
    pub cam_pos: [f32; 4],
    pub sun_dir: [f32; 4],
    pub sun_color: [f32; 4],
    pub ambient: [f32; 4],
    /// Clear colour (rgb), for the fill pass that re-clears a scissored region.
    pub background: [f32; 4],
    /// Set by `Gpu`: the fill pass's rectangles (NDC x0, y0, x1, y1), one per instance.
    pub fill_rects: [[f32; 4]; MAX_REDRAW_RECTS],
}

/// One view to draw: the output slot (its own target), uniforms, the static vertex
/// ranges and the moving ones (drawn after a depth pre-pass: see `Gpu::main_pass`).
pub struct ViewJob {
    pub slot: usize,
    pub width: u32,
    pub height: u32,
    pub uniforms: Uniforms,
    pub ranges: Vec<Range<u32>>,
    pub dynamic: Range<u32>,
}

/// How far (pixels) the post-process pass reads around an output pixel.
pub const POST_REACH: u32 = crate::fxaa::REACH;

/// Most rectangles one overlay view redraws (more are merged by the caller).
pub const MAX_REDRAW_RECTS: usize = 32;

/// One view drawn over its cached static image (see [`Gpu::cache_static`]): each
/// `redraw` rectangle (x, y, width, height in pixels: where moving bodies may cast
/// shadows; at most `MAX_REDRAW_RECTS`) has its static surfaces shaded again (see
/// `Gpu::redraw_static`), and the moving bodies are drawn everywhere.
pub struct OverlayJob {
    pub slot: usize,
    pub uniforms: Uniforms,
    pub redraw: Vec<([u32; 4], Vec<Range<u32>>)>,
    pub dynamic: Range<u32>,
    /// Rectangles (x, y, width, height) holding every pixel within `POST_REACH` of one
    /// that may differ from the static image (the redraws and the moving bodies): where
    /// the post-process pass is redone. Empty: nothing changed.
    pub post_rects: Vec<[u32; 4]>,
}

struct Target {
    width: u32,
    height: u32,
    /// The multisampled colour attachment (`None` without MSAA: `resolve` is drawn into).
    msaa: Option<(wgpu::Texture, wgpu::TextureView)>,
    resolve: wgpu::Texture,
    resolve_view: wgpu::TextureView,
    depth: wgpu::Texture,
    depth_view: wgpu::TextureView,
    /// The static scene's colour and depth (same sample count as the attachments),
    /// copied in before each overlay frame.
    cache_color: wgpu::Texture,
    cache_depth: wgpu::Texture,
    /// The static image as drawn and anti-aliased (`crate::fxaa`): lit overlay frames
    /// start from the latter and are filtered again only where they differ from the
    /// former (`None` without post-process anti-aliasing, or before `cache_static`).
    aa_cache: Option<StaticImage>,
    readback: wgpu::Buffer,
    padded_row: u32,
    uniform: wgpu::Buffer,
    bind: wgpu::BindGroup,
    /// Where the colour attachment may differ from the cached static image (the last
    /// overlay frame's `post_rects`, which hold every pixel it changed); the next overlay
    /// frame restores only these from the cache. `None`: unknown (a whole frame was
    /// drawn, or no cache yet), restore all.
    dirty: Option<Vec<[u32; 4]>>,
}

/// One worker's renderer state: its shadow maps, targets and vertex buffer, on the
/// thread's device and pipelines (`setup::Shared`).
pub struct Gpu {
    device: wgpu::Device,
    queue: wgpu::Queue,
    pub adapter_name: String,
    /// What `build.json` records of the adapter.
    pub adapter: rh_contract::adapter::RenderAdapter,
    samples: u32,
    main: wgpu::RenderPipeline,
    /// Depth only (no colour written): the moving bodies' pre-pass.
    depth_only: wgpu::RenderPipeline,
    /// Lit, depth test `LessEqual` without depth writes: shades each pre-passed pixel once.
    main_over: wgpu::RenderPipeline,
    fill: wgpu::RenderPipeline,
    shadow: wgpu::RenderPipeline,
    main_bgl: wgpu::BindGroupLayout,
    shadow_tex: wgpu::Texture,
    shadow_view: wgpu::TextureView,
    /// Shadow map of the fixed casters only (see [`Gpu::cache_static`]).
    static_shadow: wgpu::Texture,
    shadow_sampler: wgpu::Sampler,
    model_textures: textures::ModelTextures,
    shadow_uniform: wgpu::Buffer,
    shadow_bind: wgpu::BindGroup,
    /// Post-process anti-aliasing (`crate::fxaa`) of lit frames: MSAA is off and it is
    /// enabled.
    fxaa: bool,
    /// The id pass's pipelines, built on first use (shared like the device's).
    id_pipelines: std::sync::Arc<std::sync::OnceLock<ids::IdPipelines>>,
    vbuf: wgpu::Buffer,
    vcap: u64,
    static_len: u32,
    targets: Vec<Option<Target>>,
    /// Where read-back images come from (the encoders hand them back).
    pub frames: super::encode::FramePool,
    /// This renderer's last submission (`Gpu::submit`), which `Gpu::wait` waits for.
    last_submit: std::cell::Cell<Option<wgpu::SubmissionIndex>>,
}

/// What a lit pass draws of the static scene.
#[derive(Debug, Clone, Copy)]
enum Redraw<'a> {
    /// Everything, from a cleared target: these ranges.
    Whole(&'a [Range<u32>]),
    /// Over the copied-in static image, per pixel rectangle (x, y, width, height; none
    /// empty) these ranges; `[]` redraws nothing.
    Regions(&'a [([u32; 4], &'a [Range<u32>])]),
}

impl Gpu {
    pub fn samples(&self) -> u32 {
        self.samples
    }

    /// Uploads the scene's static geometry (kept until the next call), followed by the
    /// same triangles in reverse order (`Gpu::reversed`, for the equal-depth re-shade).
    pub fn set_static(&mut self, verts: &[Vertex]) {
        debug_assert_eq!(verts.len() % 3, 0, "a triangle list");
        self.model_textures.sync(&self.queue);
        self.ensure_capacity(std::mem::size_of_val(verts) as u64 * 3);
        self.queue
            .write_buffer(&self.vbuf, 0, bytemuck::cast_slice(verts));
        let reversed: Vec<Vertex> = verts.rchunks(3).flatten().copied().collect();
        self.queue.write_buffer(
            &self.vbuf,
            std::mem::size_of_val(verts) as u64,
            bytemuck::cast_slice(&reversed),
        );
        self.static_len = verts.len() as u32;
    }

    /// Where the static vertices `r` lie in the reversed copy: the same triangles, last
    /// first.
    fn reversed(&self, r: &Range<u32>) -> Range<u32> {
        2 * self.static_len - r.end..2 * self.static_len - r.start
    }

    fn ensure_capacity(&mut self, bytes: u64) {
        if bytes > self.vcap {
            let cap = bytes.next_power_of_two();
            self.vbuf = vertex_buffer(&self.device, cap);
            self.vcap = cap;
        }
    }

    /// Uploads the moving geometry after the static part; returns its vertex range.
    pub fn set_dynamic(&mut self, verts: &[Vertex]) -> Result<Range<u32>, RenderError> {
        let stride = std::mem::size_of::<Vertex>() as u64;
        let base = 2 * self.static_len;
        let need = (base as u64 + verts.len() as u64) * stride;
        if need > self.vcap {
            return Err(RenderError::Gpu(format!(
                "vertex buffer of {} bytes too small for {need}",
                self.vcap
            )));
        }
        self.model_textures.sync(&self.queue);
        if !verts.is_empty() {
            self.queue.write_buffer(
                &self.vbuf,
                base as u64 * stride,
                bytemuck::cast_slice(verts),
            );
        }
        Ok(base..base + verts.len() as u32)
    }

    /// Reserves room for `static_len + dynamic` vertices (call before `set_static`),
    /// and the reversed copy of the static ones.
    pub fn reserve(&mut self, vertices: usize) {
        self.ensure_capacity(2 * vertices as u64 * std::mem::size_of::<Vertex>() as u64);
    }

    /// Frees a slot's target (made again by the next draw into it).
    pub fn release_target(&mut self, slot: usize) {
        if let Some(t) = self.targets.get_mut(slot) {
            *t = None;
        }
    }

    fn target(&mut self, slot: usize, width: u32, height: u32) -> &Target {
        if self.targets.len() <= slot {
            self.targets.resize_with(slot + 1, || None);
        }
        let fits = self.targets[slot]
            .as_ref()
            .is_some_and(|t| t.width == width && t.height == height);
        if !fits {
            self.targets[slot] = Some(self.make_target(width, height));
        }
        self.targets[slot].as_ref().unwrap()
    }

    fn make_target(&self, width: u32, height: u32) -> Target {
        let size = extent(width, height);
        let tex = |samples: u32, format, usage| {
            self.device.create_texture(&wgpu::TextureDescriptor {
                label: None,
                size,
                mip_level_count: 1,
                sample_count: samples,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage,
                view_formats: &[],
            })
        };
        let attachment = wgpu::TextureUsages::RENDER_ATTACHMENT
            | wgpu::TextureUsages::COPY_SRC
            | wgpu::TextureUsages::COPY_DST;
        let copy_only = wgpu::TextureUsages::COPY_SRC | wgpu::TextureUsages::COPY_DST;
        let msaa = (self.samples > 1).then(|| {
            let t = tex(self.samples, COLOR_FORMAT, attachment);
            let v = t.create_view(&Default::default());
            (t, v)
        });
        let resolve = self.device.create_texture(&wgpu::TextureDescriptor {
            label: None,
            size,
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: COLOR_FORMAT,
            usage: attachment,
            view_formats: &[],
        });
        let resolve_view = resolve.create_view(&Default::default());
        let depth = tex(self.samples, DEPTH_FORMAT, attachment);
        let depth_view = depth.create_view(&Default::default());
        // Copies need no render usage, but a multisampled texture must be renderable.
        let cache_usage = if self.samples > 1 {
            attachment
        } else {
            copy_only
        };
        let cache_color = tex(self.samples, COLOR_FORMAT, cache_usage);
        let cache_depth = tex(self.samples, DEPTH_FORMAT, attachment);
        let padded_row = (width * 4).div_ceil(256) * 256;
        let readback = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: None,
            size: padded_row as u64 * height as u64,
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
            mapped_at_creation: false,
        });
        let uniform = uniform_buffer(&self.device);
        let bind = self.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: None,
            layout: &self.main_bgl,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: uniform.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::TextureView(&self.shadow_view),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: wgpu::BindingResource::Sampler(&self.shadow_sampler),
                },
                wgpu::BindGroupEntry {
                    binding: 3,
                    resource: wgpu::BindingResource::TextureView(&self.model_textures.view),
                },
                wgpu::BindGroupEntry {
                    binding: 4,
                    resource: wgpu::BindingResource::Sampler(&self.model_textures.sampler),
                },
            ],
        });
        Target {
            width,
            height,
            msaa,
            resolve,
            resolve_view,
            depth,
            depth_view,
            cache_color,
            cache_depth,
            aa_cache: None,
            readback,
            padded_row,
            uniform,
            bind,
            dirty: None,
        }
    }

    /// Draws the shadow map from `casters`, then every view; returns tightly packed RGBA
    /// (sRGB) images, one per view, in order.
    pub fn draw(
        &mut self,
        light_vp: [[f32; 4]; 4],
        casters: &[Range<u32>],
        views: &[ViewJob],
    ) -> Result<Vec<Vec<u8>>, RenderError> {
        let enc = self.encode_whole(light_vp, casters, views, false);
        self.submit(enc);
        self.read_back(&self.whole_finishes(views))
    }

    /// Renders the fixed casters' shadow map and each view's static geometry once, and
    /// keeps them: [`Gpu::draw_overlay`] then starts every frame from these images
    /// instead of drawing the room, furniture and observer again (the cameras do not
    /// move within a scene).
    pub fn cache_static(
        &mut self,
        light_vp: [[f32; 4]; 4],
        casters: &[Range<u32>],
        views: &[ViewJob],
    ) -> Result<(), RenderError> {
        let enc = self.encode_whole(light_vp, casters, views, true);
        self.submit(enc);
        if !self.fxaa {
            self.wait()?;
            return Ok(());
        }
        self.keep_static_images(views)
    }

    /// Encodes the shadow map from `casters` and every view drawn from a cleared
    /// target; then either keeps shadow map and views as the static cache (`cache`) or
    /// queues each view's read-back.
    fn encode_whole(
        &mut self,
        light_vp: [[f32; 4]; 4],
        casters: &[Range<u32>],
        views: &[ViewJob],
        cache: bool,
    ) -> wgpu::CommandEncoder {
        for v in views {
            self.target(v.slot, v.width, v.height);
            self.write_uniforms(v.slot, &v.uniforms, Redraw::Whole(&[]));
        }
        self.write_shadow_uniforms(light_vp);
        let mut enc = self.encoder();
        self.shadow_pass(&mut enc, casters, true);
        if cache {
            copy_whole(&mut enc, &self.shadow_tex, &self.static_shadow);
        }
        for v in views {
            let t = self.targets[v.slot].as_ref().unwrap();
            self.main_pass(&mut enc, t, Redraw::Whole(&v.ranges), &v.dynamic);
            if cache {
                copy_whole(&mut enc, t.color(), &t.cache_color);
                copy_whole(&mut enc, &t.depth, &t.cache_depth);
            }
            if !cache || self.fxaa {
                Self::copy_to_readback(&mut enc, t);
            }
        }
        // A cached view's attachment now equals its cache.
        for v in views {
            self.targets[v.slot].as_mut().unwrap().dirty = cache.then(Vec::new);
        }
        enc
    }

    /// One frame over the cached static images (same pixels as [`Gpu::draw`] of the
    /// whole scene when each job's `redraw` covers every static pixel a moving caster
    /// can shade): adds `casters` to the cached shadow map, shades the static surfaces
    /// inside `redraw` again and draws the moving bodies (`main_pass`), then reads the
    /// frame back, anti-aliased around what changed.
    pub fn draw_overlay(
        &mut self,
        light_vp: [[f32; 4]; 4],
        casters: &[Range<u32>],
        views: &[OverlayJob],
    ) -> Result<Vec<Vec<u8>>, RenderError> {
        let mut redraws = Vec::with_capacity(views.len());
        for v in views {
            if self.targets.get(v.slot).is_none_or(Option::is_none) {
                return Err(RenderError::Gpu(format!(
                    "view slot {} has no cached static image",
                    v.slot
                )));
            }
            if v.redraw.len() > MAX_REDRAW_RECTS {
                return Err(RenderError::Gpu(format!(
                    "{} redraw rectangles (at most {MAX_REDRAW_RECTS})",
                    v.redraw.len()
                )));
            }
            let rects: Vec<([u32; 4], &[Range<u32>])> = v
                .redraw
                .iter()
                .filter(|(r, _)| r[2] > 0 && r[3] > 0)
                .map(|(r, ranges)| (*r, &ranges[..]))
                .collect();
            self.write_uniforms(v.slot, &v.uniforms, Redraw::Regions(&rects));
            redraws.push(rects);
        }
        self.write_shadow_uniforms(light_vp);
        let mut enc = self.encoder();
        copy_whole(&mut enc, &self.static_shadow, &self.shadow_tex);
        self.shadow_pass(&mut enc, casters, false);
        for (v, rects) in views.iter().zip(&redraws) {
            let t = self.targets[v.slot].as_ref().unwrap();
            // Colour: only what the last frame changed (multisampled textures and depth
            // are copied whole: wgpu allows no partial copies of them).
            let dirty = t.dirty.as_deref().filter(|_| self.samples == 1);
            copy::restore(&mut enc, &t.cache_color, t.color(), dirty);
            copy_whole(&mut enc, &t.cache_depth, &t.depth);
            let redraw = Redraw::Regions(rects);
            self.main_pass(&mut enc, t, redraw, &v.dynamic);
            match self.over_static(t, v) {
                // Anti-aliased over the static image: only what the filter reads.
                true => Self::copy_rects_to_readback(&mut enc, t, &v.post_rects),
                false => Self::copy_to_readback(&mut enc, t),
            }
        }
        self.submit(enc);
        for v in views {
            self.targets[v.slot].as_mut().unwrap().dirty = Some(v.post_rects.clone());
        }
        let finishes: Vec<(usize, Finish)> = views
            .iter()
            .map(|v| {
                let t = self.targets[v.slot].as_ref().unwrap();
                match (self.over_static(t, v), &t.aa_cache) {
                    // Anti-aliased: the static image's, redone around what changed.
                    (true, Some(c)) => (v.slot, Finish::Over(&c.filtered, &c.drawn, &v.post_rects)),
                    _ => (v.slot, Finish::AsDrawn),
                }
            })
            .collect();
        self.read_back(&finishes)
    }

    /// Whether an overlay frame of `v` is finished over its view's anti-aliased static
    /// image (`Finish::Over`): lit, with an anti-aliased cache.
    fn over_static(&self, t: &Target, v: &OverlayJob) -> bool {
        t.aa_cache.is_some() && lit(&v.uniforms)
    }

    fn encoder(&self) -> wgpu::CommandEncoder {
        self.device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: None })
    }

    /// Writes a view's uniforms, with the fill rectangles of `redraw`.
    fn write_uniforms(&self, slot: usize, u: &Uniforms, redraw: Redraw) {
        let t = self.targets[slot].as_ref().unwrap();
        let mut u = *u;
        let (fw, fh) = (t.width as f32, t.height as f32);
        u.fill_rects = [[-1.0, -1.0, 1.0, 1.0]; MAX_REDRAW_RECTS];
        if let Redraw::Regions(rects) = redraw {
            for (ndc, &([x, y, w, h], _)) in u.fill_rects.iter_mut().zip(rects) {
                *ndc = [
                    x as f32 / fw * 2.0 - 1.0,
                    1.0 - (y + h) as f32 / fh * 2.0,
                    (x + w) as f32 / fw * 2.0 - 1.0,
                    1.0 - y as f32 / fh * 2.0,
                ];
            }
        }
        self.queue
            .write_buffer(&t.uniform, 0, bytemuck::bytes_of(&u));
    }

    fn write_shadow_uniforms(&self, light_vp: [[f32; 4]; 4]) {
        let mut su: Uniforms = bytemuck::Zeroable::zeroed();
        su.light_vp = light_vp;
        su.view_proj = light_vp;
        self.queue
            .write_buffer(&self.shadow_uniform, 0, bytemuck::bytes_of(&su));
    }

    /// Depth of `casters` into the shadow map, cleared first or added to what is there.
    fn shadow_pass(&self, enc: &mut wgpu::CommandEncoder, casters: &[Range<u32>], clear: bool) {
        let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("shadow"),
            color_attachments: &[],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &self.shadow_view,
                depth_ops: Some(wgpu::Operations {
                    load: if clear {
                        wgpu::LoadOp::Clear(1.0)
                    } else {
                        wgpu::LoadOp::Load
                    },
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&self.shadow);
        pass.set_bind_group(0, &self.shadow_bind, &[]);
        pass.set_vertex_buffer(0, self.vbuf.slice(..));
        for r in casters.iter().filter(|r| !r.is_empty()) {
            pass.draw(r.clone(), 0..1);
        }
    }

    /// One lit pass into a target. `Redraw::Whole` clears it and draws its ranges;
    /// `Redraw::Regions` continues from the copied-in static image and shades the static
    /// surfaces inside its rectangles again (`redraw_static`: re-cleared first only with
    /// MSAA). `dynamic` is drawn over the whole target, depth first (before the re-shade
    /// without MSAA), then shaded. The colour is resolved (MSAA) at the end.
    fn main_pass(
        &self,
        enc: &mut wgpu::CommandEncoder,
        t: &Target,
        redraw: Redraw,
        dynamic: &Range<u32>,
    ) {
        let (view, resolve) = match &t.msaa {
            Some((_, m)) => (m, Some(&t.resolve_view)),
            None => (&t.resolve_view, None),
        };
        let whole = matches!(redraw, Redraw::Whole(_));
        let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("main"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view,
                depth_slice: None,
                resolve_target: resolve,
                ops: wgpu::Operations {
                    // A whole frame is cleared by the fill draw below.
                    load: if whole {
                        wgpu::LoadOp::Clear(wgpu::Color::BLACK)
                    } else {
                        wgpu::LoadOp::Load
                    },
                    // Whole frames may become the static cache; overlays need only the
                    // resolved image.
                    store: if whole || resolve.is_none() {
                        wgpu::StoreOp::Store
                    } else {
                        wgpu::StoreOp::Discard
                    },
                },
            })],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &t.depth_view,
                depth_ops: Some(wgpu::Operations {
                    load: if whole {
                        wgpu::LoadOp::Clear(1.0)
                    } else {
                        wgpu::LoadOp::Load
                    },
                    store: if whole {
                        wgpu::StoreOp::Store
                    } else {
                        wgpu::StoreOp::Discard
                    },
                }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_bind_group(0, &t.bind, &[]);
        pass.set_vertex_buffer(0, self.vbuf.slice(..));
        match redraw {
            Redraw::Whole(ranges) => {
                // Clearing by drawing (not LoadOp::Clear's colour) keeps the background
                // bit-identical between whole frames and the static image.
                pass.set_pipeline(&self.fill);
                pass.draw(0..6, 0..1);
                pass.set_pipeline(&self.main);
                for r in ranges.iter().filter(|r| !r.is_empty()) {
                    pass.draw(r.clone(), 0..1);
                }
            }
            Redraw::Regions(rects) if self.samples == 1 => {
                // The moving bodies' depth first: the re-shade then skips the static
                // pixels they cover, which their shading below overwrites anyway.
                if !dynamic.is_empty() {
                    pass.set_pipeline(&self.depth_only);
                    pass.draw(dynamic.clone(), 0..1);
                }
                self.redraw_static(&mut pass, rects, false);
                pass.set_scissor_rect(0, 0, t.width, t.height);
                if !dynamic.is_empty() {
                    pass.set_pipeline(&self.main_over);
                    pass.draw(dynamic.clone(), 0..1);
                }
                return;
            }
            Redraw::Regions(rects) => {
                // Multisampled (a GPU): re-cleared, then drawn again as in the static
                // image (an equal-depth re-shade left a few edge pixels different).
                pass.set_pipeline(&self.fill);
                for (i, &([x, y, w, h], _)) in rects.iter().enumerate() {
                    pass.set_scissor_rect(x, y, w, h);
                    pass.draw(0..6, i as u32..i as u32 + 1);
                }
                self.redraw_static(&mut pass, rects, true)
            }
        }
        pass.set_scissor_rect(0, 0, t.width, t.height);
        if !dynamic.is_empty() {
            pass.set_pipeline(&self.depth_only);
            pass.draw(dynamic.clone(), 0..1);
            pass.set_pipeline(&self.main_over);
            pass.draw(dynamic.clone(), 0..1);
        }
    }

    /// Draws the static surfaces inside `rects` again (with the frame's shadow map), over
    /// the copied-in static image and depth: each static piece a group of nearby
    /// rectangles needs, once per group over the group's bounding rectangle (drawing per
    /// rectangle ran the vertex work of a piece once per rectangle; one bounding
    /// rectangle for all made lavapipe depth-test every pixel between scattered
    /// rectangles). The groups' rectangles are disjoint.
    ///
    /// `recleared` (the rectangles were re-cleared to depth 1): the pieces are drawn in
    /// the static image's order with its `Less` test; outside the rectangles the copied
    /// depth rejects them. Otherwise each pixel is shaded once, not once per
    /// overlapping piece: a `LessEqual` test without depth write passes only the surfaces
    /// at the depth the static image shows (no static fragment lies in front of it), and
    /// every triangle goes in reverse order (the pieces, and within each piece its
    /// triangles: `Gpu::reversed`), so where several show the same depth the first one
    /// in drawing order, the one `Less` kept, is shaded last; pixels with no static
    /// surface keep the background.
    fn redraw_static(
        &self,
        pass: &mut wgpu::RenderPass<'_>,
        rects: &[([u32; 4], &[Range<u32>])],
        recleared: bool,
    ) {
        pass.set_pipeline(if recleared {
            &self.main
        } else {
            &self.main_over
        });
        for group in redraw_groups(rects, MAX_REDRAW_GROUPS) {
            let mut statics: Vec<&Range<u32>> =
                group.iter().flat_map(|&i| rects[i].1.iter()).collect();
            statics.sort_by_key(|r| (r.start, r.end));
            statics.dedup();
            // Runs that follow each other in the buffer (a piece's nearby chunks) as one.
            let mut runs: Vec<Range<u32>> = Vec::new();
            for r in statics {
                match runs.last_mut() {
                    Some(last) if last.end == r.start => last.end = r.end,
                    _ => runs.push(r.clone()),
                }
            }
            if !recleared {
                runs = runs.iter().rev().map(|r| self.reversed(r)).collect();
            }
            let Some([x, y, w, h]) = group.iter().map(|&i| rects[i].0).reduce(rect_union) else {
                continue;
            };
            pass.set_scissor_rect(x, y, w, h);
            for r in runs.into_iter().filter(|r| !r.is_empty()) {
                pass.draw(r, 0..1);
            }
        }
    }
}

impl Target {
    /// The colour attachment drawn into (multisampled when MSAA is on).
    fn color(&self) -> &wgpu::Texture {
        match &self.msaa {
            Some((t, _)) => t,
            None => &self.resolve,
        }
    }
}

/// Most groups of redraw rectangles whose static pieces are drawn together.
const MAX_REDRAW_GROUPS: usize = 8;

/// Groups of `rects` (indices) with disjoint bounding rectangles, at most `max` (unless
/// overlaps force fewer): starting from one group per rectangle, overlapping groups are
/// merged, then the pair whose merge adds the least area while more than `max` remain
/// or a merge adds none.
fn redraw_groups(rects: &[([u32; 4], &[Range<u32>])], max: usize) -> Vec<Vec<usize>> {
    let mut groups: Vec<(Vec<usize>, [u32; 4])> = rects
        .iter()
        .enumerate()
        .map(|(i, (r, _))| (vec![i], *r))
        .collect();
    loop {
        // (overlapping first, then least added area, i, j)
        let mut best: Option<(bool, i64, usize, usize)> = None;
        for i in 0..groups.len() {
            for j in i + 1..groups.len() {
                let (a, b) = (groups[i].1, groups[j].1);
                let added =
                    rect_area(rect_union(a, b)) as i64 - rect_area(a) as i64 - rect_area(b) as i64;
                let key = (!rects_meet(a, b), added);
                if best.is_none_or(|(o, d, _, _)| key < (o, d)) {
                    best = Some((key.0, added, i, j));
                }
            }
        }
        match best {
            Some((disjoint, added, i, j)) if !disjoint || added <= 0 || groups.len() > max => {
                let (members, r) = groups.swap_remove(j);
                groups[i].0.extend(members);
                groups[i].1 = rect_union(groups[i].1, r);
            }
            _ => return groups.into_iter().map(|(g, _)| g).collect(),
        }
    }
}

/// Whether a view is shaded for the dataset (not an unlit diagnostic: `ambient.w`).
fn lit(u: &Uniforms) -> bool {
    u.ambient[3] <= 0.5
}

fn extent(width: u32, height: u32) -> wgpu::Extent3d {
    wgpu::Extent3d {
        width,
        height,
        depth_or_array_layers: 1,
    }
}

/// A whole single-level texture as a copy source or destination.
fn whole(texture: &wgpu::Texture) -> wgpu::TexelCopyTextureInfo<'_> {
    wgpu::TexelCopyTextureInfo {
        texture,
        mip_level: 0,
        origin: wgpu::Origin3d::ZERO,
        aspect: wgpu::TextureAspect::All,
    }
}

/// Copies a whole texture into one of the same size (colour or depth, any sample count).
fn copy_whole(enc: &mut wgpu::CommandEncoder, from: &wgpu::Texture, to: &wgpu::Texture) {
    enc.copy_texture_to_texture(whole(from), whole(to), from.size());
}

fn uniform_buffer(device: &wgpu::Device) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: None,
        size: std::mem::size_of::<Uniforms>() as u64,
        usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}

fn vertex_buffer(device: &wgpu::Device, size: u64) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("vertices"),
        size,
        usage: wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}
