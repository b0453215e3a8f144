//! H.264 (libx264) yuv420p MP4 writing with ffmpeg-next: RGBA frames in, a
//! browser-playable file (`+faststart`) out, written to a temporary sibling and renamed.
//! Without the crate's `video` feature (no FFmpeg linked: the Python wheel's ego camera)
//! the encoder is `encode_off`'s, which refuses at [`init`] and never writes a file.

#[cfg(not(feature = "video"))]
pub use super::encode_off::{init, Mp4Writer};
#[cfg(feature = "video")]
use ffmpeg_next as ff;
#[cfg(feature = "video")]
use std::path::Path;
use std::path::PathBuf;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::mpsc::{sync_channel, SyncSender};
#[cfg(feature = "video")]
use std::sync::Once;
use std::thread::JoinHandle;

/// Encoder settings (from `[render]`).
#[derive(Debug, Clone)]
pub struct EncodeSettings {
    pub preset: String,
    pub crf: u32,
    /// libx264 threads per video (0 = libx264's automatic choice).
    pub threads: u32,
    /// B-frames between reference frames (libx264's `bframes`).
    pub bframes: u32,
}

#[cfg(feature = "video")]
static INIT: Once = Once::new();

#[cfg(feature = "video")]
pub fn init() -> Result<(), String> {
    let mut err = None;
    INIT.call_once(|| {
        if let Err(e) = ff::init() {
            err = Some(e.to_string());
        }
        ff::util::log::set_level(ff::util::log::Level::Error);
    });
    match err {
        Some(e) => Err(format!("ffmpeg init: {e}")),
        None => Ok(()),
    }
}

/// `rgba` (tightly packed, `width` × `height`) into the planes of `yuv` (4:2:0, through
/// `planes`, tightly packed scratch planes): BT.601 limited range, as swscale converted
/// before and players assume for these videos.
#[cfg(feature = "video")]
fn to_yuv420(
    rgba: &[u8],
    (width, height): (u32, u32),
    planes: &mut [Vec<u8>; 3],
    yuv: &mut ff::frame::Video,
) -> Result<(), String> {
    let cw = width.div_ceil(2);
    let [y, u, v] = planes;
    let mut image = yuv::YuvPlanarImageMut {
        y_plane: yuv::BufferStoreMut::Borrowed(y),
        y_stride: width,
        u_plane: yuv::BufferStoreMut::Borrowed(u),
        u_stride: cw,
        v_plane: yuv::BufferStoreMut::Borrowed(v),
        v_stride: cw,
        width,
        height,
    };
    yuv::rgba_to_yuv420(
        &mut image,
        rgba,
        width * 4,
        yuv::YuvRange::Limited,
        yuv::YuvStandardMatrix::Bt601,
        yuv::YuvConversionMode::Balanced,
    )
    .map_err(|e| format!("RGBA to YUV: {e}"))?;
    for (p, plane) in planes.iter().enumerate() {
        let row = if p == 0 { width } else { cw } as usize;
        let stride = yuv.stride(p);
        let data = yuv.data_mut(p);
        for (r, src) in plane.chunks_exact(row).enumerate() {
            data[r * stride..][..row].copy_from_slice(src);
        }
    }
    Ok(())
}

/// One MP4 being written.
#[cfg(feature = "video")]
pub struct Mp4Writer {
    octx: ff::format::context::Output,
    encoder: ff::encoder::Video,
    yuv: ff::frame::Video,
    /// Y, U and V converted from a frame, tightly packed (`to_yuv420`).
    planes: [Vec<u8>; 3],
    enc_tb: ff::Rational,
    width: u32,
    height: u32,
    frames: i64,
    /// Set by `finish`: the temporary file is now the caller's to rename.
    done: bool,
    tmp: PathBuf,
    path: PathBuf,
}

#[cfg(feature = "video")]
fn fferr(what: &str, e: ff::Error) -> String {
    format!("{what}: {e}")
}

#[cfg(feature = "video")]
impl Mp4Writer {
    pub fn create(
        path: &Path,
        width: u32,
        height: u32,
        fps: u32,
        settings: &EncodeSettings,
    ) -> Result<Mp4Writer, String> {
        init()?;
        let dir = path.parent().unwrap_or(Path::new("."));
        std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
        let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("video");
        static COUNTER: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
        let n = COUNTER.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        let tmp = dir.join(format!(".{name}.{}.{n}.tmp.mp4", std::process::id()));
        let mut octx = ff::format::output_as(&tmp, "mp4")
            .map_err(|e| fferr(&format!("open {}", tmp.display()), e))?;
        let codec = ff::encoder::find_by_name("libx264")
            .or_else(|| ff::encoder::find(ff::codec::Id::H264))
            .ok_or("no H.264 encoder in this FFmpeg build (install libavcodec with libx264)")?;
        let global_header = octx
            .format()
            .flags()
            .contains(ff::format::Flags::GLOBAL_HEADER);
        let mut enc = ff::codec::context::Context::new_with_codec(codec)
            .encoder()
            .video()
            .map_err(|e| fferr("video encoder", e))?;
        let enc_tb = ff::Rational::new(1, fps as i32);
        enc.set_width(width);
        enc.set_height(height);
        enc.set_format(ff::format::Pixel::YUV420P);
        // What the samples are, written into the stream so that players and ffprobe
        // need not guess: the renderer's sRGB pixels (BT.709 primaries, the sRGB
        // transfer curve) converted by `to_yuv420` with the BT.601 matrix (SMPTE 170M)
        // into limited range.
        enc.set_colorspace(ff::color::Space::SMPTE170M);
        enc.set_color_range(ff::color::Range::MPEG);
        enc.set_color_primaries(ff::color::Primaries::BT709);
        enc.set_color_transfer_characteristic(ff::color::TransferCharacteristic::IEC61966_2_1);
        enc.set_time_base(enc_tb);
        enc.set_frame_rate(Some(ff::Rational::new(fps as i32, 1)));
        enc.set_gop(fps.max(1) * 2);
        if global_header {
            enc.set_flags(ff::codec::Flags::GLOBAL_HEADER);
        }
        let mut opts = ff::Dictionary::new();
        opts.set("preset", &settings.preset);
        opts.set("crf", &settings.crf.to_string());
        opts.set("profile", "high");
        // Macroblock-tree rate control off: with it, libx264 (r3095, Debian's) reads past
        // the end of a lookahead buffer (valgrind: "invalid read of size 16"), so a
        // video's bytes depended on whatever memory lay there — different bitstreams
        // for identical frames when scenes were encoded concurrently. Without it the
        // encoder reads only what it wrote, and a build's videos are reproducible byte
        // for byte (tested by merging shards and resuming killed builds).
        opts.set(
            "x264-params",
            &format!("mbtree=0:bframes={}", settings.bframes),
        );
        if settings.threads > 0 {
            opts.set("threads", &settings.threads.to_string());
        }
        let encoder = enc.open_with(opts).map_err(|e| fferr("open libx264", e))?;
        {
            let mut st = octx.add_stream(codec).map_err(|e| fferr("add stream", e))?;
            st.set_parameters(&encoder);
            st.set_time_base(enc_tb);
            st.set_rate(ff::Rational::new(fps as i32, 1));
            st.set_avg_frame_rate(ff::Rational::new(fps as i32, 1));
        }
        let mut mopts = ff::Dictionary::new();
        mopts.set("movflags", "+faststart");
        octx.write_header_with(mopts)
            .map_err(|e| fferr("write mp4 header", e))?;
        // FFmpeg leaves frame buffers uninitialised, row padding included: zeroed, so
        // nothing but the pixels can reach the encoder.
        let mut yuv = ff::frame::Video::new(ff::format::Pixel::YUV420P, width, height);
        for plane in 0..3 {
            yuv.data_mut(plane).fill(0);
        }
        Ok(Mp4Writer {
            octx,
            encoder,
            yuv,
            planes: {
                let (cw, ch) = (width.div_ceil(2) as usize, height.div_ceil(2) as usize);
                [
                    vec![0; (width * height) as usize],
                    vec![0; cw * ch],
                    vec![0; cw * ch],
                ]
            },
            enc_tb,
            width,
            height,
            frames: 0,
            done: false,
            tmp,
            path: path.to_path_buf(),
        })
    }

    /// Appends one tightly packed RGBA frame.
    pub fn push(&mut self, rgba: &[u8]) -> Result<(), String> {
        let row = self.width as usize * 4;
        if rgba.len() != row * self.height as usize {
            return Err(format!(
                "frame of {} bytes, expected {}",
                rgba.len(),
                row * self.height as usize
            ));
        }
        to_yuv420(
            rgba,
            (self.width, self.height),
            &mut self.planes,
            &mut self.yuv,
        )?;
        self.yuv.set_pts(Some(self.frames));
        self.frames += 1;
        self.encoder
            .send_frame(&self.yuv)
            .map_err(|e| fferr("encode", e))?;
        self.drain()
    }

    fn drain(&mut self) -> Result<(), String> {
        let st_tb = self
            .octx
            .stream(0)
            .map(|s| s.time_base())
            .unwrap_or(self.enc_tb);
        let mut packet = ff::Packet::empty();
        while self.encoder.receive_packet(&mut packet).is_ok() {
            packet.set_stream(0);
            // The duration must be set before rescaling, or the file ends a frame short.
            packet.set_duration(1);
            packet.rescale_ts(self.enc_tb, st_tb);
            packet
                .write_interleaved(&mut self.octx)
                .map_err(|e| fferr("write packet", e))?;
        }
        Ok(())
    }

    /// Flushes the encoder, writes the trailer, syncs and renames into place.
    pub fn finish(mut self) -> Result<u32, String> {
        self.encoder.send_eof().map_err(|e| fferr("flush", e))?;
        self.drain()?;
        self.octx
            .write_trailer()
            .map_err(|e| fferr("write mp4 trailer", e))?;
        let frames = self.frames as u32;
        let (tmp, path) = (self.tmp.clone(), self.path.clone());
        self.done = true;
        drop(self);
        let result = std::fs::File::open(&tmp)
            .and_then(|f| f.sync_all())
            .and_then(|_| std::fs::rename(&tmp, &path));
        if let Err(e) = result {
            let _ = std::fs::remove_file(&tmp);
            return Err(format!("{}: {e}", path.display()));
        }
        Ok(frames)
    }
}

#[cfg(feature = "video")]
impl Drop for Mp4Writer {
    fn drop(&mut self) {
        // A writer dropped without `finish` leaves no partial file behind.
        if !self.done {
            let _ = std::fs::remove_file(&self.tmp);
        }
    }
}

/// Frame buffers handed back by the encoder threads for the renderer to fill again: a
/// 720p frame is 3.7 MB, and allocating one per frame costs page faults and zeroing.
#[derive(Clone, Default)]
pub struct FramePool(std::sync::Arc<std::sync::Mutex<Vec<Vec<u8>>>>);

impl FramePool {
    /// Most buffers kept (a cap: the pool holds what was in flight at once, per video
    /// `QUEUED` + one being encoded + one being drawn). Each kept 720p buffer is 3.7 MB of
    /// resident memory per worker (48 of them were 177 MB).
    const KEEP: usize = 16;

    /// A buffer of `len` bytes (contents unspecified: the caller overwrites all of it).
    /// Kept buffers of another size (an earlier video's) are freed first when none of
    /// this size is left: the videos of a scene run one after the other, so they would
    /// only sit idle while this one's are in use.
    pub fn take(&self, len: usize) -> Vec<u8> {
        let mut free = self.0.lock().unwrap_or_else(|e| e.into_inner());
        match free.iter().position(|b| b.len() == len) {
            Some(i) => free.swap_remove(i),
            None => {
                free.clear();
                vec![0; len]
            }
        }
    }

    /// Frees every kept buffer (at the end of a scene).
    pub fn clear(&self) {
        self.0.lock().unwrap_or_else(|e| e.into_inner()).clear();
    }

    pub fn give(&self, buffer: Vec<u8>) {
        let mut free = self.0.lock().unwrap_or_else(|e| e.into_inner());
        if free.len() < Self::KEEP {
            free.push(buffer);
        }
    }
}

/// CPU time spent by encoder threads (RGBA → YUV conversion, libx264, MP4 writing), in
/// microseconds, summed over every video this process finished.
static ENCODE_CPU_US: AtomicU64 = AtomicU64::new(0);

/// CPU seconds the encoder threads of this process have spent so far (the render bench's
/// encode-only bound). Linux only (`/proc`); 0 elsewhere.
pub fn encode_cpu_seconds() -> f64 {
    ENCODE_CPU_US.load(Ordering::Relaxed) as f64 / 1e6
}

/// This thread's user + system CPU time (s), from `/proc/thread-self/stat` (clock ticks).
fn thread_cpu_seconds() -> f64 {
    let Ok(stat) = std::fs::read_to_string("/proc/thread-self/stat") else {
        return 0.0;
    };
    // Fields after the command name in parentheses: utime and stime are the 12th and 13th.
    let rest = stat.rsplit(')').next().unwrap_or("");
    let f: Vec<&str> = rest.split_whitespace().collect();
    let ticks = |i: usize| f.get(i).and_then(|v| v.parse::<f64>().ok()).unwrap_or(0.0);
    (ticks(11) + ticks(12)) / 100.0
}

/// Frames queued per video beyond the one being encoded: enough to keep the encoder
/// busy while the next frame is drawn; each is 3.7 MB at 720p.
const QUEUED: usize = 1;

/// A video encoded on its own thread: frames are sent through a bounded channel, so
/// rendering (this thread) overlaps with encoding (that one).
pub struct VideoJob {
    tx: Option<SyncSender<Vec<u8>>>,
    handle: Option<JoinHandle<Result<u32, String>>>,
}

impl VideoJob {
    pub fn spawn(
        path: PathBuf,
        width: u32,
        height: u32,
        fps: u32,
        settings: EncodeSettings,
        pool: FramePool,
    ) -> VideoJob {
        let (tx, rx) = sync_channel::<Vec<u8>>(QUEUED);
        let handle = std::thread::Builder::new()
            .name("rh-encode".into())
            .spawn(move || {
                let start = thread_cpu_seconds();
                let written = (|| {
                    let mut writer = Mp4Writer::create(&path, width, height, fps, &settings)?;
                    for frame in rx {
                        writer.push(&frame)?;
                        pool.give(frame);
                    }
                    writer.finish()
                })();
                let spent = (thread_cpu_seconds() - start).max(0.0);
                ENCODE_CPU_US.fetch_add((spent * 1e6) as u64, Ordering::Relaxed);
                written
            })
            .expect("spawn encoder thread");
        VideoJob {
            tx: Some(tx),
            handle: Some(handle),
        }
    }

    /// Queues a frame; false when the encoder has stopped (its error comes from `finish`).
    pub fn send(&self, frame: Vec<u8>) -> bool {
        self.tx.as_ref().is_some_and(|tx| tx.send(frame).is_ok())
    }

    /// Waits for the file; returns the number of frames written.
    pub fn finish(mut self) -> Result<u32, String> {
        drop(self.tx.take());
        match self.handle.take().map(|h| h.join()) {
            Some(Ok(r)) => r,
            _ => Err("encoder thread panicked".into()),
        }
    }
}

impl Drop for VideoJob {
    fn drop(&mut self) {
        drop(self.tx.take());
        if let Some(h) = self.handle.take() {
            let _ = h.join();
        }
    }
}
