//! Partial copies of the cached static images (`Gpu::draw_overlay`).

use super::{copy_whole, extent, whole};

/// Copies the rectangles `dirty` (x, y, width, height) of `from` into `to`, or all of
/// it (`None`).
pub(super) fn restore(
    enc: &mut wgpu::CommandEncoder,
    from: &wgpu::Texture,
    to: &wgpu::Texture,
    dirty: Option<&[[u32; 4]]>,
) {
    let Some(rects) = dirty else {
        return copy_whole(enc, from, to);
    };
    for &[x, y, w, h] in rects.iter().filter(|r| r[2] > 0 && r[3] > 0) {
        let at = |texture| wgpu::TexelCopyTextureInfo {
            origin: wgpu::Origin3d { x, y, z: 0 },
            ..whole(texture)
        };
        enc.copy_texture_to_texture(at(from), at(to), extent(w, h));
    }
}
