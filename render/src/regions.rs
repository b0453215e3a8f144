//! Shadow-tile rectangle maths: where on screen a moving body's shadow can change static
//! pixels (`shadow_regions`), as few tile-snapped rectangles.

use super::cells::{rect_area, rect_union, runs_to_rects};
use super::gpu;
use super::mesh::Vertex;
use rh_physics::spec::{CameraSpec, Vec3};
use rh_scenes::view::View;

/// Axis-aligned bounds of some vertices (`None` when there are none).
pub(super) fn bounds(verts: &[Vertex]) -> Option<[Vec3; 2]> {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for v in verts {
        for i in 0..3 {
            lo[i] = lo[i].min(v.pos[i] as f64);
            hi[i] = hi[i].max(v.pos[i] as f64);
        }
    }
    (!verts.is_empty()).then_some([lo, hi])
}

/// Screen bounds (x, y, width, height; clamped, padded by 2 pixels) of the box
/// `[lo, hi]` in `cam` seen through `view` (its camera model): `None` when off screen,
/// the whole frame when the box reaches behind the camera or there is no view (a
/// camera looking straight up or down).
pub(super) fn screen_rect(
    cam: &CameraSpec,
    view: Option<&View>,
    [lo, hi]: [Vec3; 2],
) -> Option<[u32; 4]> {
    let whole = Some([0, 0, cam.width, cam.height]);
    let Some(view) = view else {
        return whole;
    };
    let (mut x0, mut y0) = (f64::INFINITY, f64::INFINITY);
    let (mut x1, mut y1) = (f64::NEG_INFINITY, f64::NEG_INFINITY);
    for corner in 0..8 {
        let p = [0, 1, 2].map(|i| if corner >> i & 1 == 1 { hi[i] } else { lo[i] });
        let Some([nx, ny]) = view.project(p) else {
            return whole;
        };
        let px = (nx * 0.5 + 0.5) * cam.width as f64;
        let py = (0.5 - ny * 0.5) * cam.height as f64;
        x0 = x0.min(px);
        y0 = y0.min(py);
        x1 = x1.max(px);
        y1 = y1.max(py);
    }
    let clamp_x = |v: f64| v.clamp(0.0, cam.width as f64) as u32;
    let clamp_y = |v: f64| v.clamp(0.0, cam.height as f64) as u32;
    let (x0, y0) = (clamp_x(x0.floor() - 2.0), clamp_y(y0.floor() - 2.0));
    let (x1, y1) = (clamp_x(x1.ceil() + 2.0), clamp_y(y1.ceil() + 2.0));
    (x1 > x0 && y1 > y0).then_some([x0, y0, x1 - x0, y1 - y0])
}

/// Merges rectangles pairwise, cheapest first (least area added), while a merge adds
/// no area or more than `max` remain.
pub(super) fn merge_rects(rects: &mut Vec<[u32; 4]>, max: usize) {
    loop {
        let mut best: Option<(i64, usize, usize)> = None;
        for i in 0..rects.len() {
            for j in i + 1..rects.len() {
                let added = rect_area(rect_union(rects[i], rects[j])) as i64
                    - rect_area(rects[i]) as i64
                    - rect_area(rects[j]) as i64;
                if best.is_none_or(|(b, _, _)| added < b) {
                    best = Some((added, i, j));
                }
            }
        }
        match best {
            Some((added, i, j)) if added <= 0 || rects.len() > max => {
                rects[i] = rect_union(rects[i], rects[j]);
                rects.swap_remove(j);
            }
            _ => return,
        }
    }
}

/// Pixel rectangles (x, y, width, height) where moving geometry with bounds `[lo, hi]`
/// may shade static surfaces, i.e. where its shadow can fall. The shadow of a box B
/// lies in the translates B + d·t (t ≥ 0, `d` the sun's direction); those that meet a
/// receiver box R have t in an interval [t0, t1], and their union lies in the box
/// spanned by B + d·t0 and B + d·t1. Each receiver gives the screen bounds of that box
/// intersected with R. Rectangles are then merged, cheapest first, while a merge adds
/// no area or more than `MAX_REDRAW_RECTS` remain.
pub(super) fn shadow_regions(
    cam: &CameraSpec,
    view: Option<&View>,
    [lo, hi]: [Vec3; 2],
    reach: f64,
    sun_dir: [f32; 4],
    receivers: &[[Vec3; 2]],
) -> Vec<[u32; 4]> {
    // A shaded point is on its triangle (centroid interpolation), so inside its
    // receiver box; the box only needs rounding slack.
    const PAD: f64 = 0.001;
    let (lo, hi) = (lo.map(|v| v - reach), hi.map(|v| v + reach));
    let d = [sun_dir[0] as f64, sun_dir[1] as f64, sun_dir[2] as f64];
    let mut rects: Vec<[u32; 4]> = Vec::new();
    for [rlo, rhi] in receivers {
        let receiver = [rlo.map(|v| v - PAD), rhi.map(|v| v + PAD)];
        let Some((t0, t1)) = sweep_interval([lo, hi], d, receiver) else {
            continue;
        };
        let mut box_lo = [0.0; 3];
        let mut box_hi = [0.0; 3];
        for i in 0..3 {
            box_lo[i] = (lo[i] + d[i] * t0).min(lo[i] + d[i] * t1).max(rlo[i] - PAD);
            box_hi[i] = (hi[i] + d[i] * t0).max(hi[i] + d[i] * t1).min(rhi[i] + PAD);
        }
        if (0..3).any(|i| box_lo[i] > box_hi[i]) {
            continue;
        }
        if let Some(r) = screen_rect(cam, view, [box_lo, box_hi]) {
            rects.push(r);
        }
    }
    let mut rects = cover_with_tiles(&rects, cam.width, cam.height);
    merge_rects(&mut rects, gpu::MAX_REDRAW_RECTS);
    rects
}

/// The translates B + d·t (t >= 0) of box `b` that meet box `r`: t in `[t0, t1]`
/// (`None` when none do).
fn sweep_interval(b: [Vec3; 2], d: Vec3, r: [Vec3; 2]) -> Option<(f64, f64)> {
    let ([lo, hi], [rlo, rhi]) = (b, r);
    let (mut t0, mut t1) = (0.0f64, f64::INFINITY);
    for i in 0..3 {
        if d[i].abs() < 1e-9 {
            if hi[i] < rlo[i] || lo[i] > rhi[i] {
                return None;
            }
            continue;
        }
        let (a, b) = ((rlo[i] - hi[i]) / d[i], (rhi[i] - lo[i]) / d[i]);
        t0 = t0.max(a.min(b));
        t1 = t1.min(a.max(b));
    }
    (t1 >= t0).then_some((t0, t1))
}

/// Whether the shadow sweep of box `b` along `d` (its translates B + d·t, t >= 0)
/// meets box `r`.
pub(super) fn sweep_meets(b: [Vec3; 2], d: Vec3, r: [Vec3; 2]) -> bool {
    sweep_interval(b, d, r).is_some()
}

/// Side of the screen tiles `cover_with_tiles` snaps to (pixels).
const REDRAW_TILE: u32 = 16;

/// Few rectangles covering the union of many: mark the `REDRAW_TILE` tiles any
/// rectangle touches, take each tile row's runs, and stack runs with the same span in
/// consecutive rows into one rectangle.
fn cover_with_tiles(rects: &[[u32; 4]], width: u32, height: u32) -> Vec<[u32; 4]> {
    let (marked, cols, rows) = mark_cells(rects, 0, REDRAW_TILE, width, height);
    runs_to_rects(&marked, cols, rows, REDRAW_TILE, width, height)
}

/// The `cell`-pixel grid cells (row-major, with the grid's columns and rows) of a
/// `width` × `height` frame that meet one of `rects` grown by `grow` pixels on each side.
fn mark_cells(
    rects: &[[u32; 4]],
    grow: u32,
    cell: u32,
    width: u32,
    height: u32,
) -> (Vec<bool>, u32, u32) {
    let (cols, rows) = (width.div_ceil(cell), height.div_ceil(cell));
    let mut marked = vec![false; (cols * rows) as usize];
    for &[x, y, w, h] in rects {
        let (c0, r0) = (x.saturating_sub(grow) / cell, y.saturating_sub(grow) / cell);
        let c1 = (x + w + grow).min(width).div_ceil(cell);
        let r1 = (y + h + grow).min(height).div_ceil(cell);
        for ty in r0..r1 {
            for tx in c0..c1 {
                marked[(ty * cols + tx) as usize] = true;
            }
        }
    }
    (marked, cols, rows)
}

/// Rectangles (pixels; at most `max`, possibly overlapping) covering every `cell`-pixel
/// grid cell that meets one of `rects` (x, y, width, height) grown by `grow` pixels on
/// each side, in a `width` × `height` frame: where a pass that reads `grow` pixels
/// around each output pixel must be redone when `rects` changed. Much less than their
/// bounding rectangle when they are scattered (a falling body and its shadow).
pub(super) fn cover(
    rects: &[[u32; 4]],
    grow: u32,
    cell: u32,
    width: u32,
    height: u32,
    max: usize,
) -> Vec<[u32; 4]> {
    let changed: Vec<[u32; 4]> = rects
        .iter()
        .copied()
        .filter(|r| r[2] > 0 && r[3] > 0)
        .collect();
    let (marked, cols, rows) = mark_cells(&changed, grow, cell, width, height);
    let mut out = runs_to_rects(&marked, cols, rows, cell, width, height);
    merge_rects(&mut out, max);
    out
}
