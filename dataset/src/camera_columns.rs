//! The head camera's columns (specification §7, "the ego camera is calibrated"): its field of
//! view, intrinsics and pose in the body and world frames (`rh_contract::camera`, from the
//! spec's `ego` camera and observer), and how far the event moves in its image
//! (`ego_motion_px`). Null for a scene without cameras (framing failed: invalid).

use arrow::array::{ArrayRef, FixedSizeListBuilder, Float64Builder, ListBuilder};
use arrow::datatypes::{DataType, Field};
use rh_contract::camera::{BodyFrame, HeadCamera};
use rh_scenes::driver::SceneResult;
use std::sync::Arc;

/// The calibration of a scene's `ego` camera, if it has one.
pub fn head_camera(r: &SceneResult) -> Option<HeadCamera> {
    let cam = r.spec.cameras.iter().find(|c| c.name == "ego")?;
    let o = &r.spec.observer;
    let body = BodyFrame {
        x: o.x,
        y: o.y,
        yaw: o.yaw,
        pelvis_z: o.pelvis_z,
    };
    HeadCamera::new(
        cam.position,
        cam.look_at,
        cam.fov_y,
        (cam.width, cam.height),
        body,
    )
}

/// The columns from `ego_fov_y` to `ego_motion_px`, in `COLUMNS` order.
pub fn columns(results: &[SceneResult]) -> Vec<ArrayRef> {
    let cams: Vec<Option<HeadCamera>> = results.iter().map(head_camera).collect();
    let scalars = |f: &dyn Fn(&HeadCamera) -> f64| {
        let mut b = Float64Builder::with_capacity(cams.len());
        for c in &cams {
            b.append_option(c.as_ref().map(f));
        }
        Arc::new(b.finish()) as ArrayRef
    };
    let lists = |f: &dyn Fn(&HeadCamera) -> Vec<f64>| {
        let mut b = ListBuilder::new(Float64Builder::new());
        for c in &cams {
            match c {
                Some(c) => {
                    b.values().append_slice(&f(c));
                    b.append(true);
                }
                None => b.append(false),
            }
        }
        Arc::new(b.finish()) as ArrayRef
    };
    let vec3s = |f: &dyn Fn(&HeadCamera) -> [f64; 3]| {
        let mut b = FixedSizeListBuilder::new(Float64Builder::new(), 3).with_field(Field::new(
            "item",
            DataType::Float64,
            false,
        ));
        for c in &cams {
            b.values()
                .append_slice(&c.as_ref().map(f).unwrap_or([0.0; 3]));
            b.append(c.is_some());
        }
        Arc::new(b.finish()) as ArrayRef
    };
    let mut motion = Float64Builder::with_capacity(results.len());
    for r in results {
        motion.append_option(r.ego_motion_px);
    }
    vec![
        scalars(&|c| c.fov_y),
        scalars(&|c| c.fov_x),
        lists(&|c| c.intrinsics.to_vec()),
        vec3s(&|c| c.position_body),
        scalars(&|c| c.yaw_body),
        scalars(&|c| c.pitch_body),
        lists(&|c| c.rotation_body.to_vec()),
        vec3s(&|c| c.position_world),
        lists(&|c| c.rotation_world.to_vec()),
        Arc::new(motion.finish()),
    ]
}

/// The card's bullets (after the label rule's) on what the model is shown: the model-input
/// ego frames' pixel guarantee, the motion rule and the head camera's calibration, with the
/// build's numbers (`config`: the manifest's configuration).
pub fn card_note(config: &serde_json::Value) -> String {
    let validator = |key: &str| {
        config
            .pointer(&format!("/validators/{key}"))
            .and_then(|x| x.as_f64())
            .unwrap_or(0.0)
    };
    let (px_min, safety) = (validator("visible_px_min"), validator("visible_px_safety"));
    let pixels = if safety > 0.0 {
        format!(
            "\n* **What the model sees** (part of `valid_visible`): at each model-input ego frame \
(t = 0, 0.15, 0.30, 0.45, 0.60 s) before the hazard comes within {until} m of the torso axis, \
rays through a grid of pixel centres over the hazard's box in the image are cast at its \
collision shapes shrunk to {inset} of their size; those that meet it with no fixed body, no \
other moving body in front must stand for at least {need} px ({px_min} × {safety}). A rendered \
build checks the renderer's own count (`ego_hazard_visible_px`) against {px_min} px at those \
frames and stops with an error naming the scene if one falls short, so a label-only build \
and a rendered one have the same valid scenes.",
            until = validator("frame_check_until_within"),
            inset = validator("visible_px_inset"),
            need = px_min * safety,
        )
    } else {
        String::new()
    };
    let motion = validator("motion_px_min");
    let motion = if motion > 0.0 {
        format!(
            "\n* **The event is under way** (validator `valid_motion`): between t = 0 and Δ some \
point sampled on the hazard's collision shapes (or on a moving prop's: a chain's trigger, a \
neighbour) moves at least {motion} px in the ego image (`ego_motion_px`); stiller scenes are \
resampled."
        )
    } else {
        String::new()
    };
    format!(
        "{pixels}{motion}\n* **The head camera is calibrated** (prompt v5): a pinhole camera \
without distortion at the observer's head, aimed and given a field of view per scene group \
(fitted to the hazard's path); `ego_fov_y`, `ego_fov_x`, `ego_intrinsics`, the optical \
centre and orientation in the body frame (`ego_position_body`, `ego_yaw_body`, \
`ego_pitch_body`, `ego_rotation_body`) and in the world (`ego_position_world`, \
`ego_rotation_world`) are columns, and the prompt states the field of view and the pose."
    )
}

#[cfg(test)]
mod tests {
    use crate::rows::record_batch;
    use arrow::array::{Array, FixedSizeListArray, Float64Array, ListArray};
    use rh_catalog::Catalog;
    use rh_contract::columns::col;
    use rh_scenes::config::Config;
    use rh_scenes::driver::produce_group;
    use rh_scenes::selection::plan_group;
    use rh_scenes::view::View;

    fn floats(batch: &arrow::array::RecordBatch, name: &str, row: usize) -> Vec<f64> {
        let c = batch.column_by_name(name).unwrap();
        let values = if let Some(l) = c.as_any().downcast_ref::<ListArray>() {
            l.value(row)
        } else {
            c.as_any()
                .downcast_ref::<FixedSizeListArray>()
                .unwrap()
                .value(row)
        };
        let v = values.as_any().downcast_ref::<Float64Array>().unwrap();
        (0..v.len()).map(|i| v.value(i)).collect()
    }

    /// The stored columns project a point where the renderer draws it: the hazard's start
    /// through `ego_intrinsics`, `ego_rotation_world` and `ego_position_world` (and through
    /// the body-frame columns, from the observer pose) lands on the pixel of the camera
    /// model the frames are drawn with (`view::View`, whose matrix the renderer uses).
    #[test]
    fn the_stored_calibration_projects_to_the_drawn_pixel() {
        let catalog = Catalog::embedded().unwrap();
        let config = Config::embedded().unwrap();
        let families = vec!["object_drop".to_string()];
        let sel = plan_group(&catalog, &families, 3, 0).unwrap();
        let results = produce_group(&sel, 3, 0, 2, &catalog, &config).unwrap();
        let batch = record_batch(&results, &catalog);
        for (row, r) in results.iter().enumerate() {
            let cam = r.spec.cameras.iter().find(|c| c.name == "ego").unwrap();
            let p = r.spec.hazard_body().position;
            let [x, y] = View::new(cam).unwrap().project(p).unwrap();
            let (w, h) = (cam.width as f64, cam.height as f64);
            let drawn = [(x + 1.0) / 2.0 * w, (1.0 - y) / 2.0 * h];
            let k = floats(&batch, col::EGO_INTRINSICS, row);
            let project = |rot: &[f64], pos: &[f64], q: [f64; 3]| {
                let d = [q[0] - pos[0], q[1] - pos[1], q[2] - pos[2]];
                let c: Vec<f64> = (0..3)
                    .map(|j| rot[j] * d[0] + rot[3 + j] * d[1] + rot[6 + j] * d[2])
                    .collect();
                [k[0] * c[0] / c[2] + k[2], k[1] * c[1] / c[2] + k[3]]
            };
            let world = project(
                &floats(&batch, col::EGO_ROTATION_WORLD, row),
                &floats(&batch, col::EGO_POSITION_WORLD, row),
                p,
            );
            let o = &r.spec.observer;
            let (s, c) = o.yaw.sin_cos();
            let d = [p[0] - o.x, p[1] - o.y, p[2] - o.pelvis_z];
            let in_body = [c * d[0] + s * d[1], -s * d[0] + c * d[1], d[2]];
            let body = project(
                &floats(&batch, col::EGO_ROTATION_BODY, row),
                &floats(&batch, col::EGO_POSITION_BODY, row),
                in_body,
            );
            for uv in [world, body] {
                assert!(
                    (uv[0] - drawn[0]).abs() < 1e-6 && (uv[1] - drawn[1]).abs() < 1e-6,
                    "{uv:?} vs {drawn:?}"
                );
            }
            let fov = batch
                .column_by_name(col::EGO_FOV_Y)
                .unwrap()
                .as_any()
                .downcast_ref::<Float64Array>()
                .unwrap()
                .value(row);
            assert_eq!(fov, cam.fov_y);
            let motion = batch.column_by_name(col::EGO_MOTION_PX).unwrap();
            assert!(!motion.is_null(row));
        }
    }
}
