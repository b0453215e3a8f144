//! End-to-end test of the render stage inside `rh-pipeline build` (specification §7, §8): every
//! valid scene of a small rendered build has its three camera videos and the full-event
//! video (ffprobe: H.264, yuv420p, the configured size and rate, the exact frame count),
//! its fifteen observation frames, and the Parquet columns that name them; two rendered
//! shards merge into the same bytes as one build drawn on one device shared by its
//! workers; `rh-pipeline sheet` tiles the families.

use rh_e2e::{files_under, python, run, run_ok};
use std::path::{Path, PathBuf};
use std::process::Command;

const W: u32 = 160;
const H: u32 = 96;
const FAMILIES: &str = "object_drop,rolling_ball";

fn small_config(dir: &Path) -> PathBuf {
    rh_e2e::small_render_config(dir, W, H, true)
}

/// `rh-pipeline` arguments of the tests' 8-scene build into `out`, plus `extra`.
fn build_args<'a>(config: &'a Path, out: &'a Path, extra: &[&'a str]) -> Vec<&'a str> {
    let mut args = vec![
        "--config",
        config.to_str().unwrap(),
        "build",
        "--n",
        "8",
        "--seed",
        "3",
        "--quiet",
        "--families",
        FAMILIES,
        "--out",
        out.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    args
}

/// `rh-pipeline sheet DIR --out OUT` and `extra`.
fn sheet_args<'a>(dir: &'a Path, out: &'a Path, extra: &[&'a str]) -> Vec<&'a str> {
    let mut args = vec![
        "sheet",
        dir.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    args
}

fn build(config: &Path, out: &Path, extra: &[&str]) {
    run_ok("rh-pipeline", &build_args(config, out, extra));
}

/// `(codec, pix_fmt, width, height, r_frame_rate, frames)` of a video's first stream.
fn probe(path: &Path) -> (String, String, u64, u64, String, u64) {
    let out = Command::new("ffprobe")
        .args([
            "-v",
            "error",
            "-select_streams",
            "v:0",
            "-count_frames",
            "-show_entries",
            "stream=codec_name,pix_fmt,width,height,r_frame_rate,nb_read_frames",
            "-of",
            "json",
        ])
        .arg(path)
        .output()
        .expect("ffprobe (scripts/setup.sh installs ffmpeg)");
    assert!(out.status.success(), "ffprobe {}", path.display());
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let s = &v["streams"][0];
    (
        s["codec_name"].as_str().unwrap().to_string(),
        s["pix_fmt"].as_str().unwrap().to_string(),
        s["width"].as_u64().unwrap(),
        s["height"].as_u64().unwrap(),
        s["r_frame_rate"].as_str().unwrap().to_string(),
        s["nb_read_frames"].as_str().unwrap().parse().unwrap(),
    )
}

/// The colour tags of a video's first stream as ffprobe reads them:
/// `[color_space, color_primaries, color_transfer, color_range]` ("" when absent).
fn colour_tags(path: &Path) -> [String; 4] {
    let out = Command::new("ffprobe")
        .args(["-v", "error", "-select_streams", "v:0", "-show_entries"])
        .arg("stream=color_space,color_primaries,color_transfer,color_range")
        .args(["-of", "json"])
        .arg(path)
        .output()
        .expect("ffprobe (scripts/setup.sh installs ffmpeg)");
    assert!(out.status.success(), "ffprobe {}", path.display());
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let s = &v["streams"][0];
    [
        "color_space",
        "color_primaries",
        "color_transfer",
        "color_range",
    ]
    .map(|k| s[k].as_str().unwrap_or("").to_string())
}

/// What every video says of its colour (render/src/encode.rs): sRGB pixels (BT.709
/// primaries, sRGB transfer) through the BT.601 matrix into limited range.
const COLOUR_TAGS: [&str; 4] = ["smpte170m", "bt709", "iec61966-2-1", "tv"];

/// Width and height from a PNG's header (and that it is one).
fn png_size(path: &Path) -> (u32, u32) {
    let bytes = std::fs::read(path).unwrap();
    assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n", "{}", path.display());
    let be = |i: usize| u32::from_be_bytes(bytes[i..i + 4].try_into().unwrap());
    (be(16), be(20))
}

#[test]
fn rendered_build_has_probed_videos_frames_columns_and_merges_byte_equal() {
    let tmp = tempfile::tempdir().unwrap();
    let config = small_config(tmp.path());
    let single = tmp.path().join("single");
    // Both workers draw on one device, as they do on a GPU (`RH_RENDER_DEVICES`); the
    // shards below, each worker on its own device, must merge into the same bytes.
    let shared = [("RH_RENDER_DEVICES", "shared")];
    rh_e2e::run_ok_env(
        "rh-pipeline",
        &build_args(&config, &single, &["--jobs", "2"]),
        &shared,
    );
    // Rerunning the finished build does nothing, and says only that (no renderer banner).
    let args: Vec<&str> = build_args(&config, &single, &[])
        .into_iter()
        .filter(|a| *a != "--quiet")
        .collect();
    let rerun = run("rh-pipeline", &args);
    let err = String::from_utf8_lossy(&rerun.stderr);
    assert!(rerun.status.success(), "{err}");
    assert!(
        err.contains("nothing to do") && !err.contains("rendering on"),
        "{err}"
    );
    let said = String::from_utf8_lossy(&rerun.stdout);
    assert!(
        !said.contains("resumed"),
        "nothing to do, nothing resumed: {said}"
    );

    // Per row: scene id, validity, the four video columns (pyarrow reads the table).
    let rows = python(&format!(
        "import pyarrow.parquet as pq\n\
         t = pq.read_table('{}/data/test-00000-of-00001.parquet').to_pylist()\n\
         for r in t:\n    print(r['scene_id'], r['valid'], r['ego_file_name'], r['closeup_file_name'], r['overhead_file_name'], r['full_event_file_name'], r['sim_steps'], r['strike_impulse'])",
        single.display()
    ));
    let mut rendered = 0;
    for line in rows.lines() {
        let f: Vec<&str> = line.split(' ').collect();
        let (id, valid, steps) = (f[0], f[1] == "True", f[6].parse::<u64>().unwrap());
        if !valid {
            assert!(
                f[2..6].iter().all(|c| *c == "None"),
                "{id}: invalid but rendered"
            );
            continue;
        }
        rendered += 1;
        for (cam, file) in ["ego", "closeup", "overhead"].iter().zip(&f[2..5]) {
            assert_eq!(*file, format!("videos/{cam}/{id}.mp4"));
            let (codec, pix, w, h, rate, frames) = probe(&single.join(file));
            assert_eq!(
                (codec.as_str(), pix.as_str(), w, h, rate.as_str()),
                ("h264", "yuv420p", W as u64, H as u64, "60/1"),
                "{file}"
            );
            // The observation window [0, 0.6 s] at 60 fps, both ends included.
            assert_eq!(frames, 37, "{file}");
            assert_eq!(colour_tags(&single.join(file)), COLOUR_TAGS, "{file}");
            for t in ["0.000", "0.150", "0.300", "0.450", "0.600"] {
                let png = single.join(format!("frames/{id}/{cam}_t{t}.png"));
                assert_eq!(png_size(&png), (W, H), "{}", png.display());
            }
        }
        assert_eq!(f[5], format!("videos/full/{id}.mp4"));
        let (codec, pix, w, h, rate, frames) = probe(&single.join(f[5]));
        assert_eq!(
            (codec.as_str(), pix.as_str(), w, h, rate.as_str()),
            ("h264", "yuv420p", W as u64, H as u64, "30/1")
        );
        assert_eq!(colour_tags(&single.join(f[5])), COLOUR_TAGS, "{}", f[5]);
        // The full-event run (steps at 240 Hz) at 30 fps, both ends included. It is the
        // counterfactual run (the standing body as fixed colliders), which is step for step
        // the plain run — `sim_steps` long — while nothing touches the body (no strike
        // window: `strike_impulse` null); after a touch it settles on its own, within the
        // 4 s horizon and not before the decision moment.
        if f[7] == "None" {
            assert_eq!(frames, steps * 30 / 240 + 1, "{}", f[5]);
        } else {
            assert!((19..=121).contains(&frames), "{}: {frames} frames", f[5]);
        }
    }
    assert!(rendered >= 6, "only {rendered} of 8 scenes rendered");

    // Two rendered shards merge into exactly the single build.
    let shards: Vec<PathBuf> = (0..2).map(|i| tmp.path().join(format!("s{i}"))).collect();
    for (i, s) in shards.iter().enumerate() {
        build(&config, s, &["--shard", &format!("{i}/2"), "--jobs", "1"]);
    }
    let merged = tmp.path().join("merged");
    run_ok(
        "rh-pipeline",
        &[
            "merge",
            merged.to_str().unwrap(),
            shards[1].to_str().unwrap(),
            shards[0].to_str().unwrap(),
        ],
    );
    let (a, b) = (files_under(&single), files_under(&merged));
    assert_eq!(a.keys().collect::<Vec<_>>(), b.keys().collect::<Vec<_>>());
    for (name, bytes) in &a {
        assert!(
            bytes == &b[name],
            "{name} differs between the build and the merge"
        );
    }
    shards_from_two_adapters_do_not_merge(tmp.path(), &shards);

    // The model-input frames are data: `datasets` (run from another folder) gives each
    // rendered row's `<cam>_frames` as five PIL images in time order, pixel for pixel the
    // PNG files; unrendered (invalid) rows have none; the eval config carries them too.
    let hf_home = tempfile::tempdir().unwrap();
    let report = python(&format!(
        r#"
import os, json
os.environ["HF_HOME"] = {home:?}
os.environ["HF_DATASETS_OFFLINE"] = "1"
os.environ["HF_HUB_OFFLINE"] = "1"
import numpy as np
from PIL import Image
import datasets
d = {dir:?}
os.chdir("/")
ds = datasets.load_dataset(d, "default", split="test")
ev = datasets.load_dataset(d, "eval", split="test")
times = ["0.000", "0.150", "0.300", "0.450", "0.600"]
checked, unrendered, bad = 0, 0, []
for r in ds:
    for cam in ["ego", "closeup", "overhead"]:
        frames = r[cam + "_frames"]
        if r[cam + "_file_name"] is None:
            unrendered += frames is None
            continue
        if len(frames) != 5:
            bad.append((r["scene_id"], cam, len(frames)))
            continue
        for t, img in zip(times, frames):
            want = np.asarray(Image.open(os.path.join(d, "frames", r["scene_id"], cam + "_t" + t + ".png")).convert("RGB"))
            if not isinstance(img, Image.Image) or not np.array_equal(np.asarray(img.convert("RGB")), want):
                bad.append((r["scene_id"], cam, t))
            checked += 1
print(json.dumps({{"checked": checked, "unrendered": unrendered, "bad": bad,
  "feature": str(ds.features["ego_frames"]),
  "eval_frames": sum(1 for r in ev if r["ego_frames"] is not None and len(r["ego_frames"]) == 5),
  "eval_rows": ev.num_rows}}))
"#,
        home = hf_home.path().to_str().unwrap(),
        dir = single.to_str().unwrap()
    ));
    let v: serde_json::Value = serde_json::from_str(report.trim()).unwrap();
    assert_eq!(v["bad"], serde_json::json!([]), "{v}");
    assert_eq!(v["checked"], (rendered * 15) as u64, "{v}");
    assert_eq!(v["unrendered"], ((8 - rendered) * 3) as u64, "{v}");
    assert!(v["feature"].as_str().unwrap().contains("Image"), "{v}");
    assert_eq!(
        v["eval_frames"], v["eval_rows"],
        "every eval scene is rendered: {v}"
    );

    // The contact sheet: one tile per family.
    let sheet = tmp.path().join("sheet.png");
    let json = run_ok("rh-pipeline", &sheet_args(&single, &sheet, &["--json"]));
    let v: serde_json::Value = serde_json::from_str(&json).unwrap();
    let families: Vec<&str> = v["tiles"]
        .as_array()
        .unwrap()
        .iter()
        .map(|t| t["family"].as_str().unwrap())
        .collect();
    assert_eq!(families, ["object_drop", "rolling_ball"]);
    // What the model sees: ego frames, captioned with the object, ground truth and time.
    assert_eq!(v["camera"], "ego");
    for t in v["tiles"].as_array().unwrap() {
        let frame = t["frame"].as_str().unwrap();
        let id = t["scene_id"].as_str().unwrap();
        assert!(frame.starts_with(&format!("frames/{id}/ego_t")), "{t}");
        assert!(single.join(frame).is_file(), "{frame}");
        let caption = t["caption"][1].as_str().unwrap();
        assert!(
            ["gt catch", "gt dodge", "gt no_action"]
                .iter()
                .any(|g| caption.starts_with(g)),
            "{caption}"
        );
        let time = &frame[frame.len() - 9..frame.len() - 4];
        assert!(
            caption.contains(&format!("ego t {} s", &time[..4])),
            "{caption} / {frame}"
        );
    }
    let plain = run_ok("rh-pipeline", &sheet_args(&single, &sheet, &[]));
    assert!(plain.contains("ego frames"), "{plain}");
    let other = run_ok(
        "rh-pipeline",
        &sheet_args(&single, &sheet, &["--camera", "closeup", "--json"]),
    );
    let o: serde_json::Value = serde_json::from_str(&other).unwrap();
    assert!(
        o["tiles"][0]["frame"]
            .as_str()
            .unwrap()
            .contains("/closeup_t"),
        "{o}"
    );
    let bad = run(
        "rh-pipeline",
        &sheet_args(&single, &sheet, &["--camera", "top"]),
    );
    assert_eq!(bad.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&bad.stderr).contains("--camera top"));
    let (w, h) = png_size(&sheet);
    assert_eq!(
        (w as u64, h as u64),
        (v["width"].as_u64().unwrap(), v["height"].as_u64().unwrap())
    );

    // A dataset built without rendering has nothing to tile: a clear error, exit 2.
    let bare = tmp.path().join("bare");
    build(&config, &bare, &["--no-render"]);
    let out = run("rh-pipeline", &sheet_args(&bare, &sheet, &[]));
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("no rendered scenes"));
}

/// A rendered build killed (SIGKILL) while it writes videos resumes to exactly the bytes
/// of an uninterrupted build: half-written videos are temporary files, swept on restart,
/// and a group counts as done only once its videos and frames are all there.
#[test]
fn rendered_build_killed_mid_video_resumes_to_the_same_bytes() {
    use std::process::Stdio;
    use std::time::{Duration, Instant};
    let tmp = tempfile::tempdir().unwrap();
    let config = small_config(tmp.path());
    let reference = tmp.path().join("reference");
    build(&config, &reference, &["--jobs", "1"]);

    let killed = tmp.path().join("killed");
    let mut child = Command::new(rh_e2e::bin("rh-pipeline"))
        .args(build_args(&config, &killed, &["--jobs", "1"]))
        .env("XDG_RUNTIME_DIR", std::env::temp_dir())
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    // Kill it once the first group is done and the second one's videos are being written.
    let deadline = Instant::now() + Duration::from_secs(120);
    let temporary_video = |dir: &Path| {
        ["ego", "closeup", "overhead", "full"].iter().any(|cam| {
            std::fs::read_dir(dir.join("videos").join(cam))
                .map(|d| {
                    d.flatten()
                        .any(|e| e.file_name().to_string_lossy().ends_with(".tmp.mp4"))
                })
                .unwrap_or(false)
        })
    };
    let records = |dir: &Path| {
        std::fs::read_dir(dir.join(".rh-build/groups"))
            .map(|d| {
                d.flatten()
                    .filter(|e| e.file_name().to_string_lossy().ends_with(".parquet"))
                    .count()
            })
            .unwrap_or(0)
    };
    loop {
        let records = records(&killed);
        if (records >= 1 && temporary_video(&killed)) || Instant::now() > deadline {
            break;
        }
        std::thread::sleep(Duration::from_millis(1));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    assert!(
        !killed.join("README.md").exists(),
        "the build finished before it could be killed"
    );
    assert!(
        temporary_video(&killed),
        "killed while no video was being written"
    );

    // The restarted build loads the finished groups instead of rendering them again, and
    // says so: recomputing everything would also give the same bytes, so count.
    let finished = records(&killed);
    assert!(finished >= 1);
    let summary: serde_json::Value = serde_json::from_str(&run_ok(
        "rh-pipeline",
        &build_args(&config, &killed, &["--jobs", "1", "--json"]),
    ))
    .unwrap();
    assert_eq!(
        summary["resumed_groups"].as_u64(),
        Some(finished as u64),
        "{summary}"
    );
    assert_eq!(
        summary["computed_groups"].as_u64(),
        Some(2 - finished as u64),
        "{summary}"
    );
    let (a, b) = (files_under(&reference), files_under(&killed));
    assert_eq!(a.keys().collect::<Vec<_>>(), b.keys().collect::<Vec<_>>());
    for (name, bytes) in &a {
        assert!(bytes == &b[name], "{name} differs after the resumed build");
    }
}

/// `build.json` names the adapter that rendered a shard; shards whose adapters differ do
/// not merge (exit 2, naming both adapters and both directories), and `verify` prints the
/// recorded adapter beside this machine's. The second adapter is faked by editing a copy
/// of shard 1's `build.json`: the manifest is not among the checksummed files, so the
/// copy passes merge's integrity checks and is refused for its adapter alone.
fn shards_from_two_adapters_do_not_merge(tmp: &Path, shards: &[PathBuf]) {
    let read = |dir: &Path| -> serde_json::Value {
        serde_json::from_str(&std::fs::read_to_string(dir.join("build.json")).unwrap()).unwrap()
    };
    let ours = read(&shards[0])["render_adapter"].clone();
    assert!(
        ours["name"].as_str().is_some_and(|n| !n.is_empty()) && ours["backend"].is_string(),
        "build.json records the adapter: {ours}"
    );
    let other = tmp.join("s1-other-adapter");
    let cp = Command::new("cp")
        .arg("-r")
        .arg(&shards[1])
        .arg(&other)
        .status()
        .unwrap();
    assert!(cp.success());
    let mut m = read(&other);
    m["render_adapter"]["name"] = "Other GPU 9000".into();
    m["render_adapter"]["driver_info"] = "other driver 1.0".into();
    std::fs::write(
        other.join("build.json"),
        serde_json::to_string_pretty(&m).unwrap(),
    )
    .unwrap();
    let out = run(
        "rh-pipeline",
        &[
            "merge",
            tmp.join("m-adapters").to_str().unwrap(),
            shards[0].to_str().unwrap(),
            other.to_str().unwrap(),
        ],
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    for needle in [
        "different adapters",
        ours["name"].as_str().unwrap(),
        "Other GPU 9000",
        shards[0].to_str().unwrap(),
        other.to_str().unwrap(),
    ] {
        assert!(err.contains(needle), "'{needle}' not in: {err}");
    }
    assert!(!tmp.join("m-adapters").exists());
    // verify reports the recorded adapter and this machine's, and when they differ.
    let same = run_ok(
        "rh-pipeline",
        &["verify", shards[0].to_str().unwrap(), "--fast"],
    );
    assert!(
        same.contains("render adapter (recorded)") && same.contains("(the same)"),
        "{same}"
    );
    let differs = run(
        "rh-pipeline",
        &["verify", other.to_str().unwrap(), "--fast"],
    );
    let text = String::from_utf8_lossy(&differs.stdout);
    assert!(
        text.contains("Other GPU 9000") && text.contains("DIFFERS"),
        "{text}"
    );
}
