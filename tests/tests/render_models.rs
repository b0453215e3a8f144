//! Real meshes of catalog objects in rendered builds (issue 45): a rendered build drawing
//! models gives the same bytes with one worker and with two; its labels are the
//! label-only build's; its card credits the models it drew; a missing package or a
//! model whose bytes differ from the catalog's hash stops a rendered build with exit 2
//! naming the package (and its install command) or the file, while a label-only build
//! never needs the package.

use rh_e2e::{files_under, python, run, run_ok};
use std::path::{Path, PathBuf};

const W: u32 = 160;
const H: u32 = 96;
/// Families whose hazards in this build are objects with models (boxes, balls, books).
const FAMILIES: &str = "object_drop,rolling_ball";

fn build_args<'a>(config: &'a Path, out: &'a Path, extra: &[&'a str]) -> Vec<&'a str> {
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
        FAMILIES,
        "--out",
        out.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    args
}

/// The label columns of a build's rows, one line per scene.
fn labels(dir: &Path) -> String {
    python(&format!(
        "import pyarrow.parquet as pq\n\
         t = pq.read_table('{}/data/test-00000-of-00001.parquet').to_pylist()\n\
         for r in t:\n    print(r['scene_id'], r['valid'], r['gt_action'], r['dangerous'], r['danger_reasons'], r['time_to_impact'], r['harm_region'], r['state_hash'], r['decision_state_hash'])",
        dir.display()
    ))
}

#[test]
fn a_rendered_build_with_meshes_is_reproducible_keeps_its_labels_and_credits_its_models() {
    let tmp = tempfile::tempdir().unwrap();
    let config = rh_e2e::small_render_config(tmp.path(), W, H, true);
    let one = tmp.path().join("one");
    let two = tmp.path().join("two");
    let plain = tmp.path().join("plain");
    run_ok("rh-pipeline", &build_args(&config, &one, &["--jobs", "1"]));
    run_ok("rh-pipeline", &build_args(&config, &two, &["--jobs", "2"]));
    run_ok(
        "rh-pipeline",
        &build_args(&config, &plain, &["--no-render"]),
    );
    let (a, b) = (files_under(&one), files_under(&two));
    assert_eq!(
        a.keys().collect::<Vec<_>>(),
        b.keys().collect::<Vec<_>>(),
        "the same files"
    );
    for (name, bytes) in &a {
        assert!(
            b[name] == *bytes,
            "{name} differs between --jobs 1 and --jobs 2"
        );
    }
    assert_eq!(labels(&one), labels(&plain), "labels of the rendered build");
    let specs = |d: &Path| {
        files_under(d)
            .into_iter()
            .filter(|(k, _)| k.starts_with("specs/"))
            .collect::<Vec<_>>()
    };
    assert_eq!(specs(&one), specs(&plain), "the same scenes");
    // The card names the models of the objects its scenes drew, with creator and licence.
    let card = std::fs::read_to_string(one.join("README.md")).unwrap();
    let drawn: Vec<String> = python(&format!(
        "import json, glob\n\
         ids = set()\n\
         for f in glob.glob('{}/specs/*.json'):\n    ids |= {{b.get('catalog_id') for b in json.load(open(f))['bodies'] if b.get('catalog_id')}}\n\
         print('\\n'.join(sorted(ids)))",
        one.display()
    ))
    .lines()
    .map(String::from)
    .collect();
    let catalog = rh_catalog::Catalog::embedded().unwrap();
    let with_model: Vec<&String> = drawn
        .iter()
        // Decor bodies name decor pieces (catalog/data/decor.toml), not catalog objects.
        .filter(|id| {
            catalog
                .object(id)
                .is_some_and(|o| rh_catalog::models::drawn_model(&catalog, o).is_some())
        })
        .collect();
    assert!(!with_model.is_empty(), "this build draws models: {drawn:?}");
    assert!(card.contains("**3D models.**"), "{card}");
    for id in with_model {
        let o = catalog.object(id).unwrap();
        let m = rh_catalog::models::drawn_model(&catalog, o).unwrap();
        let row = format!(
            "| {} | {} | {} | `sweethome3d-furniture` |",
            m.name, m.creator, m.license
        );
        assert!(card.contains(&row), "{id}: no '{row}' in the card");
    }
    let plain_card = std::fs::read_to_string(plain.join("README.md")).unwrap();
    assert!(
        !plain_card.contains("3D models"),
        "a label-only card credits no model"
    );
}

fn with_models(config: &Path, dir: &Path, section: &str) -> PathBuf {
    let text = std::fs::read_to_string(config).unwrap();
    assert!(
        text.contains("\n[render.models]\n"),
        "the [render.models] section moved"
    );
    let path = dir.join("models.toml");
    std::fs::write(
        &path,
        text.replace(
            "\n[render.models]\n",
            &format!("\n[render.models]\n{section}\n"),
        ),
    )
    .unwrap();
    path
}

#[test]
fn a_missing_package_stops_a_rendered_build_and_never_a_label_only_one() {
    let tmp = tempfile::tempdir().unwrap();
    let config = rh_e2e::small_render_config(tmp.path(), W, H, true);
    let missing = tmp.path().join("no-such-package");
    let config = with_models(
        &config,
        tmp.path(),
        &format!("package_root = {:?}", missing.to_str().unwrap()),
    );
    let out = tmp.path().join("out");
    let rendered = run("rh-pipeline", &build_args(&config, &out, &[]));
    let err = String::from_utf8_lossy(&rendered.stderr);
    assert_eq!(rendered.status.code(), Some(2), "{err}");
    assert!(err.contains("'sweethome3d-furniture'"), "{err}");
    assert!(
        err.contains("sudo apt-get install sweethome3d-furniture"),
        "{err}"
    );
    let label_only = tmp.path().join("labels");
    run_ok(
        "rh-pipeline",
        &build_args(&config, &label_only, &["--no-render"]),
    );
    assert!(label_only.join("data/test-00000-of-00001.parquet").exists());
}

#[test]
fn a_model_whose_bytes_differ_from_the_catalog_hash_stops_a_rendered_build_naming_the_file() {
    let tmp = tempfile::tempdir().unwrap();
    let config = rh_e2e::small_render_config(tmp.path(), W, H, true);
    let catalog = tmp.path().join("catalog");
    std::fs::create_dir(&catalog).unwrap();
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("../catalog/data");
    std::fs::copy(data.join("rooms.toml"), catalog.join("rooms.toml")).unwrap();
    let objects = std::fs::read_to_string(data.join("objects.toml")).unwrap();
    // The hammer's hash, one digit changed.
    let m = rh_catalog::Catalog::embedded().unwrap();
    let hammer = m.object("hammer").unwrap().model.as_ref().unwrap();
    let mut wrong = hammer.sha256.clone();
    let last = if wrong.ends_with('0') { "1" } else { "0" };
    wrong.replace_range(63.., last);
    std::fs::write(
        catalog.join("objects.toml"),
        objects.replace(&hammer.sha256, &wrong),
    )
    .unwrap();
    let out = tmp.path().join("out");
    let mut args = build_args(&config, &out, &[]);
    args.extend(["--catalog", catalog.to_str().unwrap()]);
    let rendered = run("rh-pipeline", &args);
    let err = String::from_utf8_lossy(&rendered.stderr);
    assert_eq!(rendered.status.code(), Some(2), "{err}");
    assert!(
        err.contains(&format!("{}:{}", hammer.archive, hammer.path)),
        "{err}"
    );
    assert!(err.contains("'hammer'") && err.contains(&wrong), "{err}");
}
