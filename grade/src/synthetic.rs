//! Synthetic datasets with exactly the column contract `rh-pipeline` writes (specification §8), for
//! tests, benchmarks, and `rh-score make-fixture` (hidden; feature `synthetic`, a default one, so a
//! minimal build leaves it out). The physics is not simulated:
//! labels and geometry are drawn to cover the scorer's cases (impact points in front,
//! beside, behind, near and far, above and below the pelvis; scenes without an impact
//! point; adversarial look-alikes; four speed bands per group).

use crate::dataset::{Dataset, SceneInput, SPEED_BANDS};
use anyhow::{Context, Result};
use arrow::array::{
    ArrayRef, BooleanBuilder, FixedSizeListBuilder, Float64Builder, ListBuilder, RecordBatch,
    StringBuilder, UInt32Builder, UInt64Builder,
};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rh_contract::columns::col;
use rh_contract::fsio::write_atomic;
use rh_contract::layout::{data_file_name, spec_path};
use rh_contract::Action;
use std::f64::consts::PI;
use std::path::Path;
use std::sync::Arc;

/// Whether each family of `rh_contract::FAMILIES` (same order) sweeps speed in the
/// fixture's synthetic scenes.
const FAMILY_SWEEPS: [bool; 17] = [
    false, true, false, false, true, true, true, false, true, true, true, true, true, true, false,
    true, true,
];
/// (id, name, category, looks_like, dangerous, mass)
type ObjectRow = (
    &'static str,
    &'static str,
    &'static str,
    Option<&'static str>,
    bool,
    f64,
);
const OBJECTS: [ObjectRow; 10] = [
    ("tennis_ball", "tennis ball", "ball", None, false, 0.06),
    ("apple", "apple", "food", None, false, 0.2),
    ("plush_toy", "plush toy", "toy", None, false, 0.3),
    ("kitchen_knife", "kitchen knife", "utensil", None, true, 0.2),
    ("anvil", "anvil", "tool", None, true, 20.0),
    ("glass_mirror", "glass mirror", "decor", None, true, 6.0),
    (
        "foam_anvil",
        "foam anvil",
        "prop",
        Some("anvil"),
        false,
        0.4,
    ),
    (
        "steel_apple",
        "steel apple",
        "prop",
        Some("apple"),
        true,
        1.6,
    ),
    (
        "lead_tennis_ball",
        "lead-core tennis ball",
        "prop",
        Some("tennis_ball"),
        true,
        1.1,
    ),
    (
        "foam_mirror",
        "foam mirror",
        "prop",
        Some("glass_mirror"),
        false,
        0.3,
    ),
];

/// One full dataset row.
#[derive(Debug, Clone)]
pub struct FixtureRow {
    pub scene: SceneInput,
    pub scene_index: u64,
    pub seed: u64,
    pub object_name: String,
    pub object_category: String,
    pub mass: f64,
    pub speed_value: f64,
    pub time_to_impact: Option<f64>,
}

fn splitmix(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// `n` synthetic scenes (groups of four speed bands), reproducible from `seed`.
pub fn synth_rows(n: usize, seed: u64) -> Vec<FixtureRow> {
    let mut rows = Vec::with_capacity(n);
    let mut ids = std::collections::HashSet::new();
    let mut g = 0u64;
    while rows.len() < n {
        let mut rng = ChaCha8Rng::seed_from_u64(splitmix(seed ^ splitmix(g)));
        let (family, sweep) = (
            rh_contract::FAMILIES[(g % 17) as usize],
            FAMILY_SWEEPS[(g % 17) as usize],
        );
        let obj = OBJECTS[rng.random_range(0..OBJECTS.len())];
        let group_id = format!("g{:07x}", splitmix(seed.wrapping_add(g)) & 0xfff_ffff);
        let pose = [
            rng.random_range(-2.0..2.0),
            rng.random_range(-2.0..2.0),
            rng.random_range(-PI..PI),
        ];
        // Hazard geometry in the observer's body frame.
        let no_action = g % 9 == 4;
        let bearing: f64 = match rng.random_range(0..10) {
            0 => rng.random_range(2.0..PI),   // behind
            1 => rng.random_range(-PI..-2.0), // behind, other side
            2 => rng.random_range(1.2..1.9),  // beside
            _ => rng.random_range(-1.0..1.0), // in front
        };
        let dist: f64 = match rng.random_range(0..6) {
            0 => rng.random_range(0.02..0.25), // very close
            1 => rng.random_range(1.6..4.0),   // far
            _ => rng.random_range(0.4..1.5),
        };
        let z = match rng.random_range(0..6) {
            0 => 0.25,
            1 => 1.45,
            _ => 0.9,
        };
        let world_bearing = pose[2] + bearing;
        let impact = [
            pose[0] + dist * world_bearing.cos(),
            pose[1] + dist * world_bearing.sin(),
            z,
        ];
        let start = [
            impact[0] + 0.8 * world_bearing.cos(),
            impact[1] + 0.8 * world_bearing.sin(),
            1.6,
        ];
        let base_speed = rng.random_range(0.5..2.0);
        for (b, band) in SPEED_BANDS.iter().enumerate() {
            if rows.len() >= n {
                break;
            }
            let mut k = 0u64;
            let scene_id = loop {
                let id = format!(
                    "{:08x}",
                    splitmix(seed ^ (g * 4 + b as u64) ^ (k << 40)) as u32
                );
                if ids.insert(id.clone()) {
                    break id;
                }
                k += 1;
            };
            let fast = b >= 2 && sweep;
            let (gt, danger_present, impact_point) = if no_action {
                (Action::NoAction, false, None)
            } else if obj.4 || (fast && b == 3) {
                (Action::Dodge, true, Some(impact))
            } else {
                (
                    Action::Catch,
                    rng.random_range(0.0..1.0) < 0.7,
                    Some(impact),
                )
            };
            let speed_value = base_speed * [0.4, 1.0, 1.8, 3.0][b];
            rows.push(FixtureRow {
                scene: SceneInput {
                    scene_id,
                    group_id: group_id.clone(),
                    family: family.to_string(),
                    speed_band: band.to_string(),
                    speed_sweep: sweep,
                    object_id: obj.0.to_string(),
                    looks_like: obj.3.map(str::to_string),
                    adversarial: obj.3.is_some(),
                    twin_scene_id: None,
                    gt_action: gt,
                    dangerous: obj.4,
                    danger_present,
                    impact_point,
                    object_start: start,
                    observer_pose: pose,
                    // A few invalid scenes, as a real build may leave.
                    valid: rows.len() % 29 != 7,
                },
                scene_index: rows.len() as u64,
                seed: splitmix(seed ^ rows.len() as u64),
                object_name: obj.1.to_string(),
                object_category: obj.2.to_string(),
                mass: obj.5,
                speed_value,
                time_to_impact: impact_point.map(|_| 0.6 + 1.0 / speed_value),
            });
        }
        g += 1;
    }
    rows
}

/// The scenes of fixture rows as an in-memory dataset.
pub fn dataset_of(rows: &[FixtureRow]) -> Dataset {
    Dataset::from_scenes(
        "fixture".into(),
        rows.iter().map(|r| r.scene.clone()).collect(),
    )
}

fn vec3_col<'a>(it: impl Iterator<Item = Option<&'a [f64; 3]>>) -> ArrayRef {
    // The contract's type: a fixed-size list of 3 non-null float64.
    let item = arrow::datatypes::Field::new("item", arrow::datatypes::DataType::Float64, false);
    let mut b = FixedSizeListBuilder::new(Float64Builder::new(), 3).with_field(item);
    for v in it {
        match v {
            Some(p) => {
                b.values().append_slice(p);
                b.append(true);
            }
            None => {
                b.values().append_slice(&[0.0; 3]);
                b.append(false);
            }
        }
    }
    Arc::new(b.finish())
}

/// Writes `DIR/data/test-00000-of-00001.parquet` (all contract columns except those in
/// `drop`) and `DIR/specs/<scene_id>.json`.
pub fn write_dataset(dir: &Path, rows: &[FixtureRow], drop: &[&str]) -> Result<()> {
    std::fs::create_dir_all(dir.join("data"))?;
    std::fs::create_dir_all(dir.join("specs"))?;
    let s = |f: &dyn Fn(&FixtureRow) -> Option<String>| -> ArrayRef {
        let mut b = StringBuilder::new();
        for r in rows {
            b.append_option(f(r));
        }
        Arc::new(b.finish())
    };
    let bo = |f: &dyn Fn(&FixtureRow) -> bool| -> ArrayRef {
        let mut b = BooleanBuilder::new();
        for r in rows {
            b.append_value(f(r));
        }
        Arc::new(b.finish())
    };
    let fl = |f: &dyn Fn(&FixtureRow) -> Option<f64>| -> ArrayRef {
        let mut b = Float64Builder::new();
        for r in rows {
            b.append_option(f(r));
        }
        Arc::new(b.finish())
    };
    let u64c = |f: &dyn Fn(&FixtureRow) -> u64| -> ArrayRef {
        let mut b = UInt64Builder::new();
        for r in rows {
            b.append_value(f(r));
        }
        Arc::new(b.finish())
    };
    let mut attempt = UInt32Builder::new();
    let mut hazards = ListBuilder::new(StringBuilder::new());
    for r in rows {
        attempt.append_value(0);
        if r.scene.dangerous {
            hazards
                .values()
                .append_value(if r.mass > 1.0 { "heavy" } else { "sharp" });
        }
        hazards.append(true);
    }
    let cols: Vec<(&str, ArrayRef)> = vec![
        (col::SCENE_ID, s(&|r| Some(r.scene.scene_id.clone()))),
        (col::GROUP_ID, s(&|r| Some(r.scene.group_id.clone()))),
        (col::SCENE_INDEX, u64c(&|r| r.scene_index)),
        (col::SEED, u64c(&|r| r.seed)),
        (col::ATTEMPT, Arc::new(attempt.finish())),
        (col::FAMILY, s(&|r| Some(r.scene.family.clone()))),
        (col::SPEED_BAND, s(&|r| Some(r.scene.speed_band.clone()))),
        (col::SPEED_SWEEP, bo(&|r| r.scene.speed_sweep)),
        (col::SPEED_PARAMETER, s(&|_| Some("launch_speed".into()))),
        (col::SPEED_VALUE, fl(&|r| Some(r.speed_value))),
        (col::OBJECT_ID, s(&|r| Some(r.scene.object_id.clone()))),
        (col::OBJECT_NAME, s(&|r| Some(r.object_name.clone()))),
        (
            col::OBJECT_CATEGORY,
            s(&|r| Some(r.object_category.clone())),
        ),
        (col::LOOKS_LIKE, s(&|r| r.scene.looks_like.clone())),
        (col::ADVERSARIAL, bo(&|r| r.scene.adversarial)),
        (col::OBJECT_MASS_KG, fl(&|r| Some(r.mass))),
        (col::HAZARDS, Arc::new(hazards.finish())),
        (col::ROOM, s(&|_| Some("kitchen".into()))),
        (col::DESCRIPTION, s(&|_| None)),
        (
            col::GT_ACTION,
            s(&|r| Some(r.scene.gt_action.as_str().into())),
        ),
        (col::DANGEROUS, bo(&|r| r.scene.dangerous)),
        (col::DANGER_PRESENT, bo(&|r| r.scene.danger_present)),
        (
            col::IMPACT_POINT,
            vec3_col(rows.iter().map(|r| r.scene.impact_point.as_ref())),
        ),
        (col::TIME_TO_IMPACT, fl(&|r| r.time_to_impact)),
        (
            col::TIME_TO_FLOOR,
            fl(&|r| r.time_to_impact.map(|t| t + 0.3)),
        ),
        (
            col::IMPACT_SPEED,
            fl(&|r| r.scene.impact_point.map(|_| r.speed_value)),
        ),
        (
            col::OBJECT_START,
            vec3_col(rows.iter().map(|r| Some(&r.scene.object_start))),
        ),
        (
            col::OBSERVER_POSE,
            vec3_col(rows.iter().map(|r| Some(&r.scene.observer_pose))),
        ),
        (col::LABEL_RULE, s(&|_| Some("fixture".into()))),
        (col::STATE_HASH, s(&|r| Some(format!("{:016x}", r.seed)))),
        (col::VALID, bo(&|r| r.scene.valid)),
        (col::VALID_NO_INTERPENETRATION, bo(&|_| true)),
        (col::SPEC_FILE, s(&|r| Some(spec_path(&r.scene.scene_id)))),
        (col::EGO_FILE_NAME, s(&|_| None)),
        (col::CLOSEUP_FILE_NAME, s(&|_| None)),
        (col::OVERHEAD_FILE_NAME, s(&|_| None)),
    ];
    let cols: Vec<(&str, ArrayRef)> = cols
        .into_iter()
        .filter(|(n, _)| !drop.contains(n))
        .collect();
    let batch = RecordBatch::try_from_iter(cols).context("building fixture batch")?;
    // The dataset's one table writer (its Parquet settings), written atomically.
    let path = dir.join(data_file_name(0, 1));
    write_atomic(&path, &rh_dataset::table::parquet_bytes(&batch))?;
    for r in rows {
        // The observer and its head camera, as a built spec has them (the prompt states the
        // camera's calibration): the head 1.24 m up, looking ahead and down at the floor
        // 2 m away, 720p with a 60° vertical field of view.
        let [x, y, yaw] = r.scene.observer_pose;
        let spec = serde_json::json!({
            "schema_version": 1,
            "scene_id": r.scene.scene_id,
            "fixture": true,
            "family": r.scene.family,
            "observer_pose": r.scene.observer_pose,
            "observer": { "x": x, "y": y, "yaw": yaw, "pelvis_z": 0.79 },
            "cameras": [{
                "name": "ego",
                "position": [x, y, 1.24],
                "look_at": [x + 2.0 * yaw.cos(), y + 2.0 * yaw.sin(), 0.0],
                "fov_y": std::f64::consts::FRAC_PI_3,
                "width": 1280,
                "height": 720,
            }],
        });
        write_atomic(
            &dir.join(spec_path(&r.scene.scene_id)),
            &serde_json::to_vec_pretty(&spec)?,
        )?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fixture_roundtrips_through_parquet() {
        let dir = tempfile::tempdir().unwrap();
        let rows = synth_rows(41, 7);
        write_dataset(dir.path(), &rows, &[]).unwrap();
        let ds = Dataset::load(dir.path()).unwrap();
        assert_eq!(ds.scenes.len(), 41);
        let mem = dataset_of(&rows);
        for (a, b) in ds.scenes.iter().zip(&mem.scenes) {
            assert_eq!(a.scene_id, b.scene_id);
            assert_eq!(a.impact_point, b.impact_point);
            assert_eq!(a.observer_pose, b.observer_pose);
            assert_eq!(a.gt_action, b.gt_action);
            assert_eq!(a.looks_like, b.looks_like);
        }
    }

    /// The fixture writes contract columns only, each with the contract's type.
    #[test]
    fn fixture_columns_are_contract_columns() {
        let dir = tempfile::tempdir().unwrap();
        write_dataset(dir.path(), &synth_rows(8, 3), &[]).unwrap();
        let file = std::fs::File::open(dir.path().join(data_file_name(0, 1))).unwrap();
        let reader =
            parquet::arrow::arrow_reader::ParquetRecordBatchReaderBuilder::try_new(file).unwrap();
        for field in reader.schema().fields() {
            let column = rh_contract::columns::column(field.name())
                .unwrap_or_else(|| panic!("{} is not a contract column", field.name()));
            assert_eq!(
                field.data_type(),
                &rh_contract::arrow_schema::data_type(column.ty),
                "{}",
                field.name()
            );
        }
    }

    #[test]
    fn missing_or_mistyped_column_names_file_and_column() {
        let dir = tempfile::tempdir().unwrap();
        let rows = synth_rows(8, 1);
        write_dataset(dir.path(), &rows, &["danger_present"]).unwrap();
        let err = Dataset::load(dir.path()).unwrap_err();
        let msg = format!("{err:#}");
        assert!(crate::error::is_input_error(&err));
        assert!(
            msg.contains("danger_present") && msg.contains("test-00000-of-00001.parquet"),
            "{msg}"
        );
    }
}
