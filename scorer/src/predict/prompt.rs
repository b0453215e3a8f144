//! The canonical prompt of one scene (`configs/prompt.toml`): a system message (the
//! observer, the freeze-and-predict protocol, the plan schema with an example) and a user
//! message with the observation frames, each labelled with its time. Frames are the
//! dataset's PNGs `frames/<id>/<cam>_t<t>.png`, scaled down to `max_side` and re-encoded
//! as JPEG, sent as base64 data URLs.

use super::config::PromptConfig;
use base64::Engine;
use serde_json::{json, Value};
use std::path::Path;
use std::time::Instant;

/// One scene's messages, ready to send.
#[derive(Debug, Clone)]
pub struct BuiltPrompt {
    pub messages: Value,
    /// Seconds spent decoding, scaling and encoding the frames (CPU-bound, one thread).
    pub encode_s: f64,
}

/// `frames/<id>/<cam>_t0.150.png` (the data contract's naming, SPEC §8).
pub fn frame_rel_path(scene_id: &str, camera: &str, t: f64) -> String {
    rh_contract::layout::frame_path(scene_id, camera, t)
}

fn fill(text: &str, cfg: &PromptConfig) -> String {
    let window = cfg.images.times.iter().copied().fold(0.0f64, f64::max);
    text.replace(
        "{n_frames}",
        &(cfg.images.times.len() * cfg.images.cameras.len()).to_string(),
    )
    .replace("{window_s}", &format!("{window:.2}"))
    .trim()
    .to_string()
}

/// The system message's text.
pub fn system_text(cfg: &PromptConfig) -> String {
    fill(&cfg.text.system, cfg)
}

/// Reads a PNG frame and returns it as JPEG bytes no larger than `max_side`.
pub fn encode_frame(path: &Path, max_side: u32, quality: u8) -> Result<Vec<u8>, String> {
    let img = image::open(path)
        .map_err(|e| format!("cannot read frame {}: {e}", path.display()))?
        .to_rgb8();
    let (w, h) = img.dimensions();
    let img = if w.max(h) > max_side {
        let scale = max_side as f64 / w.max(h) as f64;
        let (nw, nh) = (
            ((w as f64 * scale).round() as u32).max(1),
            ((h as f64 * scale).round() as u32).max(1),
        );
        image::imageops::resize(&img, nw, nh, image::imageops::FilterType::Triangle)
    } else {
        img
    };
    let mut out = Vec::new();
    image::codecs::jpeg::JpegEncoder::new_with_quality(&mut out, quality)
        .encode_image(&img)
        .map_err(|e| format!("cannot encode frame {} as JPEG: {e}", path.display()))?;
    Ok(out)
}

/// The messages for one scene of the dataset at `dir`.
pub fn build(cfg: &PromptConfig, dir: &Path, scene_id: &str) -> Result<BuiltPrompt, String> {
    let start = Instant::now();
    let mut content = vec![json!({"type": "text", "text": fill(&cfg.text.user_intro, cfg)})];
    for &t in &cfg.images.times {
        for cam in &cfg.images.cameras {
            let path = dir.join(frame_rel_path(scene_id, cam, t));
            if !path.is_file() {
                return Err(format!(
                    "missing observation frame {} (was the dataset built with rendering? \
                     `rh-pipeline build` without --no-render writes frames/)",
                    path.display()
                ));
            }
            let jpeg = encode_frame(&path, cfg.images.max_side, cfg.images.jpeg_quality)?;
            let label = cfg
                .text
                .frame_label
                .replace("{t}", &format!("{t:.2}"))
                .replace("{camera}", cam);
            content.push(json!({"type": "text", "text": label}));
            content.push(json!({
                "type": "image_url",
                "image_url": {
                    "url": format!(
                        "data:image/jpeg;base64,{}",
                        base64::engine::general_purpose::STANDARD.encode(&jpeg)
                    ),
                    "detail": cfg.images.detail,
                }
            }));
        }
    }
    content.push(json!({"type": "text", "text": fill(&cfg.text.user_outro, cfg)}));
    let messages = json!([
        {"role": "system", "content": system_text(cfg)},
        {"role": "user", "content": content},
    ]);
    Ok(BuiltPrompt {
        messages,
        encode_s: start.elapsed().as_secs_f64(),
    })
}

/// A copy of a request body with every image data URL replaced by a short note (for
/// `--dry-run`).
pub fn elide_images(v: &Value) -> Value {
    match v {
        Value::String(s) if s.starts_with("data:image/") => {
            let (head, data) = s.split_once(',').unwrap_or((s, ""));
            Value::String(format!("{head},<{} base64 characters elided>", data.len()))
        }
        Value::Array(a) => Value::Array(a.iter().map(elide_images).collect()),
        Value::Object(m) => Value::Object(
            m.iter()
                .map(|(k, v)| (k.clone(), elide_images(v)))
                .collect(),
        ),
        other => other.clone(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn builds_labelled_frames_and_elides_them() {
        let d = tempfile::tempdir().unwrap();
        let cfg = PromptConfig::load(None).unwrap();
        std::fs::create_dir_all(d.path().join("frames/abcd1234")).unwrap();
        for &t in &cfg.images.times {
            let img = image::RgbImage::from_pixel(1000, 500, image::Rgb([200, 10, 10]));
            img.save(d.path().join(frame_rel_path("abcd1234", "ego", t)))
                .unwrap();
        }
        let p = build(&cfg, d.path(), "abcd1234").unwrap();
        let user = p.messages[1]["content"].as_array().unwrap();
        // intro + (label, image) per frame + outro
        assert_eq!(user.len(), 2 + 2 * cfg.images.times.len());
        assert_eq!(user[1]["text"], "t = 0.00 s (ego camera)");
        assert_eq!(user[9]["text"], "t = 0.60 s (ego camera)");
        let url = user[2]["image_url"]["url"].as_str().unwrap();
        let jpeg = base64::engine::general_purpose::STANDARD
            .decode(url.strip_prefix("data:image/jpeg;base64,").unwrap())
            .unwrap();
        let back = image::load_from_memory(&jpeg).unwrap();
        assert_eq!((back.width(), back.height()), (768, 384));
        let elided = elide_images(&p.messages).to_string();
        assert!(!elided.contains(&url[30..80]));
        assert!(elided.contains("base64 characters elided"));
        assert!(p.messages[0]["content"]
            .as_str()
            .unwrap()
            .contains("0.60 s"));
        let err = build(&cfg, d.path(), "ffffffff").unwrap_err();
        assert!(err.contains("missing observation frame"), "{err}");
    }
}
