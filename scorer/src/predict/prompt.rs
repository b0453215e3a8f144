//! The canonical prompt of one scene (`configs/prompt.toml`): a system message (the
//! observer, the freeze-and-predict protocol, the plan schema with an example) and a user
//! message with the observation frames, each labelled with its time. Frames are the
//! dataset's PNGs `frames/<id>/<cam>_t<t>.png`, scaled down to `max_side` and re-encoded
//! as JPEG, sent as base64 data URLs.

use super::config::PromptConfig;
use base64::Engine;
use serde_json::{json, Value};
use std::path::Path;

/// One scene's messages, ready to send.
#[derive(Debug, Clone)]
pub struct BuiltPrompt {
    pub messages: Value,
    /// CPU seconds the building thread spent on it (decoding, scaling and JPEG-encoding
    /// the frames, base64, the message JSON): thread CPU time, not wall time.
    pub encode_cpu_s: f64,
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

/// CPU seconds used so far by the calling thread (`CLOCK_THREAD_CPUTIME_ID`): what one
/// scene's encoding costs, independent of the machine's load and of other threads.
pub fn thread_cpu_s() -> f64 {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: clock_gettime writes one timespec into a valid pointer.
    let rc = unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut ts) };
    if rc != 0 {
        return 0.0;
    }
    ts.tv_sec as f64 + ts.tv_nsec as f64 * 1e-9
}

/// Pixel buffers reused by every frame a thread encodes (a decoded 1280×720 frame is
/// 2.7 MB: allocating it per frame costs page faults and zeroing, and fragments memory).
#[derive(Default)]
struct Scratch {
    decoded: Vec<u8>,
    rgb: Vec<u8>,
    scaled: Vec<u8>,
}

thread_local! {
    static SCRATCH: std::cell::RefCell<Scratch> = std::cell::RefCell::default();
}

/// Decodes a PNG file into `sc.rgb` as 8-bit RGB (palette and low bit depths expanded,
/// 16-bit stripped, alpha dropped, grey replicated); returns (width, height).
fn decode_png(path: &Path, sc: &mut Scratch) -> Result<(u32, u32), String> {
    let bad = |e: &dyn std::fmt::Display| format!("cannot read frame {}: {e}", path.display());
    let file = std::fs::File::open(path).map_err(|e| bad(&e))?;
    let mut dec = png::Decoder::new(std::io::BufReader::new(file));
    dec.set_transformations(png::Transformations::normalize_to_color8());
    let mut reader = dec.read_info().map_err(|e| bad(&e))?;
    let size = reader
        .output_buffer_size()
        .ok_or_else(|| bad(&"image too large"))?;
    sc.decoded.resize(size, 0);
    let info = reader.next_frame(&mut sc.decoded).map_err(|e| bad(&e))?;
    let px = &sc.decoded[..info.buffer_size()];
    sc.rgb.clear();
    match info.color_type {
        png::ColorType::Rgb => sc.rgb.extend_from_slice(px),
        png::ColorType::Rgba => sc
            .rgb
            .extend(px.chunks_exact(4).flat_map(|p| [p[0], p[1], p[2]])),
        png::ColorType::Grayscale => sc.rgb.extend(px.iter().flat_map(|&g| [g, g, g])),
        png::ColorType::GrayscaleAlpha => sc.rgb.extend(px.chunks_exact(2).flat_map(|p| [p[0]; 3])),
        png::ColorType::Indexed => return Err(bad(&"palette was not expanded")),
    }
    Ok((info.width, info.height))
}

/// Scales `sc.rgb` (w×h) into `sc.scaled` so that its longer side is `max_side`, with a
/// bilinear (triangle) convolution in fixed-point arithmetic: the same bytes on every
/// CPU, with or without SIMD. Returns the new size.
fn scale_down(sc: &mut Scratch, (w, h): (u32, u32), max_side: u32) -> Result<(u32, u32), String> {
    use fast_image_resize as fr;
    let scale = max_side as f64 / w.max(h) as f64;
    let (nw, nh) = (
        ((w as f64 * scale).round() as u32).max(1),
        ((h as f64 * scale).round() as u32).max(1),
    );
    let src = fr::images::ImageRef::new(w, h, &sc.rgb, fr::PixelType::U8x3)
        .map_err(|e| format!("frame buffer: {e}"))?;
    sc.scaled.resize(nw as usize * nh as usize * 3, 0);
    let mut dst = fr::images::Image::from_slice_u8(nw, nh, &mut sc.scaled, fr::PixelType::U8x3)
        .map_err(|e| format!("frame buffer: {e}"))?;
    let opts =
        fr::ResizeOptions::new().resize_alg(fr::ResizeAlg::Convolution(fr::FilterType::Bilinear));
    fr::Resizer::new()
        .resize(&src, &mut dst, &opts)
        .map_err(|e| format!("cannot scale frame: {e}"))?;
    Ok((nw, nh))
}

/// Reads a PNG frame and returns it as JPEG bytes (baseline, 4:2:0 below quality 90) no
/// larger than `max_side`. Deterministic: the scalar JPEG encoder, whose bytes do not
/// depend on the CPU (its AVX2 path rounds differently, so it is not enabled).
pub fn encode_frame(path: &Path, max_side: u32, quality: u8) -> Result<Vec<u8>, String> {
    SCRATCH.with(|sc| {
        let sc = &mut *sc.borrow_mut();
        let (w, h) = decode_png(path, sc)?;
        let (w, h, pixels) = if w.max(h) > max_side {
            let (nw, nh) = scale_down(sc, (w, h), max_side)?;
            (nw, nh, &sc.scaled[..])
        } else {
            (w, h, &sc.rgb[..])
        };
        let too_big = || format!("{}: frame larger than 65535 pixels", path.display());
        let (w, h) = (
            u16::try_from(w).map_err(|_| too_big())?,
            u16::try_from(h).map_err(|_| too_big())?,
        );
        let mut out = Vec::with_capacity(pixels.len() / 8);
        jpeg_encoder::Encoder::new(&mut out, quality.clamp(1, 100))
            .encode(pixels, w, h, jpeg_encoder::ColorType::Rgb)
            .map_err(|e| format!("cannot encode frame {} as JPEG: {e}", path.display()))?;
        Ok(out)
    })
}

/// The messages for one scene of the dataset at `dir`.
pub fn build(cfg: &PromptConfig, dir: &Path, scene_id: &str) -> Result<BuiltPrompt, String> {
    let cpu0 = thread_cpu_s();
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
        encode_cpu_s: (thread_cpu_s() - cpu0).max(0.0),
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

    fn sha256_hex(b: &[u8]) -> String {
        use sha2::Digest;
        sha2::Sha256::digest(b)
            .iter()
            .map(|x| format!("{x:02x}"))
            .collect()
    }

    /// A 1280×720 frame with edges, gradients and flat areas, written as the pipeline
    /// writes frames (RGB, fast deflate, Sub filter).
    fn test_frame(path: &Path) {
        use image::ImageEncoder;
        let img = image::RgbImage::from_fn(1280, 720, |x, y| {
            let c = if (400..900).contains(&x) && (200..500).contains(&y) {
                [60 + (x / 10) as u8, 90, 100]
            } else {
                [
                    (x * 255 / 1279) as u8,
                    (y * 255 / 719) as u8,
                    ((x ^ y) & 0xff) as u8,
                ]
            };
            image::Rgb(c)
        });
        let mut bytes = Vec::new();
        image::codecs::png::PngEncoder::new_with_quality(
            &mut bytes,
            image::codecs::png::CompressionType::Fast,
            image::codecs::png::FilterType::Sub,
        )
        .write_image(&img, 1280, 720, image::ExtendedColorType::Rgb8)
        .unwrap();
        std::fs::write(path, bytes).unwrap();
    }

    /// The JPEG bytes of a frame are pinned: they must not depend on the machine (CPU
    /// features: the scaler's SIMD paths are exact, the JPEG encoder's AVX2 path is off),
    /// the thread or the run, or `prompt_hash` and every cache key would.
    #[test]
    fn frame_bytes_are_pinned_and_thread_independent() {
        let d = tempfile::tempdir().unwrap();
        let f = d.path().join("frame.png");
        test_frame(&f);
        let jpeg = encode_frame(&f, 768, 85).unwrap();
        let back = image::load_from_memory(&jpeg).unwrap();
        assert_eq!((back.width(), back.height()), (768, 432));
        assert_eq!(
            sha256_hex(&jpeg),
            "f53749249d89181173ce06585509ac72129015222f05a3066286c540596a3de3",
            "the frame encoder's bytes changed: bump the prompt version in configs/prompt.toml"
        );
        let others: Vec<Vec<u8>> = std::thread::scope(|s| {
            let hs: Vec<_> = (0..4)
                .map(|_| s.spawn(|| encode_frame(&f, 768, 85).unwrap()))
                .collect();
            hs.into_iter().map(|h| h.join().unwrap()).collect()
        });
        assert!(others.iter().all(|o| *o == jpeg));
        // The scaler's SIMD path (this CPU's best) gives the scalar path's bytes.
        let mut sc = Scratch::default();
        let (w, h) = decode_png(&f, &mut sc).unwrap();
        let size = scale_down(&mut sc, (w, h), 768).unwrap();
        use fast_image_resize as fr;
        let src = fr::images::ImageRef::new(w, h, &sc.rgb, fr::PixelType::U8x3).unwrap();
        let mut scalar = fr::images::Image::new(size.0, size.1, fr::PixelType::U8x3);
        let mut rs = fr::Resizer::new();
        // SAFETY: `None` (plain Rust) is supported on every CPU.
        unsafe { rs.set_cpu_extensions(fr::CpuExtensions::None) };
        let opts = fr::ResizeOptions::new()
            .resize_alg(fr::ResizeAlg::Convolution(fr::FilterType::Bilinear));
        rs.resize(&src, &mut scalar, &opts).unwrap();
        assert!(scalar.buffer() == &sc.scaled[..]);
        // Grey and RGBA PNGs are read too (as RGB), and small frames are not upscaled.
        let g = d.path().join("grey.png");
        image::GrayImage::from_pixel(300, 200, image::Luma([90]))
            .save(&g)
            .unwrap();
        let back = image::load_from_memory(&encode_frame(&g, 768, 85).unwrap()).unwrap();
        assert_eq!((back.width(), back.height()), (300, 200));
        let a = d.path().join("rgba.png");
        image::RgbaImage::from_pixel(1000, 400, image::Rgba([10, 200, 30, 128]))
            .save(&a)
            .unwrap();
        let back = image::load_from_memory(&encode_frame(&a, 500, 85).unwrap())
            .unwrap()
            .to_rgb8();
        assert_eq!(back.dimensions(), (500, 200));
        let p = back.get_pixel(250, 100).0;
        assert!(p[1] > 180 && p[0] < 40 && p[2] < 60, "{p:?}");
        let bad = d.path().join("bad.png");
        std::fs::write(&bad, b"not a png").unwrap();
        assert!(encode_frame(&bad, 768, 85)
            .unwrap_err()
            .contains("cannot read frame"));
    }
}
