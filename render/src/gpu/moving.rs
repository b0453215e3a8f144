//! Views from a moving camera over a cached shadow map of the fixed casters (the ego
//! camera of a closed-loop episode, `crate::ego`): the camera moves every frame, so no
//! view image can be cached as [`Gpu::cache_static`] does, but the light does not, so the
//! fixed casters' shadow map is drawn once per scene and each frame only adds the moving
//! casters to a copy of it. The pixels are those of [`Gpu::draw`] with every caster (a
//! shadow map texel keeps the nearest depth, whatever the order the casters are drawn in).

use super::{copy_whole, Gpu, Redraw, ViewJob};
use crate::RenderError;
use std::ops::Range;

impl Gpu {
    /// Draws the shadow map of the fixed `casters` and keeps it for
    /// [`Gpu::draw_over_static_shadow`] (uploaded static geometry: `set_static` first).
    pub fn cache_static_shadow(
        &mut self,
        light_vp: [[f32; 4]; 4],
        casters: &[Range<u32>],
    ) -> Result<(), RenderError> {
        self.write_shadow_uniforms(light_vp);
        let mut enc = self.encoder();
        self.shadow_pass(&mut enc, casters, true);
        copy_whole(&mut enc, &self.shadow_tex, &self.static_shadow);
        self.submit(enc);
        self.wait()?;
        Ok(())
    }

    /// [`Gpu::draw`] over the cached fixed casters' shadow map: adds the moving `casters`
    /// to it, then draws every view whole; returns tightly packed RGBA (sRGB) images.
    pub fn draw_over_static_shadow(
        &mut self,
        light_vp: [[f32; 4]; 4],
        casters: &[Range<u32>],
        views: &[ViewJob],
    ) -> Result<Vec<Vec<u8>>, RenderError> {
        for v in views {
            self.target(v.slot, v.width, v.height);
            self.write_uniforms(v.slot, &v.uniforms, Redraw::Whole(&[]));
        }
        self.write_shadow_uniforms(light_vp);
        let mut enc = self.encoder();
        copy_whole(&mut enc, &self.static_shadow, &self.shadow_tex);
        self.shadow_pass(&mut enc, casters, false);
        for v in views {
            let t = self.targets[v.slot].as_ref().unwrap();
            self.main_pass(&mut enc, t, Redraw::Whole(&v.ranges), &v.dynamic);
            Self::copy_to_readback(&mut enc, t);
        }
        self.submit(enc);
        self.read_back(&self.whole_finishes(views))
    }
}
