//! The scene's geometry for drawing: static pieces (furniture, observer, floor, walls,
//! ceiling) meshed once per scene, moving bodies meshed once in their body frames and
//! posed per step, ropes, and what each camera sees.

use super::camera::{inverse_view_proj_rows, view_proj};
use super::cells::rects_meet;
use super::gpu::{self, Uniforms, ViewJob};
use super::lighting::Lighting;
use super::mesh::*;
use super::observer::observer_mesh;
use super::recipes;
use super::regions::{bounds, cover, screen_rect, shadow_regions};
use super::tiles::{LightRows, SurfaceTiles};
use super::Shading;
use rh_catalog::Catalog;
use rh_contract::layout::instance;
use rh_physics::simulate::{BodyState, Simulation};
use rh_physics::spec::vec3::{add, norm, sub};
use rh_physics::spec::{BodyKind, CameraSpec, JointKind, SceneSpec, Vec3};
use rh_scenes::view::View;
use std::ops::Range;

/// One static mesh piece: its vertices in `statics`, its bounding box, and the
/// bounding boxes of its triangle pairs (meshes are built face by face, so a pair is
/// one quad: a table top apart from its legs), which bound where on it a shadow can
/// fall much tighter than the whole box.
struct Piece {
    range: Range<u32>,
    bounds: [Vec3; 2],
    receivers: Vec<[Vec3; 2]>,
}

const RECEIVER_TRIANGLES: usize = 2;

/// The piece made of `statics[from..]` (`None` when empty).
fn piece(statics: &[Vertex], from: usize) -> Option<Piece> {
    let verts = &statics[from..];
    bounds(verts).map(|whole| Piece {
        range: from as u32..statics.len() as u32,
        bounds: whole,
        receivers: verts
            .chunks(3 * RECEIVER_TRIANGLES)
            .filter_map(bounds)
            .collect(),
    })
}

/// A camera's per-scene constants for overlay frames (`SceneGeometry::fixed_view`).
pub(super) struct FixedView<'a> {
    pub(super) slot: usize,
    cam: &'a CameraSpec,
    pub(super) uniforms: Uniforms,
    view: Option<View>,
    /// Static pieces the camera sees: vertex range and screen bounds.
    visible: Vec<(Range<u32>, [u32; 4])>,
    /// Their receiver boxes (`Piece::receivers`).
    receivers: Vec<[Vec3; 2]>,
    /// Where its static surfaces are, per screen tile (without MSAA: `set_surface`).
    tiles: Option<SurfaceTiles>,
}

/// Triangles per run of a static piece in a view's redraw lists (`SceneGeometry::chunks`).
const REDRAW_CHUNK: u32 = 64;

impl FixedView<'_> {
    /// Takes the view's cached static depth (one sample per pixel): redraws are then
    /// the screen tiles whose surface the moving casters' shadow can reach.
    pub(super) fn set_surface(&mut self, depth: &[f32], sun: &LightRows) {
        let inv = inverse_view_proj_rows(self.cam);
        let size = (self.cam.width, self.cam.height);
        self.tiles = Some(SurfaceTiles::from_depth(depth, size, inv, sun));
    }
}

struct Wall {
    range: Range<u32>,
    /// Visible from cameras with `axis` coordinate on this side: `sign * p[axis] < limit`.
    axis: usize,
    sign: f64,
    limit: f64,
}

struct DynamicBody {
    slot: usize,
    hazard: bool,
    /// Instance id (`rh_contract::layout::instance::body` of its spec index).
    id: u16,
    mesh: Mesh,
}

struct Rope {
    a: (Option<usize>, Vec3),
    b: (usize, Vec3),
}

pub(super) struct SceneGeometry {
    pub(super) statics: Vec<Vertex>,
    /// Furniture and event geometry.
    fixed: Range<u32>,
    /// The observer's body and head.
    observer: Range<u32>,
    head_center: Vec3,
    floor: Range<u32>,
    walls: Vec<Wall>,
    ceiling: Range<u32>,
    ceiling_z: f64,
    dynamic: Vec<DynamicBody>,
    ropes: Vec<Rope>,
    pub(super) max_dynamic: usize,
    pub(super) light_vp: [[f32; 4]; 4],
    sun_dir: [f32; 4],
    sun_color: [f32; 4],
    ambient: [f32; 4],
    background: [f32; 4],
    /// The static pieces (each fixed body, the observer, floor, each wall, ceiling).
    pieces: Vec<Piece>,
    /// Distance (m) from a shadow volume within which shading may depend on it.
    shadow_reach: f64,
    /// The sun's view-projection rows, and the shadow map's reach in its clip space
    /// (`Lighting::shadow_reach_light`).
    sun: LightRows,
    shadow_reach_light: f64,
    /// Each fixed body's vertex range with its instance id (the id pass: `ids`).
    fixed_ids: Vec<(Range<u32>, u16)>,
}

fn fixed_color(name: &str, wall: Rgba) -> Rgba {
    let has = |k: &str| name.contains(k);
    if has("table") || has("stool") || has("counter") || has("desk") {
        hex("#8d6e4a")
    } else if has("shelf") {
        hex("#a1887f")
    } else if has("wall") {
        shade(wall, 0.92)
    } else if has("ramp") {
        hex("#90a4ae")
    } else if has("step") || has("landing") || has("stair") {
        hex("#bcaaa4")
    } else if has("jamb") || has("frame") || has("door") {
        hex("#eeeeee")
    } else if has("mount") || has("hook") || has("bar") || has("rail") || has("beam") {
        mat(hex("#78909c"), MAT_GLOSSY)
    } else {
        hex("#9e9e9e")
    }
}

impl SceneGeometry {
    pub(super) fn build(spec: &SceneSpec, sim: &Simulation, catalog: &Catalog) -> SceneGeometry {
        let mut statics: Vec<Vertex> = Vec::new();
        // Each static piece's vertices and bounds: what a moving body's shadow can fall on
        // and what must be redrawn where it does (see `shadow_regions`).
        let mut pieces: Vec<Piece> = Vec::new();
        let room = &spec.room;
        let wall_c = hex(&room.wall_color);
        let floor_c = mat(hex(&room.floor_color), MAT_FLOOR);

        // Fixed bodies (furniture, event geometry) and the observer: shadow casters.
        let mut fixed_ids = Vec::new();
        for (bi, body) in spec
            .bodies
            .iter()
            .enumerate()
            .filter(|(_, b)| b.kind == BodyKind::Fixed)
        {
            let look = || {
                let id = body.catalog_id.as_deref()?;
                object_look_mesh(catalog, id, &body.parts)
            };
            let mesh = match crate::decor::decor_mesh(catalog, body).or_else(look) {
                Some(m) => m,
                None => {
                    let mut m = Mesh::new();
                    let c = fixed_color(&body.name, wall_c);
                    recipes::parts_mesh(&mut m, &body.parts, c, c);
                    m
                }
            };
            let from = statics.len();
            mesh.transformed_into(&Xf::from_quat(body.rotation, body.position), &mut statics);
            fixed_ids.push((from as u32..statics.len() as u32, instance::body(bi)));
            pieces.extend(piece(&statics, from));
        }
        // Render-only scenery (brackets, hooks, a lit burner): drawn with the fixed bodies.
        let from = statics.len();
        crate::decor::scenery(spec).transformed_into(&Xf::ID, &mut statics);
        pieces.extend(piece(&statics, from));
        let fixed = 0..statics.len() as u32;
        let o = &spec.observer;
        let (obody, ohead) = observer_mesh(o.height, o.pelvis_z, o.shoulder_z);
        let oxf = Xf::rot(2, o.yaw as f32, [o.x as f32, o.y as f32, 0.0]);
        obody.transformed_into(&oxf, &mut statics);
        ohead.transformed_into(&oxf, &mut statics);
        let observer = fixed.end..statics.len() as u32;
        pieces.extend(piece(&statics, observer.start as usize));
        let head_center = [o.x, o.y, o.height - 0.075];
        let (floor_r, walls, ceiling) =
            room_shell(room, wall_c, floor_c, &mut statics, &mut pieces);
        let (dynamic, ropes, max_dynamic) = moving_bodies(spec, sim, catalog);
        let light = Lighting::of(spec);
        SceneGeometry {
            statics,
            fixed,
            observer,
            head_center,
            floor: floor_r,
            walls,
            ceiling,
            ceiling_z: room.ceiling_height,
            dynamic,
            ropes,
            max_dynamic,
            light_vp: light.light_vp,
            sun_dir: light.sun_dir,
            sun_color: light.sun_color,
            ambient: light.ambient,
            background: [0.04, 0.045, 0.05, 1.0],
            pieces,
            shadow_reach: light.shadow_reach,
            sun: LightRows::of(&light.light_vp),
            shadow_reach_light: light.shadow_reach_light,
            fixed_ids,
        }
    }

    /// The moving bodies (and ropes) at one step of `sim`.
    pub(super) fn dynamic_at(&self, sim: &Simulation, step: u32, mask: bool) -> Vec<Vertex> {
        let n = sim.dynamic_bodies.len();
        let at = step as usize * n;
        self.dynamic_from(&sim.states[at..at + n], mask)
    }

    /// The moving bodies (and ropes) with the given states (one per dynamic body, in the
    /// `Simulation` slot order): a simulation step or an executed one (`execute`).
    pub(super) fn dynamic_from(&self, states: &[BodyState], mask: bool) -> Vec<Vertex> {
        let pose = |slot: usize| {
            let s = &states[slot];
            Xf::from_quat(s.rotation.map(f64::from), s.position.map(f64::from))
        };
        let mut out = Vec::with_capacity(self.max_dynamic);
        for d in &self.dynamic {
            let xf = pose(d.slot);
            let from = out.len();
            d.mesh.transformed_into(&xf, &mut out);
            if mask && d.hazard {
                for v in &mut out[from..] {
                    v.color = [1.0, 0.0, 1.0, MAT_EMISSIVE];
                }
            }
        }
        let mut m = Mesh::new();
        for r in &self.ropes {
            let a = match r.a {
                (Some(slot), p) => pose(slot).apply(p.map(|v| v as f32)),
                (None, p) => p.map(|v| v as f32),
            };
            let b = pose(r.b.0).apply(r.b.1.map(|v| v as f32));
            let d = [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
            if (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt() > 0.03 {
                m.rod(&Xf::ID, a, b, 0.008, 6, &solid(hex("#3a3a3a")));
            }
        }
        out.extend_from_slice(&m.verts);
        out
    }

    /// Leaves the standing observer out of every view and the shadow casters (the
    /// execution videos draw the executing humanoid as moving geometry instead).
    pub(super) fn hide_observer(&mut self) {
        self.observer = self.observer.start..self.observer.start;
    }

    /// Static vertex ranges a camera sees: walls it stands behind are cut away, the
    /// ceiling only from below it, the observer not from inside its head.
    pub(super) fn ranges_for(&self, cam: &CameraSpec) -> Vec<Range<u32>> {
        let p = cam.position;
        let mut r = vec![self.fixed.clone()];
        // The ego camera sits in the observer's head: its own body is left out (it would
        // only block the lower part of the view).
        if norm(sub(p, self.head_center)) > 0.25 {
            r.push(self.observer.clone());
        }
        r.push(self.floor.clone());
        for w in &self.walls {
            if w.sign * p[w.axis] < w.limit {
                r.push(w.range.clone());
            }
        }
        if p[2] < self.ceiling_z {
            r.push(self.ceiling.clone());
        }
        r
    }

    /// What a camera needs per overlay frame that does not change within the scene:
    /// its uniforms, camera model, and the static pieces it sees with their screen
    /// bounds and receiver boxes.
    pub(super) fn fixed_view<'a>(&self, slot: usize, cam: &'a CameraSpec) -> FixedView<'a> {
        let seen = self.ranges_for(cam);
        let view = View::new(cam);
        let pieces: Vec<(&Piece, [u32; 4])> = self
            .pieces
            .iter()
            .filter(|p| {
                seen.iter()
                    .any(|r| r.start <= p.range.start && p.range.end <= r.end)
            })
            .filter_map(|p| screen_rect(cam, view.as_ref(), p.bounds).map(|r| (p, r)))
            .collect();
        FixedView {
            slot,
            cam,
            uniforms: self.uniforms(cam, Shading::Lit),
            receivers: pieces
                .iter()
                .flat_map(|(p, _)| p.receivers.iter().copied())
                .collect(),
            visible: pieces
                .into_iter()
                .flat_map(|(p, _)| self.chunks(p.range.clone()))
                .filter_map(|(range, b)| screen_rect(cam, view.as_ref(), b).map(|r| (range, r)))
                .collect(),
            view,
            tiles: None,
        }
    }

    /// A static piece's vertex range cut into runs of at most `REDRAW_CHUNK` triangles,
    /// each with its bounds: a redraw draws only the runs near its rectangles (a piece's
    /// triangles lie close together in order), not the whole piece.
    fn chunks(&self, range: Range<u32>) -> impl Iterator<Item = (Range<u32>, [Vec3; 2])> + '_ {
        let step = 3 * REDRAW_CHUNK;
        (range.start..range.end)
            .step_by(step as usize)
            .filter_map(move |s| {
                let r = s..(s + step).min(range.end);
                bounds(&self.statics[r.start as usize..r.end as usize]).map(|b| (r, b))
            })
    }

    /// The sun's view-projection (rows), for `FixedView::set_surface`.
    pub(super) fn sun(&self) -> &LightRows {
        &self.sun
    }

    /// Where moving geometry `dynamic` (bounds `moving`) may shade static surfaces in a
    /// view (`shadow_regions`, or the view's surface tiles), each rectangle with the
    /// static pieces it must redraw: those the camera sees whose screen bounds meet it.
    pub(super) fn shadow_redraws(
        &self,
        v: &FixedView,
        moving: [Vec3; 2],
        dynamic: &[Vertex],
    ) -> Vec<([u32; 4], Vec<Range<u32>>)> {
        let caster = v
            .tiles
            .as_ref()
            .and_then(|_| self.sun.caster_bounds(dynamic));
        match (&v.tiles, caster) {
            (Some(tiles), Some(caster)) => tiles.redraw_rects(
                (moving, self.shadow_reach, self.sun_dir),
                (caster, self.shadow_reach_light),
            ),
            _ => shadow_regions(
                v.cam,
                v.view.as_ref(),
                moving,
                self.shadow_reach,
                self.sun_dir,
                &v.receivers,
            ),
        }
        .into_iter()
        .map(|rect| {
            let ranges = v
                .visible
                .iter()
                .filter(|(_, r)| rects_meet(*r, rect))
                .map(|(range, _)| range.clone())
                .collect();
            (rect, ranges)
        })
        .collect()
    }

    /// Rectangles (x, y, width, height; at most `MAX_REDRAW_RECTS`) where view `v`'s
    /// post-process pass must be redone: every pixel within `gpu::POST_REACH` of one
    /// that may differ from the static image (the moving bodies' screen bounds, `moving`,
    /// and the `redraw` rectangles), on a 16-pixel grid. Empty when nothing can differ.
    pub(super) fn post_rects(
        &self,
        v: &FixedView,
        moving: [Vec3; 2],
        redraw: &[([u32; 4], Vec<Range<u32>>)],
    ) -> Vec<[u32; 4]> {
        let changed: Vec<[u32; 4]> = screen_rect(v.cam, v.view.as_ref(), moving)
            .into_iter()
            .chain(redraw.iter().map(|(r, _)| *r))
            .collect();
        cover(
            &changed,
            gpu::POST_REACH,
            16,
            v.cam.width,
            v.cam.height,
            gpu::MAX_REDRAW_RECTS,
        )
    }

    /// Fixed bodies and the observer: the shadow casters that never move.
    pub(super) fn static_casters(&self) -> Vec<Range<u32>> {
        vec![self.fixed.clone(), self.observer.clone()]
    }

    pub(super) fn view_job(
        &self,
        slot: usize,
        cam: &CameraSpec,
        shading: Shading,
        ranges: Vec<Range<u32>>,
        dynamic: Range<u32>,
    ) -> ViewJob {
        ViewJob {
            slot,
            width: cam.width,
            height: cam.height,
            uniforms: self.uniforms(cam, shading),
            ranges,
            dynamic,
        }
    }

    /// The static ranges `cam` sees (`ranges_for`) split by instance id: each fixed body
    /// its own, the observer `OBSERVER`, the room shell `ROOM`.
    pub(super) fn id_ranges_for(&self, cam: &CameraSpec) -> Vec<(Range<u32>, u16)> {
        let mut out = Vec::new();
        for r in self.ranges_for(cam) {
            if r == self.fixed {
                out.extend(self.fixed_ids.iter().cloned());
            } else if r == self.observer {
                out.push((r, instance::OBSERVER));
            } else {
                out.push((r, instance::ROOM));
            }
        }
        out
    }

    /// The moving geometry uploaded at `dynamic` (from `dynamic_at`) split by instance id:
    /// each body its own, the ropes after them `ROPE`.
    pub(super) fn dynamic_ids(&self, dynamic: &Range<u32>) -> Vec<(Range<u32>, u16)> {
        let mut out = Vec::new();
        let mut at = dynamic.start;
        for d in &self.dynamic {
            let end = at + d.mesh.verts.len() as u32;
            out.push((at..end, d.id));
            at = end;
        }
        if at < dynamic.end {
            out.push((at..dynamic.end, instance::ROPE));
        }
        out
    }

    fn uniforms(&self, cam: &CameraSpec, shading: Shading) -> Uniforms {
        Uniforms {
            view_proj: view_proj(cam),
            light_vp: self.light_vp,
            cam_pos: [
                cam.position[0] as f32,
                cam.position[1] as f32,
                cam.position[2] as f32,
                1.0,
            ],
            sun_dir: self.sun_dir,
            sun_color: self.sun_color,
            ambient: [
                self.ambient[0],
                self.ambient[1],
                self.ambient[2],
                if shading == Shading::HazardMask {
                    1.0
                } else {
                    0.0
                },
            ],
            background: self.background,
            fill_rects: [[-1.0, -1.0, 1.0, 1.0]; gpu::MAX_REDRAW_RECTS],
        }
    }
}

fn object_look_mesh(
    catalog: &Catalog,
    id: &str,
    parts: &[rh_physics::spec::PartSpec],
) -> Option<Mesh> {
    let object = catalog.object(id)?;
    // A real mesh where the catalog names one (loaded once per process; a rendered build
    // checked every model before any work, so a failure here only reaches a caller that
    // did not: it draws the recipe and says why).
    match crate::models::drawn_mesh(catalog, object, parts, &crate::models::config()) {
        Ok(Some(m)) => return Some(m),
        Ok(None) => {}
        Err(e) => crate::models::warn_once(&e),
    }
    let source = catalog.appearance_source(object);
    let a = &source.appearance;
    let look = recipes::Look {
        recipe: &a.recipe,
        color: hex(&a.color),
        secondary: a.secondary_color.as_deref().map(hex),
        description: a.description.as_deref().unwrap_or(""),
        parts,
    };
    Some(recipes::object_mesh(&look))
}

/// How far behind the wall plane the room's walls are drawn. Fixtures stand flush
/// against a wall (a ladder's or a shelf's wall slab has its face on the plane), and two
/// coplanar faces z-fight into a hatched pattern; set back by 1 cm, the fixture's face is
/// drawn in front, and a 1 cm gap behind a flush face is invisible at any camera distance.
const WALL_SETBACK: f32 = 0.01;

/// The room's floor, four walls and ceiling, appended to `statics` (one piece each).
fn room_shell(
    room: &rh_physics::spec::RoomSpec,
    wall_c: Rgba,
    floor_c: Rgba,
    statics: &mut Vec<Vertex>,
    pieces: &mut Vec<Piece>,
) -> (Range<u32>, Vec<Wall>, Range<u32>) {
    // Room shell.
    let (hx, hy, ch) = (
        room.size[0] as f32 / 2.0,
        room.size[1] as f32 / 2.0,
        room.ceiling_height as f32,
    );
    let start = statics.len() as u32;
    let mut floor = Mesh::new();
    floor.boxy(
        &Xf::at([0.0, 0.0, -0.02]),
        [hx + WALL_SETBACK, hy + WALL_SETBACK, 0.02],
        1,
        &solid(floor_c),
    );
    floor.transformed_into(&Xf::ID, statics);
    let floor_r = start..statics.len() as u32;
    pieces.extend(piece(statics, start as usize));
    let mut walls = Vec::new();
    let skirting = shade(wall_c, 0.55);
    let wall_paint = move |p: V3| if p[2] < 0.1 { skirting } else { wall_c };
    for (axis, sign) in [(0usize, 1.0f64), (0, -1.0), (1, 1.0), (1, -1.0)] {
        let s = statics.len() as u32;
        let mut m = Mesh::new();
        let (half_len, pos) = if axis == 0 {
            (
                [0.02, hy + 0.04 + WALL_SETBACK, ch / 2.0],
                [sign as f32 * (hx + 0.02 + WALL_SETBACK), 0.0, ch / 2.0],
            )
        } else {
            (
                [hx + 0.04 + WALL_SETBACK, 0.02, ch / 2.0],
                [0.0, sign as f32 * (hy + 0.02 + WALL_SETBACK), ch / 2.0],
            )
        };
        // Paint in world coordinates: the box is axis-aligned, so local z + centre.
        let paint = move |p: V3| wall_paint([p[0], p[1], p[2] + ch / 2.0]);
        // 24 cells along the wall: 12 up its height, so the skirting stays a low band.
        m.boxy(&Xf::at(pos), half_len, 24, &paint);
        m.transformed_into(&Xf::ID, statics);
        pieces.extend(piece(statics, s as usize));
        walls.push(Wall {
            range: s..statics.len() as u32,
            axis,
            sign,
            limit: if axis == 0 { hx as f64 } else { hy as f64 },
        });
    }
    let s = statics.len() as u32;
    let mut ceil = Mesh::new();
    ceil.boxy(
        &Xf::at([0.0, 0.0, ch + 0.02]),
        [hx + WALL_SETBACK, hy + WALL_SETBACK, 0.02],
        1,
        &solid(hex("#f4f4f0")),
    );
    ceil.transformed_into(&Xf::ID, statics);
    let ceiling = s..statics.len() as u32;
    pieces.extend(piece(statics, s as usize));

    (floor_r, walls, ceiling)
}

/// The moving bodies, meshed once in their body frames, the ropes drawn between them,
/// and an upper bound of their vertices per frame.
fn moving_bodies(
    spec: &SceneSpec,
    sim: &Simulation,
    catalog: &Catalog,
) -> (Vec<DynamicBody>, Vec<Rope>, usize) {
    // Moving bodies, meshed once in their body frames.
    let mut dynamic = Vec::new();
    let mut max_dynamic = 0;
    for (slot, &bi) in sim.dynamic_bodies.iter().enumerate() {
        let body = &spec.bodies[bi];
        let mesh = body
            .catalog_id
            .as_deref()
            .and_then(|id| object_look_mesh(catalog, id, &body.parts))
            .unwrap_or_else(|| {
                let mut m = Mesh::new();
                let c = if body.name.contains("rod") || body.name.contains("rope") {
                    hex("#424242")
                } else {
                    hex("#5c6bc0")
                };
                recipes::parts_mesh(&mut m, &body.parts, c, c);
                m
            });
        max_dynamic += mesh.verts.len();
        dynamic.push(DynamicBody {
            slot,
            hazard: bi == spec.hazard,
            id: instance::body(bi),
            mesh,
        });
    }
    let slot_of = |bi: usize| sim.dynamic_bodies.iter().position(|&b| b == bi);
    let mut ropes = Vec::new();
    for j in &spec.joints {
        if !matches!(
            j.kind,
            JointKind::Rope { .. } | JointKind::Spherical | JointKind::Revolute { .. }
        ) {
            continue;
        }
        let Some(sb) = slot_of(j.body_b) else {
            continue;
        };
        let a = match j.body_a {
            None => (None, j.anchor_a),
            Some(ba) => match slot_of(ba) {
                Some(sa) => (Some(sa), j.anchor_a),
                None => {
                    let b = &spec.bodies[ba];
                    (
                        None,
                        add(
                            rh_physics::spec::quat::rotate(b.rotation, j.anchor_a),
                            b.position,
                        ),
                    )
                }
            },
        };
        ropes.push(Rope {
            a,
            b: (sb, j.anchor_b),
        });
    }
    max_dynamic += ropes.len() * 200;
    (dynamic, ropes, max_dynamic)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn object_parts(catalog: &Catalog, id: &str) -> Vec<rh_physics::spec::PartSpec> {
        rh_scenes::families::object_parts(catalog.object(id).unwrap())
    }

    #[test]
    fn every_catalog_object_meshes_and_every_recipe_in_use_is_specific() {
        let catalog = Catalog::embedded().unwrap();
        for o in catalog.objects.iter() {
            let parts = object_parts(&catalog, &o.id);
            let mesh = object_look_mesh(&catalog, &o.id, &parts).unwrap();
            assert!(!mesh.verts.is_empty(), "{}", o.id);
            assert!(
                mesh.verts
                    .iter()
                    .all(|v| v.pos.iter().all(|c| c.is_finite())),
                "{}",
                o.id
            );
            assert!(
                recipes::is_specific(&o.appearance.recipe),
                "{}: recipe '{}' falls back to plain parts",
                o.id,
                o.appearance.recipe
            );
        }
    }

    #[test]
    fn adversarial_objects_render_exactly_like_their_look_alike() {
        let catalog = Catalog::embedded().unwrap();
        let mut n = 0;
        for o in catalog.objects.iter().filter(|o| o.is_adversarial()) {
            let twin = o.looks_like.as_deref().unwrap();
            let a = object_look_mesh(&catalog, &o.id, &object_parts(&catalog, &o.id)).unwrap();
            let b = object_look_mesh(&catalog, twin, &object_parts(&catalog, twin)).unwrap();
            assert_eq!(
                bytemuck::cast_slice::<Vertex, u8>(&a.verts),
                bytemuck::cast_slice::<Vertex, u8>(&b.verts),
                "{} vs {twin}",
                o.id
            );
            n += 1;
        }
        assert!(n >= 14);
    }

    #[test]
    fn unknown_recipes_fall_back_to_the_collision_parts() {
        let parts = vec![rh_physics::spec::PartSpec {
            shape: rh_physics::spec::ShapeSpec::Sphere { radius: 0.1 },
            offset: [0.0; 3],
            rotation: rh_physics::spec::IDENTITY,
        }];
        let look = recipes::Look {
            recipe: "no_such_recipe",
            color: hex("#ff0000"),
            secondary: None,
            description: "",
            parts: &parts,
        };
        assert!(!recipes::object_mesh(&look).verts.is_empty());
    }
}
