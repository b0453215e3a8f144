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

use super::cells::runs_to_rects;

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

/// An RGBA8 frame, row-major, rows `stride` bytes apart (at least `4 * width`).
#[derive(Clone, Copy)]
pub(crate) struct Frame<'a> {
    pub rgba: &'a [u8],
    pub width: u32,
    pub height: u32,
    pub stride: usize,
}

impl Frame<'_> {
    /// The texel at (x, y) clamped to the frame, as three values in [0, 1].
    fn texel(&self, x: i64, y: i64) -> [f32; 3] {
        let x = x.clamp(0, self.width as i64 - 1) as usize;
        let y = y.clamp(0, self.height as i64 - 1) as usize;
        unit(&self.rgba[y * self.stride + x * 4..])
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

/// An RGBA8 pixel's colour as three values in [0, 1] (its first three bytes).
fn unit(p: &[u8]) -> [f32; 3] {
    [p[0], p[1], p[2]].map(|v| v as f32 / 255.0)
}

fn luma(c: [f32; 3]) -> f32 {
    c[0] * 0.299 + c[1] * 0.587 + c[2] * 0.114
}

/// The luma of an RGBA8 pixel (the same value as `luma` of its texel).
fn luma8(p: &[u8]) -> f32 {
    luma(unit(p))
}

/// `f32::min` and `max` for values that are never NaN (these vectorise).
fn lesser(a: f32, b: f32) -> f32 {
    if a < b {
        a
    } else {
        b
    }
}

fn greater(a: f32, b: f32) -> f32 {
    if a > b {
        a
    } else {
        b
    }
}

/// Filters `src` into `dst` (the same width and height, RGBA8, tightly packed) inside
/// `rect` (x, y, width, height; clipped to the frame); the rest of `dst` is left as it
/// is. Pixels off an edge are copied as they are; blended ones are written opaque.
pub(crate) fn apply(src: Frame, dst: &mut [u8], rect: [u32; 4]) {
    let (w, h) = (src.width as usize, src.height as usize);
    let Some([x0, y0, x1, y1]) = clip(rect, w, h) else {
        return;
    };
    let at = |x: usize, y: usize| y * src.stride + x * 4;
    let n = (x1 - x0) * 4;
    for y in y0..y1 {
        dst[(y * w + x0) * 4..][..n].copy_from_slice(&src.rgba[at(x0, y)..][..n]);
    }
    // Lumas of the rectangle with a one-pixel border (the frame's edge pixels repeated
    // past it): every neighbour a pixel's edge test reads.
    let pw = x1 - x0 + 2;
    let mut lumas = vec![0f32; pw * (y1 - y0 + 2)];
    for (ly, row) in lumas.chunks_exact_mut(pw).enumerate() {
        let y = (y0 + ly).saturating_sub(1).min(h - 1);
        row[0] = luma8(&src.rgba[at(x0.saturating_sub(1), y)..]);
        row[pw - 1] = luma8(&src.rgba[at(x1.min(w - 1), y)..]);
        let pixels = src.rgba[at(x0, y)..][..n].chunks_exact(4);
        for (l, p) in row[1..pw - 1].iter_mut().zip(pixels) {
            *l = luma8(p);
        }
    }
    let (mut lo, mut hi, mut edge) = (vec![0f32; pw], vec![0f32; pw], vec![false; pw]);
    for y in y0..y1 {
        let up = &lumas[(y - y0) * pw..][..pw];
        let mid = &lumas[(y - y0 + 1) * pw..][..pw];
        let down = &lumas[(y - y0 + 2) * pw..][..pw];
        for k in 1..pw - 1 {
            let (lm, ln, ls, lw, le) = (mid[k], up[k], down[k], mid[k - 1], mid[k + 1]);
            lo[k] = lesser(lm, lesser(lesser(ln, ls), lesser(lw, le)));
            hi[k] = greater(lm, greater(greater(ln, ls), greater(lw, le)));
            edge[k] = hi[k] - lo[k] >= greater(EDGE_MIN, hi[k] * EDGE_REL);
        }
        for k in (1..pw - 1).filter(|&k| edge[k]) {
            let diag = [up[k - 1], up[k + 1], down[k - 1], down[k + 1]];
            let x = x0 + k - 1;
            let c = blend(src, x as u32, y as u32, lo[k], hi[k], diag);
            let out = &mut dst[(y * w + x) * 4..][..4];
            for i in 0..3 {
                out[i] = (c[i].clamp(0.0, 1.0) * 255.0 + 0.5) as u8;
            }
            out[3] = 255;
        }
    }
}

/// Side (pixels) of the cells in which [`apply_changed`] looks for changed pixels: with
/// `REACH` at most one cell, every pixel within `REACH` of a changed one lies in its cell
/// or one of the eight around it.
const CELL: usize = 8;
const _: () = assert!(REACH as usize <= CELL);

/// [`apply`] inside `rects` of a frame `src` that differs from `base` (tightly packed,
/// the same size) only inside `rects`, at least `REACH` pixels from their edges, into
/// `dst`, which holds `base` filtered: only around the pixels where `src` differs from
/// `base` (the cells holding one, and their neighbours) is the filter run; elsewhere its
/// output is `dst`'s already, as the filter reads nothing farther than `REACH`. Reads
/// `src` only inside `rects` grown by `REACH`.
pub(crate) fn apply_changed(src: Frame, base: &[u8], dst: &mut [u8], rects: &[[u32; 4]]) {
    let (w, h) = (src.width as usize, src.height as usize);
    let (cols, rows) = (w.div_ceil(CELL), h.div_ceil(CELL));
    let clipped: Vec<[usize; 4]> = rects.iter().filter_map(|&r| clip(r, w, h)).collect();
    let mut changed = vec![false; cols * rows];
    for &[x0, y0, x1, y1] in &clipped {
        for y in y0..y1 {
            let s = &src.rgba[y * src.stride..][x0 * 4..x1 * 4];
            let b = &base[y * w * 4..][x0 * 4..x1 * 4];
            if s == b {
                continue;
            }
            for cx in x0 / CELL..x1.div_ceil(CELL) {
                let cell = &mut changed[y / CELL * cols + cx];
                let (a, e) = ((cx * CELL).max(x0) - x0, ((cx + 1) * CELL).min(x1) - x0);
                *cell = *cell || s[a * 4..e * 4] != b[a * 4..e * 4];
            }
        }
    }
    let near = |cx: usize, cy: usize| {
        let (c0, c1) = (cx.saturating_sub(1), (cx + 1).min(cols - 1));
        let (r0, r1) = (cy.saturating_sub(1), (cy + 1).min(rows - 1));
        (r0..=r1).any(|r| (c0..=c1).any(|c| changed[r * cols + c]))
    };
    let near: Vec<bool> = (0..cols * rows).map(|i| near(i % cols, i / cols)).collect();
    // The cells near a change as rectangles, filtered where they meet `rects` (the
    // read-back holds this frame only there).
    let grid = (cols as u32, rows as u32, CELL as u32);
    let near = runs_to_rects(&near, grid.0, grid.1, grid.2, src.width, src.height);
    for &[x0, y0, x1, y1] in &clipped {
        for &[nx, ny, nw, nh] in &near {
            let (a, b) = ((nx as usize).max(x0), (ny as usize).max(y0));
            let (c, d) = (((nx + nw) as usize).min(x1), ((ny + nh) as usize).min(y1));
            if a < c && b < d {
                apply(src, dst, [a, b, c - a, d - b].map(|v| v as u32));
            }
        }
    }
}

/// `rect` (x, y, width, height) clipped to a `w` × `h` frame as (x0, y0, x1, y1).
fn clip(rect: [u32; 4], w: usize, h: usize) -> Option<[usize; 4]> {
    let (x0, y0) = ((rect[0] as usize).min(w), (rect[1] as usize).min(h));
    let x1 = (rect[0] as usize + rect[2] as usize).min(w);
    let y1 = (rect[1] as usize + rect[3] as usize).min(h);
    (x0 < x1 && y0 < y1).then_some([x0, y0, x1, y1])
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

    fn tight(rgba: &[u8], width: u32, height: u32) -> Frame<'_> {
        Frame {
            rgba,
            width,
            height,
            stride: 4 * width as usize,
        }
    }

    /// Read-back rows are padded to 256 bytes: a frame with padded rows gives the
    /// tightly packed frame's result.
    #[test]
    fn padded_rows_give_the_same_result() {
        let (w, h) = (21, 13);
        let src = frame(w, h, |x, y| ((x * 53 + y * 29) % 5 * 60) as u8);
        let stride = 256;
        let mut padded = vec![99u8; stride * h as usize];
        for (y, row) in src.chunks_exact(4 * w as usize).enumerate() {
            padded[y * stride..][..row.len()].copy_from_slice(row);
        }
        let (mut a, mut b) = (vec![0u8; src.len()], vec![0u8; src.len()]);
        apply(tight(&src, w, h), &mut a, [0, 0, w, h]);
        let p = Frame {
            rgba: &padded,
            width: w,
            height: h,
            stride,
        };
        apply(p, &mut b, [0, 0, w, h]);
        assert_eq!(a, b);
        assert_ne!(a, src, "the pattern has edges to smooth");
    }

    #[test]
    fn flat_areas_are_copied_and_a_staircase_edge_is_smoothed() {
        // A hard diagonal edge: black below the line y = x / 2, white above.
        let (w, h) = (32, 32);
        let src = frame(w, h, |x, y| if 2 * y < x { 255 } else { 0 });
        let f = tight(&src, w, h);
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
    }

    #[test]
    fn a_rectangle_gives_the_whole_frame_filter_inside_it_and_nothing_outside() {
        let (w, h) = (40, 24);
        let src = frame(w, h, |x, y| ((x * 37 + y * 91) % 7 * 40) as u8);
        let f = tight(&src, w, h);
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

    /// Filtering only around the changed pixels gives the whole frame's filter.
    #[test]
    fn filtering_around_the_changes_gives_the_whole_frame_filter() {
        let (w, h) = (70, 45);
        let base = frame(w, h, |x, y| ((x * 37 + y * 91) % 7 * 40) as u8);
        let mut aa_base = vec![0u8; base.len()];
        apply(tight(&base, w, h), &mut aa_base, [0, 0, w, h]);
        // Two changed patches, one at the frame's edge; the rectangles hold them with
        // `REACH` around (the second one far larger than its change).
        let mut src = base.clone();
        let patches = [[0u32, 3, 5, 4], [40, 20, 3, 2]];
        for &[px, py, pw, ph] in &patches {
            for y in py..py + ph {
                for x in px..px + pw {
                    let i = ((y * w + x) * 4) as usize;
                    src[i..i + 3].copy_from_slice(&[255, (x * 9) as u8, 0]);
                }
            }
        }
        let rects = [[0, 0, 13, 15], [10, 5, 60, 40]];
        let mut want = vec![0u8; src.len()];
        apply(tight(&src, w, h), &mut want, [0, 0, w, h]);
        assert_ne!(want, aa_base, "the patches change the filtered frame");
        let mut got = aa_base.clone();
        apply_changed(tight(&src, w, h), &base, &mut got, &rects);
        assert_eq!(got, want);
        // Nothing changed: nothing is filtered again (a marker survives).
        let mut marked = aa_base.clone();
        marked[(30 * w as usize + 30) * 4] ^= 1;
        let kept = marked.clone();
        apply_changed(tight(&base, w, h), &base, &mut marked, &rects);
        assert_eq!(marked, kept);
    }
}
