//! Post-process anti-aliasing on the CPU: an FXAA-style filter (after Lottes' FXAA, the
//! compact variant) over read-back frames, in display (sRGB-encoded) values, used where
//! MSAA is off (a CPU rasterizer). Pixels whose four neighbours differ little in luma
//! are kept; on an edge, the blur direction is taken from the luma gradient (the four
//! diagonal neighbours) and the frame is sampled bilinearly along it (four taps).
//!
//! It runs on the worker thread, not on the rasterizer: lavapipe pays every texel load
//! and both sides of every branch for every pixel (the edge blend for all of them), so
//! the same filter cost several times more there. Like the lit pass, it is applied to
//! each view's static image once per scene and per frame only around what changed
//! (`Gpu::draw_overlay`); the result is the same as filtering the whole frame.

/// How far (pixels) an output pixel reads from: its neighbours and diagonals (1), the
/// taps along the edge (at most `SPAN_MAX / 2` = 4 away) with their bilinear footprint
/// (1); with slack. Outside a rectangle grown by this much around every changed input
/// pixel the output is unchanged.
pub(crate) const REACH: u32 = 8;

/// Edge detection: local contrast below max(EDGE_MIN, EDGE_REL · brightest) is left alone.
const EDGE_MIN: f32 = 0.0312;
const EDGE_REL: f32 = 0.125;
const REDUCE_MUL: f32 = 0.125;
const REDUCE_MIN: f32 = 0.0078125;
const SPAN_MAX: f32 = 8.0;

/// An RGBA8 frame, row-major, tightly packed.
#[derive(Clone, Copy)]
pub(crate) struct Frame<'a> {
    pub rgba: &'a [u8],
    pub width: u32,
    pub height: u32,
}

impl Frame<'_> {
    /// The texel at (x, y) clamped to the frame, as three values in [0, 1].
    fn texel(&self, x: i64, y: i64) -> [f32; 3] {
        let x = x.clamp(0, self.width as i64 - 1) as usize;
        let y = y.clamp(0, self.height as i64 - 1) as usize;
        let i = (y * self.width as usize + x) * 4;
        let p = &self.rgba[i..i + 3];
        [p[0], p[1], p[2]].map(|v| v as f32 / 255.0)
    }

    /// A bilinear sample at (x, y) in pixel units (texel centres at half-integers),
    /// clamped at the edges.
    fn tap(&self, x: f32, y: f32) -> [f32; 3] {
        let (tx, ty) = (x - 0.5, y - 0.5);
        let (x0, y0) = (tx.floor(), ty.floor());
        let (fx, fy) = (tx - x0, ty - y0);
        let (x0, y0) = (x0 as i64, y0 as i64);
        let lerp = |a: [f32; 3], b: [f32; 3], t: f32| [0, 1, 2].map(|i| a[i] + (b[i] - a[i]) * t);
        let top = lerp(self.texel(x0, y0), self.texel(x0 + 1, y0), fx);
        let bottom = lerp(self.texel(x0, y0 + 1), self.texel(x0 + 1, y0 + 1), fx);
        lerp(top, bottom, fy)
    }
}

fn luma(c: [f32; 3]) -> f32 {
    c[0] * 0.299 + c[1] * 0.587 + c[2] * 0.114
}

/// Filters `src` into `dst` (same size, RGBA8) inside `rect` (x, y, width, height;
/// clipped to the frame); the rest of `dst` is left as it is. Alpha is written opaque.
pub(crate) fn apply(src: Frame, dst: &mut [u8], rect: [u32; 4]) {
    let (w, h) = (src.width, src.height);
    let (x0, y0) = (rect[0].min(w), rect[1].min(h));
    let (x1, y1) = ((rect[0] + rect[2]).min(w), (rect[1] + rect[3]).min(h));
    if x0 >= x1 || y0 >= y1 {
        return;
    }
    // Lumas of the rectangle grown by one pixel (clamped): every neighbour a pixel's
    // edge test reads.
    let (lx0, ly0) = (x0.saturating_sub(1), y0.saturating_sub(1));
    let (lx1, ly1) = ((x1 + 1).min(w), (y1 + 1).min(h));
    let lw = (lx1 - lx0) as usize;
    let mut lumas = Vec::with_capacity(lw * (ly1 - ly0) as usize);
    for y in ly0..ly1 {
        let row = &src.rgba[((y * w + lx0) * 4) as usize..((y * w + lx1) * 4) as usize];
        lumas.extend(
            row.chunks_exact(4)
                .map(|p| luma([p[0], p[1], p[2]].map(|v| v as f32 / 255.0))),
        );
    }
    let luma_at = |x: i64, y: i64| {
        let x = x.clamp(0, w as i64 - 1) as u32 - lx0;
        let y = y.clamp(0, h as i64 - 1) as u32 - ly0;
        lumas[y as usize * lw + x as usize]
    };
    for y in y0..y1 {
        for x in x0..x1 {
            let i = ((y * w + x) * 4) as usize;
            let (xi, yi) = (x as i64, y as i64);
            let lm = luma_at(xi, yi);
            let ln = luma_at(xi, yi - 1);
            let ls = luma_at(xi, yi + 1);
            let lw_ = luma_at(xi - 1, yi);
            let le = luma_at(xi + 1, yi);
            let lmin = lm.min(ln.min(ls).min(lw_.min(le)));
            let lmax = lm.max(ln.max(ls).max(lw_.max(le)));
            let out = &mut dst[i..i + 4];
            if lmax - lmin < EDGE_MIN.max(lmax * EDGE_REL) {
                out[..3].copy_from_slice(&src.rgba[i..i + 3]);
            } else {
                let c = blend(
                    src,
                    x,
                    y,
                    lmin,
                    lmax,
                    [
                        luma_at(xi - 1, yi - 1),
                        luma_at(xi + 1, yi - 1),
                        luma_at(xi - 1, yi + 1),
                        luma_at(xi + 1, yi + 1),
                    ],
                );
                for k in 0..3 {
                    out[k] = (c[k].clamp(0.0, 1.0) * 255.0 + 0.5) as u8;
                }
            }
            out[3] = 255;
        }
    }
}

/// The blend of an edge pixel at (x, y): `lmin`, `lmax` of its cross, the lumas of its
/// diagonal neighbours (nw, ne, sw, se).
fn blend(src: Frame, x: u32, y: u32, lmin: f32, lmax: f32, diag: [f32; 4]) -> [f32; 3] {
    let [lnw, lne, lsw, lse] = diag;
    let dir = [-((lnw + lne) - (lsw + lse)), (lnw + lsw) - (lne + lse)];
    let reduce = ((lnw + lne + lsw + lse) * 0.25 * REDUCE_MUL).max(REDUCE_MIN);
    let scale = 1.0 / (dir[0].abs().min(dir[1].abs()) + reduce);
    let dir = dir.map(|d| (d * scale).clamp(-SPAN_MAX, SPAN_MAX));
    let (cx, cy) = (x as f32 + 0.5, y as f32 + 0.5);
    let tap = |t: f32| src.tap(cx + dir[0] * t, cy + dir[1] * t);
    let (t1, t2) = (tap(1.0 / 3.0 - 0.5), tap(2.0 / 3.0 - 0.5));
    let a = [0, 1, 2].map(|k| 0.5 * (t1[k] + t2[k]));
    let (t3, t4) = (tap(-0.5), tap(0.5));
    let b = [0, 1, 2].map(|k| a[k] * 0.5 + 0.25 * (t3[k] + t4[k]));
    let lb = luma(b);
    let lo = lmin.min(lnw.min(lne).min(lsw.min(lse)));
    let up = lmax.max(lnw.max(lne).max(lsw.max(lse)));
    if lb < lo || lb > up {
        a
    } else {
        b
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame(w: u32, h: u32, f: impl Fn(u32, u32) -> u8) -> Vec<u8> {
        let mut v = Vec::new();
        for y in 0..h {
            for x in 0..w {
                let g = f(x, y);
                v.extend_from_slice(&[g, g, g, 255]);
            }
        }
        v
    }

    #[test]
    fn flat_areas_are_copied_and_a_staircase_edge_is_smoothed() {
        // A hard diagonal edge: black below the line y = x / 2, white above.
        let (w, h) = (32, 32);
        let src = frame(w, h, |x, y| if 2 * y < x { 255 } else { 0 });
        let f = Frame {
            rgba: &src,
            width: w,
            height: h,
        };
        let mut dst = vec![0u8; src.len()];
        apply(f, &mut dst, [0, 0, w, h]);
        // Far from the edge, on either side: unchanged.
        for (x, y) in [(31, 2), (1, 30)] {
            let i = ((y * w + x) * 4) as usize;
            assert_eq!(&dst[i..i + 4], &src[i..i + 4], "({x}, {y})");
        }
        // Along the edge some pixels take intermediate values (smoothed steps).
        let blended = dst
            .chunks_exact(4)
            .filter(|p| p[0] > 20 && p[0] < 235)
            .count();
        assert!(blended >= 10, "{blended} blended pixels");
        assert!(dst.chunks_exact(4).all(|p| p[3] == 255));
    }

    #[test]
    fn a_rectangle_gives_the_whole_frame_filter_inside_it_and_nothing_outside() {
        let (w, h) = (40, 24);
        let src = frame(w, h, |x, y| ((x * 37 + y * 91) % 7 * 40) as u8);
        let f = Frame {
            rgba: &src,
            width: w,
            height: h,
        };
        let mut whole = vec![0u8; src.len()];
        apply(f, &mut whole, [0, 0, w, h]);
        let mut part = vec![7u8; src.len()];
        let r = [5, 3, 17, 11];
        apply(f, &mut part, r);
        for y in 0..h {
            for x in 0..w {
                let i = ((y * w + x) * 4) as usize;
                let inside = x >= r[0] && x < r[0] + r[2] && y >= r[1] && y < r[1] + r[3];
                if inside {
                    assert_eq!(&part[i..i + 4], &whole[i..i + 4], "({x}, {y})");
                } else {
                    assert_eq!(&part[i..i + 4], &[7, 7, 7, 7], "({x}, {y})");
                }
            }
        }
    }
}
