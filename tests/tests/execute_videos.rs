//! `rh-score --execute --execute-videos DIR` end to end (issue 14, item 4) and the
//! outcome figure (item 3): on a label-only build of one furniture_tip group (a wardrobe tipping: large enough to see moving at the small test size; label rule v5 deals a thrown_object build its steel-apple probe first), two baselines'
//! executions are drawn at a small size — each decision's outside and ego MP4 (H.264, the
//! configured size, the dataset's rate, one frame per video time step from t = 0 to the
//! last executed step), the tiled video two tiles wide, `index.json` — and outcomes and
//! run hashes are the same bits with and without videos.

use rh_e2e::{run, run_ok};
use serde_json::Value;
use std::path::Path;
use std::process::Command;

const W: u64 = 160;
const H: u64 = 96;

/// `(codec, width, height, r_frame_rate, frames, duration s)` of a video.
fn probe(path: &Path) -> (String, u64, u64, String, u64, f64) {
    let out = Command::new("ffprobe")
        .args(["-v", "error", "-select_streams", "v:0", "-count_frames"])
        .args([
            "-show_entries",
            "stream=codec_name,width,height,r_frame_rate,nb_read_frames",
        ])
        .args(["-show_entries", "format=duration", "-of", "json"])
        .arg(path)
        .output()
        .expect("ffprobe (scripts/setup.sh installs ffmpeg)");
    assert!(out.status.success(), "ffprobe {}", path.display());
    let v: Value = serde_json::from_slice(&out.stdout).unwrap();
    let s = &v["streams"][0];
    (
        s["codec_name"].as_str().unwrap().to_string(),
        s["width"].as_u64().unwrap(),
        s["height"].as_u64().unwrap(),
        s["r_frame_rate"].as_str().unwrap().to_string(),
        s["nb_read_frames"].as_str().unwrap().parse().unwrap(),
        v["format"]["duration"].as_str().unwrap().parse().unwrap(),
    )
}

/// The pixels (RGB) of an image file or of a video's frame `n`, decoded by ffmpeg.
fn rgb(path: &Path, frame: Option<u64>) -> Vec<u8> {
    let mut cmd = Command::new("ffmpeg");
    cmd.args(["-v", "error", "-i"]).arg(path);
    if let Some(n) = frame {
        cmd.args(["-vf", &format!("select=eq(n\\,{n})"), "-frames:v", "1"]);
    }
    let out = cmd
        .args(["-f", "rawvideo", "-pix_fmt", "rgb24", "-"])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "ffmpeg {}: {}",
        path.display(),
        String::from_utf8_lossy(&out.stderr)
    );
    out.stdout
}

/// `frame` (RGB) is a drawn scene — its luma spans a range and no one colour fills it —
/// and it differs from at least one of `others` in a patch far above encoder noise.
fn assert_drawn_and_moving(frame: &[u8], others: &[Vec<u8>], what: &str) {
    let luma: Vec<i32> = frame
        .chunks_exact(3)
        .map(|p| (299 * p[0] as i32 + 587 * p[1] as i32 + 114 * p[2] as i32) / 1000)
        .collect();
    let (lo, hi) = (luma.iter().min().unwrap(), luma.iter().max().unwrap());
    assert!(hi - lo >= 40, "{what}: a flat frame (luma {lo}..{hi})");
    let mut colours: Vec<[u8; 3]> = frame
        .chunks_exact(3)
        .map(|p| [p[0] / 16, p[1] / 16, p[2] / 16])
        .collect();
    colours.sort();
    let largest = colours
        .chunk_by(|a, b| a == b)
        .map(|run| run.len())
        .max()
        .unwrap();
    assert!(
        largest * 10 < colours.len() * 9,
        "{what}: one colour fills {largest} of {} pixels",
        colours.len()
    );
    let changed = |other: &Vec<u8>| {
        frame
            .chunks_exact(3)
            .zip(other.chunks_exact(3))
            .filter(|(a, b)| {
                a.iter()
                    .zip(*b)
                    .map(|(&x, &y)| (x as i32 - y as i32).abs())
                    .sum::<i32>()
                    > 48
            })
            .count()
    };
    let moved: Vec<usize> = others.iter().map(changed).collect();
    assert!(
        moved.iter().any(|&n| n >= 8),
        "{what}: the middle frame shows no motion against the first and last ({moved:?} pixels changed)"
    );
}

fn near(p: &[u8], c: [u8; 3], tol: i32) -> bool {
    p.iter()
        .zip(c)
        .all(|(&a, b)| (a as i32 - b as i32).abs() <= tol)
}

/// Runs `rh-score preds --execute` with `extra`; returns (report JSON, decision lines).
fn score(
    preds: &Path,
    ds: &Path,
    config: &Path,
    work: &Path,
    extra: &[&str],
) -> (Value, Vec<Value>) {
    std::fs::create_dir_all(work).unwrap();
    let (json, decisions) = (work.join("r.json"), work.join("d.jsonl"));
    let mut args = vec![
        preds.to_str().unwrap(),
        "--dataset",
        ds.to_str().unwrap(),
        "--execute",
        "--no-exec-cache",
        "--config",
        config.to_str().unwrap(),
        "--quiet",
        "--json",
        json.to_str().unwrap(),
        "--decisions",
        decisions.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    run_ok("rh-score", &args);
    let report: Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let lines = rh_e2e::read_json_lines(&decisions);
    (report, lines)
}

#[test]
fn execution_videos_outside_ego_tiled_and_the_outcome_figure() {
    let dir = tempfile::tempdir().unwrap();
    let ds = dir.path().join("ds");
    run_ok(
        "rh-pipeline",
        &[
            "build",
            "--n",
            "4",
            "--seed",
            "14",
            "--families",
            "furniture_tip",
            "--no-render",
            "--quiet",
            "--out",
            ds.to_str().unwrap(),
        ],
    );
    let preds = dir.path().join("preds.jsonl");
    let mut text = String::new();
    for kind in ["oracle", "freeze"] {
        text += &run_ok(
            "rh-score",
            &["baseline", kind, "--dataset", ds.to_str().unwrap()],
        );
    }
    std::fs::write(&preds, text).unwrap();
    let config = dir.path().join("scoring.toml");
    let cfg = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../configs/scoring.toml"),
    )
    .unwrap();
    let small = cfg.replace(
        "\nwidth = 640\nheight = 360\n",
        &format!("\nwidth = {W}\nheight = {H}\n"),
    );
    assert_ne!(
        small, cfg,
        "the [execution_video] keys moved; update this test"
    );
    std::fs::write(&config, small).unwrap();

    // Without videos, then with videos for one scene (the tiled one) and the figures.
    let (plain, plain_lines) = score(&preds, &ds, &config, &dir.path().join("a"), &[]);
    let scene = plain_lines[0]["scene_id"].as_str().unwrap().to_string();
    let vids = dir.path().join("videos");
    let figs = dir.path().join("figs");
    let (with, with_lines) = score(
        &preds,
        &ds,
        &config,
        &dir.path().join("b"),
        &[
            "--execute-videos",
            vids.to_str().unwrap(),
            "--video-scenes",
            &scene,
            "--figures",
            figs.to_str().unwrap(),
        ],
    );
    // Outcomes and run hashes: the same bits with and without videos.
    assert_eq!(plain["execution"]["models"], with["execution"]["models"]);
    assert_eq!(
        plain["execution"]["disagreements"],
        with["execution"]["disagreements"]
    );
    let executions =
        |lines: &[Value]| -> Vec<Value> { lines.iter().map(|l| l["execution"].clone()).collect() };
    assert_eq!(executions(&plain_lines), executions(&with_lines));

    let index: Value =
        serde_json::from_str(&std::fs::read_to_string(vids.join("index.json")).unwrap()).unwrap();
    let scenes = index["scenes"].as_array().unwrap();
    assert_eq!(scenes.len(), 1, "only --video-scenes: {index}");
    let s = &scenes[0];
    assert_eq!(s["scene_id"], scene.as_str());
    let (fps, dt) = (s["fps"].as_u64().unwrap(), s["dt"].as_f64().unwrap());
    let decision = s["decision_step"].as_u64().unwrap();
    assert_eq!(
        s["start_step"], 0,
        "the observation window is included by default"
    );
    let decisions = s["decisions"].as_array().unwrap();
    assert_eq!(decisions.len(), 2);
    let mut longest = 0;
    for d in decisions {
        let model = d["model"].as_str().unwrap();
        let line = with_lines
            .iter()
            .find(|l| l["scene_id"] == scene.as_str() && l["model"] == model)
            .unwrap();
        assert_eq!(d["outcome"], line["execution"]["outcome"], "{model}");
        // Frame j shows step round(j / fps / dt), up to Δ + the executed steps.
        let last = decision + line["execution"]["steps"].as_u64().unwrap();
        let want = (0u64..)
            .take_while(|&j| (j as f64 / fps as f64 / dt).round() as u64 <= last)
            .count() as u64;
        assert_eq!(d["frames"], want, "{model}");
        longest = longest.max(want);
        for view in ["outside", "ego"] {
            let rel = d[view].as_str().unwrap();
            assert_eq!(rel, format!("{scene}/{model}__{view}.mp4"));
            let (codec, w, h, rate, frames, duration) = probe(&vids.join(rel));
            assert_eq!((codec.as_str(), w, h), ("h264", W, H), "{rel}");
            assert_eq!(rate, format!("{fps}/1"), "{rel}");
            assert_eq!(frames, want, "{rel}");
            assert!(
                (duration - want as f64 / fps as f64).abs() < 0.05,
                "{rel}: {duration} s"
            );
            // A drawn scene, not a blank frame, and a moving one: the middle frame has
            // light and dark parts (a lit room), and differs from the first or the last
            // frame where something (the tipping furniture, the humanoid) moved. No count of
            // distinct colours: a plain room corner honestly has few (19 under Debian's
            // Mesa 22.3 on an AVX-512 CPU), and that count depends on the adapter.
            let mid = rgb(&vids.join(rel), Some(want / 2));
            assert_drawn_and_moving(
                &mid,
                &[
                    rgb(&vids.join(rel), Some(0)),
                    rgb(&vids.join(rel), Some(want - 1)),
                ],
                rel,
            );
        }
    }
    // The tiled video: the two outside views side by side, as long as the longest.
    let t = &s["tiled"];
    assert_eq!(t["file"], format!("{scene}/tiled.mp4"));
    assert_eq!(
        (t["columns"].as_u64(), t["rows"].as_u64()),
        (Some(2), Some(1))
    );
    let tiles: Vec<&str> = t["tiles"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x["model"].as_str().unwrap())
        .collect();
    assert_eq!(tiles, ["baseline-freeze", "baseline-oracle"]);
    let (codec, w, h, _, frames, _) = probe(&vids.join(t["file"].as_str().unwrap()));
    assert_eq!((codec.as_str(), w, h, frames), ("h264", 2 * W, H, longest));
    // Its left tile is the first model's outside view (below the label strip).
    let first = rgb(
        &vids.join(decisions[0]["outside"].as_str().unwrap()),
        Some(0),
    );
    let tiled = rgb(&vids.join(t["file"].as_str().unwrap()), Some(0));
    let (mut diff, mut n) = (0i64, 0i64);
    for y in 20..H as usize {
        for x in 0..W as usize {
            for c in 0..3 {
                diff += (first[(y * W as usize + x) * 3 + c] as i64
                    - tiled[(y * 2 * W as usize + x) * 3 + c] as i64)
                    .abs();
                n += 1;
            }
        }
    }
    assert!(
        diff / n < 6,
        "tile 0 differs from the outside video by {} on average",
        diff / n
    );

    // The outcome figure: written beside the others, with a bar per outcome that occurred.
    let png = figs.join("outcomes.png");
    assert!(figs.join("outcomes.svg").exists() && png.exists());
    let px = rgb(&png, None);
    let count = |c: [u8; 3]| px.chunks_exact(3).filter(|p| near(p, c, 2)).count();
    let models = with["execution"]["models"].as_array().unwrap();
    for (name, colour) in [
        ("caught", [44, 160, 44]),
        ("struck", [214, 39, 40]),
        ("missed", [255, 127, 14]),
        ("clear", [120, 144, 156]),
    ] {
        let occurred = models.iter().any(|m| m["all"][name].as_u64().unwrap() > 0);
        // The legend swatch alone is 15 x 13 px; a bar is far wider.
        assert_eq!(
            count(colour) > 600,
            occurred,
            "{name}: {} px",
            count(colour)
        );
    }

    // --execute-videos needs --execute.
    let out = run(
        "rh-score",
        &[
            preds.to_str().unwrap(),
            "--dataset",
            ds.to_str().unwrap(),
            "--execute-videos",
            vids.to_str().unwrap(),
        ],
    );
    assert_eq!(out.status.code(), Some(2));
}
