//! Furnished rooms (specification §3, "Decor"): the decor never changes a scene — the
//! same build with `[decor] enabled = false` has the same rows, labels, verdicts and
//! per-step state hashes — and every room type is furnished with at least four pieces of
//! furniture in its scenes.

use rh_e2e::{python, run_ok};
use std::path::Path;

/// The embedded configuration with `[decor] enabled` set, written into `dir`.
fn config(dir: &Path, enabled: bool) -> std::path::PathBuf {
    let configs = Path::new(env!("CARGO_MANIFEST_DIR")).join("../configs");
    std::fs::copy(configs.join("labels.toml"), dir.join("labels.toml")).unwrap();
    let default = std::fs::read_to_string(configs.join("default.toml")).unwrap();
    let at = default.find("\n[decor]\n").expect("a [decor] section");
    let (head, tail) = default.split_at(at);
    let tail = tail.replacen("\nenabled = true\n", &format!("\nenabled = {enabled}\n"), 1);
    assert!(
        tail.contains(&format!("\nenabled = {enabled}\n")),
        "the [decor] keys moved"
    );
    let text = format!("{head}{tail}");
    let path = dir.join(format!("decor_{enabled}.toml"));
    std::fs::write(&path, text).unwrap();
    path
}

fn build(dir: &Path, name: &str, config: &Path, seed: u64, n: u32) -> std::path::PathBuf {
    let out = dir.join(name);
    run_ok(
        "rh-pipeline",
        &[
            "build",
            "--n",
            &n.to_string(),
            "--seed",
            &seed.to_string(),
            "--no-render",
            "--quiet",
            "--config",
            config.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ],
    );
    out
}

/// Every column of the scene table but the spec file's name, row by row, as JSON.
fn rows(out: &Path) -> String {
    python(&format!(
        "import pyarrow.parquet as pq, json\n\
         t = pq.read_table('{}/data/test-00000-of-00001.parquet').to_pylist()\n\
         print(json.dumps(sorted(t, key=lambda r: r['scene_index']), sort_keys=True, default=str))",
        out.display()
    ))
}

/// The decor pieces that are windows or doors (not furniture), as a Python list.
fn openings() -> String {
    let catalog = rh_catalog::Catalog::embedded().unwrap();
    let ids: Vec<String> = catalog
        .decor
        .pieces
        .iter()
        .filter(|p| !p.is_furniture())
        .map(|p| format!("'{}'", p.id))
        .collect();
    assert!(!ids.is_empty(), "the catalog has windows and doors");
    format!("[{}]", ids.join(", "))
}

/// Per room type: the scenes and the decor pieces of their specs: furniture (drawn-only
/// pieces too, windows and doors not), its fewest in a scene and its kinds.
fn decor_by_room(out: &Path) -> serde_json::Value {
    let script = format!(
        "import json, glob\n\
         openings = set({})\n\
         rooms = {{}}\n\
         for f in sorted(glob.glob('{}/specs/*.json')):\n\
         \x20   s = json.load(open(f))\n\
         \x20   d = [b for b in s['bodies'] if b['role'] == 'decor']\n\
         \x20   r = rooms.setdefault(s['room']['id'], {{'scenes': 0, 'min_furniture': 99, 'kinds': []}})\n\
         \x20   furniture = [b for b in d if b['catalog_id'] not in openings]\n\
         \x20   r['scenes'] += 1\n\
         \x20   r['min_furniture'] = min(r['min_furniture'], len(furniture))\n\
         \x20   r.setdefault('counts', []).append(len(furniture))\n\
         \x20   r['kinds'] = sorted(set(r['kinds']) | {{b['catalog_id'] for b in furniture}})\n\
         \x20   assert all(b['kind'] == 'fixed' for b in d), f\n\
         \x20   assert s['bodies'][-len(d):] == d if d else True, f\n\
         print(json.dumps(rooms))",
        openings(),
        out.display()
    );
    serde_json::from_str(python(&script).trim()).unwrap()
}

#[test]
fn decor_never_changes_a_scene_and_every_room_type_is_furnished() {
    let dir = tempfile::tempdir().unwrap();
    let (on, off) = (config(dir.path(), true), config(dir.path(), false));
    let mut furnished = serde_json::Map::new();
    for seed in [5u64, 808, 31337] {
        let with = build(dir.path(), &format!("on_{seed}"), &on, seed, 136);
        let without = build(dir.path(), &format!("off_{seed}"), &off, seed, 136);
        // Same scenes, labels, verdicts, state hashes and decision hashes.
        assert_eq!(
            rows(&with),
            rows(&without),
            "seed {seed}: decor changed a row"
        );
        let bare = decor_by_room(&without);
        for (room, r) in bare.as_object().unwrap() {
            assert_eq!(
                r["kinds"],
                serde_json::json!([]),
                "{room} is bare without decor"
            );
        }
        let with_decor = decor_by_room(&with);
        eprintln!("seed {seed}: {with_decor}");
        for (room, r) in with_decor.as_object().unwrap() {
            let entry = furnished
                .entry(room.clone())
                .or_insert_with(|| serde_json::json!({"scenes": 0, "kinds": []}));
            let kinds: std::collections::BTreeSet<String> = entry["kinds"]
                .as_array()
                .unwrap()
                .iter()
                .chain(r["kinds"].as_array().unwrap())
                .map(|k| k.as_str().unwrap().to_string())
                .collect();
            entry["kinds"] = serde_json::json!(kinds);
            entry["scenes"] =
                (entry["scenes"].as_u64().unwrap() + r["scenes"].as_u64().unwrap()).into();
            // Every scene of every room type: at least four pieces of furniture.
            assert!(
                r["min_furniture"].as_u64().unwrap() >= 4,
                "seed {seed}: a {room} scene has fewer than four pieces of furniture: {r}"
            );
        }
    }
    eprintln!("{}", serde_json::Value::Object(furnished.clone()));
    assert_eq!(
        furnished.len(),
        11,
        "every room type is built: {furnished:?}"
    );
    for (room, r) in &furnished {
        let kinds = r["kinds"].as_array().unwrap().len();
        assert!(
            kinds >= 4,
            "{room}: only {kinds} kinds of furniture in its scenes: {r}"
        );
    }
}
