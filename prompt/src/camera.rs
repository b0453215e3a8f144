//! The head camera's calibration as the canonical prompt states it (prompt v5, specification §9):
//! the scene's `ego` camera and observer from `specs/<id>.json`, through
//! `rh_contract::camera` — the numbers the dataset's `ego_*` columns hold — written into
//! `[text] camera` for the image size the model is sent.

use super::config::PromptConfig;
use rh_contract::camera::{BodyFrame, HeadCamera};
use serde_json::Value;
use std::path::Path;

/// The calibration of scene `scene_id`'s ego camera, from its spec in the dataset at `dir`.
pub fn scene_camera(dir: &Path, scene_id: &str) -> Result<HeadCamera, String> {
    let path = dir.join(rh_contract::layout::spec_path(scene_id));
    let text = std::fs::read_to_string(&path)
        .map_err(|e| format!("cannot read the scene's spec {}: {e}", path.display()))?;
    let spec: Value =
        serde_json::from_str(&text).map_err(|e| format!("{}: not JSON: {e}", path.display()))?;
    camera_of_spec(&spec).ok_or_else(|| {
        format!(
            "{}: no `ego` camera with position, look_at, fov_y, width and height, or no \
             observer (x, y, yaw, pelvis_z): the prompt states the head camera's calibration",
            path.display()
        )
    })
}

/// The ego camera's calibration from a spec's JSON (its `cameras` and `observer`).
pub fn camera_of_spec(spec: &Value) -> Option<HeadCamera> {
    let cam = spec["cameras"]
        .as_array()?
        .iter()
        .find(|c| c["name"] == "ego")?;
    let v3 = |v: &Value| -> Option<[f64; 3]> {
        let a = v.as_array()?;
        (a.len() == 3).then_some([a[0].as_f64()?, a[1].as_f64()?, a[2].as_f64()?])
    };
    let o = &spec["observer"];
    let body = BodyFrame {
        x: o["x"].as_f64()?,
        y: o["y"].as_f64()?,
        yaw: o["yaw"].as_f64()?,
        pelvis_z: o["pelvis_z"].as_f64()?,
    };
    let size = (
        u32::try_from(cam["width"].as_u64()?).ok()?,
        u32::try_from(cam["height"].as_u64()?).ok()?,
    );
    HeadCamera::new(
        v3(&cam["position"])?,
        v3(&cam["look_at"])?,
        cam["fov_y"].as_f64()?,
        size,
        body,
    )
}

/// The size of a `width` × `height` frame as sent (`prompt::encode_frame`: its longer side
/// scaled down to `max_side`, never up).
pub fn sent_size(width: u32, height: u32, max_side: u32) -> (u32, u32) {
    if width.max(height) <= max_side {
        return (width, height);
    }
    let scale = max_side as f64 / width.max(height) as f64;
    (
        ((width as f64 * scale).round() as u32).max(1),
        ((height as f64 * scale).round() as u32).max(1),
    )
}

/// `[text] camera` filled in for `cam`: {width} × {height} of the images as sent,
/// {fov_x}/{fov_y} (degrees), {focal} and {cx}, {cy} (px of the images as sent), the
/// optical centre in the body frame {x}, {y}, {z} and above the floor {above_floor} (m),
/// {yaw} and {pitch} (degrees, with their sense in words: {yaw_side}, {pitch_side}).
pub fn camera_text(cfg: &PromptConfig, cam: &HeadCamera) -> String {
    let (w, h) = sent_size(cam.width, cam.height, cfg.images.max_side);
    let k = cam.intrinsics_at(w, h);
    let deg = |a: f64| format!("{:.1}", a.to_degrees().abs());
    let [x, y, z] = cam.position_body;
    let m = |v: f64| format!("{:.2}", if v.abs() < 0.005 { 0.0 } else { v });
    let above_floor = cam.position_world[2];
    let yaw_side = match cam.yaw_body {
        a if a.to_degrees() >= 0.05 => "to the robot's left",
        a if a.to_degrees() <= -0.05 => "to the robot's right",
        _ => "straight ahead",
    };
    let pitch_side = if cam.pitch_body < 0.0 {
        "below the horizontal"
    } else {
        "above the horizontal"
    };
    cfg.text
        .camera
        .replace("{width}", &w.to_string())
        .replace("{height}", &h.to_string())
        .replace("{fov_x}", &deg(cam.fov_x))
        .replace("{fov_y}", &deg(cam.fov_y))
        .replace("{focal}", &format!("{:.1}", k[0]))
        .replace("{cx}", &format!("{:.1}", k[2]))
        .replace("{cy}", &format!("{:.1}", k[3]))
        .replace("{x}", &m(x))
        .replace("{y}", &m(y))
        .replace("{z}", &m(z))
        .replace("{above_floor}", &m(above_floor))
        .replace("{yaw}", &deg(cam.yaw_body))
        .replace("{yaw_side}", yaw_side)
        .replace("{pitch}", &deg(cam.pitch_body))
        .replace("{pitch_side}", pitch_side)
        .trim()
        .to_string()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A spec's ego camera 0.45 m above the pelvis, 30° to the left and 20° down, with a
    /// 60° vertical field of view at 1280 × 720: the text states exactly that, for the
    /// 768 × 432 images the model is sent.
    #[test]
    fn the_prompt_states_the_scene_cameras_calibration() {
        let yaw = 0.4f64;
        let (pitch_down, fov) = (20f64.to_radians(), 60f64.to_radians());
        let h = yaw + 30f64.to_radians();
        let pos = [1.0, 2.0, 0.79 + 0.45];
        let look = [
            pos[0] + pitch_down.cos() * h.cos(),
            pos[1] + pitch_down.cos() * h.sin(),
            pos[2] - pitch_down.sin(),
        ];
        let spec = serde_json::json!({
            "cameras": [
                {"name": "closeup", "position": [0.0, 0.0, 1.0], "look_at": [1.0, 0.0, 1.0],
                 "fov_y": 1.0, "width": 1280, "height": 720},
                {"name": "ego", "position": pos, "look_at": look, "fov_y": fov,
                 "width": 1280, "height": 720}
            ],
            "observer": {"x": 1.0, "y": 2.0, "yaw": yaw, "pelvis_z": 0.79}
        });
        let cam = camera_of_spec(&spec).unwrap();
        let cfg = PromptConfig::load(None).unwrap();
        let text = camera_text(&cfg, &cam);
        let focal = 216.0 / (30f64.to_radians()).tan();
        let fov_x = 2.0 * ((30f64.to_radians()).tan() * 16.0 / 9.0).atan();
        for needle in [
            "768 x 432".to_string(),
            "60.0° vertical".to_string(),
            format!("{:.1}° horizontal", fov_x.to_degrees()),
            format!("focal length {focal:.1} px"),
            "(384.0, 216.0)".to_string(),
            "(0.00, 0.00, 0.45) m".to_string(),
            "1.24 m above the floor".to_string(),
            "yaw 30.0° (to the robot's left)".to_string(),
            "pitch 20.0° (below the horizontal)".to_string(),
        ] {
            assert!(text.contains(&needle), "{needle:?} not in {text}");
        }
        // No camera, no calibration.
        assert!(camera_of_spec(&serde_json::json!({"observer": spec["observer"]})).is_none());
    }
}
