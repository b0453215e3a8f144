//! Reading one model: the archive (ZIP), the OBJ file and its hash, its MTL materials
//! and textures (`tobj`, `image`), the triangle budget (`meshopt`), and the turn into the
//! catalog object frame.

use super::{package_of, texture_layer, ModelError, TextureImage};
use crate::mesh::{mat, mix, srgb_to_linear, Mesh, Rgba, Vertex, MAT_GLOSSY, MAT_PLAIN, V3};
use rh_catalog::models::{ModelConfig, ModelRef};
use sha2::{Digest, Sha256};
use std::collections::BTreeMap;
use std::io::Read;

/// Material codes of textured vertices: `color` is then `[u, v, layer, code]` and the
/// shader samples the texture array (see shader.wgsl).
pub const MAT_TEXTURED: f32 = 4.0;
pub const MAT_TEXTURED_GLOSSY: f32 = 5.0;

/// A model as loaded: triangles in the catalog object frame (the package's axis
/// convention and the entry's rotation applied), in the model's own units, not yet
/// fitted to any parts.
#[derive(Debug, Clone)]
pub struct LoadedModel {
    pub mesh: Mesh,
    pub lo: V3,
    pub hi: V3,
    /// Triangles drawn, and in the file (of the selected object).
    pub triangles: usize,
    pub source_triangles: usize,
    /// Texture layers the mesh samples.
    pub textures: Vec<u32>,
}

type Zip = zip::ZipArchive<std::io::BufReader<std::fs::File>>;

fn read_entry(zip: &mut Zip, name: &str, archive: &str) -> Result<Vec<u8>, ModelError> {
    let bad = |message: String| ModelError::Bad {
        file: format!("{archive}:{name}"),
        message,
    };
    let mut f = zip
        .by_name(name)
        .map_err(|e| bad(format!("not in the archive ({e})")))?;
    let mut out = Vec::with_capacity(f.size() as usize);
    f.read_to_end(&mut out)
        .map_err(|e| bad(format!("cannot read: {e}")))?;
    Ok(out)
}

fn sha256_hex(bytes: &[u8]) -> String {
    Sha256::digest(bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

/// Opens the model's archive, checks the OBJ file's hash and returns the archive with
/// the OBJ bytes.
fn open(
    m: &ModelRef,
    entry: &str,
    config: &ModelConfig,
) -> Result<(Zip, Vec<u8>, String), ModelError> {
    let package = package_of(m)?;
    let root = config.root(package);
    if !root.is_dir() {
        return Err(ModelError::PackageMissing {
            package: package.name.to_string(),
            root,
            install: package.install.to_string(),
        });
    }
    let path = root.join(&m.archive);
    let label = path.display().to_string();
    let bad = |message: String| ModelError::Bad {
        file: label.clone(),
        message,
    };
    let file = std::fs::File::open(&path).map_err(|e| {
        bad(format!(
            "cannot open: {e} (is {} complete? `{}`)",
            package.name, package.install
        ))
    })?;
    let mut zip = zip::ZipArchive::new(std::io::BufReader::new(file))
        .map_err(|e| bad(format!("not a readable archive: {e}")))?;
    let obj = read_entry(&mut zip, &m.path, &label)?;
    let actual = sha256_hex(&obj);
    if actual != m.sha256 {
        return Err(ModelError::HashMismatch {
            file: format!("{label}:{}", m.path),
            entry: entry.to_string(),
            expected: m.sha256.clone(),
            actual,
        });
    }
    Ok((zip, obj, label))
}

/// The directory part of an archive path (`a/b/c.obj` → `a/b/`).
fn dir_of(path: &str) -> &str {
    path.rfind('/').map(|i| &path[..=i]).unwrap_or("")
}

/// The MTL files the OBJ names, read from the archive.
fn material_files(
    zip: &mut Zip,
    obj: &[u8],
    dir: &str,
    label: &str,
) -> Result<BTreeMap<String, Vec<u8>>, ModelError> {
    let mut out = BTreeMap::new();
    for line in String::from_utf8_lossy(obj).lines() {
        if let Some(name) = line.trim().strip_prefix("mtllib ") {
            let name = name.trim().to_string();
            let bytes = read_entry(zip, &format!("{dir}{name}"), label)?;
            out.insert(name, bytes);
        }
    }
    Ok(out)
}

/// How one material draws: a colour, or a texture layer; glossy or not.
#[derive(Clone, Copy)]
enum Surface {
    Color(Rgba),
    Texture { layer: u32, glossy: bool },
}

fn surface(
    material: Option<&tobj::Material>,
    zip: &mut Zip,
    dir: &str,
    label: &str,
    size: u32,
) -> Result<Surface, ModelError> {
    let Some(mtl) = material else {
        return Ok(Surface::Color([0.6, 0.6, 0.6, MAT_PLAIN]));
    };
    let shiny = mtl.shininess.unwrap_or(0.0) > 30.0
        && mtl.specular.is_some_and(|s| s.iter().any(|&c| c > 0.3));
    if let Some(tex) = mtl
        .diffuse_texture
        .as_deref()
        .filter(|t| !t.trim().is_empty())
    {
        let name = format!("{dir}{}", tex.trim());
        let key = format!("{label}:{name}");
        let layer = texture_layer(&key, || {
            let bytes = read_entry(zip, &name, label).map_err(|e| e.to_string())?;
            decode_texture(&bytes, size).map_err(|e| format!("{key}: {e}"))
        })
        .map_err(|message| ModelError::Bad {
            file: label.to_string(),
            message,
        })?;
        return Ok(Surface::Texture {
            layer,
            glossy: shiny,
        });
    }
    let kd = mtl.diffuse.unwrap_or([0.6, 0.6, 0.6]);
    let c = [
        srgb_to_linear(kd[0]),
        srgb_to_linear(kd[1]),
        srgb_to_linear(kd[2]),
        MAT_PLAIN,
    ];
    // Glass and other see-through materials: no blending here, so a light, glossy
    // surface reads as glass (the sky and walls a real one would show are bright).
    if mtl.dissolve.unwrap_or(1.0) < 0.9 {
        return Ok(Surface::Color(mat(
            mix(c, [0.85, 0.9, 0.95, 0.0], 0.6),
            MAT_GLOSSY,
        )));
    }
    Ok(Surface::Color(if shiny { mat(c, MAT_GLOSSY) } else { c }))
}

/// A texture file as `size`² sRGB RGBA8 (a deterministic resize: the same bytes in any
/// process).
pub fn decode_texture(bytes: &[u8], size: u32) -> Result<TextureImage, String> {
    let img = image::load_from_memory(bytes).map_err(|e| format!("cannot decode: {e}"))?;
    let rgba = image::imageops::resize(
        &img.to_rgba8(),
        size,
        size,
        image::imageops::FilterType::Triangle,
    );
    Ok(TextureImage {
        size,
        rgba: rgba.into_raw(),
    })
}

/// Sweet Home 3D's frame (y up, front +z) to the catalog's (z up, front +y).
fn convention(p: [f32; 3]) -> V3 {
    [-p[0], p[2], p[1]]
}

/// The entry's orientation fix: degrees about x, then y, then z.
fn rotation(deg: [f64; 3]) -> impl Fn(V3) -> V3 {
    move |mut p: V3| {
        for (axis, d) in deg.iter().enumerate() {
            if *d == 0.0 {
                continue;
            }
            let (s, c) = (d.to_radians() as f32).sin_cos();
            let (i, j) = [(1, 2), (2, 0), (0, 1)][axis];
            let (a, b) = (p[i], p[j]);
            p[i] = c * a - s * b;
            p[j] = s * a + c * b;
        }
        p
    }
}

/// Indexed triangles of all selected OBJ meshes, one vertex record each:
/// position, normal (zero when the file has none), colour.
#[derive(Default)]
struct Indexed {
    pos: Vec<[f32; 3]>,
    normal: Vec<[f32; 3]>,
    color: Vec<Rgba>,
    indices: Vec<u32>,
}

/// Loads model `m` of catalog entry `entry`: checks the package, the hash, reads the
/// meshes and materials, keeps the triangle budget and turns it into the catalog frame.
pub fn load_model(
    m: &ModelRef,
    entry: &str,
    config: &ModelConfig,
) -> Result<LoadedModel, ModelError> {
    let (mut zip, obj, label) = open(m, entry, config)?;
    let dir = dir_of(&m.path).to_string();
    let file = format!("{label}:{}", m.path);
    let bad = |message: String| ModelError::Bad {
        file: file.clone(),
        message,
    };
    let mtls = material_files(&mut zip, &obj, &dir, &label)?;
    let options = tobj::LoadOptions {
        single_index: true,
        triangulate: true,
        ignore_points: true,
        ignore_lines: true,
        ..Default::default()
    };
    let (meshes, materials) = tobj::load_obj_buf(&mut &obj[..], &options, |p| {
        let name = p.to_string_lossy().to_string();
        match mtls.get(&name) {
            Some(bytes) => tobj::load_mtl_buf(&mut &bytes[..]),
            None => Err(tobj::LoadError::OpenFileFailed),
        }
    })
    .map_err(|e| bad(format!("not a readable OBJ file: {e}")))?;
    let materials = materials.map_err(|e| bad(format!("its materials: {e}")))?;
    let mut ix = Indexed::default();
    let mut source_triangles = 0;
    let mut textures = Vec::new();
    let turn = rotation(m.rotation);
    for model in meshes
        .iter()
        .filter(|x| m.object.as_ref().is_none_or(|o| &x.name == o))
    {
        let mesh = &model.mesh;
        let s = surface(
            mesh.material_id.and_then(|i| materials.get(i)),
            &mut zip,
            &dir,
            &label,
            config.texture_size,
        )?;
        if let Surface::Texture { layer, .. } = s {
            textures.push(layer);
        }
        append_mesh(&mut ix, mesh, s, &turn);
        source_triangles += mesh.indices.len() / 3;
    }
    if ix.indices.is_empty() {
        return Err(bad(match &m.object {
            Some(o) => format!("no triangles in object '{o}'"),
            None => "no triangles".into(),
        }));
    }
    let indices = simplify(&ix, config.triangle_budget);
    textures.sort_unstable();
    textures.dedup();
    Ok(soup(&ix, &indices, source_triangles, textures))
}

fn append_mesh(ix: &mut Indexed, mesh: &tobj::Mesh, s: Surface, turn: &impl Fn(V3) -> V3) {
    let base = ix.pos.len() as u32;
    let n = mesh.positions.len() / 3;
    for i in 0..n {
        let p = [
            mesh.positions[3 * i],
            mesh.positions[3 * i + 1],
            mesh.positions[3 * i + 2],
        ];
        ix.pos.push(turn(convention(p)));
        let nn = if mesh.normals.len() >= 3 * (i + 1) {
            turn(convention([
                mesh.normals[3 * i],
                mesh.normals[3 * i + 1],
                mesh.normals[3 * i + 2],
            ]))
        } else {
            [0.0; 3]
        };
        ix.normal.push(nn);
        ix.color.push(match s {
            Surface::Color(c) => c,
            Surface::Texture { layer, glossy } => {
                let (u, v) = if mesh.texcoords.len() >= 2 * (i + 1) {
                    (mesh.texcoords[2 * i], 1.0 - mesh.texcoords[2 * i + 1])
                } else {
                    (0.5, 0.5)
                };
                let code = if glossy {
                    MAT_TEXTURED_GLOSSY
                } else {
                    MAT_TEXTURED
                };
                [u, v, layer as f32, code]
            }
        });
    }
    ix.indices.extend(mesh.indices.iter().map(|&i| base + i));
}

/// Indices within the triangle budget: meshopt's simplifier at growing error limits,
/// its sloppy one as the last resort.
fn simplify(ix: &Indexed, budget: usize) -> Vec<u32> {
    let budget = budget.max(1);
    if ix.indices.len() / 3 <= budget {
        return ix.indices.clone();
    }
    let bytes: &[u8] = bytemuck::cast_slice(&ix.pos);
    let Ok(adapter) = meshopt::VertexDataAdapter::new(bytes, 12, 0) else {
        return ix.indices.clone();
    };
    for error in [0.01, 0.05, 0.2] {
        let out = meshopt::simplify(
            &ix.indices,
            &adapter,
            budget * 3,
            error,
            meshopt::SimplifyOptions::None,
            None,
        );
        if out.len() / 3 <= budget && !out.is_empty() {
            return out;
        }
    }
    let out = meshopt::simplify_sloppy(&ix.indices, &adapter, budget * 3, 1.0, None);
    if out.is_empty() {
        ix.indices.clone()
    } else {
        out
    }
}

/// The triangle soup of `indices` with its bounds; flat normals where the file has none.
fn soup(ix: &Indexed, indices: &[u32], source_triangles: usize, textures: Vec<u32>) -> LoadedModel {
    let mut verts = Vec::with_capacity(indices.len());
    let mut lo = [f32::MAX; 3];
    let mut hi = [f32::MIN; 3];
    for t in indices.chunks_exact(3) {
        let p = [0, 1, 2].map(|k| ix.pos[t[k] as usize]);
        let e1 = [p[1][0] - p[0][0], p[1][1] - p[0][1], p[1][2] - p[0][2]];
        let e2 = [p[2][0] - p[0][0], p[2][1] - p[0][1], p[2][2] - p[0][2]];
        let flat = normalize([
            e1[1] * e2[2] - e1[2] * e2[1],
            e1[2] * e2[0] - e1[0] * e2[2],
            e1[0] * e2[1] - e1[1] * e2[0],
        ]);
        for k in 0..3 {
            let i = t[k] as usize;
            let n = ix.normal[i];
            let n = if n == [0.0; 3] { flat } else { normalize(n) };
            for a in 0..3 {
                lo[a] = lo[a].min(p[k][a]);
                hi[a] = hi[a].max(p[k][a]);
            }
            verts.push(Vertex {
                pos: p[k],
                normal: n,
                color: ix.color[i],
            });
        }
    }
    LoadedModel {
        triangles: verts.len() / 3,
        mesh: Mesh { verts },
        lo,
        hi,
        source_triangles,
        textures,
    }
}

fn normalize(v: V3) -> V3 {
    let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    if l > 1e-12 {
        [v[0] / l, v[1] / l, v[2] / l]
    } else {
        [0.0, 0.0, 1.0]
    }
}
