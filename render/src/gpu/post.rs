//! Post-process anti-aliasing: an FXAA-style full-screen pass (`fxaa.wgsl`) from a
//! target's resolved frame into the image that is read back, in two passes (copy and
//! mark edges, then blend only the edges: see `fxaa.wgsl`). Used where MSAA is off
//! (a CPU rasterizer). Like the lit pass, it runs over the whole static image once per
//! view and scene (`cache`), and per frame only around what changed.

/// The pass's output format: the frame's sRGB-encoded bytes, as they are (the resolved
/// frame is read through a non-sRGB view, so FXAA works on display values).
const POST_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;

/// The edge mask of the two FXAA passes (0: edge, 1: copied as is).
const MASK_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth16Unorm;

/// The FXAA pipelines (`mark`: copy every pixel and mark edges in the depth mask;
/// `edge`: blend the marked pixels), their bind group layout and the (bilinear,
/// clamped) sampler.
#[derive(Clone)]
pub(super) struct Post {
    mark: wgpu::RenderPipeline,
    edge: wgpu::RenderPipeline,
    bgl: wgpu::BindGroupLayout,
    sampler: wgpu::Sampler,
}

/// One target's FXAA output, the anti-aliased static image (see `Gpu::cache_static`)
/// and the bind group reading the target's resolved frame.
pub(super) struct PostTarget {
    pub out: wgpu::Texture,
    pub cache: wgpu::Texture,
    view: wgpu::TextureView,
    /// The edge mask (depth) of the two passes.
    mask: wgpu::TextureView,
    bind: wgpu::BindGroup,
}

/// How far (pixels) an output pixel of the pass reads from: its four neighbours and
/// diagonals (1), the taps along the edge (at most `SPAN_MAX / 2` = 4) with their
/// bilinear footprint (1); with slack. Outside a rectangle grown by this much around
/// every changed input pixel the pass's output is unchanged.
pub(super) const REACH: u32 = 8;

/// The view format the resolved colour texture must allow (`view_formats`).
pub(super) const SOURCE_VIEW_FORMAT: wgpu::TextureFormat = POST_FORMAT;

impl Post {
    pub(super) fn new(device: &wgpu::Device) -> Post {
        let bgl = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("fxaa-bgl"),
            entries: &[
                wgpu::BindGroupLayoutEntry {
                    binding: 0,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Float { filterable: true },
                        view_dimension: wgpu::TextureViewDimension::D2,
                        multisampled: false,
                    },
                    count: None,
                },
                wgpu::BindGroupLayoutEntry {
                    binding: 1,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
                    count: None,
                },
            ],
        });
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("fxaa-layout"),
            bind_group_layouts: &[Some(&bgl)],
            immediate_size: 0,
        });
        let shader = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("fxaa"),
            source: wgpu::ShaderSource::Wgsl(include_str!("../fxaa.wgsl").into()),
        });
        let pipeline = |entry: &str, compare, write| {
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(entry),
                layout: Some(&layout),
                vertex: wgpu::VertexState {
                    module: &shader,
                    entry_point: Some("vs_post"),
                    compilation_options: Default::default(),
                    buffers: &[],
                },
                primitive: Default::default(),
                depth_stencil: Some(wgpu::DepthStencilState {
                    format: MASK_FORMAT,
                    depth_write_enabled: Some(write),
                    depth_compare: Some(compare),
                    stencil: Default::default(),
                    bias: Default::default(),
                }),
                multisample: Default::default(),
                fragment: Some(wgpu::FragmentState {
                    module: &shader,
                    entry_point: Some(entry),
                    compilation_options: Default::default(),
                    targets: &[Some(wgpu::ColorTargetState {
                        format: POST_FORMAT,
                        blend: None,
                        write_mask: wgpu::ColorWrites::ALL,
                    })],
                }),
                multiview_mask: None,
                cache: None,
            })
        };
        // The triangle lies at depth 0: the edge pass draws where the mask holds 0.
        let mark = pipeline("fs_fxaa_mark", wgpu::CompareFunction::Always, true);
        let edge = pipeline("fs_fxaa_edge", wgpu::CompareFunction::Equal, false);
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("fxaa-sampler"),
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            ..Default::default()
        });
        Post {
            mark,
            edge,
            bgl,
            sampler,
        }
    }

    /// The output texture and bind group for a target whose resolved frame is `source`
    /// (created with `TEXTURE_BINDING` and `SOURCE_VIEW_FORMAT` among its view formats).
    pub(super) fn target(&self, device: &wgpu::Device, source: &wgpu::Texture) -> PostTarget {
        let out = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("fxaa-out"),
            size: source.size(),
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: POST_FORMAT,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT
                | wgpu::TextureUsages::COPY_SRC
                | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        });
        let cache = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("fxaa-cache"),
            size: source.size(),
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: POST_FORMAT,
            usage: wgpu::TextureUsages::COPY_SRC | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        });
        let view = out.create_view(&Default::default());
        let mask = device
            .create_texture(&wgpu::TextureDescriptor {
                label: Some("fxaa-mask"),
                size: source.size(),
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: MASK_FORMAT,
                usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
                view_formats: &[],
            })
            .create_view(&Default::default());
        let source_view = source.create_view(&wgpu::TextureViewDescriptor {
            format: Some(SOURCE_VIEW_FORMAT),
            ..Default::default()
        });
        let bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("fxaa-bind"),
            layout: &self.bgl,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::TextureView(&source_view),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::Sampler(&self.sampler),
                },
            ],
        });
        PostTarget {
            out,
            cache,
            view,
            mask,
            bind,
        }
    }

    /// Encodes the pass: the target's resolved frame, anti-aliased, into `t.out` —
    /// everywhere, or only inside `rects` (x, y, width, height; they may overlap; the
    /// rest of `t.out` is kept).
    pub(super) fn encode(
        &self,
        enc: &mut wgpu::CommandEncoder,
        t: &PostTarget,
        rects: Option<&[[u32; 4]]>,
    ) {
        let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("fxaa"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: &t.view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: if rects.is_some() {
                        wgpu::LoadOp::Load
                    } else {
                        wgpu::LoadOp::Clear(wgpu::Color::BLACK)
                    },
                    store: wgpu::StoreOp::Store,
                },
            })],
            // Written by the mark pass wherever the edge pass reads it.
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &t.mask,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(1.0),
                    store: wgpu::StoreOp::Discard,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_bind_group(0, &t.bind, &[]);
        let size = t.out.size();
        let whole = [[0, 0, size.width, size.height]];
        let rects = rects.unwrap_or(&whole);
        // Every mark before any blend: a rectangle's mark pass would otherwise copy over
        // blended edges of an overlapping one. Both passes read only the source, so
        // overlapping rectangles write the same values twice.
        pass.set_pipeline(&self.mark);
        for &[x, y, w, h] in rects {
            pass.set_scissor_rect(x, y, w, h);
            pass.draw(0..3, 0..1);
        }
        pass.set_pipeline(&self.edge);
        for &[x, y, w, h] in rects {
            pass.set_scissor_rect(x, y, w, h);
            pass.draw(0..3, 0..1);
        }
    }
}
