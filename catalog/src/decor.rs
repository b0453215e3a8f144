//! Decor (`catalog/data/decor.toml`): the furniture, fixtures, windows and doors that
//! furnish each room type, as data — every piece's primitive parts (its collider, and what
//! the renderer draws) — and which pieces each room type holds. Validated like the rest of
//! the catalog: an error names the file, the entry and the field.

use crate::{parse_toml, CatalogError, EntryCheck, ShapeKind};
use serde::Deserialize;
use std::collections::BTreeMap;

pub(crate) const DECOR_TOML: &str = include_str!("../data/decor.toml");

/// How a piece stands in the room.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Mount {
    /// On the floor, its back against a wall.
    Floor,
    /// Hung on a wall, its origin `height` above the floor.
    Wall,
    /// A window or door in the wall plane: drawn, never a collider.
    Opening,
}

/// How a part's surface is shaded.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Finish {
    #[default]
    Matte,
    Glossy,
    /// Emits its colour, unlit (a lit burner, daylight through a window).
    Glow,
}

fn yes() -> bool {
    true
}

/// One primitive of a piece, in the piece's frame (x along the wall, y into the room, z up).
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DecorPart {
    pub shape: ShapeKind,
    /// Full extents as for object parts (box [x, y, z], cylinder [diameter, height], …).
    pub size: Vec<f64>,
    #[serde(default)]
    pub offset: [f64; 3],
    pub color: String,
    #[serde(default)]
    pub finish: Finish,
    /// Whether the part belongs to the collider (false: drawn only).
    #[serde(default = "yes")]
    pub collide: bool,
}

/// A piece of decor.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DecorPiece {
    pub id: String,
    pub name: String,
    pub mount: Mount,
    /// Height of the origin above the floor (m): 0 for floor pieces.
    #[serde(default)]
    pub height: f64,
    pub parts: Vec<DecorPart>,
    /// A mesh to draw instead of the parts' look (package-relative file), if any.
    #[serde(default)]
    pub model: Option<String>,
}

impl DecorPiece {
    /// Whether the piece is furniture (stands or hangs in the room; not a window or door).
    pub fn is_furniture(&self) -> bool {
        self.mount != Mount::Opening
    }

    /// Whether the piece is a collider in physics: furniture with a colliding part.
    pub fn collides(&self) -> bool {
        self.is_furniture() && self.parts.iter().any(|p| p.collide)
    }

    /// The piece's extent along the wall (x) and out of it (y) in its frame, from its
    /// origin: `[x_min, x_max, y_max]` over every part (drawn ones too).
    pub fn footprint(&self) -> [f64; 3] {
        let mut f = [f64::INFINITY, f64::NEG_INFINITY, 0.0f64];
        for p in &self.parts {
            let h = half_extents(p);
            f[0] = f[0].min(p.offset[0] - h[0]);
            f[1] = f[1].max(p.offset[0] + h[0]);
            f[2] = f[2].max(p.offset[1] + h[1]);
        }
        f
    }

    /// The lowest and highest points of the piece above the floor (m).
    pub fn z_range(&self) -> [f64; 2] {
        let mut z = [f64::INFINITY, f64::NEG_INFINITY];
        for p in &self.parts {
            let h = half_extents(p);
            z[0] = z[0].min(self.height + p.offset[2] - h[2]);
            z[1] = z[1].max(self.height + p.offset[2] + h[2]);
        }
        z
    }
}

fn half_extents(p: &DecorPart) -> [f64; 3] {
    crate::Part {
        shape: p.shape,
        size: p.size.clone(),
        offset: p.offset,
    }
    .half_extents()
}

#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawRoomDecor {
    room: String,
    pieces: Vec<String>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct DecorFile {
    pieces: Vec<DecorPiece>,
    rooms: Vec<RawRoomDecor>,
}

/// The validated decor catalog.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Decor {
    pub pieces: Vec<DecorPiece>,
    /// Per room id, the ids of its pieces, in file order (a piece may repeat).
    pub rooms: BTreeMap<String, Vec<String>>,
    index: BTreeMap<String, usize>,
}

impl Decor {
    /// Parses and validates `decor.toml` text, its rooms against `room_ids` if given.
    pub fn parse(file: &str, text: &str, room_ids: Option<&[&str]>) -> Result<Decor, CatalogError> {
        let raw: DecorFile = parse_toml::<_, DecorPiece>(file, text, "pieces")?;
        let mut index = BTreeMap::new();
        for (i, p) in raw.pieces.iter().enumerate() {
            validate_piece(file, p)?;
            if index.insert(p.id.clone(), i).is_some() {
                let check = EntryCheck {
                    file,
                    entry: p.id.clone(),
                };
                return Err(check.fail("id", "duplicate piece id"));
            }
        }
        let mut rooms = BTreeMap::new();
        for r in raw.rooms {
            let check = EntryCheck {
                file,
                entry: r.room.clone(),
            };
            if room_ids.is_some_and(|ids| !ids.contains(&r.room.as_str())) {
                return Err(check.fail("room", format!("unknown room '{}'", r.room)));
            }
            if let Some(p) = r.pieces.iter().find(|p| !index.contains_key(p.as_str())) {
                return Err(check.fail("pieces", format!("unknown piece '{p}'")));
            }
            if rooms.insert(r.room.clone(), r.pieces).is_some() {
                return Err(check.fail("room", "room listed twice"));
            }
        }
        Ok(Decor {
            pieces: raw.pieces,
            rooms,
            index,
        })
    }

    pub fn piece(&self, id: &str) -> Option<&DecorPiece> {
        self.index.get(id).map(|&i| &self.pieces[i])
    }

    /// The pieces a room type holds, in file order (empty for a room without decor).
    pub fn for_room<'a>(&'a self, room: &str) -> impl Iterator<Item = &'a DecorPiece> + 'a {
        self.rooms
            .get(room)
            .into_iter()
            .flatten()
            .filter_map(|id| self.piece(id))
    }
}

fn validate_piece(file: &str, p: &DecorPiece) -> Result<(), CatalogError> {
    let check = EntryCheck {
        file,
        entry: p.id.clone(),
    };
    check.id("id", &p.id)?;
    if p.name.trim().is_empty() {
        return Err(check.fail("name", "must not be empty"));
    }
    if p.parts.is_empty() {
        return Err(check.fail("parts", "a piece needs at least one part"));
    }
    check.range("height", p.height, 0.0, 3.0, " m")?;
    if p.mount == Mount::Floor && p.height != 0.0 {
        return Err(check.fail("height", "a floor piece stands at height 0"));
    }
    for (i, part) in p.parts.iter().enumerate() {
        let field = format!("parts[{i}]");
        let want = match part.shape {
            ShapeKind::Box => 3,
            ShapeKind::Sphere => 1,
            ShapeKind::Cylinder | ShapeKind::Capsule => 2,
        };
        if part.size.len() != want {
            return Err(check.fail(&format!("{field}.size"), format!("needs {want} numbers")));
        }
        for &s in &part.size {
            check.range(&format!("{field}.size"), s, 0.005, 3.0, " m")?;
        }
        check.color(&format!("{field}.color"), &part.color)?;
    }
    let [x0, x1, depth] = p.footprint();
    if x1 - x0 > 3.0 || depth > 2.5 || depth <= 0.0 {
        return Err(check.fail("parts", "the piece must fit 3 m along a wall and 2.5 m out"));
    }
    if p.mount == Mount::Floor && p.z_range()[0] < -1e-9 {
        return Err(check.fail(
            "parts",
            "a floor piece's parts must not reach below the floor",
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Catalog;

    #[test]
    fn every_room_type_lists_four_pieces_of_furniture_and_an_opening() {
        let c = Catalog::embedded().unwrap();
        for room in &c.rooms {
            let pieces: Vec<_> = c.decor.for_room(&room.id).collect();
            let furniture: std::collections::BTreeSet<_> = pieces
                .iter()
                .filter(|p| p.is_furniture())
                .map(|p| p.id.as_str())
                .collect();
            assert!(furniture.len() >= 4, "{}: {furniture:?}", room.id);
            assert!(
                pieces.iter().any(|p| p.mount == Mount::Opening),
                "{}",
                room.id
            );
        }
        // Windows and doors are drawn only; furniture collides.
        assert!(!c.decor.piece("door").unwrap().collides());
        assert!(c.decor.piece("sofa").unwrap().collides());
        assert_eq!(
            c.decor.piece("sofa").unwrap().footprint(),
            [-0.95, 0.95, 0.85]
        );
    }

    #[test]
    fn a_bad_entry_is_named_with_its_field() {
        let text = DECOR_TOML.replace("color = \"#e8e4dc\"", "color = \"beige\"");
        let e = Decor::parse("decor.toml", &text, None).unwrap_err();
        assert_eq!(e.entry.as_deref(), Some("kitchen_counter"));
        assert_eq!(e.field.as_deref(), Some("parts[0].color"));
        let text = DECOR_TOML.replace("\"tv_stand\", \"bookcase\"", "\"tv_stand\", \"piano\"");
        let e = Decor::parse("decor.toml", &text, None).unwrap_err();
        assert_eq!(
            (e.entry.as_deref(), e.field.as_deref()),
            (Some("living_room"), Some("pieces"))
        );
        assert!(e.message.contains("piano"), "{e}");
        let e = Decor::parse("decor.toml", DECOR_TOML, Some(&["kitchen"][..])).unwrap_err();
        assert_eq!(e.field.as_deref(), Some("room"), "{e}");
    }

    #[test]
    fn stairs_alone_host_stair_tumble() {
        let c = Catalog::embedded().unwrap();
        let rooms: Vec<_> = c
            .rooms_for_family("stair_tumble")
            .map(|r| r.id.as_str())
            .collect();
        assert_eq!(rooms, ["living_room", "garage", "hallway", "storage_room"]);
        assert!(c.room("kitchen").unwrap().hosts("object_drop"));
    }
}
