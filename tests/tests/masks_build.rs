//! `rh-pipeline build --masks` end to end (issue 12, item 4): every rendered scene has a
//! 16-bit instance-id PNG and a 16-bit depth PNG per camera and observation time, named by
//! the `<cam>_mask_paths` / `<cam>_depth_paths` columns next to the measured
//! `<cam>_hazard_visible_px`; the files are in `build.json`'s checksums, byte-identical
//! across `--jobs` and shard + merge, checked by `verify`, and a deleted mask is rebuilt
//! by running the build again. A build without `--masks` is another build.

use rh_e2e::{files_under, python, run, run_ok};
use std::path::{Path, PathBuf};

const W: u32 = 160;
const H: u32 = 96;

fn small_config(dir: &Path) -> PathBuf {
    rh_e2e::small_render_config(dir, W, H, true)
}

fn build(config: &Path, out: &Path, extra: &[&str]) -> std::process::Output {
    let mut args = vec![
        "--config",
        config.to_str().unwrap(),
        "build",
        "--n",
        "8",
        "--seed",
        "5",
        "--quiet",
        "--families",
        "object_drop,rolling_ball",
        "--out",
        out.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    run("rh-pipeline", &args)
}

fn build_ok(config: &Path, out: &Path, extra: &[&str]) {
    let o = build(config, out, extra);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

/// (width, height, bit depth, colour type) from a PNG's header.
fn png_header(path: &Path) -> (u32, u32, u8, u8) {
    let bytes = std::fs::read(path).unwrap();
    assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n", "{}", path.display());
    let be = |i: usize| u32::from_be_bytes(bytes[i..i + 4].try_into().unwrap());
    (be(16), be(20), bytes[24], bytes[25])
}

#[test]
fn masked_build_names_checks_merges_and_repairs_its_masks() {
    let tmp = tempfile::tempdir().unwrap();
    let config = small_config(tmp.path());
    let single = tmp.path().join("single");
    build_ok(&config, &single, &["--masks", "--jobs", "2"]);

    // pyarrow: per row, validity, the measured pixels and the mask and depth paths.
    let rows = python(&format!(
        "import pyarrow.parquet as pq, json\n\
         for r in pq.read_table('{}/data/test-00000-of-00001.parquet').to_pylist():\n    \
         print(json.dumps([r['scene_id'], r['valid'], r['closeup_hazard_visible_px'], \
         r['closeup_hazard_unoccluded_fraction'], r['ego_mask_paths'], r['overhead_depth_paths']]))",
        single.display()
    ));
    let manifest: serde_json::Value =
        serde_json::from_slice(&std::fs::read(single.join("build.json")).unwrap()).unwrap();
    assert_eq!(manifest["masks"], true);
    let sums = manifest["files"].as_object().unwrap();
    let mut rendered = 0;
    for line in rows.lines() {
        let v: serde_json::Value = serde_json::from_str(line).unwrap();
        let id = v[0].as_str().unwrap();
        if v[1] != true {
            assert!(
                v[2].is_null() && v[4].is_null(),
                "{id}: invalid but measured"
            );
            continue;
        }
        rendered += 1;
        assert_eq!(v[2].as_array().unwrap().len(), 5, "{line}");
        assert_eq!(v[3].as_array().unwrap().len(), 5, "{line}");
        assert!(v[3]
            .as_array()
            .unwrap()
            .iter()
            .all(|f| (0.0..=1.0).contains(&f.as_f64().unwrap())));
        for (paths, kind, cam) in [(&v[4], "masks", "ego"), (&v[5], "depth", "overhead")] {
            let expected: Vec<String> = ["0.000", "0.150", "0.300", "0.450", "0.600"]
                .iter()
                .map(|t| format!("{kind}/{id}/{cam}_t{t}.png"))
                .collect();
            let got: Vec<String> = serde_json::from_value(paths.clone()).unwrap();
            assert_eq!(got, expected);
            for p in &got {
                assert_eq!(png_header(&single.join(p)), (W, H, 16, 0), "{p}");
                assert!(sums.contains_key(p), "{p} has no checksum in build.json");
            }
        }
    }
    assert!(rendered >= 6, "only {rendered} of 8 scenes rendered");

    // Shards built with one worker merge into exactly the two-worker build.
    let shards: Vec<PathBuf> = (0..2).map(|i| tmp.path().join(format!("s{i}"))).collect();
    for (i, s) in shards.iter().enumerate() {
        build_ok(
            &config,
            s,
            &["--masks", "--shard", &format!("{i}/2"), "--jobs", "1"],
        );
    }
    let merged = tmp.path().join("merged");
    run_ok(
        "rh-pipeline",
        &[
            "merge",
            merged.to_str().unwrap(),
            shards[0].to_str().unwrap(),
            shards[1].to_str().unwrap(),
        ],
    );
    let reference = files_under(&single);
    assert!(reference.keys().any(|k| k.starts_with("masks/")));
    assert!(reference.keys().any(|k| k.starts_with("depth/")));
    let got = files_under(&merged);
    assert_eq!(
        reference.keys().collect::<Vec<_>>(),
        got.keys().collect::<Vec<_>>()
    );
    for (name, bytes) in &reference {
        assert!(
            bytes == &got[name],
            "{name} differs between the build and the merge"
        );
    }

    // verify checks the masks; a deleted one is reported, and the build repairs it.
    run_ok("rh-pipeline", &["verify", single.to_str().unwrap()]);
    let victim = reference
        .keys()
        .find(|k| k.starts_with("depth/"))
        .unwrap()
        .clone();
    std::fs::remove_file(single.join(&victim)).unwrap();
    let out = run("rh-pipeline", &["verify", single.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains(&format!("{victim}: missing")), "{stdout}");
    build_ok(&config, &single, &["--masks"]);
    let repaired = files_under(&single);
    assert!(repaired == reference, "the rebuilt dataset differs");

    // Masks are part of what a build is: the same directory without --masks is refused.
    let o = build(&config, &single, &[]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("masks true vs false"));
    // And --masks needs rendering.
    let o = build(
        &config,
        &tmp.path().join("bare"),
        &["--masks", "--no-render"],
    );
    assert_eq!(o.status.code(), Some(2));
}
