//! Scores 10^4, 10^5 and 10^6 decisions with the full report (every breakdown and
//! analysis, the JSON written) and prints the time and peak memory of each.
//!
//! `cargo bench -p rh-grade --bench score_throughput` runs the three sizes, each in a
//! process of its own (so each peak RSS is its own); `-- N` scores N decisions only.
//! Synthetic dataset: 2,000 scenes (the fixture generator, in memory; ~1,930 valid); predictions:
//! one line per (scene, model) over as many models as needed, mixing plan objects with
//! object keyframes, bare keyframes, raw responses with ```json fences and prose, API
//! errors and malformed lines. The file is written to a temp dir first (not timed).
//! Memory is reported as the process's peak RSS (VmHWM) before and after scoring.

use rh_grade::synthetic::{dataset_of, synth_rows};
use rh_grade::{Config, Report, Scoring};
use std::io::{BufWriter, Write};
use std::time::Instant;

fn vm_hwm_kib() -> Option<u64> {
    let s = std::fs::read_to_string("/proc/self/status").ok()?;
    s.lines()
        .find(|l| l.starts_with("VmHWM:"))?
        .split_whitespace()
        .nth(1)?
        .parse()
        .ok()
}

fn main() {
    match std::env::args().skip(1).find_map(|a| a.parse().ok()) {
        Some(n) => run(n),
        None => {
            // One child process per size: each peak RSS is that size's own.
            let exe = std::env::current_exe().expect("the bench's own path");
            for n in [10_000usize, 100_000, 1_000_000] {
                let status = std::process::Command::new(&exe)
                    .arg(n.to_string())
                    .status()
                    .expect("running the bench for one size");
                assert!(status.success(), "the bench at {n} decisions failed");
            }
        }
    }
}

fn run(n: usize) {
    let rows = synth_rows(2000, 42);
    let ds = dataset_of(&rows);
    // Lines only for valid scenes (the fixture marks a few invalid, as a real build may).
    let valid: Vec<_> = ds.scenes.iter().filter(|s| s.valid).collect();
    let scenes = valid.len();
    let cfg = Config::default();
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("preds.jsonl");
    let t0 = Instant::now();
    {
        let mut w = BufWriter::with_capacity(1 << 20, std::fs::File::create(&path).unwrap());
        for i in 0..n {
            let s = valid[i % scenes];
            let model = i / scenes;
            let id = &s.scene_id;
            let line = match i % 10 {
                0..=4 => format!(
                    r#"{{"scene_id":"{id}","model":"model-{model:03}","plan":{{"intent":"I will step forward and catch the falling object with both hands before it lands.","confidence":0.8,"walking_cmd":[0.4,0.0,0.1],"walking_duration":1.2,"keyframes":[{{"t":0.3,"left_hand":[0.2,0.15,0.1],"right_hand":[0.2,-0.15,0.1],"knee_bend":0.1}},{{"t":0.8,"left_hand":[0.45,0.12,0.2],"right_hand":[0.45,-0.12,0.2],"knee_bend":0.2}}]}},"latency_s":3.2}}"#
                ),
                5 | 6 => format!(
                    r#"{{"scene_id":"{id}","model":"model-{model:03}","plan":{{"intent":"Do not catch the knife; dodge by stepping back out of its path.","confidence":0.9,"walking_cmd":[-0.8,0.2,0.0],"walking_duration":1.0,"keyframes":[[0.1,0.0,0.0],[0.12,0.0,0.05]]}}}}"#
                ),
                7 | 8 => format!(
                    r#"{{"scene_id":"{id}","model":"model-{model:03}","response":"The object is light. Plan:\n```json\n{{\"intent\": \"stay still, no action needed\", \"confidence\": 0.6, \"walking_cmd\": [0, 0, 0], \"walking_duration\": 0, \"keyframes\": [{{\"t\": 0.5, \"left_hand\": [0.1, 0.15, 0.0], \"right_hand\": [0.1, -0.15, 0.0]}}]}}\n```\nDone."}}"#
                ),
                _ => match i % 1000 {
                    9 => format!(
                        r#"{{"scene_id":"{id}","model":"model-{model:03}","error":"HTTP 429"}}"#
                    ),
                    19 => "{\"scene_id\": \"trunc".to_string(),
                    _ => format!(
                        r#"{{"scene_id":"{id}","model":"model-{model:03}","response":"I think the best reaction is to avoid the hazard: {{\"intent\": \"evade to the left\", \"walking_cmd\": [0, 0.9, 0], \"walking_duration\": 0.8, \"keyframes\": []}} as planned."}}"#
                    ),
                },
            };
            w.write_all(line.as_bytes()).unwrap();
            w.write_all(b"\n").unwrap();
        }
        w.flush().unwrap();
    }
    let bytes = std::fs::metadata(&path).unwrap().len();
    let gen_s = t0.elapsed().as_secs_f64();
    let hwm_before = vm_hwm_kib();

    let t = Instant::now();
    let mut scoring = Scoring::new(&ds, &cfg);
    scoring.score_path(&path).expect("scoring");
    let report = Report::build(&scoring, "preds.jsonl");
    let json = serde_json::to_string_pretty(&report).expect("serializing the report") + "\n";
    std::fs::write(dir.path().join("report.json"), &json).expect("writing the report");
    let secs = t.elapsed().as_secs_f64();
    let hwm_after = vm_hwm_kib();

    let scored = report.input.decisions_scored;
    println!("score_throughput: {n} lines ({:.1} MiB, generated in {gen_s:.1} s), {} models x {scenes} scenes, {} rayon threads",
        bytes as f64 / (1 << 20) as f64,
        report.models.len(),
        rayon::current_num_threads());
    println!(
        "score_throughput: scored {scored} decisions ({} lost, {} warnings) with the full report (JSON {:.1} MiB) in {secs:.2} s = {:.0} decisions/s",
        report.input.decisions_lost,
        report.input.warnings.iter().map(|w| w.count).sum::<u64>(),
        json.len() as f64 / (1 << 20) as f64,
        scored as f64 / secs
    );
    if let (Some(b), Some(a)) = (hwm_before, hwm_after) {
        println!(
            "score_throughput: peak RSS (VmHWM) {:.1} MiB before scoring, {:.1} MiB after (+{:.1} MiB)",
            b as f64 / 1024.0,
            a as f64 / 1024.0,
            (a.saturating_sub(b)) as f64 / 1024.0
        );
    }
    println!(
        "score_throughput: pooled SAA {:.3}, safety {:.3}",
        report.pooled.overall.saa.unwrap_or(f64::NAN),
        report.pooled.overall.safety.unwrap_or(f64::NAN)
    );
}
