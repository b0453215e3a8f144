//! Reading frames back from the GPU: the copies into each target's mapped buffer, and
//! the images taken out of it, finished as the caller asks (as drawn, or anti-aliased by
//! `crate::fxaa` straight from the mapped memory, all over or over the static image).

use super::{lit, whole, Gpu, Target, ViewJob};
use crate::RenderError;

impl Gpu {
    /// Submits this renderer's commands; [`Gpu::wait`] then waits for them.
    pub(super) fn submit(&self, enc: wgpu::CommandEncoder) {
        let index = self.queue.submit([enc.finish()]);
        self.last_submit.set(Some(index));
    }

    /// Waits until this renderer's last submission (and so all its earlier ones) is
    /// done and its read-backs mapped: on a device shared by the workers (a GPU), not
    /// for the other workers' frames too.
    pub(super) fn wait(&self) -> Result<(), RenderError> {
        let index = self.last_submit.take();
        self.last_submit.set(index.clone());
        self.device
            .poll(wgpu::PollType::Wait {
                submission_index: index,
                timeout: None,
            })
            .map(|_| ())
            .map_err(|e| RenderError::Gpu(format!("poll: {e}")))
    }

    /// How whole frames of `views` are read back: the lit ones anti-aliased (`fxaa`).
    pub(super) fn whole_finishes(&self, views: &[ViewJob]) -> Vec<(usize, Finish<'static>)> {
        let finish = |v: &ViewJob| match self.fxaa && lit(&v.uniforms) {
            true => Finish::AntiAliased,
            false => Finish::AsDrawn,
        };
        views.iter().map(|v| (v.slot, finish(v))).collect()
    }

    /// A view's cached static depth (one sample per pixel: `None` with MSAA), row-major
    /// (1 = no surface); read back once per scene (`tiles::SurfaceTiles`).
    pub fn cached_depth(&self, slot: usize) -> Result<Option<Vec<f32>>, RenderError> {
        let t = self.targets[slot].as_ref().unwrap();
        if self.samples > 1 {
            return Ok(None);
        }
        let mut enc = self.encoder();
        let source = wgpu::TexelCopyTextureInfo {
            aspect: wgpu::TextureAspect::DepthOnly,
            ..whole(&t.cache_depth)
        };
        enc.copy_texture_to_buffer(source, readback_buffer(t), t.cache_depth.size());
        self.submit(enc);
        let bytes = self.read_back(&[(slot, Finish::AsDrawn)])?.remove(0);
        let depth = bytemuck::pod_collect_to_vec::<u8, f32>(&bytes);
        self.frames.give(bytes);
        Ok(Some(depth))
    }

    /// Queues the copy of the frame as drawn (resolved) into the read-back buffer.
    pub(super) fn copy_to_readback(enc: &mut wgpu::CommandEncoder, t: &Target) {
        enc.copy_texture_to_buffer(whole(&t.resolve), readback_buffer(t), t.resolve.size());
    }

    /// Queues the copies into the read-back buffer of what anti-aliasing `rects` reads
    /// (each grown by `fxaa::REACH`): the rest of the buffer is never read
    /// (`Finish::Over`), so it may hold an older frame.
    pub(super) fn copy_rects_to_readback(
        enc: &mut wgpu::CommandEncoder,
        t: &Target,
        rects: &[[u32; 4]],
    ) {
        let reach = crate::fxaa::REACH;
        for &[x, y, w, h] in rects {
            let (x0, y0) = (x.saturating_sub(reach), y.saturating_sub(reach));
            let x1 = (x + w + reach).min(t.width);
            let y1 = (y + h + reach).min(t.height);
            if x1 <= x0 || y1 <= y0 {
                continue;
            }
            let source = wgpu::TexelCopyTextureInfo {
                origin: wgpu::Origin3d { x: x0, y: y0, z: 0 },
                ..whole(&t.resolve)
            };
            let mut dest = readback_buffer(t);
            dest.layout.offset = y0 as u64 * t.padded_row as u64 + x0 as u64 * 4;
            dest.layout.rows_per_image = Some(y1 - y0);
            let size = wgpu::Extent3d {
                width: x1 - x0,
                height: y1 - y0,
                depth_or_array_layers: 1,
            };
            enc.copy_texture_to_buffer(source, dest, size);
        }
    }

    /// Reads back the views just drawn as the static cache (`cache_static`) and keeps
    /// each one's image as drawn and anti-aliased, which lit overlay frames start from.
    pub(super) fn keep_static_images(&mut self, views: &[ViewJob]) -> Result<(), RenderError> {
        let drawn: Vec<(usize, Finish)> = views.iter().map(|v| (v.slot, Finish::AsDrawn)).collect();
        let images = self.read_back(&drawn)?;
        for (v, drawn) in views.iter().zip(images) {
            let mut filtered = drawn.clone();
            if lit(&v.uniforms) {
                let frame = crate::fxaa::Frame {
                    rgba: &drawn,
                    width: v.width,
                    height: v.height,
                    stride: 4 * v.width as usize,
                };
                crate::fxaa::apply(frame, &mut filtered, [0, 0, v.width, v.height]);
            }
            let cache = StaticImage { drawn, filtered };
            self.targets[v.slot].as_mut().unwrap().aa_cache = Some(cache);
        }
        Ok(())
    }

    /// Waits for the submitted work and returns the slots' images, tightly packed, each
    /// finished as asked (anti-aliased straight from the mapped buffer).
    pub(super) fn read_back(&self, jobs: &[(usize, Finish)]) -> Result<Vec<Vec<u8>>, RenderError> {
        for &(slot, _) in jobs {
            let t = self.targets[slot].as_ref().unwrap();
            t.readback.slice(..).map_async(wgpu::MapMode::Read, |_| {});
        }
        self.wait()?;
        let mut out = Vec::new();
        for (slot, finish) in jobs {
            let t = self.targets[*slot].as_ref().unwrap();
            let row = t.width as usize * 4;
            let mut img = self.frames.take(row * t.height as usize);
            {
                let data = t
                    .readback
                    .slice(..)
                    .get_mapped_range()
                    .map_err(|e| RenderError::Gpu(format!("map readback: {e:?}")))?;
                let src = crate::fxaa::Frame {
                    rgba: &data,
                    width: t.width,
                    height: t.height,
                    stride: t.padded_row as usize,
                };
                match finish {
                    Finish::AsDrawn => {
                        for (y, out) in img.chunks_exact_mut(row).enumerate() {
                            out.copy_from_slice(&data[y * src.stride..][..row]);
                        }
                    }
                    Finish::AntiAliased => {
                        crate::fxaa::apply(src, &mut img, [0, 0, t.width, t.height])
                    }
                    Finish::Over(filtered, drawn, rects) => {
                        img.copy_from_slice(filtered);
                        crate::fxaa::apply_changed(src, drawn, &mut img, rects);
                    }
                }
            }
            t.readback.unmap();
            out.push(img);
        }
        Ok(out)
    }
}

/// Where a copy of a whole target image lands: its read-back buffer, rows
/// `padded_row` bytes apart.
fn readback_buffer(t: &Target) -> wgpu::TexelCopyBufferInfo<'_> {
    wgpu::TexelCopyBufferInfo {
        buffer: &t.readback,
        layout: wgpu::TexelCopyBufferLayout {
            offset: 0,
            bytes_per_row: Some(t.padded_row),
            rows_per_image: Some(t.height),
        },
    }
}

/// A view's cached static image read back (tightly packed RGBA8): as drawn, and
/// anti-aliased (`crate::fxaa`; the same without post-process anti-aliasing or unlit).
pub(super) struct StaticImage {
    pub(super) drawn: Vec<u8>,
    pub(super) filtered: Vec<u8>,
}

/// How a read-back frame is finished (`Gpu::read_back`).
pub(super) enum Finish<'a> {
    /// As drawn.
    AsDrawn,
    /// Anti-aliased (`crate::fxaa`) all over.
    AntiAliased,
    /// The anti-aliased static image (`.0`), the filter redone inside the rectangles
    /// `.2` (every pixel that can differ from it, with `POST_REACH` around) where the
    /// frame differs from the static image as drawn (`.1`).
    Over(&'a [u8], &'a [u8], &'a [[u32; 4]]),
}
