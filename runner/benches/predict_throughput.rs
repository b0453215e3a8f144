//! `rh-score predict` against the scripted test server answering every request after
//! 200 ms, at concurrency 16: decisions/s, the runner's own CPU time per decision, the
//! CPU time of building the prompts (PNG decode, scaling, JPEG, base64) per decision,
//! reported separately, the server's CPU per request, and the peak RSS of each run at
//! three sizes (flat = memory does not grow with the number of scenes).
//! Before the runs: the thread CPU per frame of each encoding stage (PNG decode, scaling,
//! JPEG), mean of 100 frames.
//!
//! `cargo bench -p rh-runner --bench predict_throughput [-- [SCENES ...] [--frames DIR]]`
//! (default sizes 120 480 1200). Dataset: the fixture generator's scenes, each with five
//! 1280×720 ego frames written as the pipeline writes them (RGB PNG, fast deflate, Sub
//! filter): synthetic flat-shaded frames, or the five `ego_t*.png` of DIR (e.g. one scene
//! of a rendered build); one set hard-linked into every scene. No response cache, so
//! every decision is a request. The server is `tests/llm_server.py` (Python's
//! ThreadingHTTPServer) on 127.0.0.1, stopped by PID.
//!
//! Method. CPU: the process's user + system time (`getrusage`, µs) over the run; the
//! encoding CPU is the per-thread CPU time (`CLOCK_THREAD_CPUTIME_ID`) of each prompt
//! build, summed ([`rh_runner::predict::Summary::encode_cpu_s`]); runner CPU = process −
//! encoding. Both are CPU time, so they do not depend on the machine's load (wall-clock
//! rates do: the load average is printed with every run). Peak RSS: the kernel's
//! high-water mark is reset before each run (`5` into `/proc/self/clear_refs`) and
//! `VmHWM` read after it, so each run's peak is its own.

use rh_grade::dataset::Subset;
use rh_grade::Dataset;
use rh_prompt::select_scenes;
use rh_runner::predict::config::{Generation, PredictConfig, PromptConfig};
use rh_runner::predict::{run, PredictOptions};
use std::io::BufRead;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::Instant;

fn status_kib(key: &str) -> u64 {
    let s = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    s.lines()
        .find(|l| l.starts_with(key))
        .and_then(|l| l.split_whitespace().nth(1)?.parse().ok())
        .unwrap_or(0)
}

/// Resets the peak-RSS mark (Linux ≥ 4.0); false when the kernel refuses.
fn reset_peak_rss() -> bool {
    std::fs::write("/proc/self/clear_refs", "5").is_ok()
}

/// This process's user + system CPU seconds (all threads).
fn process_cpu_s() -> f64 {
    // SAFETY: getrusage fills a zeroed rusage struct.
    let mut ru: libc::rusage = unsafe { std::mem::zeroed() };
    unsafe { libc::getrusage(libc::RUSAGE_SELF, &mut ru) };
    let tv = |t: libc::timeval| t.tv_sec as f64 + t.tv_usec as f64 * 1e-6;
    tv(ru.ru_utime) + tv(ru.ru_stime)
}

/// Another process's user + system CPU seconds (from /proc; clock ticks of 1/100 s).
fn pid_cpu_s(pid: u32) -> f64 {
    let s = std::fs::read_to_string(format!("/proc/{pid}/stat")).unwrap_or_default();
    let after = s.rsplit_once(") ").map_or("", |(_, r)| r);
    let f: Vec<&str> = after.split_whitespace().collect();
    let ticks = |i: usize| f.get(i).and_then(|x| x.parse::<f64>().ok()).unwrap_or(0.0);
    // Fields 14 and 15 of stat (utime, stime) are 11 and 12 after the command name.
    (ticks(11) + ticks(12)) / 100.0
}

fn loadavg() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .map(|s| s.split_whitespace().take(3).collect::<Vec<_>>().join(" "))
        .unwrap_or_else(|_| "?".into())
}

struct Server(Child, u16);

impl Drop for Server {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

fn start_server(delay: f64) -> Server {
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/llm_server.py");
    let mut child = Command::new("python3")
        .arg(script)
        .args([
            "--delay",
            &delay.to_string(),
            "--then",
            "bare",
            "--lifetime",
            "900",
        ])
        .stdout(Stdio::piped())
        .spawn()
        .expect("python3");
    let mut line = String::new();
    std::io::BufReader::new(child.stdout.take().unwrap())
        .read_line(&mut line)
        .unwrap();
    let port = line.trim().strip_prefix("PORT ").unwrap().parse().unwrap();
    Server(child, port)
}

/// Writes a frame as the pipeline does (`rh_contract::png::write_png`).
fn write_png_like_pipeline(img: &image::RgbImage, path: &Path) {
    let (w, h) = img.dimensions();
    rh_contract::png::write_png(path, img, w, h, rh_contract::png::PngColor::Rgb8).unwrap();
}

/// A synthetic 1280×720 frame like a render: shaded floor and wall, a box with flat faces,
/// a moving ball (position by frame index `k`).
fn synthetic_frame(k: usize) -> image::RgbImage {
    image::RgbImage::from_fn(1280, 720, |x, y| {
        let (xf, yf) = (x as f32, y as f32);
        let (bx, by) = (300.0 + 120.0 * k as f32, 200.0 + 40.0 * k as f32);
        let px = if (xf - bx).powi(2) + (yf - by).powi(2) < 40.0f32.powi(2) {
            let l = 0.6 + 0.4 * ((bx - xf) + (by - yf)) / 80.0;
            [220.0 * l, 60.0 * l, 40.0 * l]
        } else if (700..1000).contains(&x) && (380..620).contains(&y) {
            if y < 420 {
                [150.0, 170.0, 180.0]
            } else {
                [70.0 + (x - 700) as f32 / 30.0, 85.0, 95.0]
            }
        } else if y > 360 {
            let l = 0.7 + 0.3 * (yf - 360.0) / 360.0;
            [170.0 * l, 160.0 * l, 150.0 * l]
        } else {
            let l = 0.8 + 0.2 * xf / 1280.0;
            [200.0 * l, 190.0 * l, 175.0 * l]
        };
        image::Rgb(px.map(|c| c.clamp(0.0, 255.0) as u8))
    })
}

fn make_dataset(dir: &Path, n: usize, frames: Option<&Path>) -> Vec<String> {
    let rows = rh_grade::synthetic::synth_rows(n, 7);
    rh_grade::synthetic::write_dataset(dir, &rows, &[]).unwrap();
    let prompt = PromptConfig::load(None).unwrap();
    let proto = dir.join("proto");
    std::fs::create_dir_all(&proto).unwrap();
    for (k, &t) in prompt.images.times.iter().enumerate() {
        let name = format!("ego_t{t:.3}.png");
        match frames {
            Some(src) => {
                std::fs::copy(src.join(&name), proto.join(&name))
                    .unwrap_or_else(|e| panic!("{}: {e}", src.join(&name).display()));
            }
            None => write_png_like_pipeline(&synthetic_frame(k), &proto.join(&name)),
        }
    }
    let ds = Dataset::load(dir).unwrap();
    let ids = select_scenes(&ds, Subset::All, None).unwrap();
    for id in &ids {
        let d = dir.join("frames").join(id);
        std::fs::create_dir_all(&d).unwrap();
        for &t in &prompt.images.times {
            let name = format!("ego_t{t:.3}.png");
            std::fs::hard_link(proto.join(&name), d.join(&name)).unwrap();
        }
    }
    ids
}

fn options(dir: &Path, port: u16, out: &Path) -> PredictOptions {
    let cfg = PredictConfig::load(None).unwrap();
    let mut client = cfg.client.clone();
    client.base_url = format!("http://127.0.0.1:{port}/v1");
    client.concurrency = 16;
    client.max_retries = 0;
    client.timeout_s = 30.0;
    PredictOptions {
        dataset: dir.to_path_buf(),
        model: "bench-model".into(),
        out: out.to_path_buf(),
        subset: Subset::All,
        limit: None,
        client,
        generation: Generation {
            temperature: 0.0,
            max_tokens: 512,
        },
        price: None,
        max_cost: None,
        retry_errors: false,
        cache_dir: None,
        sample: 0,
        prompt: PromptConfig::load(None).unwrap(),
        progress: false,
        abort_after_failures: 8,
        progress_every_s: 10.0,
    }
}

/// Thread CPU per frame of each encoding stage, mean over 20 passes over the five frames
/// (after one warm-up pass).
fn print_stages(proto: &Path) {
    let cfg = PromptConfig::load(None).unwrap();
    let im = &cfg.images;
    let sub = rh_prompt::config::subsampling(&im.chroma_subsampling).unwrap();
    let mut sum = [0.0; 3];
    let mut n = 0usize;
    for pass in 0..21 {
        for &t in &im.times {
            let f = proto.join(format!("ego_t{t:.3}.png"));
            let st = rh_prompt::messages::frame_stage_cpu_s(&f, im.max_side, im.jpeg_quality, sub)
                .unwrap();
            if pass > 0 {
                sum.iter_mut().zip(st).for_each(|(a, b)| *a += b);
                n += 1;
            }
        }
    }
    let ms = sum.map(|x| 1000.0 * x / n as f64);
    println!(
        "per frame (thread CPU, mean of {n}): PNG decode {:.2} ms, scaling {:.2} ms, JPEG {:.2} ms",
        ms[0], ms[1], ms[2]
    );
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let frames: Option<PathBuf> = args
        .iter()
        .position(|a| a == "--frames")
        .and_then(|i| args.get(i + 1))
        .map(PathBuf::from);
    let mut sizes: Vec<usize> = args.iter().filter_map(|a| a.parse().ok()).collect();
    if sizes.is_empty() {
        sizes = vec![120, 480, 1200];
    }
    sizes.sort_unstable();
    let largest = *sizes.last().unwrap();
    let tmp = tempfile::tempdir().unwrap();
    let ids = make_dataset(tmp.path(), largest, frames.as_deref());
    let server = start_server(0.2);
    println!(
        "predict_throughput: five 1280x720 ego frames per scene ({}), server answers after \
         200 ms, concurrency 16, {} CPUs; peak RSS before the runs {} MiB",
        frames
            .as_ref()
            .map_or("synthetic".into(), |f| format!("from {}", f.display())),
        std::thread::available_parallelism().map_or(0, |n| n.get()),
        status_kib("VmHWM:") / 1024
    );
    print_stages(&tmp.path().join("proto"));
    for (k, &n) in sizes.iter().enumerate() {
        let scenes = &ids[..n.min(ids.len())];
        let out = tmp.path().join(format!("run{k}.jsonl"));
        let opts = options(tmp.path(), server.1, &out);
        let load0 = loadavg();
        let reset = reset_peak_rss();
        let (cpu0, srv0) = (process_cpu_s(), pid_cpu_s(server.0.id()));
        let t0 = Instant::now();
        let s = run(&opts, scenes).unwrap();
        let wall = t0.elapsed().as_secs_f64();
        let (cpu, srv) = (process_cpu_s() - cpu0, pid_cpu_s(server.0.id()) - srv0);
        assert_eq!(s.answered, scenes.len(), "every request answered");
        let per = |x: f64| 1000.0 * x / scenes.len() as f64;
        println!(
            "{:>5} decisions in {wall:.2} s = {:.1} decisions/s | runner CPU {:.2} ms/decision \
             + prompt building (5 frames: decode, scale, JPEG, base64) {:.2} ms/decision | \
             server CPU {:.2} ms/request | peak RSS {} MiB{} | load average {load0} -> {}",
            scenes.len(),
            scenes.len() as f64 / wall,
            per(cpu - s.encode_cpu_s),
            per(s.encode_cpu_s),
            per(srv),
            status_kib("VmHWM:") / 1024,
            if reset {
                ""
            } else {
                " (cumulative: clear_refs refused)"
            },
            loadavg()
        );
    }
    drop(server);
}
