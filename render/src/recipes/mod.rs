//! Object recipes: how each catalog `appearance.recipe` is drawn, in the body frame, from
//! the object's collision parts (for its size) and its colours. Unknown recipes fall back
//! to the collision parts in the object's colours, so no object ever fails to draw.
//!
//! One file per kind of object (`round`, `boxes`, `kitchen`, `tools`, `soft`, `fixtures`,
//! `furniture`), each with a table of [`Recipe`]s: adding a look is one function and one
//! table row in one file. [`object_mesh`] looks the recipe up in [`RECIPES`]; which
//! recipes have dedicated code is that table, by construction.

use super::mesh::*;

mod boxes;
mod fixtures;
mod furniture;
mod kitchen;
mod round;
mod soft;
mod tools;
use rh_physics::spec::{PartSpec, ShapeSpec};

/// What a recipe gets: the colours and the collision parts (body frame).
pub struct Look<'a> {
    pub recipe: &'a str,
    pub color: Rgba,
    pub secondary: Option<Rgba>,
    pub description: &'a str,
    pub parts: &'a [PartSpec],
}

/// Half extents of one part's own axis-aligned box (in the part's frame).
pub(crate) fn part_half(p: &PartSpec) -> V3 {
    match p.shape {
        ShapeSpec::Box { half_extents: h } => h.map(|v| v as f32),
        ShapeSpec::Sphere { radius } => [radius as f32; 3],
        ShapeSpec::Cylinder {
            half_height,
            radius,
        } => [radius as f32, radius as f32, half_height as f32],
        ShapeSpec::Capsule {
            half_height,
            radius,
        } => [radius as f32, radius as f32, (half_height + radius) as f32],
    }
}

/// Half extents of the parts' bounding box around the body origin.
fn bounds(parts: &[PartSpec]) -> V3 {
    let mut h = [0.0f32; 3];
    for p in parts {
        let e = part_half(p);
        for k in 0..3 {
            h[k] = h[k].max(p.offset[k].abs() as f32 + e[k]);
        }
    }
    if h.iter().all(|&v| v == 0.0) {
        [0.05; 3]
    } else {
        h
    }
}

fn part_xf(p: &PartSpec) -> Xf {
    Xf::from_quat(p.rotation, p.offset)
}

/// The collision parts themselves, first part in `c0`, the rest in `c1`.
pub fn parts_mesh(m: &mut Mesh, parts: &[PartSpec], c0: Rgba, c1: Rgba) {
    for (i, p) in parts.iter().enumerate() {
        let c = if i == 0 { c0 } else { c1 };
        let xf = part_xf(p);
        let paint = solid(c);
        match p.shape {
            ShapeSpec::Box { half_extents } => {
                m.boxy(&xf, half_extents.map(|v| v as f32), 1, &paint)
            }
            ShapeSpec::Sphere { radius } => m.sphere(&xf, radius as f32, 20, &paint),
            ShapeSpec::Cylinder {
                half_height,
                radius,
            } => m.cylinder(&xf, radius as f32, half_height as f32, 24, &paint),
            ShapeSpec::Capsule {
                half_height,
                radius,
            } => m.capsule(&xf, radius as f32, half_height as f32, 16, &paint),
        }
    }
}

const DARK: Rgba = [0.02, 0.02, 0.02, MAT_PLAIN];
const STEEL: Rgba = [0.55, 0.57, 0.6, MAT_GLOSSY];
const WHITE: Rgba = [0.85, 0.85, 0.85, MAT_PLAIN];

/// What a recipe function gets besides the mesh: the look and the values every recipe
/// starts from (colour, secondary colour, half extents of the parts' box, …).
#[derive(Clone, Copy)]
struct Kit<'a> {
    look: &'a Look<'a>,
    /// Primary colour.
    c: Rgba,
    /// Secondary colour (the catalog's, else a darker primary).
    s: Rgba,
    /// Half extents of the collision parts' bounding box.
    h: V3,
    id: Xf,
    /// The smaller horizontal half extent.
    r: f32,
    desc: &'a str,
}

/// One object look: the recipe names it draws and the function that meshes it.
struct Recipe {
    names: &'static [&'static str],
    mesh: fn(&mut Mesh, &Kit),
}

/// Every recipe with dedicated code, file by file.
const RECIPES: &[&[Recipe]] = &[
    round::RECIPES,
    boxes::RECIPES,
    kitchen::RECIPES,
    tools::RECIPES,
    soft::RECIPES,
    fixtures::RECIPES,
    furniture::RECIPES,
];

fn recipe(name: &str) -> Option<&'static Recipe> {
    RECIPES
        .iter()
        .flat_map(|t| t.iter())
        .find(|r| r.names.contains(&name))
}

/// Whether `name` has dedicated code (otherwise the generic part fallback draws it).
pub fn is_specific(name: &str) -> bool {
    recipe(name).is_some()
}

/// Builds the mesh of a catalog object in its body frame.
pub fn object_mesh(look: &Look) -> Mesh {
    let mut m = Mesh::new();
    let c = look.color;
    let s = look.secondary.unwrap_or_else(|| shade(c, 0.6));
    let h = bounds(look.parts);
    match recipe(look.recipe) {
        Some(recipe) => {
            let kit = Kit {
                look,
                c,
                s,
                h,
                id: Xf::ID,
                r: h[0].min(h[1]),
                desc: look.description,
            };
            (recipe.mesh)(&mut m, &kit);
        }
        None => parts_mesh(&mut m, look.parts, c, s),
    }
    m
}
