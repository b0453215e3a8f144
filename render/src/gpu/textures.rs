//! The model textures of one renderer: a 2D texture array (one layer per texture image
//! the process loaded, `crate::models::texture_layer`) and its sampler, bound to the lit
//! passes at bindings 3 and 4. New layers are uploaded before the next draw
//! ([`ModelTextures::sync`]); a layer's content is the same image in any process.

use crate::models;

pub(super) struct ModelTextures {
    tex: wgpu::Texture,
    pub view: wgpu::TextureView,
    pub sampler: wgpu::Sampler,
    size: u32,
    layers: u32,
    uploaded: usize,
}

/// sRGB storage: the shader samples linear colour, like the vertex colours.
const FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8UnormSrgb;

impl ModelTextures {
    pub fn new(device: &wgpu::Device) -> ModelTextures {
        let config = models::config();
        let size = config.texture_size.max(1);
        // At least two layers: a one-layer array may be bound as a plain 2D texture.
        let layers = config.texture_layers.max(2);
        let tex = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("model-textures"),
            size: wgpu::Extent3d {
                width: size,
                height: size,
                depth_or_array_layers: layers,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: FORMAT,
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        });
        let view = tex.create_view(&wgpu::TextureViewDescriptor {
            dimension: Some(wgpu::TextureViewDimension::D2Array),
            ..Default::default()
        });
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("model-sampler"),
            address_mode_u: wgpu::AddressMode::Repeat,
            address_mode_v: wgpu::AddressMode::Repeat,
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            ..Default::default()
        });
        ModelTextures {
            tex,
            view,
            sampler,
            size,
            layers,
            uploaded: 0,
        }
    }

    /// Uploads the layers loaded since the last call (those that fit: the build's
    /// catalog check refuses more textures than layers).
    pub fn sync(&mut self, queue: &wgpu::Queue) {
        if models::texture_count() == self.uploaded {
            return;
        }
        for image in models::textures_from(self.uploaded) {
            let layer = self.uploaded as u32;
            self.uploaded += 1;
            if layer >= self.layers || image.size != self.size {
                continue;
            }
            queue.write_texture(
                wgpu::TexelCopyTextureInfo {
                    texture: &self.tex,
                    mip_level: 0,
                    origin: wgpu::Origin3d {
                        x: 0,
                        y: 0,
                        z: layer,
                    },
                    aspect: wgpu::TextureAspect::All,
                },
                &image.rgba,
                wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(4 * self.size),
                    rows_per_image: Some(self.size),
                },
                wgpu::Extent3d {
                    width: self.size,
                    height: self.size,
                    depth_or_array_layers: 1,
                },
            );
        }
    }
}

/// The lit passes' bind group layout entries of the model textures.
pub(super) fn layout_entries() -> [wgpu::BindGroupLayoutEntry; 2] {
    [
        wgpu::BindGroupLayoutEntry {
            binding: 3,
            visibility: wgpu::ShaderStages::FRAGMENT,
            ty: wgpu::BindingType::Texture {
                sample_type: wgpu::TextureSampleType::Float { filterable: true },
                view_dimension: wgpu::TextureViewDimension::D2Array,
                multisampled: false,
            },
            count: None,
        },
        wgpu::BindGroupLayoutEntry {
            binding: 4,
            visibility: wgpu::ShaderStages::FRAGMENT,
            ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
            count: None,
        },
    ]
}
