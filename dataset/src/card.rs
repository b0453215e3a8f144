//! The dataset card (`README.md`) and the balanced evaluation subset (specification §8).
//!
//! The card is `dataset/card_template.md` with its `{{placeholders}}` filled from the
//! build manifest, the label thresholds of the build's configuration, the schema (feature
//! table, from `table::schema()` and `table::column_description`), and counts over the
//! rows. Everything is a pure function of (manifest, rows): a merged build and a single
//! build get the same card.

use crate::manifest::Manifest;
use crate::table;
use arrow::array::{Array, RecordBatch};
use arrow::datatypes::DataType;
use rh_scenes::eval_subset::{self, EvalConfig, EvalRow};
use std::collections::BTreeMap;
use std::fmt::Write;

const TEMPLATE: &str = include_str!("../card_template.md");
/// The paper's own Hub release: metadata only (no tables, no frames), cited as the paper's.
const PAPER_RELEASE: &str = "Alan123/reacthuman-benchmark-scaled";

/// The `eval` config's Parquet file.
pub const EVAL_FILE: &str = "eval/test-00000-of-00001.parquet";

/// How to get videos from the `*_file_name` columns (plain relative paths).
const VIDEO_NOTE: &str = r#"**Videos.** The `ego_file_name`, `closeup_file_name`, `overhead_file_name` and
`full_event_file_name` columns hold paths relative to this folder (plain strings, so pyarrow,
pandas, polars and duckdb read the table as is; null for invalid or unrendered scenes). To
get decodable videos in `datasets` (decoding needs `torchcodec`), make them absolute and cast
them to `Video`:

```python
from datasets import Video
def media(row):
    return {cam: os.path.join(DIR, row[f"{cam}_file_name"]) if row[f"{cam}_file_name"] else None
            for cam in ("ego", "closeup", "overhead", "full_event")}
scenes = scenes.map(media)
for cam in ("ego", "closeup", "overhead", "full_event"):
    scenes = scenes.cast_column(cam, Video())
# scenes[0]["ego"] is a torchcodec VideoDecoder; frame k shows physics step frame_steps[k]
```

For a Hub copy, `DIR = huggingface_hub.snapshot_download("owner/name", repo_type="dataset")`
fetches the videos too."#;

/// Per-family counts of a set of rows.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct FamilyCounts {
    pub scenes: usize,
    pub valid: usize,
    /// Ground-truth labels of the valid scenes.
    pub catch: usize,
    pub dodge: usize,
    pub no_action: usize,
}

/// Counts per family (keys sorted by name).
pub fn family_counts(batch: &RecordBatch) -> BTreeMap<String, FamilyCounts> {
    let family = table::string_column(batch, "family");
    let valid = table::bool_column(batch, "valid");
    let action = table::string_column(batch, "gt_action");
    let mut out: BTreeMap<String, FamilyCounts> = BTreeMap::new();
    for i in 0..batch.num_rows() {
        let c = out.entry(family[i].clone()).or_default();
        c.scenes += 1;
        if valid[i] {
            c.valid += 1;
            match action[i].as_str() {
                "CATCH" => c.catch += 1,
                "DODGE" => c.dodge += 1,
                _ => c.no_action += 1,
            }
        }
    }
    out
}

/// The evaluation subset as the manifest's configuration chooses it (the label-blind
/// default for manifests that cannot say).
pub fn manifest_eval_selection(
    batch: &RecordBatch,
    manifest: &Manifest,
) -> (Vec<u32>, BTreeMap<String, usize>) {
    let cfg = manifest.build_config().map(|c| c.eval).unwrap_or_default();
    eval_selection(batch, &cfg)
}

/// The evaluation subset of a build's rows under `cfg` (`rh_scenes::eval_subset`): row
/// indices in scene-index order and how many scenes each family got.
pub fn eval_selection(
    batch: &RecordBatch,
    cfg: &EvalConfig,
) -> (Vec<u32>, BTreeMap<String, usize>) {
    let family = table::string_column(batch, "family");
    let valid = table::bool_column(batch, "valid");
    let index = table::u64_column(batch, "scene_index");
    let action = table::string_column(batch, "gt_action");
    // Adversarial twin pairs (label rule v5); builds before it have no such column.
    let ids = table::string_column(batch, "scene_id");
    let by_id: BTreeMap<&str, u64> = ids
        .iter()
        .map(String::as_str)
        .zip(index.iter().copied())
        .collect();
    let twins: Vec<Option<u64>> =
        table::optional_string_column(batch, rh_contract::columns::col::TWIN_SCENE_ID)
            .into_iter()
            .map(|t| t.and_then(|t| by_id.get(t.as_str()).copied()))
            .collect();
    let rows: Vec<EvalRow> = (0..batch.num_rows())
        .map(|i| EvalRow {
            family: family[i].as_str(),
            scene_index: index[i],
            valid: valid[i],
            action: action[i].as_str(),
            twin: twins[i],
        })
        .collect();
    let (chosen, counts) = eval_subset::select(&rows, cfg);
    (chosen.into_iter().map(|r| r as u32).collect(), counts)
}

/// "18 in each of 17 families" or "5 families, 2 of them with 18".
fn eval_counts_text(eval: &BTreeMap<String, usize>, per_family: usize) -> String {
    let families = eval.values().filter(|&&n| n > 0).count();
    let full = eval.values().filter(|&&n| n == per_family).count();
    if families == full {
        format!("{per_family} in each of {families} families")
    } else {
        format!(
            "{} famil{}, {full} of them with {per_family}",
            families,
            if families == 1 { "y" } else { "ies" }
        )
    }
}

/// How the subset is chosen, in words (the card's config table).
fn eval_rule_text(cfg: &EvalConfig) -> String {
    match cfg.catch_share {
        Some(share) => format!(
            "evaluation subset, stratified by label: up to {} valid scenes per \
             family, {:.0}% of them CATCH where the family has them, at most {} NO_ACTION (its \
             adversarial twin pairs, taken first{}, up to {}; never a pair of two NO_ACTION), \
             the rest DODGE; a family short of CATCH gives more DODGE and the other way round; a \
             family short of real decisions takes more NO_ACTION only while the subset's \
             NO_ACTION scenes stay within {:.1}% of it",
            cfg.per_family,
            100.0 * share,
            cfg.no_action_per_family,
            if cfg.decisive_pairs_first {
                ", CATCH / DODGE pairs before those with a NO_ACTION scene"
            } else {
                ""
            },
            cfg.no_action_per_family.max(cfg.twin_no_action_per_family),
            100.0 * cfg.no_action_fill_share
        ),
        None => format!(
            "balanced evaluation subset: up to {} valid scenes per family (whole speed-band groups first)",
            cfg.per_family
        ),
    }
}

/// Hugging Face size category of a row count.
pub fn size_category(n: usize) -> &'static str {
    match n {
        0..1_000 => "n<1K",
        1_000..10_000 => "1K<n<10K",
        10_000..100_000 => "10K<n<100K",
        100_000..1_000_000 => "100K<n<1M",
        _ => "1M<n<10M",
    }
}

fn type_name(t: &DataType) -> String {
    match t {
        DataType::Utf8 => "string".into(),
        DataType::Boolean => "bool".into(),
        DataType::Float64 => "float64".into(),
        DataType::Float32 => "float32".into(),
        DataType::UInt64 => "uint64".into(),
        DataType::UInt32 => "uint32".into(),
        DataType::FixedSizeList(item, n) => format!("{}[{n}]", type_name(item.data_type())),
        DataType::List(item) => format!("list<{}>", type_name(item.data_type())),
        other => other.to_string(),
    }
}

fn fill(template: &str, values: &BTreeMap<&str, String>) -> String {
    let mut out = template.to_string();
    for (k, v) in values {
        out = out.replace(&format!("{{{{{k}}}}}"), v);
    }
    assert!(
        !out.contains("{{"),
        "dataset/card_template.md has an unfilled placeholder"
    );
    out
}

/// Where the card's numbers come from.
pub struct CardInput<'a> {
    pub manifest: &'a Manifest,
    /// Every row of this directory's `data/` file(s).
    pub rows: &'a RecordBatch,
    /// The data files, relative to the dataset directory.
    pub data_files: &'a [String],
    /// Eval subset per-family counts, when this directory has the eval config.
    pub eval: Option<&'a BTreeMap<String, usize>>,
    /// The credits of the 3D models drawn (`card_credits::section`; "" for none).
    pub credits: &'a str,
}

/// The project's release, the paper's, and the release this build is (if one).
fn insert_release(v: &mut BTreeMap<&str, String>, m: &Manifest) {
    v.insert("repo_id", rh_hub::released_dataset());
    v.insert("paper_repo", PAPER_RELEASE.into());
    let line = m
        .release
        .as_ref()
        .map(|id| format!(", release `{id}` of the benchmark"));
    v.insert("release_line", line.unwrap_or_default());
}

/// Renders `README.md`.
pub fn text(input: &CardInput) -> String {
    let m = input.manifest;
    let n_rows = input.rows.num_rows();
    let counts = family_counts(input.rows);
    let labels = m
        .labels()
        .expect("a manifest written by this version holds the label config");
    let mut v: BTreeMap<&str, String> = BTreeMap::new();
    v.insert("size_category", size_category(n_rows).into());
    insert_release(&mut v, m);
    v.insert(
        "row_group_size",
        table::row_group_size(m.render).to_string(),
    );
    v.insert("rule_version", labels.rule_version.clone());
    let window = m
        .config
        .pointer("/observation/window_s")
        .and_then(|w| w.as_f64())
        .unwrap_or(0.6);
    v.insert("window_s", format!("{window}"));

    // configs
    let mut configs = String::from(
        "- config_name: default\n  default: true\n  data_files:\n  - split: test\n    path: data/test-*.parquet\n",
    );
    let mut table = format!(
        "| `default` | `data/test-*.parquet` | {n_rows} | every scene of this {} |\n",
        if m.is_whole() { "build" } else { "shard" }
    );
    let total_eval: usize = input.eval.map(|e| e.values().sum()).unwrap_or(0);
    let eval_cfg = m.build_config().map(|c| c.eval).unwrap_or_default();
    let per_family = eval_cfg.per_family;
    if input.eval.is_some() {
        configs.push_str(
            "- config_name: eval\n  data_files:\n  - split: test\n    path: eval/test-*.parquet\n",
        );
        let _ = writeln!(
            table,
            "| `eval` | `{EVAL_FILE}` | {total_eval} | {}; here {} |",
            eval_rule_text(&eval_cfg),
            eval_counts_text(input.eval.unwrap_or(&BTreeMap::new()), per_family)
        );
        v.insert(
            "eval_example",
            format!(
                "subset = load_dataset(DIR, \"eval\", split=\"test\")  # {total_eval} scenes\n"
            ),
        );
    } else {
        v.insert("eval_example", String::new());
    }
    v.insert("configs", configs.trim_end().to_string());
    v.insert("config_table", table.trim_end().to_string());

    let mut scope = if m.is_whole() {
        format!(
            "This build holds **{n_rows} scenes** ({} valid) of {} famil{} in {} scene group{} \
             (four speed bands per group: slow, normal, fast, very_fast).",
            counts.values().map(|c| c.valid).sum::<usize>(),
            counts.len(),
            if counts.len() == 1 { "y" } else { "ies" },
            m.n_groups(),
            if m.n_groups() == 1 { "" } else { "s" }
        )
    } else {
        format!(
            "This directory is **shard {} of {}** of a {}-scene build: {n_rows} scenes, the groups g \
             with g mod {} = {}. Combine all shards with `rh-pipeline merge OUT SHARD_DIR...`; \
             the merged dataset equals an unsharded build byte for byte and has the `eval` config.",
            m.shard[0], m.shard[1], m.n, m.shard[1], m.shard[0]
        )
    };
    let absent: Vec<&str> = m
        .families
        .iter()
        .filter(|f| !counts.contains_key(*f))
        .map(String::as_str)
        .collect();
    if !absent.is_empty() {
        let _ =
            write!(
            scope,
            "\n\nThe build was asked for {} families; {} got no scene group because the build is \
             smaller than one group per family (families are dealt to groups in turn): {}.",
            m.families.len(),
            absent.len(),
            absent.iter().map(|f| format!("`{f}`")).collect::<Vec<_>>().join(", ")
        );
    }
    if let Some(eval) = input.eval {
        scope.push_str(&eval_short_note(m, &counts, eval, &eval_cfg));
    }
    v.insert("scope", scope);
    v.insert("video_note", VIDEO_NOTE.trim_end().to_string());
    let rendered = input
        .rows
        .column_by_name("ego_file_name")
        .is_some_and(|c| c.null_count() < c.len());
    v.insert(
        "render_note",
        if rendered {
            "Videos and frames exist for the valid scenes (invalid ones have null `*_file_name` \
             columns). Video frame `k` of a camera video shows physics step \
             `round(k / fps / dt)` of the spec (`video.fps`, `physics.dt`), clamped to the \
             scene's last step; the PNG at time t is video frame `round(t · fps)` before \
             compression.\n\n**The full-event video** (`videos/full/<id>.mp4`, for people, never \
             model input) shows what the labels mean: the counterfactual run of the label \
             rule, in which the standing observer is a body of fixed colliders (the \
             humanoid's thirteen links at rest, the body `rh-score --execute` moves), run to \
             the end of the event (the run the labels use stops after a strike's window). A hazard that would \
             strike the observer stops at its body there, instead of passing through it as \
             in the plain run, where the observer is drawn but is no body. Where nothing \
             comes near the observer the two runs are the same. The camera videos and \
             frames show the plain run: they end at Δ, before anything reaches the observer \
             in a valid scene. The drawn robot is a decorative mesh close to, not exactly, \
             those links. Full-event frame `j` shows step `round(j / full_fps / dt)` of that run."
                .into()
        } else {
            "This build has no rendered videos: the `*_file_name` columns are null and there is \
             no `videos/` or `frames/` folder (built with `--no-render`)."
                .into()
        },
    );

    if let (true, Some(note)) = (!input.credits.is_empty(), v.get_mut("render_note")) {
        note.push_str("\n\n");
        note.push_str(input.credits);
    }
    v.insert("masks_note", masks_note(m.masks));
    v.insert("family_table", family_table(input, &counts, total_eval));

    v.insert("features_table", features_table());
    v.insert("teaser", crate::card_teaser::teaser(input.rows));
    v.insert("frame_size", crate::card_teaser::frame_size(m));

    v.insert(
        "label_rule",
        format!(
            "{}\n{}{}",
            label_rule(m, &labels),
            probe_rule(m),
            crate::camera_columns::card_note(&m.config)
        ),
    );

    insert_provenance(input, &mut v);
    fill(TEMPLATE, &v)
}

/// The build summary table and the command that rebuilds this dataset.
/// The card's note on families with fewer than `per_family` scenes in the eval subset
/// (empty when every family has them).
fn eval_short_note(
    m: &Manifest,
    counts: &BTreeMap<String, FamilyCounts>,
    eval: &BTreeMap<String, usize>,
    eval_cfg: &EvalConfig,
) -> String {
    let per_family = eval_cfg.per_family;
    let short: Vec<String> = m
        .families
        .iter()
        .filter(|f| counts.contains_key(*f))
        .filter(|f| eval.get(*f).copied().unwrap_or(0) < per_family)
        .map(|f| format!("`{f}` ({})", eval.get(f).copied().unwrap_or(0)))
        .collect();
    if short.is_empty() {
        return String::new();
    }
    format!(
        "\n\n**Note:** the `eval` config takes up to {per_family} valid scenes per family, at \
         most {} NO_ACTION (more only while the subset's NO_ACTION scenes stay within {:.1}% \
         of it); this build has fewer real decisions in {} of its {} families, so the subset \
         holds fewer scenes of: {}.",
        eval_cfg.no_action_per_family,
        100.0 * eval_cfg.no_action_fill_share,
        short.len(),
        counts.len(),
        short.join(", ")
    )
}

fn insert_provenance(input: &CardInput, v: &mut BTreeMap<&str, String>) {
    let m = input.manifest;
    let default_config = rh_scenes::config::Config::embedded()
        .map(|c| crate::manifest::config_sha256(&c) == m.config_sha256)
        .unwrap_or(false);
    v.insert(
        "build_summary",
        format!(
            "| | |\n|---|---|\n| build seed | {} |\n| scenes (whole build) | {} |\n| scene groups | {} |\n\
| families | {} |\n| shard | {}/{} |\n| render | {} |\n| configuration | {} (sha256 `{}`) |\n\
| render adapter | {} |\n| catalog | sha256 `{}` |\n| rh-pipeline | {} |\n| data files | {} |",
            m.seed,
            m.n,
            m.n_groups(),
            m.families.join(", "),
            m.shard[0],
            m.shard[1],
            match (m.render, m.masks) {
                (true, true) => "yes (valid scenes), with masks and depth (--masks)",
                (true, false) => "yes (valid scenes)",
                _ => "no (--no-render)",
            },
            if default_config { "the default `configs/default.toml`" } else { "custom" },
            m.config_sha256,
            match &m.render_adapter {
                Some(a) => a.describe().replace('|', "/"),
                None => "none (not rendered, or not recorded)".into(),
            },
            m.catalog_sha256,
            m.rh_pipeline_version,
            input
                .data_files
                .iter()
                .map(|f| format!("`{f}`"))
                .collect::<Vec<_>>()
                .join(", "),
        ),
    );
    v.insert(
        "rebuild_command",
        format!(
            "rh-pipeline{} build --n {} --seed {} --families {}{}{} --out DIR",
            if default_config {
                ""
            } else {
                " --config YOUR_CONFIG.toml"
            },
            m.n,
            m.seed,
            m.families.join(","),
            match (m.render, m.masks) {
                (true, true) => " --masks",
                (true, false) => "",
                _ => " --no-render",
            },
            if m.is_whole() {
                String::new()
            } else {
                format!(" --shard {}/{}", m.shard[0], m.shard[1])
            }
        ),
    );
}

/// What the measured-visibility columns mean, and the masks and depth of `--masks`.
fn masks_note(masks: bool) -> String {
    use rh_contract::layout::instance;
    // Paragraphs start at the line's first column: text indented 4+ spaces after a blank
    // line is a code block in CommonMark (the Hub's renderer).
    let mut s = format!(
        "**Measured visibility.** For every rendered scene the renderer draws an instance-id \
         image of each camera at the five observation times (unlit, one sample per pixel, \
         the same geometry as the frames: the ego camera sits in the observer's head and \
         does not see its own body). `<cam>_hazard_visible_px` counts the pixels that show \
         the hazard; `<cam>_hazard_unoccluded_fraction` divides them by the pixels the \
         hazard covers when drawn with nothing else (1 = nothing in front of it; 0 when it \
         projects to no pixel of the image). Both are null for unrendered scenes.\n\n\
         **Segmentation and depth.** Instance ids: {} = room (floor, walls, ceiling) and \
         empty background; `i + 1` = the spec's body `bodies[i]` (the hazard is \
         `hazard + 1`); {} = ropes and rods drawn along joints; {} = the observer's body. \
         Depth: Euclidean distance of the surface from the camera centre in millimetres \
         (round(d · 1000); 0 = no surface, 65535 = 65.535 m or more). ",
        instance::ROOM,
        instance::ROPE,
        instance::OBSERVER
    );
    if masks {
        s.push_str(
            "This build has them (`--masks`): `masks/<scene_id>/<cam>_t0.000.png` … and \
             `depth/<scene_id>/<cam>_t0.000.png` … (16-bit greyscale PNG, the size of the \
             frames), named by the `<cam>_mask_paths` and `<cam>_depth_paths` columns in \
             `FRAME_TIMES` order.",
        );
    } else {
        s.push_str(
            "This build has none: they are written by `rh-pipeline build --masks`, and the \
             `<cam>_mask_paths` / `<cam>_depth_paths` columns are null.",
        );
    }
    s
}

/// The per-family table, in the build's family order (label counts over valid scenes).
fn family_table(
    input: &CardInput,
    counts: &BTreeMap<String, FamilyCounts>,
    total_eval: usize,
) -> String {
    let m = input.manifest;
    let mut ft = String::from(
    "Label counts are over valid scenes.\n\n| family | scenes | valid | CATCH | DODGE | NO_ACTION |",
);
    if input.eval.is_some() {
        ft.push_str(" eval |");
    }
    ft.push_str("\n|---|---|---|---|---|---|");
    if input.eval.is_some() {
        ft.push_str("---|");
    }
    ft.push('\n');
    let mut total = FamilyCounts::default();
    for f in m.families.iter().filter(|f| counts.contains_key(*f)) {
        let c = counts.get(f).cloned().unwrap_or_default();
        let _ = write!(
            ft,
            "| {f} | {} | {} | {} | {} | {} |",
            c.scenes, c.valid, c.catch, c.dodge, c.no_action
        );
        if let Some(e) = input.eval {
            let _ = write!(ft, " {} |", e.get(f).copied().unwrap_or(0));
        }
        ft.push('\n');
        total.scenes += c.scenes;
        total.valid += c.valid;
        total.catch += c.catch;
        total.dodge += c.dodge;
        total.no_action += c.no_action;
    }
    let _ = write!(
        ft,
        "| **total** | {} | {} | {} | {} | {} |",
        total.scenes, total.valid, total.catch, total.dodge, total.no_action
    );
    if input.eval.is_some() {
        let _ = write!(ft, " {total_eval} |");
    }
    ft
}

/// The feature table: every column of the scene table with its type and meaning.
fn features_table() -> String {
    let schema = table::schema();
    let mut features = String::new();
    for field in schema.fields() {
        let _ = writeln!(
            features,
            "| `{}` | `{}`{} | {} |",
            field.name(),
            type_name(field.data_type()),
            if field.is_nullable() {
                ", nullable"
            } else {
                ""
            },
            table::column_description(field.name()).unwrap_or_default()
        );
    }
    features.trim_end().to_string()
}

/// The label rule in words, with the build's thresholds.
fn label_rule(m: &Manifest, labels: &rh_physics::spec::LabelConfig) -> String {
    let l = labels;
    let validator = |key: &str, default: f64| {
        m.config
            .pointer(&format!("/validators/{key}"))
            .and_then(|x| x.as_f64())
            .unwrap_or(default)
    };
    let shoulder = m
        .config
        .pointer("/observer/shoulder_z")
        .and_then(|x| x.as_f64())
        .unwrap_or(1.10);
    format!(
        "* **Decision moment** Δ = the end of the observation window ({window} s): the model \
commits its plan then, so every label about reaching the observer looks at t ≥ Δ.
* **Reach envelope**: every point within {arm} m (arm reach) of the *shoulder region* — the \
horizontal discs around the observer's torso axis of radius {offset} m (half the shoulder \
width) + {step} m (one step), at heights from shoulder height − {crouch} m (a knee bend) up to \
shoulder height ({shoulder} m). It reaches {reach_out:.2} m from the torso axis at shoulder \
height and spans heights {lo:.2}–{hi:.2} m near the body. The hands **hold** a hazard only in \
the part above {min_h} m (rule v4: lower, the crouched knees and thighs are in front of the \
hands).
* **Impact point** (`impact_kind = envelope`, rule v4): the hazard's centre of mass at the \
first physics step at or after Δ at which it is where the hands can hold it (in the envelope, \
above {min_h} m) *and where they can be in time* — the observer, standing still at Δ, walks the \
horizontal distance by which the point lies beyond the arms' reach at its height (from rest, \
≤ {walk_a} m/s² and ≤ {walk_v} m/s, the robot's base limits) and takes {prep} s for the hands, \
all before the hazard gets there — and before it would first touch the standing body in the \
counterfactual run below, and within {tol} m of the closest it comes to the torso \
axis (the vertical segment floor → head) at such steps: where the hands would meet it. A \
hazard that is in the envelope after Δ only too low, too soon or too late: the same choice among all \
its envelope steps (`envelope_late`, rule v3's point). A hazard that never enters the \
envelope after Δ: its closest approach to the torso axis after Δ if within {closest} m \
(`closest_approach`); else null. `time_to_impact` and `impact_speed` (of the centre of mass) \
are taken at that step.
* **Reaction time** (validator `valid_reaction_time`): the hazard must not reach the \
observer — the same interception computed from t = 0, a closest approach within {reach} m, \
or a strike of the standing body — before Δ + {reaction} s; such a scene is resampled.
* **Visibility** (validator `valid_visible`): at every frame of the observation window until the hazard comes within {until} m of the torso axis, in each of the three model-input views, at least {vis_fraction} of 15 points per collision shape sampled on the hazard (corners, face centres, rims and centre, 10% inside its surface) lie inside the image with no fixed body and no part of the observer's body — its collision capsule widened by {vis_margin} m; the ego camera, inside it, excepted — in the way, and the hazard's projected size (largest side of the box around its points) is at least {vis_px} px at the videos' resolution. The three cameras are the same for the four speed bands of a group (framed on the union of their paths), so the bands differ only in speed. Failing layouts are resampled.
* **time_to_floor**: the first floor contact of the hazard's lowest point (within {eps} m), \
refined by its ballistic fall from the last step above the floor; for a body that starts on \
the floor (a toppling wardrobe, a ladder), the moment the top corners of its bounding box \
first come within {eps} m of the floor, interpolated within the step.
* **dangerous**: the object is sharp, hot, or large and fragile (catalog hazard flags of its \
true physics), or its mass is ≥ {heavy} kg, or its impact momentum is ≥ {momentum} kg·m/s.
* **danger_present** (rule v5: danger is harm): in a counterfactual simulation with the \
observer's body as fixed colliders — the articulated humanoid the executor moves \
(`rh-score --execute`), standing at its pose with the palms at rest: pelvis, torso, head, \
upper arms, forearms, palms, thighs and shanks (capsules and boxes with Unitree G1 proportions, \
{height} m tall; the legs are two capsules 0.18 m apart, so a small ball can pass between \
them) — the standing body would be **harmed**. Each touch is placed in a body region of \
ISO/TS 15066:2016 Annex A (the link, and for the head and torso where on it: the head's \
base is the neck, its lower front the face, the rest skull and forehead; the torso's back \
and top are back and shoulders, its front above the middle the chest, below it the \
abdomen). Within {window_strike} s of a touch a region is harmed when the **transient \
energy** of a touch, E = ½ μ v² — v the speed of the hazard's contact point along the \
contact normal relative to the body (with the hazard's velocities just before contact), \
μ = m_h m_b / (m_h + m_b) the reduced mass of the hazard's effective mass at that point \
(the free body's, rotation included) and the region's effective body mass m_b (the \
standard's two-body model) — reaches the region's permissible transient energy \
(f·F)² / (2k), or when the **sustained force** (the impulse the region receives over the \
window, divided by its length) reaches F; F is the standard's maximum permissible \
quasi-static force, k its effective spring constant, f = {harm_f} (transient contact may \
reach twice F). A **sharp or hot** hazard harms by touching the body at all (any contact impulse). A touch \
that does not harm closes after the window and a later touch is judged afresh. The \
recorded window's worst region, energy, force and ratio to the limits are the columns \
`harm_region`, `harm_energy`, `harm_force`, `harm_ratio` (≥ 1: harm). These are the \
standard's onsets of pain and minor injury, taken as the line for harm (a 58 g ball \
rolling into the shin at 1 m/s, 0.03 J, is no harm; a 1 kg book dropped 1 m onto the \
head, ≈ 8 J, is). Rules v2–v4 called any touch with a contact speed ≥ 0.5 m/s and an \
impulse ≥ 0.05 N·s a strike, a tennis ball rolling into the foot included.

{harm_table}
* **reachable**: the hazard passes within {reach} m of the torso axis at or after Δ, or \
danger is present.
* **gt_action** (rule v5), in this order: `CATCH` when the hazard is benign (not \
dangerous, impact speed ≤ {fast} m/s and impact kinetic energy ≤ {energy} J), reachable, \
comes where the hands can meet it in time (`impact_kind = envelope`) and fits in the arms \
(bounding radius around its centre ≤ {catch_r} m, half the arm span: a 2.2 m prop ladder \
or a hinged prop door is fended off, not caught) — rule v4's CATCH; else `DODGE` when \
danger is present (the standing body would be harmed); else `NO_ACTION` — nothing reaches \
the observer, or only harmlessly, including a dangerous object that never harms the \
standing body (a knife that stops a metre away: standing still is safe). Rule v4 called \
every dangerous or too fast reachable hazard `DODGE`, touch or not, and rules v2–v3 every \
benign reachable one `CATCH`, including balls rolling to the feet, which the executor's \
humanoid cannot catch (`rh-score --execute`: on a 340-scene build the oracle baseline \
caught 58 of 146 rule-v3 CATCH labels, 131 of 137 rule-v6 ones; 69 of 72 under rule v4).
* **Escape** (validator `valid_escapable`, rule v4): a `DODGE` scene with danger present whose \
hazard reaches the observer within {esc_within} s of Δ must be escapable — of {esc_n} walks of {esc_d} m at {esc_v} m/s in evenly spaced directions (the \
first straight back), hands at rest, executed in physics from Δ by the executor of `rh-score \
--execute`, at least one is not struck. A scene no walk escapes (a heavy object sliding into \
the shins 0.3 s after Δ) is resampled: no decision could matter.",
        until = validator("frame_check_until_within", 0.45),
        vis_fraction = validator("visible_fraction_min", 0.5),
        vis_margin = validator("visibility_observer_margin", 0.08),
        vis_px = validator("visible_size_px_min", 8.0),
        window = m
            .config
            .pointer("/observation/window_s")
            .and_then(|x| x.as_f64())
            .unwrap_or(0.6),
        arm = l.envelope_arm_reach,
        offset = l.envelope_shoulder_offset,
        step = l.envelope_step,
        crouch = l.envelope_crouch,
        shoulder = shoulder,
        reach_out = l.envelope_shoulder_offset + l.envelope_step + l.envelope_arm_reach,
        lo = shoulder - l.envelope_crouch - l.envelope_arm_reach,
        min_h = l.envelope_min_height,
        walk_a = l.catch_walk_accel,
        walk_v = l.catch_walk_speed,
        prep = l.catch_prepare_s,
        catch_r = l.catch_radius_max,
        esc_n = l.escape_directions,
        esc_d = l.escape_distance,
        esc_v = l.escape_speed,
        esc_within = l.escape_check_within_s,
        hi = shoulder + l.envelope_arm_reach,
        tol = l.interception_tolerance,
        closest = l.closest_approach_max,
        reach = l.reach_radius,
        reaction = l.reaction_time_min,
        eps = l.floor_contact_eps,
        heavy = l.heavy_mass_kg,
        momentum = l.heavy_momentum,
        height = m
            .config
            .pointer("/observer/height")
            .and_then(|x| x.as_f64())
            .unwrap_or(1.32),
        window_strike = l.strike_window_s,
        harm_f = l.harm_transient_factor,
        harm_table = harm_table(l),
        fast = l.catch_speed_max,
        energy = l.catch_energy_max,
    )
}

/// Label rule v6's words on the adversarial probes, with the build's numbers.
fn probe_rule(m: &Manifest) -> String {
    let num = |path: &str| m.config.pointer(path).and_then(|x| x.as_f64());
    let divergence = num("/probes/divergence_min").unwrap_or(0.0);
    let drag = match (
        num("/physics/drag/air_density"),
        num("/physics/drag/terminal_speed_max"),
    ) {
        (Some(rho), Some(vt)) => format!(
            "quadratic air drag F = −½ ρ C_d A(v̂) |v| v (ρ = {rho} kg/m³, C_d {} for spheres and \
             capsules, {} for boxes and cylinders, A the area projected along the velocity) acts \
             every step on every body whose terminal speed is below {vt} m/s",
            num("/physics/drag/sphere_coefficient").unwrap_or(0.0),
            num("/physics/drag/flat_coefficient").unwrap_or(0.0),
        ),
        _ => "no air drag acts".to_string(),
    };
    format!(
        "* **Probes answerable from the window** (rule v6): an adversarial twin pair (the same \
spec with only the object replaced by its look-alike, `twin_scene_id`) is a probe only where \
its hazards' centres of mass come at least {divergence} m apart at some physics step of the \
observation window; other pairs' scenes stay, unpaired (`family_params.twin_divergence_m` \
records the distance). What reveals the physics: every launch is a push — the spec's \
velocities are what the push gives a body of `push_mass`, so a lighter twin leaves faster \
(the same momentum) — and {drag}, so a large light twin falls or swings slower."
    )
}

/// The harm limits per body region (rule v5), as a Markdown table.
fn harm_table(l: &rh_physics::spec::LabelConfig) -> String {
    let mut out = String::from(
        "| Body region (ISO/TS 15066 Annex A) | F, quasi-static (N) | k (N/mm) | body mass (kg) | \
         transient energy (f·F)²/(2k) (J) |\n|---|---|---|---|---|\n",
    );
    for r in rh_physics::strike::Region::ALL {
        if let Some(h) = l.harm.get(r.name()) {
            let e = rh_physics::strike::RegionLimit::of(h, l.harm_transient_factor).energy_max;
            out += &format!(
                "| {} | {} | {} | {} | {:.2} |\n",
                r.name(),
                h.force_n,
                h.spring_n_per_mm,
                h.body_mass_kg,
                e
            );
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn masks_note_is_prose_not_a_code_block() {
        // CommonMark: a line indented 4+ spaces after a blank line starts a code block.
        for masks in [false, true] {
            let note = masks_note(masks);
            assert!(note.contains("\n\n**Segmentation and depth.**"), "{note}");
            for line in note.lines() {
                assert!(!line.starts_with("    "), "indented line: {line:?}");
                assert!(!line.contains("  "), "a run of spaces: {line:?}");
            }
        }
    }

    #[test]
    fn the_card_prints_every_harm_limit() {
        let l = rh_physics::spec::LabelConfig::embedded();
        let t = harm_table(&l);
        assert_eq!(t.lines().count(), 2 + 12, "{t}");
        assert!(
            t.contains("| skull_forehead | 130 | 150 | 4.4 | 0.23 |"),
            "{t}"
        );
        assert!(t.contains("| lower_leg | 130 | 60 | 75 | 0.56 |"), "{t}");
    }

    #[test]
    fn size_categories() {
        assert_eq!(size_category(306), "n<1K");
        assert_eq!(size_category(10_000), "10K<n<100K");
        assert_eq!(size_category(9_999), "1K<n<10K");
    }
}
