//! Where a view's static surfaces are, per screen tile: the box of the surface points
//! each `TILE`-pixel tile shows, rebuilt once per view from the cached static depth.
//! Without MSAA a frame redraws only the tiles whose box meets the moving casters'
//! shadow sweep (much tighter than projecting receiver boxes: a floor tile behind the
//! sweep, or a wall above it, is left alone).

use super::gpu;
use super::regions::{merge_rects, runs_to_rects, sweep_meets};
use rh_physics::spec::Vec3;

/// Side of a tile (pixels).
const TILE: u32 = 16;

/// Slack around each tile's box (m): the points are rebuilt from 32-bit depths (errors
/// well under a millimetre at room distances).
const SLACK: f64 = 0.01;

pub(super) struct SurfaceTiles {
    width: u32,
    height: u32,
    cols: u32,
    /// Per tile (row-major): the box of its surface points, `None` where it shows only
    /// background.
    boxes: Vec<Option<[Vec3; 2]>>,
}

impl SurfaceTiles {
    /// From a view's depth image (`width` × `height`, one sample per pixel, 1 = no
    /// surface) and the inverse of its view-projection matrix (row-major, f64).
    pub(super) fn from_depth(depth: &[f32], width: u32, height: u32, inv: [[f64; 4]; 4]) -> Self {
        let (cols, rows) = (width.div_ceil(TILE), height.div_ceil(TILE));
        let mut boxes: Vec<Option<[Vec3; 2]>> = vec![None; (cols * rows) as usize];
        for py in 0..height {
            let ny = 1.0 - (py as f64 + 0.5) / height as f64 * 2.0;
            for px in 0..width {
                let d = depth[(py * width + px) as usize] as f64;
                if d >= 1.0 {
                    continue;
                }
                let nx = (px as f64 + 0.5) / width as f64 * 2.0 - 1.0;
                let h = [0, 1, 2, 3]
                    .map(|r| inv[r][0] * nx + inv[r][1] * ny + inv[r][2] * d + inv[r][3]);
                let p = [h[0] / h[3], h[1] / h[3], h[2] / h[3]];
                let b = &mut boxes[((py / TILE) * cols + px / TILE) as usize];
                match b {
                    Some([lo, hi]) => {
                        for i in 0..3 {
                            lo[i] = lo[i].min(p[i]);
                            hi[i] = hi[i].max(p[i]);
                        }
                    }
                    None => *b = Some([p, p]),
                }
            }
        }
        for [lo, hi] in boxes.iter_mut().flatten() {
            *lo = lo.map(|v| v - SLACK);
            *hi = hi.map(|v| v + SLACK);
        }
        SurfaceTiles {
            width,
            height,
            cols,
            boxes,
        }
    }

    /// Pixel rectangles (x, y, width, height; at most `MAX_REDRAW_RECTS`) covering the
    /// tiles whose surface a moving caster inside `moving` grown by `reach` can shade
    /// (its shadow sweep along the sun's direction `sun_dir` meets their box).
    pub(super) fn redraw_rects(
        &self,
        moving: [Vec3; 2],
        reach: f64,
        sun_dir: [f32; 4],
    ) -> Vec<[u32; 4]> {
        let [lo, hi] = moving;
        let swept = [lo.map(|v| v - reach), hi.map(|v| v + reach)];
        let d = [sun_dir[0] as f64, sun_dir[1] as f64, sun_dir[2] as f64];
        let marked: Vec<bool> = self
            .boxes
            .iter()
            .map(|b| b.is_some_and(|b| sweep_meets(swept, d, b)))
            .collect();
        let rows = self.height.div_ceil(TILE);
        let mut rects = runs_to_rects(&marked, self.cols, rows, TILE, self.width, self.height);
        merge_rects(&mut rects, gpu::MAX_REDRAW_RECTS);
        rects
    }
}
