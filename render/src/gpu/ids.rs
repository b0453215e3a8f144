//! The instance-id pass: per view, an unlit single-sample image of (instance id, depth in
//! mm) per pixel, plus the pixels one body (the hazard) covers when drawn with nothing
//! else. Cheap by construction: no lighting, no shadow map, no MSAA, flat outputs, and
//! run only at the observation frames; the static geometry of a camera is drawn once
//! ([`Gpu::cache_static_ids`]) and each frame only adds the moving bodies over it
//! ([`Gpu::draw_ids_over`]). Its pipelines are built on first use ([`IdPass::new`]), so
//! a renderer that never measures pays nothing.

use super::super::mesh::Vertex;
use super::RenderError;
use super::{copy_whole, extent, whole, Gpu, DEPTH_FORMAT};
use std::ops::Range;

const ID_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rg16Uint;
const COVER_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R8Uint;

/// Per-view uniforms (matches `U` in ids.wgsl).
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
struct IdUniforms {
    view_proj: [[f32; 4]; 4],
    cam_pos: [f32; 4],
}

/// One view of the id pass: its slot (own targets), camera, the vertex ranges to draw
/// with their instance ids, and the ranges drawn alone for the coverage count.
pub struct IdView {
    pub slot: usize,
    pub width: u32,
    pub height: u32,
    pub view_proj: [[f32; 4]; 4],
    pub cam_pos: [f32; 3],
    pub ranges: Vec<(Range<u32>, u16)>,
    pub alone: Vec<Range<u32>>,
}

/// What the id pass read back for one view (row-major, top row first).
pub struct IdImage {
    pub width: u32,
    pub height: u32,
    /// Instance id per pixel.
    pub ids: Vec<u16>,
    /// Distance from the camera centre per pixel (mm; 0 = no surface).
    pub depth_mm: Vec<u16>,
    /// Pixels the `alone` ranges cover with nothing else drawn.
    pub covered: u32,
}

struct IdTarget {
    width: u32,
    height: u32,
    ids: wgpu::Texture,
    ids_view: wgpu::TextureView,
    depth: wgpu::Texture,
    depth_view: wgpu::TextureView,
    /// The static geometry's ids and depth (`Gpu::cache_static_ids`).
    cache_ids: wgpu::Texture,
    cache_depth: wgpu::Texture,
    cover: wgpu::Texture,
    cover_view: wgpu::TextureView,
    ids_readback: wgpu::Buffer,
    ids_row: u32,
    cover_readback: wgpu::Buffer,
    cover_row: u32,
    uniform: wgpu::Buffer,
    bind: wgpu::BindGroup,
}

/// The id pass's per-slot targets, and its pipelines (the device's: see `Shared`).
pub struct IdPass {
    pipes: IdPipelines,
    targets: Vec<Option<IdTarget>>,
}

/// The id and coverage pipelines and their bind group layout, built once per device.
#[derive(Clone)]
pub(super) struct IdPipelines {
    ids: wgpu::RenderPipeline,
    cover: wgpu::RenderPipeline,
    bgl: wgpu::BindGroupLayout,
}

impl IdPass {
    pub fn new(gpu: &Gpu) -> IdPass {
        let pipes = gpu
            .id_pipelines
            .get_or_init(|| IdPipelines::new(&gpu.device));
        IdPass {
            pipes: pipes.clone(),
            targets: Vec::new(),
        }
    }

    /// Frees the targets (made again by the next `draw_ids`).
    pub fn release(&mut self) {
        self.targets.clear();
    }

    fn target(&mut self, device: &wgpu::Device, slot: usize, width: u32, height: u32) {
        if self.targets.len() <= slot {
            self.targets.resize_with(slot + 1, || None);
        }
        let fits = self.targets[slot]
            .as_ref()
            .is_some_and(|t| t.width == width && t.height == height);
        if !fits {
            self.targets[slot] = Some(make_target(device, &self.pipes.bgl, width, height));
        }
    }
}

impl IdPipelines {
    fn new(device: &wgpu::Device) -> IdPipelines {
        let bgl = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("ids-bgl"),
            entries: &[wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::VERTEX_FRAGMENT,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
                count: None,
            }],
        });
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: None,
            bind_group_layouts: &[Some(&bgl)],
            immediate_size: 0,
        });
        let shader = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("rh-ids"),
            source: wgpu::ShaderSource::Wgsl(include_str!("ids.wgsl").into()),
        });
        let pipeline = |label, vs, fs, format, depth: bool| {
            let attrs = [wgpu::VertexAttribute {
                format: wgpu::VertexFormat::Float32x3,
                offset: 0,
                shader_location: 0,
            }];
            // The shared vertex buffer (`Vertex`); only the position is read.
            let buffers = [Some(wgpu::VertexBufferLayout {
                array_stride: std::mem::size_of::<Vertex>() as u64,
                step_mode: wgpu::VertexStepMode::Vertex,
                attributes: &attrs,
            })];
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(label),
                layout: Some(&layout),
                vertex: wgpu::VertexState {
                    module: &shader,
                    entry_point: Some(vs),
                    compilation_options: Default::default(),
                    buffers: &buffers,
                },
                primitive: wgpu::PrimitiveState {
                    cull_mode: None,
                    ..Default::default()
                },
                depth_stencil: depth.then(|| wgpu::DepthStencilState {
                    format: DEPTH_FORMAT,
                    depth_write_enabled: Some(true),
                    depth_compare: Some(wgpu::CompareFunction::Less),
                    stencil: Default::default(),
                    bias: Default::default(),
                }),
                multisample: Default::default(),
                fragment: Some(wgpu::FragmentState {
                    module: &shader,
                    entry_point: Some(fs),
                    compilation_options: Default::default(),
                    targets: &[Some(wgpu::ColorTargetState {
                        format,
                        blend: None,
                        write_mask: wgpu::ColorWrites::ALL,
                    })],
                }),
                multiview_mask: None,
                cache: None,
            })
        };
        IdPipelines {
            ids: pipeline("ids", "vs_ids", "fs_ids", ID_FORMAT, true),
            cover: pipeline("cover", "vs_cover", "fs_cover", COVER_FORMAT, false),
            bgl,
        }
    }
}

fn make_target(
    device: &wgpu::Device,
    bgl: &wgpu::BindGroupLayout,
    width: u32,
    height: u32,
) -> IdTarget {
    let tex = |format, usage| {
        device.create_texture(&wgpu::TextureDescriptor {
            label: Some("ids"),
            size: extent(width, height),
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage,
            view_formats: &[],
        })
    };
    let color = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC;
    let copied = color | wgpu::TextureUsages::COPY_DST;
    let ids = tex(ID_FORMAT, copied);
    let depth = tex(DEPTH_FORMAT, copied);
    let cache_ids = tex(ID_FORMAT, copied);
    let cache_depth = tex(DEPTH_FORMAT, copied);
    let cover = tex(COVER_FORMAT, color);
    let readback = |row: u32| {
        device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("ids-readback"),
            size: row as u64 * height as u64,
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
            mapped_at_creation: false,
        })
    };
    let ids_row = (width * 4).div_ceil(256) * 256;
    let cover_row = width.div_ceil(256) * 256;
    let uniform = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("ids-uniform"),
        size: std::mem::size_of::<IdUniforms>() as u64,
        usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: None,
        layout: bgl,
        entries: &[wgpu::BindGroupEntry {
            binding: 0,
            resource: uniform.as_entire_binding(),
        }],
    });
    IdTarget {
        width,
        height,
        ids_view: ids.create_view(&Default::default()),
        ids,
        depth_view: depth.create_view(&Default::default()),
        depth,
        cache_ids,
        cache_depth,
        cover_view: cover.create_view(&Default::default()),
        cover,
        ids_readback: readback(ids_row),
        ids_row,
        cover_readback: readback(cover_row),
        cover_row,
        uniform,
        bind,
    }
}

impl Gpu {
    /// Draws `view`'s id image from its ranges (the camera's static geometry) and keeps
    /// its ids and depth as the slot's static image for [`Gpu::draw_ids_over`].
    pub fn cache_static_ids(
        &mut self,
        pass: &mut IdPass,
        view: &IdView,
    ) -> Result<(), RenderError> {
        self.id_target(pass, view);
        let t = pass.targets[view.slot].as_ref().unwrap();
        let mut enc = self.encoder();
        self.id_pass(&mut enc, pass, t, view, false);
        copy_whole(&mut enc, &t.ids, &t.cache_ids);
        copy_whole(&mut enc, &t.depth, &t.cache_depth);
        self.submit(enc);
        self.wait()
    }

    /// The id image of the slot's cached static image (`cache_static_ids`, the same
    /// camera) with `view`'s ranges (the moving bodies) drawn over it, and `view`'s
    /// coverage image; read back. The same images as [`Gpu::draw_ids`] of the static and
    /// moving ranges together (static first: the depth test then meets the same values).
    pub fn draw_ids_over(
        &mut self,
        pass: &mut IdPass,
        view: &IdView,
    ) -> Result<IdImage, RenderError> {
        self.id_images(pass, std::slice::from_ref(view), true)
            .map(|mut v| v.remove(0))
    }

    /// Draws each view's id image and coverage image from the vertex buffer as it is
    /// (statics and the current moving geometry) and reads them back, in view order.
    pub fn draw_ids(
        &mut self,
        pass: &mut IdPass,
        views: &[IdView],
    ) -> Result<Vec<IdImage>, RenderError> {
        self.id_images(pass, views, false)
    }

    /// `draw_ids`, or (`over_cache`) `draw_ids_over` of each view.
    fn id_images(
        &mut self,
        pass: &mut IdPass,
        views: &[IdView],
        over_cache: bool,
    ) -> Result<Vec<IdImage>, RenderError> {
        for v in views {
            self.id_target(pass, v);
        }
        let mut enc = self.encoder();
        for v in views {
            let t = pass.targets[v.slot].as_ref().unwrap();
            if over_cache {
                copy_whole(&mut enc, &t.cache_ids, &t.ids);
                copy_whole(&mut enc, &t.cache_depth, &t.depth);
            }
            self.id_pass(&mut enc, pass, t, v, over_cache);
            self.cover_pass(&mut enc, pass, t, v);
            copy_out(&mut enc, &t.ids, &t.ids_readback, t.ids_row, t.height);
            copy_out(&mut enc, &t.cover, &t.cover_readback, t.cover_row, t.height);
        }
        self.submit(enc);
        for v in views {
            let t = pass.targets[v.slot].as_ref().unwrap();
            t.ids_readback
                .slice(..)
                .map_async(wgpu::MapMode::Read, |_| {});
            t.cover_readback
                .slice(..)
                .map_async(wgpu::MapMode::Read, |_| {});
        }
        self.wait()?;
        views
            .iter()
            .map(|v| read_id_image(pass.targets[v.slot].as_ref().unwrap()))
            .collect()
    }

    /// Makes the slot's target for `v` (to its size) and writes `v`'s uniforms.
    fn id_target(&self, pass: &mut IdPass, v: &IdView) {
        pass.target(&self.device, v.slot, v.width, v.height);
        let t = pass.targets[v.slot].as_ref().unwrap();
        let u = IdUniforms {
            view_proj: v.view_proj,
            cam_pos: [v.cam_pos[0], v.cam_pos[1], v.cam_pos[2], 1.0],
        };
        self.queue
            .write_buffer(&t.uniform, 0, bytemuck::bytes_of(&u));
    }

    /// The id pass of one view: its ranges drawn into the target, cleared first (id 0,
    /// depth 1) or (`over`) over what it holds.
    fn id_pass(
        &self,
        enc: &mut wgpu::CommandEncoder,
        pass: &IdPass,
        t: &IdTarget,
        v: &IdView,
        over: bool,
    ) {
        let mut rp = begin(enc, "ids", &t.ids_view, Some(&t.depth_view), over);
        rp.set_pipeline(&pass.pipes.ids);
        rp.set_bind_group(0, &t.bind, &[]);
        rp.set_vertex_buffer(0, self.vbuf.slice(..));
        for (r, id) in v.ranges.iter().filter(|(r, _)| !r.is_empty()) {
            let id = *id as u32;
            rp.draw(r.clone(), id..id + 1);
        }
    }

    /// The coverage pass of one view: its `alone` ranges into the cleared coverage image.
    fn cover_pass(&self, enc: &mut wgpu::CommandEncoder, pass: &IdPass, t: &IdTarget, v: &IdView) {
        let mut rp = begin(enc, "cover", &t.cover_view, None, false);
        rp.set_pipeline(&pass.pipes.cover);
        rp.set_bind_group(0, &t.bind, &[]);
        rp.set_vertex_buffer(0, self.vbuf.slice(..));
        for r in v.alone.iter().filter(|r| !r.is_empty()) {
            rp.draw(r.clone(), 0..1);
        }
    }
}

/// A render pass into `color` and `depth` (if any), each cleared (id 0, depth 1) or
/// (`over`) continued from what it holds.
fn begin<'e>(
    enc: &'e mut wgpu::CommandEncoder,
    label: &str,
    color: &wgpu::TextureView,
    depth: Option<&wgpu::TextureView>,
    over: bool,
) -> wgpu::RenderPass<'e> {
    enc.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some(label),
        color_attachments: &[Some(wgpu::RenderPassColorAttachment {
            view: color,
            depth_slice: None,
            resolve_target: None,
            ops: operations(over, wgpu::Color::TRANSPARENT),
        })],
        depth_stencil_attachment: depth.map(|view| wgpu::RenderPassDepthStencilAttachment {
            view,
            depth_ops: Some(operations(over, 1.0)),
            stencil_ops: None,
        }),
        timestamp_writes: None,
        occlusion_query_set: None,
        multiview_mask: None,
    })
}

/// Cleared to `clear`, or (`over`) continued from what the attachment holds; stored.
fn operations<V>(over: bool, clear: V) -> wgpu::Operations<V> {
    wgpu::Operations {
        load: if over {
            wgpu::LoadOp::Load
        } else {
            wgpu::LoadOp::Clear(clear)
        },
        store: wgpu::StoreOp::Store,
    }
}

fn copy_out(
    enc: &mut wgpu::CommandEncoder,
    texture: &wgpu::Texture,
    buffer: &wgpu::Buffer,
    row: u32,
    height: u32,
) {
    enc.copy_texture_to_buffer(
        whole(texture),
        wgpu::TexelCopyBufferInfo {
            buffer,
            layout: wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(row),
                rows_per_image: Some(height),
            },
        },
        texture.size(),
    );
}

/// Unpacks a view's mapped read-back buffers and unmaps them.
fn read_id_image(t: &IdTarget) -> Result<IdImage, RenderError> {
    let (w, h) = (t.width as usize, t.height as usize);
    let map_err = |e| RenderError::Gpu(format!("map id readback: {e:?}"));
    let mut ids = vec![0u16; w * h];
    let mut depth_mm = vec![0u16; w * h];
    {
        let data = t
            .ids_readback
            .slice(..)
            .get_mapped_range()
            .map_err(map_err)?;
        let rows = ids.chunks_exact_mut(w).zip(depth_mm.chunks_exact_mut(w));
        for (y, (ids, depth)) in rows.enumerate() {
            let row = &data[y * t.ids_row as usize..][..w * 4];
            for ((px, id), d) in row.chunks_exact(4).zip(ids).zip(depth) {
                *id = u16::from_le_bytes([px[0], px[1]]);
                *d = u16::from_le_bytes([px[2], px[3]]);
            }
        }
    }
    t.ids_readback.unmap();
    let mut covered = 0u32;
    {
        let data = t
            .cover_readback
            .slice(..)
            .get_mapped_range()
            .map_err(map_err)?;
        for y in 0..h {
            let row = &data[y * t.cover_row as usize..][..w];
            covered += row.iter().filter(|&&b| b != 0).count() as u32;
        }
    }
    t.cover_readback.unmap();
    Ok(IdImage {
        width: t.width,
        height: t.height,
        ids,
        depth_mm,
        covered,
    })
}
