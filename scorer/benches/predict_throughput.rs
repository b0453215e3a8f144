//! `rh-score predict` against the scripted test server answering every request after
//! 200 ms: decisions/s at concurrency 16, the runner's own CPU time per decision (image
//! encoding excluded and reported separately), and peak RSS after a small and after a
//! 4× larger run (flat = memory does not grow with the number of scenes).
//!
//! `cargo bench -p rh-score --bench predict_throughput [-- SCENES]` (default 480).
//! Dataset: the fixture generator's scenes, each with five 1280×720 ego frames (one set
//! of PNGs hard-linked per scene); no cache, so every decision is a request. The server
//! is `tests/llm_server.py` (Python's ThreadingHTTPServer) on 127.0.0.1, stopped by PID.

use rh_score::predict::config::{Generation, PredictConfig, PromptConfig};
use rh_score::predict::{run, select_scenes, PredictOptions, Subset};
use rh_score::Dataset;
use std::io::BufRead;
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::Instant;

fn vm_hwm_kib() -> u64 {
    let s = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    s.lines()
        .find(|l| l.starts_with("VmHWM:"))
        .and_then(|l| l.split_whitespace().nth(1)?.parse().ok())
        .unwrap_or(0)
}

/// This process's user + system CPU seconds (from /proc; clock ticks of 1/100 s).
fn cpu_s() -> f64 {
    let s = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    let after = s.rsplit_once(") ").map_or("", |(_, r)| r);
    let f: Vec<&str> = after.split_whitespace().collect();
    let ticks = |i: usize| f.get(i).and_then(|x| x.parse::<f64>().ok()).unwrap_or(0.0);
    // Fields 14 and 15 of stat (utime, stime) are 11 and 12 after the command name.
    (ticks(11) + ticks(12)) / 100.0
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

fn make_dataset(dir: &Path, n: usize) -> Vec<String> {
    let rows = rh_score::fixture::synth_rows(n, 7);
    rh_score::fixture::write_dataset(dir, &rows, &[]).unwrap();
    let prompt = PromptConfig::load(None).unwrap();
    let proto = dir.join("proto");
    std::fs::create_dir_all(&proto).unwrap();
    for (k, &t) in prompt.images.times.iter().enumerate() {
        // A frame with some structure, so JPEG has work to do.
        let img = image::RgbImage::from_fn(1280, 720, |x, y| {
            image::Rgb([
                (x / 5 % 256) as u8,
                (y / 3 % 256) as u8,
                ((x + y + 40 * k as u32) % 256) as u8,
            ])
        });
        img.save(proto.join(format!("ego_t{t:.3}.png"))).unwrap();
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
    }
}

fn main() {
    let n: usize = std::env::args()
        .skip(1)
        .find_map(|a| a.parse().ok())
        .unwrap_or(480);
    let tmp = tempfile::tempdir().unwrap();
    let ids = make_dataset(tmp.path(), n);
    let server = start_server(0.2);
    let small = ids.len() / 4;
    println!(
        "predict_throughput: {} scenes (5 ego frames of 1280x720 each), server answers after 200 ms, concurrency 16",
        ids.len()
    );
    let hwm0 = vm_hwm_kib();
    for (label, scenes) in [("small", &ids[..small]), ("large", &ids[..])] {
        let out = tmp.path().join(format!("{label}.jsonl"));
        let opts = options(tmp.path(), server.1, &out);
        let cpu0 = cpu_s();
        let t0 = Instant::now();
        let s = run(&opts, scenes).unwrap();
        let wall = t0.elapsed().as_secs_f64();
        let cpu = cpu_s() - cpu0;
        assert_eq!(s.answered, scenes.len(), "every request answered");
        let per = |x: f64| 1000.0 * x / scenes.len() as f64;
        println!(
            "{label:>5}: {} decisions in {wall:.2} s = {:.1} decisions/s; runner CPU {:.2} ms/decision \
             excluding image encoding, image encoding {:.2} ms/decision (5 frames); peak RSS {} MiB",
            scenes.len(),
            scenes.len() as f64 / wall,
            per(cpu - s.encode_s).max(0.0),
            per(s.encode_s),
            vm_hwm_kib() / 1024
        );
    }
    println!("peak RSS before the runs: {} MiB", hwm0 / 1024);
    drop(server);
}
