//! The ReactHuman catalog: objects and rooms as data (`catalog/data/*.toml`), plus a
//! loader that validates every entry and names the entry and field it rejects.
//!
//! The catalog is embedded in the binaries, so a build needs no files at run time;
//! `Catalog::load_dir` reads an edited copy instead.

pub mod models;

use serde::Deserialize;
use std::collections::{BTreeMap, BTreeSet};
use std::fmt;
use std::path::Path;

pub mod decor;
pub use decor::Decor;

/// The seventeen event families (specification §4), in their canonical order (the data contract's).
pub use rh_contract::FAMILIES;

/// Hazard flags an object may carry (specification §5). `heavy` must agree with the mass.
pub const HAZARDS: [&str; 5] = ["sharp", "hot", "heavy", "fragile", "large"];

/// Physical plausibility bounds: the densest common solid (osmium ~22,600) and the
/// lightest foam used for props (~5 kg/m³).
const DENSITY_RANGE: (f64, f64) = (5.0, 23_000.0);
const SIZE_RANGE_M: (f64, f64) = (0.005, 3.0);
const MASS_RANGE_KG: (f64, f64) = (0.001, 400.0);
/// An object flagged `heavy` must weigh at least this much, and an unflagged one less.
/// The label rule has its own (configurable) mass threshold; this only keeps the flag honest.
pub const HEAVY_FLAG_MIN_KG: f64 = 2.0;

const OBJECTS_TOML: &str = include_str!("../data/objects.toml");
const ROOMS_TOML: &str = include_str!("../data/rooms.toml");

/// A validation or parse failure that names the file, the entry and the field.
#[derive(Debug, Clone, PartialEq)]
pub struct CatalogError {
    pub file: String,
    pub entry: Option<String>,
    pub field: Option<String>,
    pub message: String,
}

impl fmt::Display for CatalogError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.file)?;
        if let Some(entry) = &self.entry {
            write!(f, ": entry '{entry}'")?;
        }
        if let Some(field) = &self.field {
            write!(f, " field '{field}'")?;
        }
        write!(f, ": {}", self.message)
    }
}

impl std::error::Error for CatalogError {}

/// Primitive shape of one collision part. Sizes are full extents in metres.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ShapeKind {
    /// `size = [x, y, z]`
    Box,
    /// `size = [diameter]`
    Sphere,
    /// `size = [diameter, height]`, axis along z
    Cylinder,
    /// `size = [diameter, total_length]`, axis along z
    Capsule,
}

#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Part {
    pub shape: ShapeKind,
    pub size: Vec<f64>,
    /// Offset of the part's centre from the object's origin (m).
    #[serde(default)]
    pub offset: [f64; 3],
}

impl Part {
    /// Volume in m³.
    pub fn volume(&self) -> f64 {
        use std::f64::consts::PI;
        match self.shape {
            ShapeKind::Box => self.size[0] * self.size[1] * self.size[2],
            ShapeKind::Sphere => PI / 6.0 * self.size[0].powi(3),
            ShapeKind::Cylinder => PI * (self.size[0] / 2.0).powi(2) * self.size[1],
            ShapeKind::Capsule => {
                let r = self.size[0] / 2.0;
                let cyl = (self.size[1] - self.size[0]).max(0.0);
                PI * r * r * cyl + 4.0 / 3.0 * PI * r.powi(3)
            }
        }
    }

    /// Half extents of the part's axis-aligned box in the object frame (unrotated).
    pub fn half_extents(&self) -> [f64; 3] {
        match self.shape {
            ShapeKind::Box => [self.size[0] / 2.0, self.size[1] / 2.0, self.size[2] / 2.0],
            ShapeKind::Sphere => [self.size[0] / 2.0; 3],
            ShapeKind::Cylinder | ShapeKind::Capsule => {
                [self.size[0] / 2.0, self.size[0] / 2.0, self.size[1] / 2.0]
            }
        }
    }

    fn expected_size_len(&self) -> usize {
        match self.shape {
            ShapeKind::Box => 3,
            ShapeKind::Sphere => 1,
            ShapeKind::Cylinder | ShapeKind::Capsule => 2,
        }
    }
}

/// How an object looks: a render recipe name plus its colours (`#rrggbb`).
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Appearance {
    pub recipe: String,
    pub color: String,
    #[serde(default)]
    pub secondary_color: Option<String>,
    /// Free text describing the look, for people and the dataset card.
    #[serde(default)]
    pub description: Option<String>,
}

#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawObject {
    id: String,
    name: String,
    category: String,
    material: String,
    families: Vec<String>,
    #[serde(default)]
    synonyms: Vec<String>,
    #[serde(default)]
    hazards: Vec<String>,
    friction: f64,
    restitution: f64,
    #[serde(default)]
    density: Option<f64>,
    #[serde(default)]
    mass: Option<f64>,
    parts: Vec<Part>,
    appearance: Appearance,
    #[serde(default)]
    looks_like: Option<String>,
    #[serde(default)]
    model: Option<models::ModelRef>,
}

/// A validated catalog object. `mass` and `density` are both resolved.
#[derive(Debug, Clone, PartialEq)]
pub struct Object {
    pub id: String,
    pub name: String,
    pub category: String,
    pub material: String,
    pub families: Vec<String>,
    pub synonyms: Vec<String>,
    pub hazards: BTreeSet<String>,
    pub friction: f64,
    pub restitution: f64,
    pub density: f64,
    pub mass: f64,
    pub parts: Vec<Part>,
    pub appearance: Appearance,
    pub looks_like: Option<String>,
    /// The real mesh it is drawn with, if any (drawing only: the collider is `parts`).
    pub model: Option<models::ModelRef>,
}

impl Object {
    pub fn has_hazard(&self, flag: &str) -> bool {
        self.hazards.contains(flag)
    }
    pub fn is_adversarial(&self) -> bool {
        self.looks_like.is_some()
    }
    pub fn volume(&self) -> f64 {
        self.parts.iter().map(Part::volume).sum()
    }
    /// Half extents of the object's bounding box (object frame, around its origin).
    pub fn half_extents(&self) -> [f64; 3] {
        let mut h = [0.0f64; 3];
        for p in &self.parts {
            let e = p.half_extents();
            for k in 0..3 {
                h[k] = h[k].max(p.offset[k].abs() + e[k]);
            }
        }
        h
    }
    /// Radius of the smallest origin-centred sphere holding the object.
    pub fn bounding_radius(&self) -> f64 {
        let h = self.half_extents();
        (h[0] * h[0] + h[1] * h[1] + h[2] * h[2]).sqrt()
    }
}

#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawRoom {
    id: String,
    name: String,
    #[serde(default)]
    synonyms: Vec<String>,
    size: [f64; 2],
    ceiling_height: f64,
    floor_material: String,
    floor_friction: f64,
    floor_restitution: f64,
    table_height: [f64; 2],
    shelf_height: [f64; 2],
    wall_color: String,
    floor_color: String,
    #[serde(default)]
    families: Vec<String>,
    #[serde(default)]
    excludes: Vec<String>,
    #[serde(default)]
    stairs: bool,
}

/// A validated room.
#[derive(Debug, Clone, PartialEq)]
pub struct Room {
    pub id: String,
    pub name: String,
    pub synonyms: Vec<String>,
    /// Floor extents along x and y (m); the room is centred on the origin.
    pub size: [f64; 2],
    pub ceiling_height: f64,
    pub floor_material: String,
    pub floor_friction: f64,
    pub floor_restitution: f64,
    /// Range of work-surface heights (tables, counters) in this room (m).
    pub table_height: [f64; 2],
    /// Range of high-shelf heights (m).
    pub shelf_height: [f64; 2],
    pub wall_color: String,
    pub floor_color: String,
    /// Families this room hosts; empty means all (but `stair_tumble` only where `stairs`).
    pub families: Vec<String>,
    /// Families this room is too small for (a throw the room cannot hold).
    pub excludes: Vec<String>,
    /// Whether the room has a staircase (the only rooms `stair_tumble` happens in).
    pub stairs: bool,
}

/// The family that needs a room with stairs (`Room::stairs`).
pub const STAIRS_FAMILY: &str = "stair_tumble";

impl Room {
    pub fn hosts(&self, family: &str) -> bool {
        (self.families.is_empty() || self.families.iter().any(|f| f == family))
            && !self.excludes.iter().any(|f| f == family)
            && (family != STAIRS_FAMILY || self.stairs)
    }
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct ObjectsFile {
    objects: Vec<RawObject>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RoomsFile {
    rooms: Vec<RawRoom>,
}

/// The whole validated catalog, in file order.
#[derive(Debug, Clone)]
pub struct Catalog {
    pub objects: Vec<Object>,
    pub rooms: Vec<Room>,
    /// What furnishes each room type (`decor.toml`).
    pub decor: Decor,
    object_index: BTreeMap<String, usize>,
    room_index: BTreeMap<String, usize>,
}

impl Catalog {
    /// The catalog compiled into the binary.
    pub fn embedded() -> Result<Catalog, CatalogError> {
        Catalog::from_sources(
            ("catalog/data/objects.toml", OBJECTS_TOML),
            ("catalog/data/rooms.toml", ROOMS_TOML),
        )
    }

    /// Loads `objects.toml` and `rooms.toml` from a directory.
    pub fn load_dir(dir: &Path) -> Result<Catalog, CatalogError> {
        let read = |name: &str| {
            let path = dir.join(name);
            std::fs::read_to_string(&path)
                .map(|text| (path.display().to_string(), text))
                .map_err(|e| CatalogError {
                    file: path.display().to_string(),
                    entry: None,
                    field: None,
                    message: format!("cannot read: {e}"),
                })
        };
        let (objects_name, objects) = read("objects.toml")?;
        let (rooms_name, rooms) = read("rooms.toml")?;
        let mut catalog = Catalog::from_sources((&objects_name, &objects), (&rooms_name, &rooms))?;
        // A directory without its own decor.toml furnishes its rooms with the embedded one
        // (rooms it does not list stay bare).
        if dir.join("decor.toml").exists() {
            let (decor_name, decor) = read("decor.toml")?;
            catalog.decor = catalog.decor_from(&decor_name, &decor)?;
        }
        Ok(catalog)
    }

    /// Parses `decor.toml` text against this catalog's rooms.
    pub fn decor_from(&self, file: &str, text: &str) -> Result<Decor, CatalogError> {
        let ids: Vec<&str> = self.rooms.iter().map(|r| r.id.as_str()).collect();
        Decor::parse(file, text, Some(&ids))
    }

    /// Parses and validates catalog text; `(file name, text)` pairs name the sources in errors.
    pub fn from_sources(
        objects: (&str, &str),
        rooms: (&str, &str),
    ) -> Result<Catalog, CatalogError> {
        let parsed_objects: ObjectsFile =
            parse_toml::<_, RawObject>(objects.0, objects.1, "objects")?;
        let parsed_rooms: RoomsFile = parse_toml::<_, RawRoom>(rooms.0, rooms.1, "rooms")?;
        let rooms = validate_rooms(rooms.0, parsed_rooms.rooms)?;
        let objects = validate_objects(objects.0, parsed_objects.objects)?;
        let object_index = objects
            .iter()
            .enumerate()
            .map(|(i, o)| (o.id.clone(), i))
            .collect();
        let room_index = rooms
            .iter()
            .enumerate()
            .map(|(i, r)| (r.id.clone(), i))
            .collect();
        let mut catalog = Catalog {
            objects,
            rooms,
            decor: Decor::default(),
            object_index,
            room_index,
        };
        // The embedded decor, for the rooms of these sources it lists.
        let ids: Vec<&str> = catalog.rooms.iter().map(|r| r.id.as_str()).collect();
        let mut decor = Decor::parse("catalog/data/decor.toml", decor::DECOR_TOML, None)?;
        decor.rooms.retain(|room, _| ids.contains(&room.as_str()));
        catalog.decor = decor;
        Ok(catalog)
    }

    pub fn object(&self, id: &str) -> Option<&Object> {
        self.object_index.get(id).map(|&i| &self.objects[i])
    }

    pub fn room(&self, id: &str) -> Option<&Room> {
        self.room_index.get(id).map(|&i| &self.rooms[i])
    }

    /// Objects allowed in a family, in catalog order.
    pub fn objects_for_family<'a>(
        &'a self,
        family: &'a str,
    ) -> impl Iterator<Item = &'a Object> + 'a {
        self.objects
            .iter()
            .filter(move |o| o.families.iter().any(|f| f == family))
    }

    /// Rooms hosting a family, in catalog order.
    pub fn rooms_for_family<'a>(&'a self, family: &'a str) -> impl Iterator<Item = &'a Room> + 'a {
        self.rooms.iter().filter(move |r| r.hosts(family))
    }

    /// The object whose appearance an object is rendered with (itself unless adversarial).
    pub fn appearance_source<'a>(&'a self, object: &'a Object) -> &'a Object {
        object
            .looks_like
            .as_deref()
            .and_then(|id| self.object(id))
            .unwrap_or(object)
    }
}

/// Parses a catalog file whose entries (of type `E`) sit in the array `list`. A failure names
/// the file with the line (`file:LINE`) and, when the text is valid TOML but an entry does not
/// fit the schema (a missing, unknown or mistyped field), the entry and the field too.
fn parse_toml<T, E>(file: &str, text: &str, list: &str) -> Result<T, CatalogError>
where
    T: serde::de::DeserializeOwned,
    E: serde::de::DeserializeOwned,
{
    toml::from_str(text).map_err(|e| {
        let line = e.span().map(|span| line_number(text, span.start));
        let entry = failing_entry::<E>(text, list);
        let field = field_named_in(e.message()).or_else(|| line.and_then(|l| key_on_line(text, l)));
        CatalogError {
            file: match line {
                Some(l) => format!("{file}:{l}"),
                None => file.to_string(),
            },
            entry,
            field,
            message: e.message().to_string(),
        }
    })
}

/// 1-based line number of a byte offset.
fn line_number(text: &str, offset: usize) -> usize {
    text.as_bytes()[..offset.min(text.len())]
        .iter()
        .filter(|&&b| b == b'\n')
        .count()
        + 1
}

/// The first entry of `list` that does not deserialize on its own: its id, else `#n`.
fn failing_entry<E: serde::de::DeserializeOwned>(text: &str, list: &str) -> Option<String> {
    let table: toml::Table = toml::from_str(text).ok()?;
    let toml::Value::Array(items) = table.get(list)? else {
        return None;
    };
    items.iter().enumerate().find_map(|(i, item)| {
        item.clone().try_into::<E>().err()?;
        let id = item
            .get("id")
            .and_then(|v| v.as_str())
            .filter(|s| !s.is_empty());
        Some(id.map_or_else(|| format!("#{}", i + 1), str::to_string))
    })
}

/// The field a serde message names ("missing field `friction`").
fn field_named_in(message: &str) -> Option<String> {
    let rest = ["missing field `", "unknown field `", "duplicate field `"]
        .iter()
        .find_map(|prefix| message.strip_prefix(prefix))?;
    rest.split('`').next().map(str::to_string)
}

/// The key assigned on a line (`key = value`), for errors that point at a value.
fn key_on_line(text: &str, line: usize) -> Option<String> {
    let (key, _) = text.lines().nth(line - 1)?.split_once('=')?;
    let key = key.trim();
    let ok = !key.is_empty()
        && key
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-');
    ok.then(|| key.to_string())
}

struct EntryCheck<'a> {
    file: &'a str,
    entry: String,
}

impl EntryCheck<'_> {
    fn fail(&self, field: &str, message: impl Into<String>) -> CatalogError {
        CatalogError {
            file: self.file.to_string(),
            entry: Some(self.entry.clone()),
            field: Some(field.to_string()),
            message: message.into(),
        }
    }

    fn range(
        &self,
        field: &str,
        value: f64,
        lo: f64,
        hi: f64,
        unit: &str,
    ) -> Result<(), CatalogError> {
        if value.is_finite() && value >= lo && value <= hi {
            Ok(())
        } else {
            Err(self.fail(
                field,
                format!("must be between {lo} and {hi}{unit} (got {value})"),
            ))
        }
    }

    fn color(&self, field: &str, value: &str) -> Result<(), CatalogError> {
        parse_hex_color(value).map(|_| ()).ok_or_else(|| {
            self.fail(
                field,
                format!("must be a colour like \"#a0b1c2\" (got \"{value}\")"),
            )
        })
    }

    fn families(&self, field: &str, families: &[String]) -> Result<(), CatalogError> {
        for f in families {
            if !FAMILIES.contains(&f.as_str()) {
                return Err(self.fail(
                    field,
                    format!("unknown family '{f}' (known: {})", FAMILIES.join(", ")),
                ));
            }
        }
        Ok(())
    }

    fn id(&self, field: &str, id: &str) -> Result<(), CatalogError> {
        let ok = !id.is_empty()
            && id
                .chars()
                .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '_');
        if ok {
            Ok(())
        } else {
            Err(self.fail(
                field,
                format!("must be non-empty snake_case ascii (got \"{id}\")"),
            ))
        }
    }
}

/// Parses `#rrggbb` into linear-free sRGB bytes.
pub fn parse_hex_color(value: &str) -> Option<[u8; 3]> {
    let hex = value.strip_prefix('#')?;
    if hex.len() != 6 || !hex.chars().all(|c| c.is_ascii_hexdigit()) {
        return None;
    }
    let byte = |i: usize| u8::from_str_radix(&hex[i..i + 2], 16).ok();
    Some([byte(0)?, byte(2)?, byte(4)?])
}

fn validate_objects(file: &str, raw: Vec<RawObject>) -> Result<Vec<Object>, CatalogError> {
    let mut seen = BTreeSet::new();
    let mut objects = Vec::with_capacity(raw.len());
    for (i, o) in raw.into_iter().enumerate() {
        let check = EntryCheck {
            file,
            entry: if o.id.is_empty() {
                format!("#{}", i + 1)
            } else {
                o.id.clone()
            },
        };
        check.id("id", &o.id)?;
        if !seen.insert(o.id.clone()) {
            return Err(check.fail("id", "duplicate id"));
        }
        if o.name.trim().is_empty() {
            return Err(check.fail("name", "must not be empty"));
        }
        if o.category.trim().is_empty() {
            return Err(check.fail("category", "must not be empty"));
        }
        if o.material.trim().is_empty() {
            return Err(check.fail("material", "must not be empty"));
        }
        if o.families.is_empty() {
            return Err(check.fail("families", "must list at least one family"));
        }
        check.families("families", &o.families)?;
        for h in &o.hazards {
            if !HAZARDS.contains(&h.as_str()) {
                return Err(check.fail(
                    "hazards",
                    format!("unknown hazard '{h}' (known: {})", HAZARDS.join(", ")),
                ));
            }
        }
        check.range("friction", o.friction, 0.0, 1.5, "")?;
        check.range("restitution", o.restitution, 0.0, 0.95, "")?;
        if o.parts.is_empty() {
            return Err(check.fail("parts", "must have at least one part"));
        }
        check_parts(&check, &o.parts)?;
        let volume: f64 = o.parts.iter().map(Part::volume).sum();
        let (density, mass) = match (o.density, o.mass) {
            (Some(_), Some(_)) => {
                return Err(check.fail("mass", "give either density or mass, not both"))
            }
            (None, None) => {
                return Err(check.fail("density", "give either density (kg/m³) or mass (kg)"))
            }
            (Some(d), None) => {
                check.range("density", d, DENSITY_RANGE.0, DENSITY_RANGE.1, " kg/m³")?;
                (d, d * volume)
            }
            (None, Some(m)) => {
                check.range("mass", m, MASS_RANGE_KG.0, MASS_RANGE_KG.1, " kg")?;
                let d = m / volume;
                if !(DENSITY_RANGE.0..=DENSITY_RANGE.1).contains(&d) {
                    return Err(check.fail(
                        "mass",
                        format!("{m} kg in {volume:.6} m³ is a density of {d:.1} kg/m³, outside {DENSITY_RANGE:?}"),
                    ));
                }
                (d, m)
            }
        };
        check.range("mass", mass, MASS_RANGE_KG.0, MASS_RANGE_KG.1, " kg")?;
        let heavy = o.hazards.iter().any(|h| h == "heavy");
        if heavy != (mass >= HEAVY_FLAG_MIN_KG) {
            return Err(check.fail(
                "hazards",
                format!(
                    "'heavy' must be set exactly when the mass is at least {HEAVY_FLAG_MIN_KG} kg (mass {mass:.3} kg, heavy = {heavy})"
                ),
            ));
        }
        if o.appearance.recipe.trim().is_empty() {
            return Err(check.fail("appearance.recipe", "must not be empty"));
        }
        check.color("appearance.color", &o.appearance.color)?;
        if let Some(c) = &o.appearance.secondary_color {
            check.color("appearance.secondary_color", c)?;
        }
        if let Some(m) = &o.model {
            models::check_model(&check, m, o.looks_like.is_some())?;
        }
        objects.push(Object {
            id: o.id,
            name: o.name,
            category: o.category,
            material: o.material,
            families: o.families,
            synonyms: o.synonyms,
            hazards: o.hazards.into_iter().collect(),
            friction: o.friction,
            restitution: o.restitution,
            density,
            mass,
            parts: o.parts,
            appearance: o.appearance,
            looks_like: o.looks_like,
            model: o.model,
        });
    }
    check_look_alikes(file, &objects)?;
    Ok(objects)
}

/// Each part's size (as many numbers as its shape needs, within range) and offset.
fn check_parts(check: &EntryCheck, parts: &[Part]) -> Result<(), CatalogError> {
    for (k, p) in parts.iter().enumerate() {
        let field = format!("parts[{k}].size");
        if p.size.len() != p.expected_size_len() {
            return Err(check.fail(
                &field,
                format!(
                    "a {:?} needs {} numbers (got {})",
                    p.shape,
                    p.expected_size_len(),
                    p.size.len()
                ),
            ));
        }
        for &s in &p.size {
            check.range(&field, s, SIZE_RANGE_M.0, SIZE_RANGE_M.1, " m")?;
        }
        if p.shape == ShapeKind::Capsule && p.size[1] < p.size[0] {
            return Err(check.fail(&field, "a capsule's length must be at least its diameter"));
        }
        for &v in &p.offset {
            check.range(
                &format!("parts[{k}].offset"),
                v,
                -SIZE_RANGE_M.1,
                SIZE_RANGE_M.1,
                " m",
            )?;
        }
    }
    Ok(())
}

/// Look-alikes need the whole list: an adversarial entry must point at a genuine
/// object and share its shape, so that rendering it "exactly like" the other is honest.
fn check_look_alikes(file: &str, objects: &[Object]) -> Result<(), CatalogError> {
    for o in objects {
        let Some(target) = &o.looks_like else {
            continue;
        };
        let check = EntryCheck {
            file,
            entry: o.id.clone(),
        };
        let Some(t) = objects.iter().find(|x| &x.id == target) else {
            return Err(check.fail("looks_like", format!("no object with id '{target}'")));
        };
        if t.looks_like.is_some() {
            return Err(check.fail("looks_like", format!("'{target}' is itself adversarial")));
        }
        if t.parts != o.parts {
            return Err(check.fail(
                "parts",
                format!("must equal the parts of its look-alike '{target}'"),
            ));
        }
        if t.appearance != o.appearance {
            return Err(check.fail(
                "appearance",
                format!("must equal the appearance of its look-alike '{target}'"),
            ));
        }
    }
    Ok(())
}

fn validate_rooms(file: &str, raw: Vec<RawRoom>) -> Result<Vec<Room>, CatalogError> {
    let mut seen = BTreeSet::new();
    let mut rooms = Vec::with_capacity(raw.len());
    for (i, r) in raw.into_iter().enumerate() {
        let check = EntryCheck {
            file,
            entry: if r.id.is_empty() {
                format!("#{}", i + 1)
            } else {
                r.id.clone()
            },
        };
        check.id("id", &r.id)?;
        if !seen.insert(r.id.clone()) {
            return Err(check.fail("id", "duplicate id"));
        }
        if r.name.trim().is_empty() {
            return Err(check.fail("name", "must not be empty"));
        }
        check.range("size", r.size[0], 3.0, 30.0, " m")?;
        check.range("size", r.size[1], 3.0, 30.0, " m")?;
        check.range("ceiling_height", r.ceiling_height, 2.2, 6.0, " m")?;
        check.range("floor_friction", r.floor_friction, 0.05, 1.5, "")?;
        check.range("floor_restitution", r.floor_restitution, 0.0, 0.9, "")?;
        for (field, range, lo, hi) in [
            ("table_height", r.table_height, 0.4, 1.2),
            ("shelf_height", r.shelf_height, 1.2, 2.4),
        ] {
            check.range(field, range[0], lo, hi, " m")?;
            check.range(field, range[1], lo, hi, " m")?;
            if range[0] > range[1] {
                return Err(check.fail(
                    field,
                    format!("range [{}, {}] is reversed", range[0], range[1]),
                ));
            }
        }
        if r.shelf_height[1] >= r.ceiling_height - 0.2 {
            return Err(check.fail("shelf_height", "must stay at least 0.2 m below the ceiling"));
        }
        check.color("wall_color", &r.wall_color)?;
        check.color("floor_color", &r.floor_color)?;
        check.families("families", &r.families)?;
        check.families("excludes", &r.excludes)?;
        rooms.push(Room {
            id: r.id,
            name: r.name,
            synonyms: r.synonyms,
            size: r.size,
            ceiling_height: r.ceiling_height,
            floor_material: r.floor_material,
            floor_friction: r.floor_friction,
            floor_restitution: r.floor_restitution,
            table_height: r.table_height,
            shelf_height: r.shelf_height,
            wall_color: r.wall_color,
            floor_color: r.floor_color,
            families: r.families,
            excludes: r.excludes,
            stairs: r.stairs,
        });
    }
    if rooms.is_empty() {
        return Err(CatalogError {
            file: file.to_string(),
            entry: None,
            field: Some("rooms".into()),
            message: "at least one room is required".into(),
        });
    }
    Ok(rooms)
}

#[cfg(test)]
mod tests;
