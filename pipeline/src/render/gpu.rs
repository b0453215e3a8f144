//! The wgpu side: device, pipelines (shadow + lit MSAA), render targets per output slot,
//! and one call that draws a set of views of the current geometry and reads them back.

use super::mesh::Vertex;
use super::RenderError;
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
}

/// One view to draw: the output slot (its own target), uniforms and vertex ranges.
pub struct ViewJob {
    pub slot: usize,
    pub width: u32,
    pub height: u32,
    pub uniforms: Uniforms,
    pub ranges: Vec<Range<u32>>,
}

struct Target {
    width: u32,
    height: u32,
    msaa: Option<wgpu::TextureView>,
    resolve: wgpu::Texture,
    resolve_view: wgpu::TextureView,
    depth: wgpu::TextureView,
    readback: wgpu::Buffer,
    padded_row: u32,
    uniform: wgpu::Buffer,
    bind: wgpu::BindGroup,
}

pub struct Gpu {
    device: wgpu::Device,
    queue: wgpu::Queue,
    pub adapter_name: String,
    samples: u32,
    main: wgpu::RenderPipeline,
    shadow: wgpu::RenderPipeline,
    main_bgl: wgpu::BindGroupLayout,
    shadow_view: wgpu::TextureView,
    shadow_sampler: wgpu::Sampler,
    shadow_uniform: wgpu::Buffer,
    shadow_bind: wgpu::BindGroup,
    vbuf: wgpu::Buffer,
    vcap: u64,
    static_len: u32,
    targets: Vec<Option<Target>>,
}

const VERTEX_ATTRS: [wgpu::VertexAttribute; 3] =
    wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3, 2 => Float32x4];

impl Gpu {
    pub fn new(samples: u32) -> Result<Gpu, RenderError> {
        if std::env::var_os("XDG_RUNTIME_DIR").is_none() {
            // Silences a harmless probe error of the Vulkan loader on headless machines.
            // SAFETY: called before any other thread of ours reads the environment here.
            unsafe { std::env::set_var("XDG_RUNTIME_DIR", std::env::temp_dir()) };
        }
        let mut desc = wgpu::InstanceDescriptor::new_without_display_handle_from_env();
        if std::env::var_os("WGPU_BACKEND").is_none() {
            desc.backends = wgpu::Backends::VULKAN;
        }
        let instance = wgpu::Instance::new(desc);
        let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
            power_preference: wgpu::PowerPreference::HighPerformance,
            force_fallback_adapter: false,
            compatible_surface: None,
            ..Default::default()
        }))
        .map_err(|e| {
            RenderError::NoAdapter(format!(
                "{e} (install a Vulkan driver: Mesa's lavapipe, package mesa-vulkan-drivers)"
            ))
        })?;
        let adapter_name = adapter.get_info().name;
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("rh-render"),
            required_features: wgpu::Features::empty(),
            required_limits: wgpu::Limits::downlevel_defaults().using_resolution(adapter.limits()),
            ..Default::default()
        }))
        .map_err(|e| RenderError::NoAdapter(format!("request device on {adapter_name}: {e}")))?;
        let samples = if samples >= 4 { 4 } else { 1 };

        let shader = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("rh-shader"),
            source: wgpu::ShaderSource::Wgsl(include_str!("shader.wgsl").into()),
        });
        let uniform_entry = wgpu::BindGroupLayoutEntry {
            binding: 0,
            visibility: wgpu::ShaderStages::VERTEX_FRAGMENT,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Uniform,
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        };
        let shadow_bgl = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("shadow-bgl"),
            entries: &[uniform_entry],
        });
        let main_bgl = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("main-bgl"),
            entries: &[
                uniform_entry,
                wgpu::BindGroupLayoutEntry {
                    binding: 1,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Depth,
                        view_dimension: wgpu::TextureViewDimension::D2,
                        multisampled: false,
                    },
                    count: None,
                },
                wgpu::BindGroupLayoutEntry {
                    binding: 2,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Comparison),
                    count: None,
                },
            ],
        });
        let layout = |bgl: &wgpu::BindGroupLayout| {
            device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: None,
                bind_group_layouts: &[Some(bgl)],
                immediate_size: 0,
            })
        };
        let vlayout = [Some(wgpu::VertexBufferLayout {
            array_stride: std::mem::size_of::<Vertex>() as u64,
            step_mode: wgpu::VertexStepMode::Vertex,
            attributes: &VERTEX_ATTRS,
        })];
        let main_layout = layout(&main_bgl);
        let main = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("main"),
            layout: Some(&main_layout),
            vertex: wgpu::VertexState {
                module: &shader,
                entry_point: Some("vs_main"),
                compilation_options: Default::default(),
                buffers: &vlayout,
            },
            primitive: wgpu::PrimitiveState {
                cull_mode: None,
                ..Default::default()
            },
            depth_stencil: Some(wgpu::DepthStencilState {
                format: DEPTH_FORMAT,
                depth_write_enabled: Some(true),
                depth_compare: Some(wgpu::CompareFunction::Less),
                stencil: Default::default(),
                bias: Default::default(),
            }),
            multisample: wgpu::MultisampleState {
                count: samples,
                ..Default::default()
            },
            fragment: Some(wgpu::FragmentState {
                module: &shader,
                entry_point: Some("fs_main"),
                compilation_options: Default::default(),
                targets: &[Some(wgpu::ColorTargetState {
                    format: COLOR_FORMAT,
                    blend: None,
                    write_mask: wgpu::ColorWrites::ALL,
                })],
            }),
            multiview_mask: None,
            cache: None,
        });
        let shadow_layout = layout(&shadow_bgl);
        let shadow = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("shadow"),
            layout: Some(&shadow_layout),
            vertex: wgpu::VertexState {
                module: &shader,
                entry_point: Some("vs_shadow"),
                compilation_options: Default::default(),
                buffers: &vlayout,
            },
            primitive: wgpu::PrimitiveState {
                cull_mode: None,
                ..Default::default()
            },
            depth_stencil: Some(wgpu::DepthStencilState {
                format: DEPTH_FORMAT,
                depth_write_enabled: Some(true),
                depth_compare: Some(wgpu::CompareFunction::Less),
                stencil: Default::default(),
                bias: wgpu::DepthBiasState {
                    constant: 2,
                    slope_scale: 2.0,
                    clamp: 0.0,
                },
            }),
            multisample: Default::default(),
            fragment: None,
            multiview_mask: None,
            cache: None,
        });
        let shadow_tex = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("shadow-map"),
            size: wgpu::Extent3d {
                width: SHADOW_SIZE,
                height: SHADOW_SIZE,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: DEPTH_FORMAT,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        });
        let shadow_view = shadow_tex.create_view(&Default::default());
        let shadow_sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("shadow-sampler"),
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            compare: Some(wgpu::CompareFunction::LessEqual),
            ..Default::default()
        });
        let shadow_uniform = uniform_buffer(&device);
        let shadow_bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: None,
            layout: &shadow_bgl,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: shadow_uniform.as_entire_binding(),
            }],
        });
        let vcap = 1 << 20;
        let vbuf = vertex_buffer(&device, vcap);
        Ok(Gpu {
            device,
            queue,
            adapter_name,
            samples,
            main,
            shadow,
            main_bgl,
            shadow_view,
            shadow_sampler,
            shadow_uniform,
            shadow_bind,
            vbuf,
            vcap,
            static_len: 0,
            targets: Vec::new(),
        })
    }

    /// Uploads the scene's static geometry (kept until the next call).
    pub fn set_static(&mut self, verts: &[Vertex]) {
        self.ensure_capacity(std::mem::size_of_val(verts) as u64 * 2);
        self.queue
            .write_buffer(&self.vbuf, 0, bytemuck::cast_slice(verts));
        self.static_len = verts.len() as u32;
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
        let need = (self.static_len as u64 + verts.len() as u64) * stride;
        if need > self.vcap {
            return Err(RenderError::Gpu(format!(
                "vertex buffer of {} bytes too small for {need}",
                self.vcap
            )));
        }
        if !verts.is_empty() {
            self.queue.write_buffer(
                &self.vbuf,
                self.static_len as u64 * stride,
                bytemuck::cast_slice(verts),
            );
        }
        Ok(self.static_len..self.static_len + verts.len() as u32)
    }

    /// Reserves room for `static_len + dynamic` vertices (call before `set_static`).
    pub fn reserve(&mut self, vertices: usize) {
        self.ensure_capacity(vertices as u64 * std::mem::size_of::<Vertex>() as u64);
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
        let size = wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: 1,
        };
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
        let msaa = (self.samples > 1).then(|| {
            tex(
                self.samples,
                COLOR_FORMAT,
                wgpu::TextureUsages::RENDER_ATTACHMENT,
            )
            .create_view(&Default::default())
        });
        let resolve = tex(
            1,
            COLOR_FORMAT,
            wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
        );
        let resolve_view = resolve.create_view(&Default::default());
        let depth = tex(
            self.samples,
            DEPTH_FORMAT,
            wgpu::TextureUsages::RENDER_ATTACHMENT,
        )
        .create_view(&Default::default());
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
            ],
        });
        Target {
            width,
            height,
            msaa,
            resolve,
            resolve_view,
            depth,
            readback,
            padded_row,
            uniform,
            bind,
        }
    }

    /// Draws the shadow map from `casters`, then every view; returns tightly packed RGBA
    /// (sRGB) images, one per view, in order.
    pub fn draw(
        &mut self,
        light_vp: [[f32; 4]; 4],
        casters: &[Range<u32>],
        views: &[ViewJob],
        background: [f64; 3],
    ) -> Result<Vec<Vec<u8>>, RenderError> {
        for v in views {
            self.target(v.slot, v.width, v.height);
        }
        let mut su: Uniforms = bytemuck::Zeroable::zeroed();
        su.light_vp = light_vp;
        su.view_proj = light_vp;
        self.queue
            .write_buffer(&self.shadow_uniform, 0, bytemuck::bytes_of(&su));
        for v in views {
            let t = self.targets[v.slot].as_ref().unwrap();
            self.queue
                .write_buffer(&t.uniform, 0, bytemuck::bytes_of(&v.uniforms));
        }
        let mut enc = self
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: None });
        {
            let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("shadow"),
                color_attachments: &[],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &self.shadow_view,
                    depth_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Clear(1.0),
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
            for r in casters {
                if !r.is_empty() {
                    pass.draw(r.clone(), 0..1);
                }
            }
        }
        let [br, bg, bb] = background;
        for v in views {
            let t = self.targets[v.slot].as_ref().unwrap();
            {
                let (view, resolve) = match &t.msaa {
                    Some(m) => (m, Some(&t.resolve_view)),
                    None => (&t.resolve_view, None),
                };
                let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some("main"),
                    color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                        view,
                        depth_slice: None,
                        resolve_target: resolve,
                        ops: wgpu::Operations {
                            load: wgpu::LoadOp::Clear(wgpu::Color {
                                r: br,
                                g: bg,
                                b: bb,
                                a: 1.0,
                            }),
                            store: if resolve.is_some() {
                                wgpu::StoreOp::Discard
                            } else {
                                wgpu::StoreOp::Store
                            },
                        },
                    })],
                    depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                        view: &t.depth,
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
                pass.set_pipeline(&self.main);
                pass.set_bind_group(0, &t.bind, &[]);
                pass.set_vertex_buffer(0, self.vbuf.slice(..));
                for r in &v.ranges {
                    if !r.is_empty() {
                        pass.draw(r.clone(), 0..1);
                    }
                }
            }
            enc.copy_texture_to_buffer(
                wgpu::TexelCopyTextureInfo {
                    texture: &t.resolve,
                    mip_level: 0,
                    origin: wgpu::Origin3d::ZERO,
                    aspect: wgpu::TextureAspect::All,
                },
                wgpu::TexelCopyBufferInfo {
                    buffer: &t.readback,
                    layout: wgpu::TexelCopyBufferLayout {
                        offset: 0,
                        bytes_per_row: Some(t.padded_row),
                        rows_per_image: Some(t.height),
                    },
                },
                wgpu::Extent3d {
                    width: t.width,
                    height: t.height,
                    depth_or_array_layers: 1,
                },
            );
        }
        self.queue.submit([enc.finish()]);
        for v in views {
            let t = self.targets[v.slot].as_ref().unwrap();
            t.readback.slice(..).map_async(wgpu::MapMode::Read, |_| {});
        }
        self.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| RenderError::Gpu(format!("poll: {e}")))?;
        let mut out = Vec::with_capacity(views.len());
        for v in views {
            let t = self.targets[v.slot].as_ref().unwrap();
            let row = t.width as usize * 4;
            let mut img = vec![0u8; row * t.height as usize];
            {
                let data = t
                    .readback
                    .slice(..)
                    .get_mapped_range()
                    .map_err(|e| RenderError::Gpu(format!("map readback: {e:?}")))?;
                for y in 0..t.height as usize {
                    let src = y * t.padded_row as usize;
                    img[y * row..(y + 1) * row].copy_from_slice(&data[src..src + row]);
                }
            }
            t.readback.unmap();
            out.push(img);
        }
        Ok(out)
    }
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
