//! Opening the GPU and building the render pipelines (`Gpu::new`).

use super::textures;
use super::*;
use rh_contract::adapter::RenderAdapter;

/// What differs between the render pipelines.
struct PipelineDesc<'a> {
    label: &'static str,
    layout: &'a wgpu::PipelineLayout,
    vertex: &'static str,
    vertex_buffer: bool,
    fragment: Option<&'static str>,
    depth_compare: wgpu::CompareFunction,
    depth_write: bool,
    color_writes: wgpu::ColorWrites,
    depth_bias: wgpu::DepthBiasState,
    samples: u32,
}

const VERTEX_ATTRS: [wgpu::VertexAttribute; 3] =
    wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3, 2 => Float32x4];

/// The adapter the renderer uses: Vulkan unless `WGPU_BACKEND` says otherwise, the
/// high-performance one (a GPU before lavapipe).
fn request_adapter() -> Result<wgpu::Adapter, RenderError> {
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
    pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
        power_preference: wgpu::PowerPreference::HighPerformance,
        force_fallback_adapter: false,
        compatible_surface: None,
        ..Default::default()
    }))
    .map_err(|e| {
        RenderError::NoAdapter(format!(
            "{e} (install a Vulkan driver: Mesa's lavapipe, package mesa-vulkan-drivers)"
        ))
    })
}

/// What `build.json` records of an adapter: wgpu's `AdapterInfo`, and for a CPU
/// rasterizer the CPU's vector features and `LP_NATIVE_VECTOR_WIDTH`.
fn adapter_record(info: &wgpu::AdapterInfo) -> RenderAdapter {
    let cpu = info.device_type == wgpu::DeviceType::Cpu;
    RenderAdapter {
        name: info.name.clone(),
        backend: info.backend.to_str().to_string(),
        device_type: match info.device_type {
            wgpu::DeviceType::Cpu => "cpu",
            wgpu::DeviceType::DiscreteGpu => "discrete_gpu",
            wgpu::DeviceType::IntegratedGpu => "integrated_gpu",
            wgpu::DeviceType::VirtualGpu => "virtual_gpu",
            wgpu::DeviceType::Other => "other",
        }
        .to_string(),
        driver: info.driver.clone(),
        driver_info: info.driver_info.clone(),
        cpu_features: if cpu {
            rh_contract::adapter::cpu_vector_features()
        } else {
            Vec::new()
        },
        lp_native_vector_width: cpu
            .then(|| std::env::var(rh_contract::adapter::LP_NATIVE_VECTOR_WIDTH).ok())
            .flatten(),
    }
}

/// The adapter this machine would render on, without opening a device (`rh-pipeline
/// verify` compares it with the one a build recorded).
pub fn probe_adapter() -> Result<RenderAdapter, RenderError> {
    Ok(adapter_record(&request_adapter()?.get_info()))
}

/// The device and queue of the adapter, its record, and the MSAA sample count to use
/// (`samples` on a hardware GPU, `cpu_samples` on a CPU rasterizer; 4 or 1).
fn open_device(
    samples: u32,
    cpu_samples: u32,
) -> Result<(wgpu::Device, wgpu::Queue, RenderAdapter, u32), RenderError> {
    let adapter = request_adapter()?;
    let info = adapter.get_info();
    let record = adapter_record(&info);
    let adapter_name = info.name;
    let samples = if info.device_type == wgpu::DeviceType::Cpu {
        cpu_samples
    } else {
        samples
    };
    let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
        label: Some("rh-render"),
        required_features: wgpu::Features::empty(),
        required_limits: wgpu::Limits::downlevel_defaults().using_resolution(adapter.limits()),
        // Small memory blocks (wgpu's default reserves 64-256 MB blocks, whose pages its
        // staging buffers touch one after another: on a CPU adapter all of it resident).
        memory_hints: wgpu::MemoryHints::MemoryUsage,
        ..Default::default()
    }))
    .map_err(|e| RenderError::NoAdapter(format!("request device on {adapter_name}: {e}")))?;
    let samples = if samples >= 4 { 4 } else { 1 };
    Ok((device, queue, record, samples))
}

/// The bind group layouts: the shadow pass's (uniforms) and the lit passes' (uniforms,
/// shadow map, comparison sampler).
fn bind_group_layouts(device: &wgpu::Device) -> (wgpu::BindGroupLayout, wgpu::BindGroupLayout) {
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
            textures::layout_entries()[0],
            textures::layout_entries()[1],
        ],
    });
    (shadow_bgl, main_bgl)
}

/// One render pipeline of the shader.
fn make_pipeline(
    device: &wgpu::Device,
    shader: &wgpu::ShaderModule,
    p: PipelineDesc,
) -> wgpu::RenderPipeline {
    let vlayout = [Some(wgpu::VertexBufferLayout {
        array_stride: std::mem::size_of::<Vertex>() as u64,
        step_mode: wgpu::VertexStepMode::Vertex,
        attributes: &VERTEX_ATTRS,
    })];
    let targets = [Some(wgpu::ColorTargetState {
        format: COLOR_FORMAT,
        blend: None,
        write_mask: p.color_writes,
    })];
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(p.label),
        layout: Some(p.layout),
        vertex: wgpu::VertexState {
            module: shader,
            entry_point: Some(p.vertex),
            compilation_options: Default::default(),
            buffers: if p.vertex_buffer { &vlayout } else { &[] },
        },
        primitive: wgpu::PrimitiveState {
            cull_mode: None,
            ..Default::default()
        },
        depth_stencil: Some(wgpu::DepthStencilState {
            format: DEPTH_FORMAT,
            depth_write_enabled: Some(p.depth_write),
            depth_compare: Some(p.depth_compare),
            stencil: Default::default(),
            bias: p.depth_bias,
        }),
        multisample: wgpu::MultisampleState {
            count: p.samples,
            ..Default::default()
        },
        fragment: p.fragment.map(|entry| wgpu::FragmentState {
            module: shader,
            entry_point: Some(entry),
            compilation_options: Default::default(),
            targets: &targets,
        }),
        multiview_mask: None,
        cache: None,
    })
}

/// The pipelines: (main, depth-only, main-over, fill, shadow).
fn pipelines(
    device: &wgpu::Device,
    main_layout: &wgpu::PipelineLayout,
    shadow_layout: &wgpu::PipelineLayout,
    samples: u32,
) -> [wgpu::RenderPipeline; 5] {
    let shader = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("rh-shader"),
        source: wgpu::ShaderSource::Wgsl(include_str!("../shader.wgsl").into()),
    });
    let pipeline = |p: PipelineDesc| make_pipeline(device, &shader, p);
    let main = pipeline(PipelineDesc {
        label: "main",
        layout: main_layout,
        vertex: "vs_main",
        vertex_buffer: true,
        fragment: Some("fs_main"),
        depth_compare: wgpu::CompareFunction::Less,
        depth_write: true,
        color_writes: wgpu::ColorWrites::ALL,
        depth_bias: Default::default(),
        samples,
    });
    // Moving bodies are drawn twice: depth only, then shaded where their depth won,
    // so overlapping and back-facing surfaces (meshes are not closed: a pan is an
    // open disc) are shaded once per pixel instead of in draw order.
    let depth_only = pipeline(PipelineDesc {
        label: "depth-only",
        layout: main_layout,
        vertex: "vs_main",
        vertex_buffer: true,
        fragment: Some("fs_fill"),
        depth_compare: wgpu::CompareFunction::Less,
        depth_write: true,
        color_writes: wgpu::ColorWrites::empty(),
        depth_bias: Default::default(),
        samples,
    });
    let main_over = pipeline(PipelineDesc {
        label: "main-over",
        layout: main_layout,
        vertex: "vs_main",
        vertex_buffer: true,
        fragment: Some("fs_main"),
        depth_compare: wgpu::CompareFunction::LessEqual,
        depth_write: false,
        color_writes: wgpu::ColorWrites::ALL,
        depth_bias: Default::default(),
        samples,
    });
    // Re-clears a scissored region (depth 1, background colour) before it is redrawn.
    let fill = pipeline(PipelineDesc {
        label: "fill",
        layout: main_layout,
        vertex: "vs_fill",
        vertex_buffer: false,
        fragment: Some("fs_fill"),
        depth_compare: wgpu::CompareFunction::Always,
        depth_write: true,
        color_writes: wgpu::ColorWrites::ALL,
        depth_bias: Default::default(),
        samples,
    });
    let shadow = pipeline(PipelineDesc {
        label: "shadow",
        layout: shadow_layout,
        vertex: "vs_shadow",
        vertex_buffer: true,
        fragment: None,
        depth_compare: wgpu::CompareFunction::Less,
        depth_write: true,
        color_writes: wgpu::ColorWrites::ALL,
        depth_bias: wgpu::DepthBiasState {
            constant: 2,
            slope_scale: 1.0,
            clamp: 0.0,
        },
        samples: 1,
    });
    [main, depth_only, main_over, fill, shadow]
}

/// The device and what is built once for it (pipelines, bind group layouts, the shadow
/// sampler, the id pipelines), shared by every [`Gpu`] of the threads that use it (a
/// Python process's environments, say). Which threads share one ([`DeviceSharing`]):
/// on a CPU rasterizer each worker thread has its own, because lavapipe runs one
/// queue's submissions one after another, so workers sharing a device waited for each
/// other's frames (two workers used ≈ 78% of two cores, with their own devices ≈ 94%);
/// on a GPU all threads share one, because each device is a context the GPU switches
/// between (docs/rendering.md, "On a GPU machine").
#[derive(Clone)]
struct Shared {
    /// Every thread may use it at once (`DeviceSharing`), not only its holder.
    all_threads: bool,
    device: wgpu::Device,
    queue: wgpu::Queue,
    adapter: RenderAdapter,
    samples: u32,
    /// (main, depth-only, main-over, fill, shadow): see `pipelines`.
    pipelines: [wgpu::RenderPipeline; 5],
    main_bgl: wgpu::BindGroupLayout,
    shadow_bgl: wgpu::BindGroupLayout,
    shadow_sampler: wgpu::Sampler,
    id_pipelines: std::sync::Arc<std::sync::OnceLock<ids::IdPipelines>>,
}

/// A device's settings: (samples, cpu_samples).
type SharedKey = (u32, u32);

/// Every device the process opened, with its settings and whether a live thread holds
/// it. Devices are never closed: a worker thread of a dropped thread pool ends while the
/// process may already be exiting, and lavapipe tearing a device down then crashed the
/// process now and then (a jump into freed shader code). A thread's claim is released
/// when the thread ends, and the next thread that needs a device takes it over, so a
/// process holds at most as many devices as it ever ran rendering threads at once.
static DEVICES: std::sync::Mutex<Vec<(SharedKey, Shared, bool)>> =
    std::sync::Mutex::new(Vec::new());

/// A thread's hold on one entry of `DEVICES` (its index), given back when the thread
/// ends.
struct Claim(usize);

impl Drop for Claim {
    fn drop(&mut self) {
        let mut all = DEVICES.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(entry) = all.get_mut(self.0) {
            entry.2 = false;
        }
    }
}

thread_local! {
    static CLAIMS: std::cell::RefCell<Vec<Claim>> = const { std::cell::RefCell::new(Vec::new()) };
}

/// Which threads share a device: `RH_RENDER_DEVICES` = `per-worker` (each thread its
/// own), `shared` (one for all), or `auto` (unset: per worker on a CPU rasterizer,
/// shared on a GPU). Only speed depends on it, never a pixel.
#[derive(Clone, Copy, PartialEq, Debug)]
enum DeviceSharing {
    Auto,
    PerWorker,
    Shared,
}

impl DeviceSharing {
    const VAR: &str = "RH_RENDER_DEVICES";

    fn from_env() -> Result<DeviceSharing, RenderError> {
        Self::parse(std::env::var(Self::VAR).ok().as_deref())
    }

    fn parse(value: Option<&str>) -> Result<DeviceSharing, RenderError> {
        match value {
            None | Some("") | Some("auto") => Ok(DeviceSharing::Auto),
            Some("per-worker") => Ok(DeviceSharing::PerWorker),
            Some("shared") => Ok(DeviceSharing::Shared),
            Some(other) => Err(RenderError::Setting(format!(
                "{}={other}: expected auto, per-worker or shared",
                Self::VAR
            ))),
        }
    }

    /// Whether every thread may use a device of this adapter at once.
    fn all_threads(self, adapter: &RenderAdapter) -> bool {
        match self {
            DeviceSharing::Auto => adapter.device_type != "cpu",
            DeviceSharing::PerWorker => false,
            DeviceSharing::Shared => true,
        }
    }
}

impl Shared {
    /// The thread's device for these settings: the one it holds, else one every thread
    /// may use, else one no live thread holds, else a new one.
    fn get(samples: u32, cpu_samples: u32) -> Result<Shared, RenderError> {
        let key = (samples, cpu_samples);
        CLAIMS.with_borrow_mut(|claims| {
            let mut all = DEVICES.lock().unwrap_or_else(|e| e.into_inner());
            if let Some(Claim(i)) = claims.iter().find(|c| all[c.0].0 == key) {
                return Ok(all[*i].1.clone());
            }
            let free =
                |(k, s, held): &(SharedKey, Shared, bool)| *k == key && (s.all_threads || !held);
            let index = match all.iter().position(free) {
                Some(i) => i,
                None => {
                    all.push((key, Shared::open(samples, cpu_samples)?, false));
                    all.len() - 1
                }
            };
            all[index].2 = true;
            claims.push(Claim(index));
            Ok(all[index].1.clone())
        })
    }

    fn open(samples: u32, cpu_samples: u32) -> Result<Shared, RenderError> {
        let sharing = DeviceSharing::from_env()?;
        let (device, queue, adapter, samples) = open_device(samples, cpu_samples)?;
        let (shadow_bgl, main_bgl) = bind_group_layouts(&device);
        let layout = |bgl: &wgpu::BindGroupLayout| {
            device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: None,
                bind_group_layouts: &[Some(bgl)],
                immediate_size: 0,
            })
        };
        let main_layout = layout(&main_bgl);
        let shadow_layout = layout(&shadow_bgl);
        let pipelines = pipelines(&device, &main_layout, &shadow_layout, samples);
        let shadow_sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("shadow-sampler"),
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            compare: Some(wgpu::CompareFunction::LessEqual),
            ..Default::default()
        });
        Ok(Shared {
            all_threads: sharing.all_threads(&adapter),
            device,
            queue,
            adapter,
            samples,
            pipelines,
            main_bgl,
            shadow_bgl,
            shadow_sampler,
            id_pipelines: Default::default(),
        })
    }
}

impl Gpu {
    /// A renderer on the thread's device (opened with its pipelines on first
    /// use: see `Shared`) with `samples` MSAA samples on a hardware GPU, `cpu_samples` on
    /// a CPU rasterizer (4 or 1 each); `fxaa`: a post-process anti-aliasing pass on lit
    /// frames wherever MSAA is off (`crate::fxaa`). Its shadow maps, targets and vertex
    /// buffer are its own.
    pub fn new(samples: u32, cpu_samples: u32, fxaa: bool) -> Result<Gpu, RenderError> {
        let shared = Shared::get(samples, cpu_samples)?;
        let device = shared.device;
        let [main, depth_only, main_over, fill, shadow] = shared.pipelines;
        let shadow_map = |label| {
            device.create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size: extent(SHADOW_SIZE, SHADOW_SIZE),
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: DEPTH_FORMAT,
                usage: wgpu::TextureUsages::RENDER_ATTACHMENT
                    | wgpu::TextureUsages::TEXTURE_BINDING
                    | wgpu::TextureUsages::COPY_SRC
                    | wgpu::TextureUsages::COPY_DST,
                view_formats: &[],
            })
        };
        let shadow_tex = shadow_map("shadow-map");
        let static_shadow = shadow_map("static-shadow-map");
        let shadow_view = shadow_tex.create_view(&Default::default());
        let shadow_uniform = uniform_buffer(&device);
        let shadow_bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: None,
            layout: &shared.shadow_bgl,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: shadow_uniform.as_entire_binding(),
            }],
        });
        let vcap = 1 << 20;
        let vbuf = vertex_buffer(&device, vcap);
        let model_textures = textures::ModelTextures::new(&device);
        Ok(Gpu {
            device,
            queue: shared.queue,
            adapter_name: shared.adapter.name.clone(),
            adapter: shared.adapter,
            samples: shared.samples,
            main,
            depth_only,
            main_over,
            fill,
            shadow,
            main_bgl: shared.main_bgl,
            shadow_tex,
            shadow_view,
            static_shadow,
            shadow_sampler: shared.shadow_sampler,
            model_textures,
            shadow_uniform,
            shadow_bind,
            fxaa: fxaa && shared.samples == 1,
            id_pipelines: shared.id_pipelines,
            vbuf,
            vcap,
            static_len: 0,
            targets: Vec::new(),
            frames: Default::default(),
            last_submit: Default::default(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::{DeviceSharing, RenderAdapter};

    fn adapter(device_type: &str) -> RenderAdapter {
        RenderAdapter {
            name: "test".into(),
            backend: "vulkan".into(),
            device_type: device_type.into(),
            driver: String::new(),
            driver_info: String::new(),
            cpu_features: Vec::new(),
            lp_native_vector_width: None,
        }
    }

    #[test]
    fn workers_share_a_gpu_device_and_keep_their_own_on_a_cpu_rasterizer() {
        let auto = DeviceSharing::parse(None).unwrap();
        assert_eq!(auto, DeviceSharing::parse(Some("auto")).unwrap());
        assert!(auto.all_threads(&adapter("discrete_gpu")));
        assert!(!auto.all_threads(&adapter("cpu")));
        let shared = DeviceSharing::parse(Some("shared")).unwrap();
        assert!(shared.all_threads(&adapter("cpu")));
        let own = DeviceSharing::parse(Some("per-worker")).unwrap();
        assert!(!own.all_threads(&adapter("discrete_gpu")));
        let err = DeviceSharing::parse(Some("both")).unwrap_err().to_string();
        assert!(err.contains("RH_RENDER_DEVICES=both"), "{err}");
    }
}
