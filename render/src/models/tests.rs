use super::fit::bounds_deviation;
use super::*;
use crate::models::obj::{MAT_TEXTURED, MAT_TEXTURED_GLOSSY};
use rh_catalog::models::{ModelConfig, ModelRef};
use rh_physics::spec::{PartSpec, ShapeSpec};
use std::io::Write;

/// A y-up box 10 (x) × 20 (y, up) × 40 (z, front) units, corner at the origin, with a
/// textured material; the OBJ text.
const BOX_OBJ: &str = "mtllib box.mtl
o box
v 0 0 0
v 10 0 0
v 10 20 0
v 0 20 0
v 0 0 40
v 10 0 40
v 10 20 40
v 0 20 40
vt 0 0
vt 1 0
vt 1 1
vt 0 1
usemtl skin
f 1/1 2/2 3/3 4/4
f 5/1 8/4 7/3 6/2
f 1/1 5/2 6/3 2/4
f 4/1 3/2 7/3 8/4
f 1/1 4/2 8/3 5/4
f 2/1 6/2 7/3 3/4
";
const BOX_MTL: &str = "newmtl skin\nKd 1 1 1\nmap_Kd skin.png\n";

fn png() -> Vec<u8> {
    let img = image::RgbaImage::from_fn(4, 4, |x, y| {
        image::Rgba([(x * 60) as u8, (y * 60) as u8, 90, 255])
    });
    let mut out = std::io::Cursor::new(Vec::new());
    img.write_to(&mut out, image::ImageFormat::Png).unwrap();
    out.into_inner()
}

/// A package directory holding `test.sh3f` with the box model.
fn package_dir(obj: &str) -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    let f = std::fs::File::create(dir.path().join("test.sh3f")).unwrap();
    let mut z = zip::ZipWriter::new(f);
    let opt = zip::write::SimpleFileOptions::default();
    for (name, bytes) in [
        ("m/box/box.obj", obj.as_bytes().to_vec()),
        ("m/box/box.mtl", BOX_MTL.as_bytes().to_vec()),
        ("m/box/skin.png", png()),
    ] {
        z.start_file(name, opt).unwrap();
        z.write_all(&bytes).unwrap();
    }
    z.finish().unwrap();
    dir
}

fn sha(s: &str) -> String {
    use sha2::{Digest, Sha256};
    Sha256::digest(s.as_bytes())
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

fn box_ref(rotation: [f64; 3]) -> ModelRef {
    ModelRef {
        package: "sweethome3d-furniture".into(),
        archive: "test.sh3f".into(),
        path: "m/box/box.obj".into(),
        sha256: sha(BOX_OBJ),
        object: None,
        rotation,
        name: "Box".into(),
        creator: "test".into(),
        license: "CC0-1.0".into(),
    }
}

fn config(root: &std::path::Path) -> ModelConfig {
    ModelConfig {
        package_root: Some(root.to_path_buf()),
        ..ModelConfig::default()
    }
}

fn box_parts(h: [f64; 3]) -> Vec<PartSpec> {
    vec![PartSpec {
        shape: ShapeSpec::Box { half_extents: h },
        offset: [0.0; 3],
        rotation: [0.0, 0.0, 0.0, 1.0],
    }]
}

fn extents(m: &LoadedModel) -> [f32; 3] {
    std::array::from_fn(|k| m.hi[k] - m.lo[k])
}

#[test]
fn a_model_turns_from_y_up_front_z_into_the_catalog_frame_and_its_fix_rotates_it() {
    let dir = package_dir(BOX_OBJ);
    let m = load_model(&box_ref([0.0; 3]), "box", &config(dir.path())).unwrap();
    // Sweet Home 3D y (up) becomes z; its z (front) becomes y.
    assert_eq!(extents(&m), [10.0, 40.0, 20.0]);
    assert_eq!(m.triangles, 12);
    let turned = load_model(&box_ref([0.0, 0.0, 90.0]), "box", &config(dir.path())).unwrap();
    let e = extents(&turned);
    assert!(
        (e[0] - 40.0).abs() < 1e-4 && (e[1] - 10.0).abs() < 1e-4 && e[2] == 20.0,
        "{e:?}"
    );
    // Every vertex samples the texture (code 4), from a layer the process table holds.
    let layer = m.textures[0];
    assert!(m
        .mesh
        .verts
        .iter()
        .all(|v| v.color[3] == MAT_TEXTURED && v.color[2] == layer as f32));
    assert!(texture_count() > layer as usize);
    assert_ne!(MAT_TEXTURED, MAT_TEXTURED_GLOSSY);
}

#[test]
fn the_fit_scales_a_model_onto_its_parts_and_turns_its_normals_with_it() {
    let dir = package_dir(BOX_OBJ);
    let m = load_model(&box_ref([0.0; 3]), "box", &config(dir.path())).unwrap();
    // Parts 0.1 × 0.4 × 0.2 m: the model's proportions, in metres.
    let mesh = fit_model(&m, &box_parts([0.05, 0.2, 0.1]), 0.45).unwrap();
    let mut lo = [f32::MAX; 3];
    let mut hi = [f32::MIN; 3];
    for v in &mesh.verts {
        for k in 0..3 {
            lo[k] = lo[k].min(v.pos[k]);
            hi[k] = hi[k].max(v.pos[k]);
        }
        let l: f32 = v.normal.iter().map(|c| c * c).sum();
        assert!((l - 1.0).abs() < 1e-4);
    }
    for k in 0..3 {
        assert!((lo[k] + [0.05, 0.2, 0.1][k]).abs() < 1e-6, "{lo:?}");
        assert!((hi[k] - [0.05, 0.2, 0.1][k]).abs() < 1e-6, "{hi:?}");
    }
}

#[test]
fn the_bounds_check_refuses_a_model_whose_proportions_disagree_with_the_parts() {
    assert_eq!(
        bounds_deviation([1.0, 2.0, 3.0], [2.0, 4.0, 6.0])
            .unwrap()
            .0,
        0.0
    );
    // Twice as tall as the parts want: axis scales 1, 1, 1/2, their mean 2^(-1/3), so z
    // is off by 1 - 2^(-2/3) and x, y by 2^(1/3) - 1 (less).
    let (d, axis) = bounds_deviation([1.0, 1.0, 2.0], [1.0, 1.0, 1.0]).unwrap();
    assert_eq!(axis, 2);
    assert!((d - (1.0 - 2f64.powf(-2.0 / 3.0))).abs() < 1e-9, "{d}");
    let dir = package_dir(BOX_OBJ);
    let m = load_model(&box_ref([0.0; 3]), "box", &config(dir.path())).unwrap();
    // A plate-shaped collider for a box standing 4:2:1: refused, naming the axis.
    let err = fit_model(&m, &box_parts([0.2, 0.2, 0.01]), 0.45).unwrap_err();
    assert!(matches!(err, FitError::Bounds { .. }), "{err}");
    assert!(err.to_string().contains("tolerance 0.45"), "{err}");
    // Within a wider tolerance the same fit passes: the number is the configuration's.
    assert!(fit_model(&m, &box_parts([0.2, 0.2, 0.01]), 10.0).is_ok());
    assert!(matches!(
        bounds_deviation([1.0, 0.0, 1.0], [1.0, 1.0, 1.0]),
        Err(FitError::Flat { axis: 'y', .. })
    ));
}

#[test]
fn a_model_whose_bytes_differ_from_the_catalog_hash_is_refused_naming_the_file() {
    let dir = package_dir(&BOX_OBJ.replace("v 10 20 40", "v 10 21 40"));
    let err = load_model(&box_ref([0.0; 3]), "box", &config(dir.path())).unwrap_err();
    let msg = err.to_string();
    assert!(matches!(err, ModelError::HashMismatch { .. }), "{msg}");
    assert!(
        msg.contains("test.sh3f:m/box/box.obj") && msg.contains("'box'"),
        "{msg}"
    );
}

#[test]
fn a_missing_package_names_the_package_and_its_install_command() {
    let dir = tempfile::tempdir().unwrap();
    let root = dir.path().join("not-installed");
    let err = load_model(&box_ref([0.0; 3]), "box", &config(&root)).unwrap_err();
    let msg = err.to_string();
    assert!(matches!(err, ModelError::PackageMissing { .. }), "{msg}");
    assert!(msg.contains("'sweethome3d-furniture'"), "{msg}");
    assert!(
        msg.contains("sudo apt-get install sweethome3d-furniture"),
        "{msg}"
    );
}

#[test]
fn the_triangle_budget_holds_for_a_model_larger_than_it() {
    // A 60 × 60 grid (7200 triangles) cut down to 500.
    let mut obj = String::from("o grid\n");
    let n = 61;
    for i in 0..n {
        for j in 0..n {
            let h = ((i * 7 + j * 3) % 5) as f32 * 0.01;
            obj += &format!("v {i} {h} {j}\n");
        }
    }
    for i in 0..n - 1 {
        for j in 0..n - 1 {
            let a = i * n + j + 1;
            obj += &format!(
                "f {a} {} {}\nf {a} {} {}\n",
                a + n,
                a + n + 1,
                a + n + 1,
                a + 1
            );
        }
    }
    let dir = package_dir(&obj);
    let mut r = box_ref([0.0; 3]);
    r.sha256 = sha(&obj);
    let cfg = ModelConfig {
        triangle_budget: 500,
        ..config(dir.path())
    };
    let m = load_model(&r, "grid", &cfg).unwrap();
    assert_eq!(m.source_triangles, 7200);
    assert!(m.triangles <= 500 && m.triangles > 50, "{}", m.triangles);
    // Deterministic: the same triangles again.
    let again = load_model(&r, "grid", &cfg).unwrap();
    let bits = |m: &LoadedModel| {
        m.mesh
            .verts
            .iter()
            .map(|v| v.pos.map(f32::to_bits))
            .collect::<Vec<_>>()
    };
    assert_eq!(bits(&m), bits(&again));
}

/// The installed package (scripts/setup.sh installs it): every model the catalog names
/// matches its hash, loads within the budget and fits its entry's parts; a known model
/// stands the right way up.
#[test]
fn every_catalog_model_loads_and_fits_from_the_installed_package() {
    let catalog = Catalog::embedded().unwrap();
    let cfg = ModelConfig::default();
    let (models, textures) = check_catalog(&catalog, &cfg, rh_scenes::families::object_parts)
        .unwrap_or_else(|e| panic!("{e}"));
    assert!(models >= 30, "{models}");
    assert!(textures <= cfg.texture_layers as usize);
    let drawn = catalog
        .objects
        .iter()
        .filter(|o| rh_catalog::models::drawn_model(&catalog, o).is_some())
        .count();
    assert!(
        drawn >= 40,
        "{drawn} catalog objects drawn from a real mesh"
    );
    // The wine bottle stands: its height (z) is its largest extent, before any fit.
    let bottle = catalog.object("wine_bottle").unwrap();
    let m = cached_model(bottle.model.as_ref().unwrap(), "wine_bottle", &cfg).unwrap();
    let e = extents(&m);
    assert!(e[2] > 3.0 * e[0] && e[2] > 3.0 * e[1], "{e:?}");
    assert!(m.triangles <= cfg.triangle_budget);
    // The hammer lies along x with its head across y, as its parts do.
    let hammer = catalog.object("hammer").unwrap();
    let m = cached_model(hammer.model.as_ref().unwrap(), "hammer", &cfg).unwrap();
    let e = extents(&m);
    assert!(e[0] > e[1] && e[1] > e[2], "{e:?}");
}
