//! Hostile predictions stay cheap: lines of 10⁶ keyframes and deeply nested plans score
//! as R1 (`r1_plan_too_large`) while `rh-score`'s peak memory stays flat. Its own test
//! binary, so that the peak RSS of waited-for children (`getrusage(RUSAGE_CHILDREN)`)
//! is `rh-score`'s alone.

use rh_e2e::{bin, run_ok};
use serde_json::Value;
use std::io::Write;
use std::path::Path;
use std::process::Command;

/// Peak resident set size of any child waited for so far, in MiB.
fn children_peak_rss_mib() -> f64 {
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    // SAFETY: getrusage fills the struct it is given.
    let rc = unsafe { libc::getrusage(libc::RUSAGE_CHILDREN, &mut usage) };
    assert_eq!(rc, 0);
    usage.ru_maxrss as f64 / 1024.0 // kilobytes on Linux
}

#[test]
fn hostile_predictions_score_as_r1_with_flat_memory() {
    let tmp = tempfile::tempdir().unwrap();
    let ds = tmp.path().join("ds");
    rh_e2e::make_fixture(&ds, 40, 3);
    let base = run_ok(
        "rh-score",
        &["baseline", "oracle", "--dataset", ds.to_str().unwrap()],
    );
    let ids: Vec<String> = base
        .lines()
        .map(|l| {
            serde_json::from_str::<Value>(l).unwrap()["scene_id"]
                .as_str()
                .unwrap()
                .to_string()
        })
        .collect();
    let before = children_peak_rss_mib();

    let preds = tmp.path().join("preds.jsonl");
    let mut f = std::io::BufWriter::new(std::fs::File::create(&preds).unwrap());
    // Lines 1–4: one 16 MB line each, 10⁶ `{"pos": …}` keyframes.
    let many = "{\"pos\":[0,0,0]},".repeat(1_000_000);
    let many = &many[..many.len() - 1];
    for id in &ids[..4] {
        writeln!(f, r#"{{"scene_id":"{id}","model":"hostile","plan":{{"walking_cmd":[0,0,0],"keyframes":[{many}]}}}}"#).unwrap();
    }
    // Line 5: the same inside a raw response text.
    let bare = "[0.1,0.0,0.1],".repeat(500_000);
    let bare = &bare[..bare.len() - 1];
    writeln!(f, r#"{{"scene_id":"{}","model":"hostile","response":"```json\n{{\"walking_cmd\":[0,0,0],\"keyframes\":[{bare}]}}\n```"}}"#, ids[4]).unwrap();
    // Line 6: nested 100 levels deep.
    writeln!(
        f,
        r#"{{"scene_id":"{}","model":"hostile","plan":{{"walking_cmd":[0,0,0],"x":{}1{}}}}}"#,
        ids[5],
        "[".repeat(100),
        "]".repeat(100)
    )
    .unwrap();
    // Line 7: 200 bare keyframes without walking — automatic times, a valid plan.
    let pts = vec!["[0.3,0.0,0.1]"; 200].join(",");
    writeln!(f, r#"{{"scene_id":"{}","model":"hostile","plan":{{"intent":"catch","walking_cmd":[0,0,0],"walking_duration":0,"keyframes":[{pts}]}}}}"#, ids[6]).unwrap();
    drop(f);

    let out = Command::new(bin("rh-score"))
        .args([
            preds.to_str().unwrap(),
            "--dataset",
            ds.to_str().unwrap(),
            "--json",
            "-",
            "--quiet",
        ])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    let peak = children_peak_rss_mib();
    let report: Value = serde_json::from_slice(&out.stdout).unwrap();
    let warnings = report["input"]["warnings"].as_array().unwrap();
    let too_large = warnings
        .iter()
        .find(|w| w["kind"] == "r1_plan_too_large")
        .expect("r1_plan_too_large counted");
    assert_eq!(too_large["count"], 6, "{too_large}");
    assert_eq!(too_large["first_lines"][0], 1);
    assert!(
        !warnings.iter().any(|w| w["kind"] == "absurd_number"),
        "{warnings:?}"
    );
    assert_eq!(report["input"]["decisions_scored"], 7);
    // stderr names the first line of each kind.
    assert!(
        stderr.contains("r1_plan_too_large ×6 (first at line 1)"),
        "{stderr}"
    );
    // 4 × 16 MB of keyframes: the lines are read one at a time and never turned into trees.
    assert!(
        peak < 200.0,
        "rh-score peaked at {peak:.0} MiB RSS (the fixture steps before: {before:.0} MiB)"
    );
    eprintln!("rh-score peak RSS on hostile input: {peak:.1} MiB");
    let _ = Path::new(".");
}
