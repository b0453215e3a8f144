//! Fitting a loaded model onto its catalog entry's parts, and the bounds check.
//!
//! The fit scales each axis so that the model's bounding box is exactly the parts'
//! (what is drawn is where the collider is: contacts, shadows and hazard masks agree).
//! The check bounds the distortion that needs: scaled uniformly (by the geometric mean
//! of the three axis scales), no axis of the model may differ from the parts' by more
//! than the configured tolerance (`render.models.bounds_tolerance`). A model of the wrong
//! object, or a wrong orientation fix (a plate standing on its rim), fails it.

use super::LoadedModel;
use crate::mesh::{Mesh, Vertex, Xf, V3};
use rh_physics::spec::PartSpec;

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FitError {
    #[error(
        "the model is flat along {axis} (extent {extent:.6}): it cannot be fitted to the parts"
    )]
    Flat { axis: char, extent: f32 },
    #[error(
        "its bounds disagree with the parts' along {axis} by {deviation:.2} (tolerance {tolerance}): model extents {model:?} (scaled uniformly), parts extents {parts:?} m; check the entry's model.rotation or choose another model"
    )]
    Bounds {
        axis: char,
        deviation: f64,
        tolerance: f64,
        model: [f32; 3],
        parts: [f32; 3],
    },
}

const AXES: [char; 3] = ['x', 'y', 'z'];

/// The parts' axis-aligned bounding box in the body frame: (min, max).
pub fn parts_box(parts: &[PartSpec]) -> (V3, V3) {
    let mut lo = [f32::MAX; 3];
    let mut hi = [f32::MIN; 3];
    for p in parts {
        let h: V3 = crate::recipes::part_half(p);
        let xf = Xf::from_quat(p.rotation, p.offset);
        for k in 0..3 {
            // Half extent of the rotated box along world axis k.
            let e: f32 = (0..3).map(|j| (xf.r[j][k] * h[j]).abs()).sum();
            lo[k] = lo[k].min(xf.t[k] - e);
            hi[k] = hi[k].max(xf.t[k] + e);
        }
    }
    if parts.is_empty() {
        return ([0.0; 3], [0.0; 3]);
    }
    (lo, hi)
}

/// The largest relative disagreement of the model's extents (scaled uniformly) with the
/// parts' extents, and its axis: `max_k |s_k / g − 1|` with `s_k` the axis scale that
/// maps the model onto the parts and `g` their geometric mean.
pub fn bounds_deviation(model: V3, parts: V3) -> Result<(f64, usize), FitError> {
    for k in 0..3 {
        if model[k] <= 1e-6 || parts[k] <= 1e-6 {
            return Err(FitError::Flat {
                axis: AXES[k],
                extent: model[k].min(parts[k]),
            });
        }
    }
    let s: [f64; 3] = std::array::from_fn(|k| parts[k] as f64 / model[k] as f64);
    let g = (s[0] * s[1] * s[2]).cbrt();
    let mut worst = (0.0, 0);
    for (k, sk) in s.iter().enumerate() {
        let d = (sk / g - 1.0).abs();
        if d > worst.0 {
            worst = (d, k);
        }
    }
    Ok(worst)
}

/// The model fitted onto `parts` (each axis scaled so its bounds are the parts'), after
/// the bounds check with `tolerance`.
pub fn fit_model(m: &LoadedModel, parts: &[PartSpec], tolerance: f64) -> Result<Mesh, FitError> {
    let (plo, phi) = parts_box(parts);
    let pe: V3 = std::array::from_fn(|k| phi[k] - plo[k]);
    let me: V3 = std::array::from_fn(|k| m.hi[k] - m.lo[k]);
    let (deviation, axis) = bounds_deviation(me, pe)?;
    if deviation > tolerance {
        let s: [f64; 3] = std::array::from_fn(|k| pe[k] as f64 / me[k] as f64);
        let g = (s[0] * s[1] * s[2]).cbrt() as f32;
        return Err(FitError::Bounds {
            axis: AXES[axis],
            deviation,
            tolerance,
            model: me.map(|e| e * g),
            parts: pe,
        });
    }
    let s: V3 = std::array::from_fn(|k| pe[k] / me[k]);
    let verts = m
        .mesh
        .verts
        .iter()
        .map(|v| {
            let pos = std::array::from_fn(|k| plo[k] + (v.pos[k] - m.lo[k]) * s[k]);
            // Normals transform by the inverse transpose: divide by the scale.
            let n: V3 = std::array::from_fn(|k| v.normal[k] / s[k]);
            let l = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt().max(1e-12);
            Vertex {
                pos,
                normal: n.map(|c| c / l),
                color: v.color,
            }
        })
        .collect();
    Ok(Mesh { verts })
}
