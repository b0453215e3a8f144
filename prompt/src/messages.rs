//! The canonical prompt of one scene (`configs/prompt.toml`): a system message (the
//! observer, the freeze-and-predict protocol, the plan schema with an example) and a user
//! message with the observation frames, each labelled with its time. Frames are the
//! dataset's PNGs `frames/<id>/<cam>_t<t>.png`, scaled down to `max_side` and re-encoded
//! as JPEG, sent as base64 data URLs.

use crate::config::{subsampling, PromptConfig};
use base64::Engine;
use rh_contract::camera::HeadCamera;
use serde_json::{json, Value};
use std::path::{Path, PathBuf};

/// Why a scene's prompt cannot be built.
#[derive(Debug, thiserror::Error)]
pub enum PromptError {
    /// An observation frame is not on disk (a label-only build has none).
    #[error(
        "missing observation frame {} (was the dataset built with rendering? \
         `rh-pipeline build` without --no-render writes frames/)",
        .0.display()
    )]
    MissingFrame(PathBuf),
    /// A frame that cannot be read or encoded, a spec without its head camera, an unknown
    /// setting: the message names the file or the setting.
    #[error("{0}")]
    Invalid(String),
}

impl From<String> for PromptError {
    fn from(message: String) -> PromptError {
        PromptError::Invalid(message)
    }
}

/// For callers whose errors are text (the export's examples).
impl From<PromptError> for String {
    fn from(e: PromptError) -> String {
        e.to_string()
    }
}

/// One scene's messages, ready to send.
#[derive(Debug, Clone)]
pub struct BuiltPrompt {
    pub messages: Value,
    /// CPU seconds the building thread spent on it (decoding, scaling and JPEG-encoding
    /// the frames, base64, the message JSON): thread CPU time, not wall time.
    pub encode_cpu_s: f64,
}

/// `frames/<id>/<cam>_t0.150.png` (the data contract's naming, specification §8).
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
    jpeg: Vec<u8>,
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
    let n = info.buffer_size();
    if info.color_type == png::ColorType::Rgb {
        // Already RGB: the decoded buffer becomes the frame (no copy).
        sc.decoded.truncate(n);
        std::mem::swap(&mut sc.decoded, &mut sc.rgb);
    } else {
        let px = &sc.decoded[..n];
        sc.rgb.clear();
        match info.color_type {
            png::ColorType::Rgba => sc
                .rgb
                .extend(px.chunks_exact(4).flat_map(|p| [p[0], p[1], p[2]])),
            png::ColorType::Grayscale => sc.rgb.extend(px.iter().flat_map(|&g| [g, g, g])),
            png::ColorType::GrayscaleAlpha => {
                sc.rgb.extend(px.chunks_exact(2).flat_map(|p| [p[0]; 3]))
            }
            other => return Err(bad(&format!("unexpected colour type {other:?}"))),
        }
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

thread_local! {
    static COMPRESSOR: std::cell::RefCell<Option<turbojpeg::Compressor>> =
        const { std::cell::RefCell::new(None) };
}

/// JPEG-encodes packed 8-bit RGB (w×h) with libjpeg-turbo into `out`: baseline, the
/// standard's Huffman tables, the accurate integer DCT (`JDCT_ISLOW`; the fast and float
/// DCTs are off), libjpeg's quality scaling. libjpeg-turbo's SIMD paths for this
/// configuration (colour conversion, downsampling, DCT, quantisation, Huffman coding) write
/// the bytes its C path writes, so the result does not depend on the CPU (tested with
/// `JSIMD_FORCENONE` / `JSIMD_FORCESSE2` in a child process). Returns the JPEG's length.
fn encode_jpeg(
    pixels: &[u8],
    (w, h): (u32, u32),
    quality: u8,
    sub: turbojpeg::Subsamp,
    out: &mut Vec<u8>,
) -> Result<usize, String> {
    let bad = |e: turbojpeg::Error| format!("JPEG encoder: {e}");
    COMPRESSOR.with(|c| {
        let mut slot = c.borrow_mut();
        if slot.is_none() {
            *slot = Some(turbojpeg::Compressor::new().map_err(bad)?);
        }
        let comp = slot.as_mut().expect("compressor was just created");
        comp.set_quality(quality.clamp(1, 100) as i32)
            .map_err(bad)?;
        comp.set_subsamp(sub).map_err(bad)?;
        comp.set_optimize(false).map_err(bad)?;
        comp.set_progressive(false).map_err(bad)?;
        comp.set_arithmetic(false).map_err(bad)?;
        let image = turbojpeg::Image {
            pixels,
            width: w as usize,
            pitch: w as usize * 3,
            height: h as usize,
            format: turbojpeg::PixelFormat::RGB,
        };
        // The worst-case size, allocated once per thread and size.
        out.resize(comp.buf_len(w as usize, h as usize).map_err(bad)?, 0);
        comp.compress_to_slice(image, out).map_err(bad)
    })
}

/// Reads a PNG frame and returns it as JPEG bytes no larger than `max_side` (see
/// [`encode_jpeg`]). Deterministic: the same bytes on every CPU, thread and run.
pub fn encode_frame(
    path: &Path,
    max_side: u32,
    quality: u8,
    sub: turbojpeg::Subsamp,
) -> Result<Vec<u8>, String> {
    SCRATCH.with(|sc| {
        let sc = &mut *sc.borrow_mut();
        let (w, h) = decode_png(path, sc)?;
        let (size, pixels) = if w.max(h) > max_side {
            let size = scale_down(sc, (w, h), max_side)?;
            (size, &sc.scaled[..])
        } else {
            ((w, h), &sc.rgb[..])
        };
        let n = encode_jpeg(pixels, size, quality, sub, &mut sc.jpeg)
            .map_err(|e| format!("cannot encode frame {} as JPEG: {e}", path.display()))?;
        Ok(sc.jpeg[..n].to_vec())
    })
}

/// Thread CPU seconds of each stage of [`encode_frame`] for one frame: PNG decode, scaling,
/// JPEG (the benchmark's breakdown of the prompt-building cost).
pub fn frame_stage_cpu_s(
    path: &Path,
    max_side: u32,
    quality: u8,
    sub: turbojpeg::Subsamp,
) -> Result<[f64; 3], String> {
    SCRATCH.with(|sc| {
        let sc = &mut *sc.borrow_mut();
        let t0 = thread_cpu_s();
        let (w, h) = decode_png(path, sc)?;
        let t1 = thread_cpu_s();
        let size = scale_down(sc, (w, h), max_side.min(w.max(h)))?;
        let t2 = thread_cpu_s();
        encode_jpeg(&sc.scaled, size, quality, sub, &mut sc.jpeg)?;
        Ok([t1 - t0, t2 - t1, thread_cpu_s() - t2])
    })
}

/// One part of the canonical user message, in order.
#[derive(Debug, Clone, PartialEq)]
pub enum UserPart {
    Text(String),
    /// The observation frame of `camera` at `t` (s): `frames/<id>/<camera>_t<t>.png`.
    Frame {
        camera: String,
        t: f64,
    },
}

/// The canonical user message's parts: the scene's head camera calibration
/// (`camera::camera_text`), the intro, then per time and camera the frame's label and the
/// frame, then the outro. [`build`] sends them (frames as JPEG data URLs); `rh-score
/// export` writes them as training examples (text-only: the texts alone).
pub fn user_parts(cfg: &PromptConfig, camera: &HeadCamera) -> Vec<UserPart> {
    let mut parts = vec![
        UserPart::Text(crate::camera::camera_text(cfg, camera)),
        UserPart::Text(fill(&cfg.text.user_intro, cfg)),
    ];
    for &t in &cfg.images.times {
        for cam in &cfg.images.cameras {
            let label = cfg
                .text
                .frame_label
                .replace("{t}", &format!("{t:.2}"))
                .replace("{camera}", cam);
            parts.push(UserPart::Text(label));
            parts.push(UserPart::Frame {
                camera: cam.clone(),
                t,
            });
        }
    }
    parts.push(UserPart::Text(fill(&cfg.text.user_outro, cfg)));
    parts
}

/// The frame file of a [`UserPart::Frame`], or an error naming it when it is missing.
pub fn frame_file(
    dir: &Path,
    scene_id: &str,
    camera: &str,
    t: f64,
) -> Result<PathBuf, PromptError> {
    let path = dir.join(frame_rel_path(scene_id, camera, t));
    if !path.is_file() {
        return Err(PromptError::MissingFrame(path));
    }
    Ok(path)
}

/// The frame encoder's chroma subsampling from the prompt configuration.
pub fn subsampling_of(cfg: &PromptConfig) -> Result<turbojpeg::Subsamp, String> {
    subsampling(&cfg.images.chroma_subsampling).ok_or_else(|| {
        format!(
            "unknown chroma subsampling {:?}",
            cfg.images.chroma_subsampling
        )
    })
}

/// The messages for one scene of the dataset at `dir`.
pub fn build(cfg: &PromptConfig, dir: &Path, scene_id: &str) -> Result<BuiltPrompt, PromptError> {
    let cpu0 = thread_cpu_s();
    let sub = subsampling_of(cfg)?;
    let camera = crate::camera::scene_camera(dir, scene_id)?;
    let mut content = Vec::new();
    for part in user_parts(cfg, &camera) {
        match part {
            UserPart::Text(text) => content.push(json!({"type": "text", "text": text})),
            UserPart::Frame { camera, t } => {
                let path = frame_file(dir, scene_id, &camera, t)?;
                let jpeg = encode_frame(&path, cfg.images.max_side, cfg.images.jpeg_quality, sub)?;
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
    }
    let messages = json!([
        {"role": "system", "content": system_text(cfg)},
        {"role": "user", "content": content},
    ]);
    Ok(BuiltPrompt {
        messages,
        encode_cpu_s: (thread_cpu_s() - cpu0).max(0.0),
    })
}

/// `prompt_hash`: the SHA-256 (hex) of the messages JSON exactly as sent (the prompt text
/// and the image bytes inside their data URLs; model and generation parameters are not
/// part of it) — what `rh_llm::ChatRequest::prompt_hash` records (a test holds the two
/// equal).
pub fn prompt_hash(messages: &Value) -> String {
    rh_contract::digest::sha256_hex(messages.to_string().as_bytes())
}

/// One scene's canonical messages and their [`prompt_hash`] — the hash `rh-score predict`
/// records and `--dry-run` prints.
pub fn canonical(
    cfg: &PromptConfig,
    dir: &Path,
    scene_id: &str,
) -> Result<(Value, String), PromptError> {
    let built = build(cfg, dir, scene_id)?;
    let hash = prompt_hash(&built.messages);
    Ok((built.messages, hash))
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
    fn prompt_hash_is_the_clients() {
        let m = json!([{"role": "user", "content": [{"type": "text", "text": "é \"x\""}]}]);
        let client = rh_llm::ChatRequest::new("m", m.clone(), Default::default(), 3);
        assert_eq!(prompt_hash(&m), client.prompt_hash());
        assert_ne!(prompt_hash(&m), prompt_hash(&json!([])));
    }

    /// The canonical prompt's body numbers are the scorer's and executor's (rh-prompt-v4
    /// tells the model what knee_bend does; action rule v2 and `--execute` do just that).
    #[test]
    fn the_prompt_states_the_scoring_body() {
        let cfg = PromptConfig::load(None).unwrap();
        let text = system_text(&cfg);
        let c = rh_grade::config::Config::default();
        let drop = c.execution.max_pelvis_drop;
        assert!(
            text.contains(&format!("by knee_bend x {drop:.2} m")),
            "{text}"
        );
        let low = c.body.pelvis_height - drop;
        assert!(
            text.contains(&format!("{low:.2} m above the floor")),
            "{text}"
        );
        assert!(text.contains(&format!("pelvis {:.2} m", c.body.pelvis_height)));
    }

    #[test]
    fn builds_labelled_frames_and_elides_them() {
        let d = tempfile::tempdir().unwrap();
        let cfg = PromptConfig::load(None).unwrap();
        std::fs::create_dir_all(d.path().join("frames/abcd1234")).unwrap();
        std::fs::create_dir_all(d.path().join("specs")).unwrap();
        let spec = serde_json::json!({
            "cameras": [{"name": "ego", "position": [0.0, 0.0, 1.24],
                         "look_at": [1.0, 0.0, 1.0], "fov_y": 1.0, "width": 1000, "height": 500}],
            "observer": {"x": 0.0, "y": 0.0, "yaw": 0.0, "pelvis_z": 0.79}
        });
        std::fs::write(d.path().join("specs/abcd1234.json"), spec.to_string()).unwrap();
        for &t in &cfg.images.times {
            let img = image::RgbImage::from_pixel(1000, 500, image::Rgb([200, 10, 10]));
            img.save(d.path().join(frame_rel_path("abcd1234", "ego", t)))
                .unwrap();
        }
        let p = build(&cfg, d.path(), "abcd1234").unwrap();
        let user = p.messages[1]["content"].as_array().unwrap();
        // camera + intro + (label, image) per frame + outro
        assert_eq!(user.len(), 3 + 2 * cfg.images.times.len());
        let camera = user[0]["text"].as_str().unwrap();
        assert!(
            camera.contains("768 x 384") && camera.contains("57.3° vertical"),
            "{camera}"
        );
        assert_eq!(user[2]["text"], "t = 0.00 s (ego camera)");
        assert_eq!(user[10]["text"], "t = 0.60 s (ego camera)");
        let url = user[3]["image_url"]["url"].as_str().unwrap();
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
        std::fs::copy(
            d.path().join("specs/abcd1234.json"),
            d.path().join("specs/ffffffff.json"),
        )
        .unwrap();
        let err = build(&cfg, d.path(), "ffffffff").unwrap_err();
        assert!(matches!(err, PromptError::MissingFrame(_)), "{err}");
        assert!(
            err.to_string().contains("missing observation frame"),
            "{err}"
        );
        let err = build(&cfg, d.path(), "eeeeeeee").unwrap_err();
        assert!(matches!(err, PromptError::Invalid(_)), "{err}");
        assert!(
            err.to_string().contains("cannot read the scene's spec"),
            "{err}"
        );
    }

    /// [`test_frame`] as `frame.png` in a new temporary directory.
    fn test_frame_in_tempdir() -> (tempfile::TempDir, std::path::PathBuf) {
        let d = tempfile::tempdir().unwrap();
        let f = d.path().join("frame.png");
        test_frame(&f);
        (d, f)
    }

    /// A 1280×720 frame with edges, gradients and flat areas, written as the pipeline
    /// writes frames (RGB, fast deflate, Sub filter).
    fn test_frame(path: &Path) {
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
        rh_contract::png::write_png(path, &img, 1280, 720, rh_contract::png::PngColor::Rgb8)
            .unwrap();
    }

    const SUB: turbojpeg::Subsamp = turbojpeg::Subsamp::Sub2x2;

    /// Set in the child process of `jpeg_bytes_do_not_depend_on_simd`: the frame to
    /// encode and the file to write its JPEG bytes to.
    const CHILD_ENV: &str = "RH_TEST_ENCODE_CHILD";

    /// Runs only as the child of `jpeg_bytes_do_not_depend_on_simd` (libjpeg-turbo reads
    /// `JSIMD_FORCE*` once per thread, so another SIMD path needs another process).
    #[test]
    #[ignore]
    fn encode_child() {
        let Ok(arg) = std::env::var(CHILD_ENV) else {
            return;
        };
        let (frame, out) = arg.split_once('\n').unwrap();
        let jpeg = encode_frame(Path::new(frame), 768, 85, SUB).unwrap();
        std::fs::write(out, jpeg).unwrap();
    }

    /// The JPEG bytes of a frame are pinned: they must not depend on the machine (CPU
    /// features), the thread or the run, or `prompt_hash` and every cache key would.
    #[test]
    fn frame_bytes_are_pinned_and_thread_independent() {
        let (_d, f) = test_frame_in_tempdir();
        let jpeg = encode_frame(&f, 768, 85, SUB).unwrap();
        let back = image::load_from_memory(&jpeg).unwrap();
        assert_eq!((back.width(), back.height()), (768, 432));
        assert_eq!(
            rh_contract::digest::sha256_hex(&jpeg),
            "1d1464c2357283ebefd1ee065bc71d26269bee8997e300c8029f14987c480fde",
            "the frame encoder's bytes changed: bump the prompt version in configs/prompt.toml"
        );
        let others: Vec<Vec<u8>> = std::thread::scope(|s| {
            let hs: Vec<_> = (0..4)
                .map(|_| s.spawn(|| encode_frame(&f, 768, 85, SUB).unwrap()))
                .collect();
            hs.into_iter().map(|h| h.join().unwrap()).collect()
        });
        assert!(others.iter().all(|o| *o == jpeg));
        // 4:4:4 is another encoding of the same frame.
        let full = encode_frame(&f, 768, 85, turbojpeg::Subsamp::None).unwrap();
        assert_ne!(full, jpeg);
        assert_eq!(image::load_from_memory(&full).unwrap().width(), 768);
    }

    /// libjpeg-turbo's SIMD paths (AVX2 and SSE2 on x86-64) write the bytes of its plain C
    /// path: the same frame encoded in child processes with `JSIMD_FORCENONE=1` (C only),
    /// `JSIMD_FORCESSE2=1`, `JSIMD_FORCEAVX2=1` and `JSIMD_NOHUFFENC=1` (C Huffman coder)
    /// gives this process's bytes (its best SIMD).
    #[test]
    fn jpeg_bytes_do_not_depend_on_simd() {
        let (d, f) = test_frame_in_tempdir();
        let here = encode_frame(&f, 768, 85, SUB).unwrap();
        for (i, force) in [
            "JSIMD_FORCENONE",
            "JSIMD_FORCESSE2",
            "JSIMD_FORCEAVX2",
            "JSIMD_NOHUFFENC",
        ]
        .iter()
        .enumerate()
        {
            let out = d.path().join(format!("child{i}.jpg"));
            let st = std::process::Command::new(std::env::current_exe().unwrap())
                .args(["--exact", "messages::tests::encode_child", "--ignored"])
                .env(CHILD_ENV, format!("{}\n{}", f.display(), out.display()))
                .env(force, "1")
                .stdout(std::process::Stdio::null())
                .status()
                .unwrap();
            assert!(st.success(), "child with {force}=1 failed");
            let child = std::fs::read(&out).unwrap();
            assert!(child == here, "{force}=1 gives other JPEG bytes");
        }
    }

    /// The scaler gives the same bytes on every CPU extension this machine has (plain
    /// Rust, SSE4.1, AVX2 on x86-64), so its default (the best one) is safe.
    #[test]
    fn scaling_does_not_depend_on_simd() {
        use fast_image_resize as fr;
        let (_d, f) = test_frame_in_tempdir();
        let mut sc = Scratch::default();
        let (w, h) = decode_png(&f, &mut sc).unwrap();
        let size = scale_down(&mut sc, (w, h), 768).unwrap();
        let src = fr::images::ImageRef::new(w, h, &sc.rgb, fr::PixelType::U8x3).unwrap();
        let opts = fr::ResizeOptions::new()
            .resize_alg(fr::ResizeAlg::Convolution(fr::FilterType::Bilinear));
        let mut exts = vec![fr::CpuExtensions::None];
        #[cfg(target_arch = "x86_64")]
        exts.extend([fr::CpuExtensions::Sse4_1, fr::CpuExtensions::Avx2]);
        #[cfg(target_arch = "aarch64")]
        exts.push(fr::CpuExtensions::Neon);
        for ext in exts.into_iter().filter(|e| e.is_supported()) {
            let mut out = fr::images::Image::new(size.0, size.1, fr::PixelType::U8x3);
            let mut rs = fr::Resizer::new();
            // SAFETY: only extensions this CPU supports.
            unsafe { rs.set_cpu_extensions(ext) };
            rs.resize(&src, &mut out, &opts).unwrap();
            assert!(out.buffer() == &sc.scaled[..], "{ext:?} scales differently");
        }
    }

    /// Grey and RGBA PNGs are read too (as RGB), small frames are not upscaled, and a
    /// file that is not a PNG is an error naming it.
    #[test]
    fn other_png_kinds_and_bad_files() {
        let d = tempfile::tempdir().unwrap();
        let g = d.path().join("grey.png");
        image::GrayImage::from_pixel(300, 200, image::Luma([90]))
            .save(&g)
            .unwrap();
        let back = image::load_from_memory(&encode_frame(&g, 768, 85, SUB).unwrap()).unwrap();
        assert_eq!((back.width(), back.height()), (300, 200));
        let a = d.path().join("rgba.png");
        image::RgbaImage::from_pixel(1000, 400, image::Rgba([10, 200, 30, 128]))
            .save(&a)
            .unwrap();
        let back = image::load_from_memory(&encode_frame(&a, 500, 85, SUB).unwrap())
            .unwrap()
            .to_rgb8();
        assert_eq!(back.dimensions(), (500, 200));
        let p = back.get_pixel(250, 100).0;
        assert!(p[1] > 180 && p[0] < 40 && p[2] < 60, "{p:?}");
        let bad = d.path().join("bad.png");
        std::fs::write(&bad, b"not a png").unwrap();
        let err = encode_frame(&bad, 768, 85, SUB).unwrap_err();
        assert!(
            err.contains("cannot read frame") && err.contains("bad.png"),
            "{err}"
        );
    }
}
