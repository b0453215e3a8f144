//! Tests of the catalog data (`catalog/data/*.toml`) and of the validating loader.

use super::*;
use std::path::PathBuf;

fn catalog() -> Catalog {
    Catalog::embedded().unwrap_or_else(|e| panic!("embedded catalog must load: {e}"))
}

fn obj<'a>(cat: &'a Catalog, id: &str) -> &'a Object {
    cat.object(id)
        .unwrap_or_else(|| panic!("catalog must contain '{id}'"))
}

/// Largest full extent of an object's bounding box (m).
fn max_extent(o: &Object) -> f64 {
    o.half_extents().iter().fold(0.0f64, |a, &b| a.max(2.0 * b))
}

fn full_extents(o: &Object) -> [f64; 3] {
    let h = o.half_extents();
    [2.0 * h[0], 2.0 * h[1], 2.0 * h[2]]
}

const HANDHELD_FAMILIES: [&str; 5] = [
    "object_drop",
    "thrown_object",
    "stair_tumble",
    "chain_reaction",
    "surface_cascade",
];
const SLIDER_FAMILIES: [&str; 4] = [
    "sliding_object",
    "shelf_slide",
    "stack_collapse",
    "multi_object",
];
const BALL_FAMILIES: [&str; 2] = ["rolling_ball", "bouncing_object"];

// ------------------------------------------------------------------ the embedded data

#[test]
fn embedded_catalog_meets_the_spec_floor() {
    let cat = catalog();
    assert!(
        cat.objects.len() >= 82,
        "{} objects, spec needs at least 82",
        cat.objects.len()
    );
    let adversarial = cat.objects.iter().filter(|o| o.is_adversarial()).count();
    assert!(
        adversarial >= 14,
        "{adversarial} adversarial objects, spec needs at least 14"
    );
    assert!(cat.rooms.len() >= 8, "{} rooms", cat.rooms.len());
    assert!(cat.object("apple").is_some() && cat.room("kitchen").is_some());
    assert!(cat.object("no_such_object").is_none() && cat.room("no_such_room").is_none());
}

#[test]
fn every_family_has_five_objects_and_four_rooms() {
    let cat = catalog();
    for family in FAMILIES {
        let objects = cat.objects_for_family(family).count();
        let rooms = cat.rooms_for_family(family).count();
        assert!(objects >= 5, "family {family}: only {objects} objects");
        assert!(rooms >= 4, "family {family}: only {rooms} rooms");
    }
}

#[test]
fn objects_for_family_filters_and_keeps_catalog_order() {
    let cat = catalog();
    let ladders: Vec<&str> = cat
        .objects_for_family("ladder_slip")
        .map(|o| o.id.as_str())
        .collect();
    assert!(ladders.contains(&"step_ladder"));
    assert!(!ladders.contains(&"apple"));
    let positions: Vec<usize> = ladders
        .iter()
        .map(|id| cat.objects.iter().position(|o| o.id == *id).unwrap())
        .collect();
    assert!(
        positions.windows(2).all(|w| w[0] < w[1]),
        "not in catalog order: {ladders:?}"
    );
    assert_eq!(cat.objects_for_family("no_such_family").count(), 0);
}

#[test]
fn look_alikes_exist_are_genuine_and_share_shape_look_and_families() {
    let cat = catalog();
    for o in cat.objects.iter().filter(|o| o.is_adversarial()) {
        let target_id = o.looks_like.as_deref().unwrap();
        let target = obj(&cat, target_id);
        assert!(
            !target.is_adversarial(),
            "{}: look-alike {target_id} is itself adversarial",
            o.id
        );
        assert_eq!(
            o.parts, target.parts,
            "{}: parts differ from {target_id}",
            o.id
        );
        assert_eq!(
            o.appearance, target.appearance,
            "{}: appearance differs from {target_id}",
            o.id
        );
        assert_eq!(
            o.families, target.families,
            "{}: families differ from {target_id}",
            o.id
        );
        assert_eq!(cat.appearance_source(o).id, target_id);
        // The point of an adversarial entry: its physics is not what it looks like.
        let ratio = o.mass / target.mass;
        assert!(
            !(1.0 / 3.0..=3.0).contains(&ratio) || o.hazards != target.hazards,
            "{}: mass ratio {ratio:.2} and hazards equal to {target_id}: not adversarial",
            o.id
        );
    }
    let apple = obj(&cat, "apple");
    assert_eq!(cat.appearance_source(apple).id, "apple");
}

#[test]
fn required_adversarial_objects_are_present() {
    let cat = catalog();
    let pairs = [
        ("steel_apple", "apple"),
        ("foam_anvil", "anvil"),
        ("lead_core_tennis_ball", "tennis_ball"),
        ("foam_mirror", "wall_mirror"),
        ("hollow_prop_door", "heavy_oak_door"),
        ("foam_ceiling_panel", "ceiling_panel"),
        ("lead_sandbag", "bean_bag"),
        ("solid_steel_can", "soda_can"),
        ("foam_bowling_ball", "bowling_ball"),
        ("rubber_prop_knife", "chef_knife"),
        ("foam_brick", "brick"),
        ("cardboard_prop_pan", "cast_iron_pan"),
        ("plastic_toy_dumbbell", "dumbbell"),
        ("steel_filled_plush", "teddy_bear"),
        ("styrofoam_tv", "flat_screen_tv"),
        ("lead_weighted_pillow", "pillow"),
    ];
    for (adv, target) in pairs {
        assert_eq!(
            obj(&cat, adv).looks_like.as_deref(),
            Some(target),
            "{adv} must look like {target}"
        );
    }
    assert!(cat.objects.iter().filter(|o| o.is_adversarial()).count() >= 16);
}

#[test]
fn ball_families_hold_only_single_spheres() {
    let cat = catalog();
    for family in BALL_FAMILIES {
        for o in cat.objects_for_family(family) {
            assert_eq!(
                o.parts.len(),
                1,
                "{family}: {} has {} parts",
                o.id,
                o.parts.len()
            );
            assert_eq!(
                o.parts[0].shape,
                ShapeKind::Sphere,
                "{family}: {} is not a sphere",
                o.id
            );
            assert_eq!(
                o.parts[0].offset, [0.0; 3],
                "{family}: {} sphere is off-centre",
                o.id
            );
        }
    }
}

#[test]
fn slider_families_hold_single_flat_based_parts() {
    let cat = catalog();
    for family in SLIDER_FAMILIES {
        for o in cat.objects_for_family(family) {
            assert_eq!(
                o.parts.len(),
                1,
                "{family}: {} has {} parts",
                o.id,
                o.parts.len()
            );
            let p = &o.parts[0];
            assert!(
                matches!(p.shape, ShapeKind::Box | ShapeKind::Cylinder),
                "{family}: {} is a {:?}, needs a flat base",
                o.id,
                p.shape
            );
            // Wide enough not to tip at once: the narrowest base width is at least half the height.
            let [x, y, z] = full_extents(o);
            assert!(
                x.min(y) >= 0.5 * z,
                "{family}: {} base {x}×{y} is too narrow for height {z}",
                o.id
            );
        }
    }
}

#[test]
fn handheld_families_are_small_light_and_mixed() {
    let cat = catalog();
    for family in HANDHELD_FAMILIES {
        let mut benign = 0;
        let mut dangerous = 0;
        for o in cat.objects_for_family(family) {
            assert!(
                o.mass <= 15.0 + 1e-9,
                "{family}: {} weighs {:.2} kg",
                o.id,
                o.mass
            );
            assert!(
                max_extent(o) <= 0.6 + 1e-9,
                "{family}: {} is {:.2} m long",
                o.id,
                max_extent(o)
            );
            if o.hazards.is_empty() {
                benign += 1;
            }
            if ["sharp", "hot", "heavy"].iter().any(|h| o.has_hazard(h)) {
                dangerous += 1;
            }
        }
        assert!(benign >= 5, "{family}: only {benign} benign objects");
        assert!(
            dangerous >= 5,
            "{family}: only {dangerous} dangerous objects"
        );
    }
}

#[test]
fn ladders_are_tall_boxes_along_z() {
    let cat = catalog();
    let ladders: Vec<&Object> = cat.objects_for_family("ladder_slip").collect();
    assert!(ladders.len() >= 5);
    for o in ladders {
        assert_eq!(o.parts.len(), 1, "{}", o.id);
        assert_eq!(o.parts[0].shape, ShapeKind::Box, "{}", o.id);
        let [x, y, z] = full_extents(o);
        assert!(
            z >= 1.5 && z > 3.0 * x && x > y,
            "{}: a ladder stands along z ({x}×{y}×{z})",
            o.id
        );
        assert!(o.name.contains("ladder"), "{}", o.id);
        assert!(o.has_hazard("large"));
        assert_eq!(
            o.families,
            vec!["ladder_slip".to_string()],
            "{}: ladders only slip",
            o.id
        );
    }
}

#[test]
fn doors_are_upright_slabs() {
    let cat = catalog();
    let doors: Vec<&Object> = cat.objects_for_family("door_swing").collect();
    assert!(doors.len() >= 5);
    for o in doors {
        assert_eq!(o.parts.len(), 1, "{}", o.id);
        assert_eq!(o.parts[0].shape, ShapeKind::Box, "{}", o.id);
        let [x, y, z] = full_extents(o);
        assert!(
            z > x && x > 5.0 * y,
            "{}: a door is tall (z), wide (x) and thin (y): {x}×{y}×{z}",
            o.id
        );
        assert!(o.name.contains("door"), "{}", o.id);
        assert_eq!(o.appearance.recipe, "door", "{}", o.id);
    }
}

#[test]
fn tipping_furniture_is_tall_for_its_depth() {
    let cat = catalog();
    for o in cat.objects_for_family("furniture_tip") {
        let [x, y, z] = full_extents(o);
        assert!(z >= 2.0 * x.min(y), "{}: {x}×{y}×{z} would not tip", o.id);
        assert!(o.has_hazard("large"), "{}", o.id);
    }
}

#[test]
fn wall_fixtures_and_ceiling_objects_are_mountable() {
    let cat = catalog();
    for o in cat.objects_for_family("hanging_fall") {
        let [_, y, _] = full_extents(o);
        assert!(y <= 0.25, "{}: sticks {y} m out of the wall", o.id);
        assert!(o.mass <= 20.0, "{}: {:.1} kg on a wall hook", o.id, o.mass);
    }
    for family in ["ceiling_drop", "pendulum_swing"] {
        for o in cat.objects_for_family(family) {
            assert!(o.mass <= 40.0, "{family}: {} weighs {:.1} kg", o.id, o.mass);
            assert!(
                max_extent(o) <= 1.5,
                "{family}: {} is too big to hang",
                o.id
            );
        }
    }
}

#[test]
fn hazard_flags_agree_with_size_and_mass() {
    let cat = catalog();
    for o in &cat.objects {
        assert_eq!(
            o.has_hazard("heavy"),
            o.mass >= HEAVY_FLAG_MIN_KG,
            "{}: heavy vs {:.3} kg",
            o.id,
            o.mass
        );
        assert_eq!(
            o.has_hazard("large"),
            max_extent(o) >= 0.5,
            "{}: large vs {:.2} m",
            o.id,
            max_extent(o)
        );
        if o.has_hazard("hot") {
            let n = &o.name;
            assert!(
                n.contains("hot") || n.contains("boiling"),
                "{}: a hot object's name must say so",
                o.id
            );
        }
    }
}

#[test]
fn adversarial_objects_carry_their_own_true_hazards() {
    let cat = catalog();
    let flags = |id: &str| obj(&cat, id).hazards.iter().cloned().collect::<Vec<_>>();
    assert_eq!(flags("chef_knife"), ["sharp"]);
    assert!(flags("rubber_prop_knife").is_empty());
    assert!(
        obj(&cat, "wall_mirror").has_hazard("fragile")
            && obj(&cat, "wall_mirror").has_hazard("heavy")
    );
    assert_eq!(flags("foam_mirror"), ["large"]);
    assert!(
        obj(&cat, "steel_apple").has_hazard("heavy") && !obj(&cat, "apple").has_hazard("heavy")
    );
    assert!(obj(&cat, "anvil").has_hazard("heavy") && obj(&cat, "foam_anvil").hazards.is_empty());
    assert!(
        obj(&cat, "flat_screen_tv").has_hazard("fragile")
            && !obj(&cat, "styrofoam_tv").has_hazard("fragile")
    );
    assert!(
        obj(&cat, "lead_weighted_pillow").has_hazard("heavy")
            && !obj(&cat, "pillow").has_hazard("heavy")
    );
    assert!(
        obj(&cat, "heavy_oak_door").has_hazard("heavy")
            && !obj(&cat, "hollow_prop_door").has_hazard("heavy")
    );
    for (id, flag) in [
        ("scissors", "sharp"),
        ("hatchet", "sharp"),
        ("broken_glass", "sharp"),
        ("pot_of_boiling_water", "hot"),
        ("electric_kettle", "hot"),
        ("hot_frying_pan", "hot"),
        ("glass_vase", "fragile"),
        ("glass_door", "fragile"),
    ] {
        assert!(obj(&cat, id).has_hazard(flag), "{id} must be {flag}");
    }
}

#[test]
fn densities_are_physically_sensible() {
    let cat = catalog();
    let mass = |id: &str| obj(&cat, id).mass;
    let density = |id: &str| obj(&cat, id).density;
    assert!(mass("steel_apple") > 5.0 * mass("apple"));
    assert!(mass("foam_anvil") < 0.01 * mass("anvil"));
    assert!(mass("lead_core_tennis_ball") > 10.0 * mass("tennis_ball"));
    assert!(mass("foam_bowling_ball") < 0.05 * mass("bowling_ball"));
    assert!(mass("solid_steel_can") > 5.0 * mass("soda_can"));
    assert!(mass("lead_sandbag") > 5.0 * mass("bean_bag"));
    assert!(mass("foam_mirror") < 0.1 * mass("wall_mirror"));
    assert!(mass("hollow_prop_door") < 0.1 * mass("heavy_oak_door"));
    // Named materials sit at their textbook densities.
    for (id, lo, hi) in [
        ("apple", 700.0, 1100.0),
        ("steel_apple", 7700.0, 8000.0),
        ("anvil", 6800.0, 7900.0),
        ("brick", 1600.0, 2200.0),
        ("crystal_ball", 2300.0, 2700.0),
        ("broken_glass", 2300.0, 2700.0),
        ("heavy_oak_door", 600.0, 800.0),
        ("wall_shelf", 400.0, 650.0),
        ("foam_brick", 10.0, 100.0),
        ("sponge", 10.0, 100.0),
        ("lead_core_tennis_ball", 4000.0, 11_340.0),
    ] {
        let d = density(id);
        assert!(
            (lo..=hi).contains(&d),
            "{id}: density {d:.0} kg/m³ outside [{lo}, {hi}]"
        );
    }
    for o in &cat.objects {
        assert!(
            (5.0..=23_000.0).contains(&o.density),
            "{}: density {}",
            o.id,
            o.density
        );
        assert!(
            (o.mass - o.density * o.volume()).abs() < 1e-9 * o.mass.max(1.0),
            "{}: mass ≠ ρV",
            o.id
        );
        assert!(
            (0.0..=1.5).contains(&o.friction) && (0.0..=0.95).contains(&o.restitution),
            "{}",
            o.id
        );
    }
    // Balls bounce, dead weights do not.
    assert!(
        obj(&cat, "tennis_ball").restitution >= 0.7 && obj(&cat, "basketball").restitution >= 0.7
    );
    assert!(obj(&cat, "lead_core_tennis_ball").restitution < 0.4);
}

#[test]
fn names_synonyms_and_appearances_are_well_formed() {
    let cat = catalog();
    let mut owner: BTreeMap<&str, &str> = BTreeMap::new();
    for o in &cat.objects {
        for s in std::iter::once(&o.name).chain(&o.synonyms) {
            assert_eq!(s, &s.to_lowercase(), "{}: '{s}' must be lowercase", o.id);
            assert!(!s.trim().is_empty(), "{}: empty name or synonym", o.id);
            if let Some(other) = owner.insert(s, &o.id) {
                assert_eq!(other, o.id, "'{s}' names both {other} and {}", o.id);
            }
        }
        assert!(
            o.appearance
                .description
                .as_deref()
                .is_some_and(|d| !d.is_empty()),
            "{}: no description",
            o.id
        );
        assert!(parse_hex_color(&o.appearance.color).is_some(), "{}", o.id);
    }
    let mut room_words = BTreeSet::new();
    for r in &cat.rooms {
        for s in std::iter::once(&r.name).chain(&r.synonyms) {
            assert!(room_words.insert(s.clone()), "room word '{s}' used twice");
        }
    }
}

#[test]
fn rooms_are_realistic() {
    let cat = catalog();
    let expected_floor = [
        ("wood", 0.5, 0.3),
        ("tile", 0.6, 0.2),
        ("carpet", 0.8, 0.1),
        ("concrete", 0.7, 0.15),
        ("rubber", 0.9, 0.35),
    ];
    for r in &cat.rooms {
        assert!(
            r.size[0] >= 4.0 && r.size[1] >= 4.0,
            "{}: {:?} too small for events",
            r.id,
            r.size
        );
        assert!(
            (2.4..=3.2).contains(&r.ceiling_height),
            "{}: ceiling {}",
            r.id,
            r.ceiling_height
        );
        assert!(r.shelf_height[1] <= r.ceiling_height - 0.2, "{}", r.id);
        assert!(
            r.table_height[1] < r.shelf_height[0],
            "{}: tables above shelves",
            r.id
        );
        let (_, mu, e) = expected_floor
            .iter()
            .find(|(m, _, _)| *m == r.floor_material)
            .unwrap_or_else(|| panic!("{}: unknown floor material {}", r.id, r.floor_material));
        assert_eq!(
            (r.floor_friction, r.floor_restitution),
            (*mu, *e),
            "{}",
            r.id
        );
    }
}

#[test]
fn part_geometry() {
    use std::f64::consts::PI;
    let part = |shape, size: &[f64]| Part {
        shape,
        size: size.to_vec(),
        offset: [0.0; 3],
    };
    let close = |a: f64, b: f64| (a - b).abs() < 1e-12;
    assert!(close(part(ShapeKind::Box, &[1.0, 2.0, 3.0]).volume(), 6.0));
    assert!(close(
        part(ShapeKind::Sphere, &[2.0]).volume(),
        4.0 / 3.0 * PI
    ));
    assert!(close(
        part(ShapeKind::Cylinder, &[2.0, 3.0]).volume(),
        3.0 * PI
    ));
    // A capsule of diameter 2 and length 4: a cylinder of length 2 plus a unit sphere.
    assert!(close(
        part(ShapeKind::Capsule, &[2.0, 4.0]).volume(),
        2.0 * PI + 4.0 / 3.0 * PI
    ));
    assert_eq!(
        part(ShapeKind::Capsule, &[0.2, 1.0]).half_extents(),
        [0.1, 0.1, 0.5]
    );
    let cat = catalog();
    let lamp = obj(&cat, "floor_lamp");
    let h = lamp.half_extents();
    assert!(
        (h[2] - 0.89).abs() < 1e-9,
        "floor lamp half height {}",
        h[2]
    );
    assert!(lamp.bounding_radius() > h[2]);
}

// ------------------------------------------------------------------ malformed input

const ROOMS_OK: &str = r##"
[[rooms]]
id = "lab"
name = "lab"
size = [5.0, 5.0]
ceiling_height = 2.7
floor_material = "tile"
floor_friction = 0.6
floor_restitution = 0.2
table_height = [0.8, 0.9]
shelf_height = [1.5, 2.0]
wall_color = "#ffffff"
floor_color = "#808080"
"##;

/// One valid object (a 0.5 kg pine cube) with some lines replaced (`Some`) or removed (`None`).
fn object_entry(id: &str, edits: &[(&str, Option<&str>)]) -> String {
    let base = [
        ("id", format!("\"{id}\"")),
        ("name", "\"test block\"".to_string()),
        ("category", "\"toy\"".to_string()),
        ("material", "\"pine\"".to_string()),
        ("families", "[\"object_drop\"]".to_string()),
        ("hazards", "[]".to_string()),
        ("friction", "0.5".to_string()),
        ("restitution", "0.3".to_string()),
        ("density", "500.0".to_string()),
        (
            "parts",
            "[{ shape = \"box\", size = [0.1, 0.1, 0.1] }]".to_string(),
        ),
        (
            "appearance",
            "{ recipe = \"block\", color = \"#aabbcc\" }".to_string(),
        ),
    ];
    let mut lines = vec!["[[objects]]".to_string()];
    for (key, value) in &base {
        match edits.iter().find(|(k, _)| k == key) {
            Some((_, Some(v))) => lines.push(format!("{key} = {v}")),
            Some((_, None)) => {}
            None => lines.push(format!("{key} = {value}")),
        }
    }
    for (key, value) in edits {
        if let (false, Some(v)) = (base.iter().any(|(k, _)| k == key), value) {
            lines.push(format!("{key} = {v}"));
        }
    }
    lines.join("\n") + "\n\n"
}

fn load(objects: &str) -> Result<Catalog, CatalogError> {
    Catalog::from_sources(("objects.toml", objects), ("rooms.toml", ROOMS_OK))
}

fn load_err(objects: &str) -> CatalogError {
    match load(objects) {
        Ok(_) => panic!("expected an error for:\n{objects}"),
        Err(e) => e,
    }
}

/// Asserts the error's fields and that its Display text names each of them.
fn assert_names(
    e: &CatalogError,
    file: &str,
    entry: Option<&str>,
    field: Option<&str>,
    message_part: &str,
) {
    let text = e.to_string();
    assert_eq!(e.file, file, "file in {text}");
    assert_eq!(e.entry.as_deref(), entry, "entry in {text}");
    assert_eq!(e.field.as_deref(), field, "field in {text}");
    assert!(
        e.message.contains(message_part),
        "message '{}' lacks '{message_part}'",
        e.message
    );
    assert!(text.starts_with(file), "{text}");
    if let Some(entry) = entry {
        assert!(text.contains(&format!("entry '{entry}'")), "{text}");
    }
    if let Some(field) = field {
        assert!(text.contains(&format!("field '{field}'")), "{text}");
    }
    assert!(text.ends_with(&e.message), "{text}");
}

#[test]
fn the_test_template_itself_is_valid() {
    let text = object_entry("block", &[]) + &object_entry("block_two", &[]);
    let cat = load(&text).unwrap();
    let block = cat.object("block").unwrap();
    assert!((block.mass - 0.5).abs() < 1e-9);
    assert!(block.hazards.is_empty() && !block.is_adversarial());
    assert_eq!(cat.room("lab").unwrap().families, Vec::<String>::new());
    assert!(cat.room("lab").unwrap().hosts("door_swing"));
}

#[test]
fn negative_density_is_rejected() {
    let e = load_err(&object_entry("block", &[("density", Some("-500.0"))]));
    assert_names(&e, "objects.toml", Some("block"), Some("density"), "-500");
}

#[test]
fn implausible_mass_for_the_volume_is_rejected() {
    // 50 kg in a 10 cm cube is 50,000 kg/m³: denser than anything.
    let e = load_err(&object_entry(
        "block",
        &[("density", None), ("mass", Some("50.0"))],
    ));
    assert_names(&e, "objects.toml", Some("block"), Some("mass"), "density");
}

#[test]
fn density_and_mass_together_or_neither_are_rejected() {
    let e = load_err(&object_entry("block", &[("mass", Some("0.5"))]));
    assert_names(&e, "objects.toml", Some("block"), Some("mass"), "not both");
    let e = load_err(&object_entry("block", &[("density", None)]));
    assert_names(
        &e,
        "objects.toml",
        Some("block"),
        Some("density"),
        "density",
    );
}

#[test]
fn unknown_family_is_rejected() {
    let e = load_err(&object_entry(
        "block",
        &[("families", Some("[\"object_drop\", \"juggling\"]"))],
    ));
    assert_names(
        &e,
        "objects.toml",
        Some("block"),
        Some("families"),
        "unknown family 'juggling'",
    );
    let e = load_err(&object_entry("block", &[("families", Some("[]"))]));
    assert_names(
        &e,
        "objects.toml",
        Some("block"),
        Some("families"),
        "at least one",
    );
}

#[test]
fn unknown_hazard_is_rejected() {
    let e = load_err(&object_entry(
        "block",
        &[("hazards", Some("[\"radioactive\"]"))],
    ));
    assert_names(
        &e,
        "objects.toml",
        Some("block"),
        Some("hazards"),
        "unknown hazard 'radioactive'",
    );
}

#[test]
fn heavy_flag_must_match_the_mass() {
    // A 0.5 kg cube flagged heavy.
    let e = load_err(&object_entry("block", &[("hazards", Some("[\"heavy\"]"))]));
    assert_names(
        &e,
        "objects.toml",
        Some("block"),
        Some("hazards"),
        "'heavy'",
    );
    // A 7.85 kg steel cube not flagged heavy.
    let e = load_err(&object_entry("block", &[("density", Some("7850.0"))]));
    assert_names(
        &e,
        "objects.toml",
        Some("block"),
        Some("hazards"),
        "7.850 kg",
    );
    // And flagged, it loads.
    let ok = object_entry(
        "block",
        &[
            ("density", Some("7850.0")),
            ("hazards", Some("[\"heavy\"]")),
        ],
    );
    assert!(load(&ok)
        .unwrap()
        .object("block")
        .unwrap()
        .has_hazard("heavy"));
}

#[test]
fn looks_like_must_point_at_an_existing_genuine_twin() {
    let e = load_err(&object_entry("block", &[("looks_like", Some("\"ghost\""))]));
    assert_names(
        &e,
        "objects.toml",
        Some("block"),
        Some("looks_like"),
        "no object with id 'ghost'",
    );

    let genuine = object_entry("block", &[]);
    let twin = object_entry(
        "foam_block",
        &[("density", Some("20.0")), ("looks_like", Some("\"block\""))],
    );
    let cat = load(&(genuine.clone() + &twin)).unwrap();
    assert_eq!(
        cat.appearance_source(cat.object("foam_block").unwrap()).id,
        "block"
    );

    let chained = object_entry("foam_foam_block", &[("looks_like", Some("\"foam_block\""))]);
    let e = load_err(&(genuine.clone() + &twin + &chained));
    assert_names(
        &e,
        "objects.toml",
        Some("foam_foam_block"),
        Some("looks_like"),
        "itself adversarial",
    );

    let other_shape = object_entry(
        "round_block",
        &[
            ("parts", Some("[{ shape = \"sphere\", size = [0.1] }]")),
            ("looks_like", Some("\"block\"")),
        ],
    );
    let e = load_err(&(genuine.clone() + &other_shape));
    assert_names(
        &e,
        "objects.toml",
        Some("round_block"),
        Some("parts"),
        "'block'",
    );

    let other_look = object_entry(
        "red_block",
        &[
            (
                "appearance",
                Some("{ recipe = \"block\", color = \"#ff0000\" }"),
            ),
            ("looks_like", Some("\"block\"")),
        ],
    );
    let e = load_err(&(genuine + &other_look));
    assert_names(
        &e,
        "objects.toml",
        Some("red_block"),
        Some("appearance"),
        "'block'",
    );
}

#[test]
fn duplicate_id_is_rejected() {
    let text =
        object_entry("block", &[]) + &object_entry("other", &[]) + &object_entry("block", &[]);
    let e = load_err(&text);
    assert_names(&e, "objects.toml", Some("block"), Some("id"), "duplicate");
}

#[test]
fn bad_ids_are_rejected() {
    let e = load_err(&object_entry("Big Block", &[]));
    assert_names(
        &e,
        "objects.toml",
        Some("Big Block"),
        Some("id"),
        "snake_case",
    );
    let e = load_err(&object_entry("", &[]));
    assert_names(&e, "objects.toml", Some("#1"), Some("id"), "snake_case");
}

#[test]
fn wrong_part_sizes_are_rejected() {
    let e = load_err(&object_entry(
        "block",
        &[("parts", Some("[{ shape = \"box\", size = [0.1, 0.2] }]"))],
    ));
    assert_names(
        &e,
        "objects.toml",
        Some("block"),
        Some("parts[0].size"),
        "needs 3 numbers (got 2)",
    );
    let two_parts =
        "[{ shape = \"box\", size = [0.1, 0.1, 0.1] }, { shape = \"sphere\", size = [0.0] }]";
    let e = load_err(&object_entry("block", &[("parts", Some(two_parts))]));
    assert_names(
        &e,
        "objects.toml",
        Some("block"),
        Some("parts[1].size"),
        "between",
    );
    let e = load_err(&object_entry(
        "block",
        &[(
            "parts",
            Some("[{ shape = \"capsule\", size = [0.2, 0.1] }]"),
        )],
    ));
    assert_names(
        &e,
        "objects.toml",
        Some("block"),
        Some("parts[0].size"),
        "capsule",
    );
    let e = load_err(&object_entry("block", &[("parts", Some("[]"))]));
    assert_names(
        &e,
        "objects.toml",
        Some("block"),
        Some("parts"),
        "at least one part",
    );
}

#[test]
fn out_of_range_numbers_and_bad_colours_are_rejected() {
    let e = load_err(&object_entry("block", &[("friction", Some("2.0"))]));
    assert_names(
        &e,
        "objects.toml",
        Some("block"),
        Some("friction"),
        "between 0 and 1.5",
    );
    let e = load_err(&object_entry("block", &[("restitution", Some("1.2"))]));
    assert_names(
        &e,
        "objects.toml",
        Some("block"),
        Some("restitution"),
        "between 0 and 0.95",
    );
    let e = load_err(&object_entry(
        "block",
        &[(
            "appearance",
            Some("{ recipe = \"block\", color = \"red\" }"),
        )],
    ));
    assert_names(
        &e,
        "objects.toml",
        Some("block"),
        Some("appearance.color"),
        "\"red\"",
    );
    let e = load_err(&object_entry(
        "block",
        &[(
            "appearance",
            Some("{ recipe = \" \", color = \"#aabbcc\" }"),
        )],
    ));
    assert_names(
        &e,
        "objects.toml",
        Some("block"),
        Some("appearance.recipe"),
        "empty",
    );
}

#[test]
fn toml_syntax_error_names_the_file_and_line() {
    // Line 1 is blank, line 2 the header, the broken line (no value after `=`) is line 5.
    let text =
        "\n[[objects]]\nid = \"block\"\nname = \"test block\"\ncategory =\nmaterial = \"pine\"\n";
    let e = load_err(text);
    assert!(e.file.starts_with("objects.toml:5"), "{e}");
    assert!(e.to_string().starts_with("objects.toml:5"), "{e}");
    assert_eq!(e.entry, None);
    // An error at the very start of a line is still reported on that line.
    let text = object_entry("block", &[]) + "@oops = 1\n";
    let e = load_err(&text);
    let line = text.lines().position(|l| l.starts_with("@oops")).unwrap() + 1;
    assert_eq!(e.file, format!("objects.toml:{line}"), "{e}");
}

#[test]
fn missing_required_field_names_file_line_entry_and_field() {
    let text = object_entry("block", &[]) + &object_entry("slippery", &[("friction", None)]);
    let e = load_err(&text);
    assert!(e.file.starts_with("objects.toml:"), "{e}");
    let line: usize = e.file["objects.toml:".len()..]
        .parse()
        .expect("a line number");
    assert!(line >= 13, "line {line} is in the first (valid) entry: {e}");
    assert_eq!(e.entry.as_deref(), Some("slippery"), "{e}");
    assert_eq!(e.field.as_deref(), Some("friction"), "{e}");
    assert!(e.message.contains("friction"), "{e}");
    assert!(
        e.to_string().contains("entry 'slippery' field 'friction'"),
        "{e}"
    );
}

#[test]
fn unknown_and_mistyped_fields_are_named() {
    let e = load_err(&object_entry("block", &[("colour", Some("\"red\""))]));
    assert_eq!(
        (e.entry.as_deref(), e.field.as_deref()),
        (Some("block"), Some("colour")),
        "{e}"
    );
    let e = load_err(&object_entry("block", &[("friction", Some("\"high\""))]));
    assert_eq!(
        (e.entry.as_deref(), e.field.as_deref()),
        (Some("block"), Some("friction")),
        "{e}"
    );
    assert!(e.file.starts_with("objects.toml:"), "{e}");
    let e = load_err(&object_entry(
        "block",
        &[("parts", Some("[{ shape = \"cube\", size = [0.1] }]"))],
    ));
    assert_eq!(
        (e.entry.as_deref(), e.field.as_deref()),
        (Some("block"), Some("parts")),
        "{e}"
    );
    assert!(e.message.contains("cube"), "{e}");
}

#[test]
fn room_errors_name_the_room_and_field() {
    let objects = object_entry("block", &[]);
    let room_err = |rooms: &str| {
        Catalog::from_sources(("objects.toml", &objects), ("rooms.toml", rooms))
            .expect_err("must fail")
    };
    let e = room_err(
        &ROOMS_OK
            .replace("ceiling_height = 2.7", "ceiling_height = 2.3")
            .replace("shelf_height = [1.5, 2.0]", "shelf_height = [1.5, 2.2]"),
    );
    assert_names(
        &e,
        "rooms.toml",
        Some("lab"),
        Some("shelf_height"),
        "below the ceiling",
    );
    let e = room_err(&ROOMS_OK.replace("table_height = [0.8, 0.9]", "table_height = [0.9, 0.8]"));
    assert_names(
        &e,
        "rooms.toml",
        Some("lab"),
        Some("table_height"),
        "reversed",
    );
    let e = room_err(&format!("{ROOMS_OK}families = [\"swimming\"]\n"));
    assert_names(
        &e,
        "rooms.toml",
        Some("lab"),
        Some("families"),
        "unknown family 'swimming'",
    );
    let e = room_err(&(ROOMS_OK.to_string() + ROOMS_OK));
    assert_names(&e, "rooms.toml", Some("lab"), Some("id"), "duplicate");
    let e = room_err(&ROOMS_OK.replace("floor_friction = 0.6\n", ""));
    assert_eq!(
        (e.entry.as_deref(), e.field.as_deref()),
        (Some("lab"), Some("floor_friction")),
        "{e}"
    );
    assert!(e.file.starts_with("rooms.toml:"), "{e}");
    let e = room_err("rooms = []\n");
    assert_names(&e, "rooms.toml", None, Some("rooms"), "at least one room");
}

#[test]
fn a_room_restricted_to_some_families_hosts_only_those() {
    let rooms = format!("{ROOMS_OK}families = [\"door_swing\", \"ladder_slip\"]\n");
    let cat = Catalog::from_sources(
        ("objects.toml", &object_entry("block", &[])),
        ("rooms.toml", &rooms),
    )
    .unwrap();
    let lab = cat.room("lab").unwrap();
    assert!(lab.hosts("door_swing") && !lab.hosts("object_drop"));
    assert_eq!(cat.rooms_for_family("object_drop").count(), 0);
}

#[test]
fn a_room_too_small_for_a_family_excludes_it() {
    let rooms = format!("{ROOMS_OK}excludes = [\"thrown_object\"]\n");
    let cat = Catalog::from_sources(
        ("objects.toml", &object_entry("block", &[])),
        ("rooms.toml", &rooms),
    )
    .unwrap();
    let lab = cat.room("lab").unwrap();
    assert!(lab.hosts("door_swing") && !lab.hosts("thrown_object"));
    assert_eq!(cat.rooms_for_family("thrown_object").count(), 0);
    let bad = format!("{ROOMS_OK}excludes = [\"juggling\"]\n");
    let e = Catalog::from_sources(
        ("objects.toml", &object_entry("block", &[])),
        ("rooms.toml", &bad),
    )
    .expect_err("an unknown family must fail");
    assert_names(&e, "rooms.toml", Some("lab"), Some("excludes"), "juggling");
}

// ------------------------------------------------------------------ loading from a directory

fn temp_dir(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("rh-catalog-test-{}-{tag}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

#[test]
fn load_dir_reads_a_copy_of_the_data() {
    let dir = temp_dir("copy");
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("objects.toml"), OBJECTS_TOML).unwrap();
    std::fs::write(dir.join("rooms.toml"), ROOMS_TOML).unwrap();
    let loaded = Catalog::load_dir(&dir);
    // An edited copy reports errors under its own path.
    std::fs::write(
        dir.join("objects.toml"),
        OBJECTS_TOML.replace("density = 800.0", "density = -1.0"),
    )
    .unwrap();
    let broken = Catalog::load_dir(&dir);
    let _ = std::fs::remove_dir_all(&dir);

    let loaded = loaded.unwrap();
    let embedded = catalog();
    assert_eq!(loaded.objects, embedded.objects);
    assert_eq!(loaded.rooms, embedded.rooms);
    let e = broken.expect_err("edited copy must fail");
    assert_eq!(e.file, dir.join("objects.toml").display().to_string());
    assert_eq!(
        (e.entry.as_deref(), e.field.as_deref()),
        (Some("apple"), Some("density"))
    );
}

#[test]
fn load_dir_on_a_missing_directory_names_the_path() {
    let dir = temp_dir("missing").join("nowhere");
    let e = Catalog::load_dir(&dir).expect_err("missing dir must fail");
    let path = dir.join("objects.toml").display().to_string();
    assert_eq!(e.file, path);
    assert!(e.message.contains("cannot read"), "{e}");
    assert!(e.to_string().contains(&path), "{e}");
}
