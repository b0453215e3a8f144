//! Where a view's static surfaces are, per screen tile: the box of the surface points
//! each `TILE`-pixel tile shows, rebuilt once per view from the cached static depth.
//! Without MSAA a frame redraws only the tiles whose box meets the moving casters'
//! shadow sweep (much tighter than projecting receiver boxes: a floor tile behind the
//! sweep, or a wall above it, is left alone), and whose box seen from the sun (its
//! clip-space box) lies within the shadow map's reach of the casters' footprint there
//! and not in front of them. Each test is conservative, so both must pass.

use super::cells::runs_to_rects;
use super::gpu;
use super::mesh::Vertex;
use super::regions::{merge_rects, sweep_meets};
use rh_physics::spec::Vec3;

/// Slack (the sun's clip-space depth, 1 ≈ the room's diagonal and more) for a receiver
/// in front of the casters' nearest point: the shader's comparison offset (0.002) and
/// the lookup point's normal offset towards the sun both make shadowing rarer, so this
/// only covers rounding.
const DEPTH_SLACK: f64 = 0.01;

/// Rows x, y, depth of the sun's view-projection (column-major, as the shader gets it).
pub(super) struct LightRows([[f64; 4]; 3]);

impl LightRows {
    pub(super) fn of(light_vp: &[[f32; 4]; 4]) -> LightRows {
        LightRows([0, 1, 2].map(|r| [0, 1, 2, 3].map(|c| light_vp[c][r] as f64)))
    }

    fn apply(&self, p: Vec3) -> Vec3 {
        self.0
            .map(|r| r[0] * p[0] + r[1] * p[1] + r[2] * p[2] + r[3])
    }

    /// The clip-space box of `points` (`None` when there are none).
    fn bounds(&self, points: impl Iterator<Item = Vec3>) -> Option<[Vec3; 2]> {
        let mut out: Option<[Vec3; 2]> = None;
        for q in points.map(|p| self.apply(p)) {
            let [lo, hi] = out.unwrap_or([q, q]);
            out = Some([
                [0, 1, 2].map(|i| lo[i].min(q[i])),
                [0, 1, 2].map(|i| hi[i].max(q[i])),
            ]);
        }
        out
    }

    /// The moving casters' clip-space box (the vertices the shadow pass draws).
    pub(super) fn caster_bounds(&self, verts: &[Vertex]) -> Option<[Vec3; 2]> {
        self.bounds(verts.iter().map(|v| v.pos.map(|c| c as f64)))
    }
}

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
    /// Per tile: that box's clip-space box in the sun's view (`LightRows`).
    light: Vec<Option<[Vec3; 2]>>,
}

impl SurfaceTiles {
    /// From a view's depth image (`width` × `height`, one sample per pixel, 1 = no
    /// surface), the inverse of its view-projection matrix (row-major, f64) and the sun's
    /// view-projection.
    pub(super) fn from_depth(
        depth: &[f32],
        (width, height): (u32, u32),
        inv: [[f64; 4]; 4],
        sun: &LightRows,
    ) -> Self {
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
        let light = boxes
            .iter()
            .map(|b| {
                let [lo, hi] = (*b)?;
                let corner =
                    |k: usize| [0, 1, 2].map(|i| if k >> i & 1 == 0 { lo[i] } else { hi[i] });
                sun.bounds((0..8).map(corner))
            })
            .collect();
        SurfaceTiles {
            width,
            height,
            cols,
            boxes,
            light,
        }
    }

    /// Pixel rectangles (x, y, width, height; at most `MAX_REDRAW_RECTS`) covering the
    /// tiles whose surface a moving caster inside `moving` grown by `reach` can shade:
    /// its shadow sweep along the sun's direction `sun_dir` meets their box, and their
    /// clip-space box in the sun's view meets the casters' (`caster`) grown by
    /// `reach_light` in x and y, and does not lie wholly in front of it (nearer the sun).
    pub(super) fn redraw_rects(
        &self,
        (moving, reach, sun_dir): ([Vec3; 2], f64, [f32; 4]),
        (caster, reach_light): ([Vec3; 2], f64),
    ) -> Vec<[u32; 4]> {
        let [lo, hi] = moving;
        let swept = [lo.map(|v| v - reach), hi.map(|v| v + reach)];
        let d = [sun_dir[0] as f64, sun_dir[1] as f64, sun_dir[2] as f64];
        let [clo, chi] = caster;
        let in_reach = |[tlo, thi]: [Vec3; 2]| {
            (0..2).all(|i| thi[i] >= clo[i] - reach_light && tlo[i] <= chi[i] + reach_light)
                && thi[2] >= clo[2] - DEPTH_SLACK
        };
        let marked: Vec<bool> = self
            .boxes
            .iter()
            .zip(&self.light)
            .map(|(b, l)| b.is_some_and(|b| sweep_meets(swept, d, b)) && l.is_some_and(in_reach))
            .collect();
        let rows = self.height.div_ceil(TILE);
        let mut rects = runs_to_rects(&marked, self.cols, rows, TILE, self.width, self.height);
        merge_rects(&mut rects, gpu::MAX_REDRAW_RECTS);
        rects
    }
}
