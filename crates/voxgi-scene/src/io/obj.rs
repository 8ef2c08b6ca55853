//! Wavefront OBJ + MTL, through `tobj` (triangulated, single index).
//!
//! One [`Mesh`] per tobj model (tobj splits at `o`, `g` and `usemtl`), one static instance each.
//! MTL mapping: `Kd` → base colour, `Ke` → emission, `map_Kd` / `map_Ke` → textures (paths
//! relative to the MTL file), `d` or `Tr` → alpha, `Ns` → roughness `sqrt(2 / (Ns + 2))` (the
//! usual Phong-exponent to microfacet-width mapping, Walter et al. 2007).
//! A missing or broken MTL is a warning, not an error: the geometry still loads with defaults.
//! OBJ texture coordinates have their origin bottom-left; we flip v to the model's top-left.

use crate::{
    AlphaMode, Instance, Material, Mesh, Result, Scene, SceneError, Texture, compute_normals,
    limits,
};
use glam::{Mat4, Vec2, Vec3};
use std::cell::RefCell;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

pub fn load(path: &Path) -> Result<Scene> {
    let bytes = super::source::read(path).map_err(|e| SceneError::load(path, e))?;
    let dir = path.parent().unwrap_or(Path::new(".")).to_path_buf();
    let mtl_dirs: RefCell<Vec<PathBuf>> = RefCell::new(Vec::new());
    let opts = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        // Otherwise tobj turns `l` and `p` elements into degenerate triangles.
        ignore_lines: true,
        ignore_points: true,
    };
    let (models, materials) = tobj::load_obj_buf(&mut bytes.as_slice(), &opts, |mtl| {
        let p = dir.join(mtl);
        let r = super::source::read(&p)
            .map_err(|_| tobj::LoadError::OpenFileFailed)
            .and_then(|b| tobj::load_mtl_buf(&mut b.as_slice()));
        match &r {
            Ok(_) => mtl_dirs
                .borrow_mut()
                .push(p.parent().unwrap_or(&dir).to_path_buf()),
            Err(e) => log::warn!(
                "{}: material library {} not loaded ({e}); using default materials",
                path.display(),
                p.display()
            ),
        }
        r
    })
    .map_err(|e| SceneError::load(path, describe_obj_error(&bytes, e)))?;
    let materials = materials.unwrap_or_else(|e| {
        // Already warned in the loader closure when the file itself failed.
        log::debug!("{}: no materials ({e})", path.display());
        Vec::new()
    });
    let tex_dir = mtl_dirs.borrow().first().cloned().unwrap_or(dir.clone());

    let mut scene = Scene {
        name: path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "obj".into()),
        ..Default::default()
    };
    let mut tex_cache: HashMap<PathBuf, Option<usize>> = HashMap::new();
    for m in &materials {
        let mat = convert_material(m, &tex_dir, &dir, &mut scene.textures, &mut tex_cache);
        scene.materials.push(mat);
    }
    let mut default_mat = None;
    for model in models {
        let m = model.mesh;
        if m.indices.len() < 3 {
            continue;
        }
        let n = m.positions.len() / 3;
        if n > limits::MAX_ELEMENTS {
            return Err(SceneError::load(
                path,
                format!(
                    "object '{}' has {n} vertices, more than the limit",
                    model.name
                ),
            ));
        }
        let positions: Vec<Vec3> = m
            .positions
            .chunks_exact(3)
            .map(|c| Vec3::new(c[0], c[1], c[2]))
            .collect();
        if let Some(i) = positions.iter().position(|p| !p.is_finite()) {
            return Err(SceneError::load(
                path,
                format!("object '{}': vertex {i} is not finite", model.name),
            ));
        }
        let indices = m.indices;
        let normals = if m.normals.len() == m.positions.len() {
            let computed = compute_normals(&positions, &indices);
            m.normals
                .chunks_exact(3)
                .zip(computed)
                .map(|(c, fallback)| {
                    Vec3::new(c[0], c[1], c[2])
                        .try_normalize()
                        .unwrap_or(fallback)
                })
                .collect()
        } else {
            compute_normals(&positions, &indices)
        };
        let uvs = if m.texcoords.len() == 2 * n {
            m.texcoords
                .chunks_exact(2)
                .map(|c| Vec2::new(c[0], 1.0 - c[1]))
                .collect()
        } else {
            Vec::new()
        };
        let material = match m.material_id.filter(|&i| i < scene.materials.len()) {
            Some(i) => i,
            None => *default_mat.get_or_insert_with(|| {
                scene.materials.push(Material::default());
                scene.materials.len() - 1
            }),
        };
        scene.meshes.push(Mesh {
            name: model.name.clone(),
            positions,
            normals,
            uvs,
            indices,
            material,
        });
        scene.instances.push(Instance {
            name: model.name,
            mesh: scene.meshes.len() - 1,
            transform: Mat4::IDENTITY,
            dynamic: false,
            light: None,
        });
    }
    if scene.meshes.is_empty() {
        return Err(SceneError::load(path, "contains no triangles"));
    }
    Ok(scene)
}

fn convert_material(
    m: &tobj::Material,
    tex_dir: &Path,
    obj_dir: &Path,
    textures: &mut Vec<Texture>,
    cache: &mut HashMap<PathBuf, Option<usize>>,
) -> Material {
    let mut mat = Material {
        name: m.name.clone(),
        ..Default::default()
    };
    // Kept as written: `Scene::validate` refuses NaN, negative and too-bright values,
    // naming the material, as it does for glTF's.
    if let Some(kd) = m.diffuse {
        mat.base_color = [kd[0], kd[1], kd[2], 1.0];
    }
    if let Some(ke) = m.emissive {
        mat.emissive = ke;
    }
    let alpha = m.dissolve.or_else(|| {
        m.unknown_param
            .get("Tr")
            .and_then(|t| t.trim().parse::<f32>().ok())
            .map(|t| 1.0 - t)
    });
    if let Some(a) = alpha.filter(|a| a.is_finite()) {
        mat.base_color[3] = a.clamp(0.0, 1.0);
        if a < 1.0 {
            mat.alpha_mode = AlphaMode::Blend;
        }
    }
    if let Some(ns) = m.shininess.filter(|s| s.is_finite() && *s >= 0.0) {
        mat.roughness = (2.0 / (ns + 2.0)).sqrt();
    }
    let mut texture = |name: &str| -> Option<usize> {
        // Options such as `-bm 1` may precede the file name; the name is the last word.
        let file = name.split_whitespace().last()?.replace('\\', "/");
        let mut p = tex_dir.join(&file);
        if !super::source::is_file(&p) && super::source::is_file(&obj_dir.join(&file)) {
            p = obj_dir.join(&file);
        }
        *cache
            .entry(p.clone())
            .or_insert_with(|| match load_texture(&p) {
                Ok(t) => {
                    textures.push(t);
                    Some(textures.len() - 1)
                }
                Err(e) => {
                    log::warn!("texture {} not loaded: {e}", p.display());
                    None
                }
            })
    };
    if let Some(t) = &m.diffuse_texture {
        mat.base_color_texture = texture(t);
    }
    if let Some(t) = m.unknown_param.get("map_Ke") {
        mat.emissive_texture = texture(t);
        // A texture multiplies `emissive`; a map without Ke means "emit the texture".
        if mat.emissive_texture.is_some() && !mat.is_emissive() {
            mat.emissive = [1.0; 3];
        }
    }
    mat
}

/// Decodes an image file to RGBA8 (sRGB values kept as they are).
pub fn load_texture(p: &Path) -> std::result::Result<Texture, String> {
    let bytes = super::source::read(p).map_err(|e| e.to_string())?;
    let name = p
        .file_name()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    super::texture::decode(&bytes, name)
}

/// tobj's errors carry no line numbers; for index errors find the offending line ourselves.
fn describe_obj_error(bytes: &[u8], e: tobj::LoadError) -> String {
    if e == tobj::LoadError::FaceVertexOutOfBounds {
        let text = String::from_utf8_lossy(bytes);
        let (mut nv, mut nt, mut nn) = (0i64, 0i64, 0i64);
        for (i, line) in text.lines().enumerate() {
            let mut w = line.split_whitespace();
            match w.next() {
                Some("v") => nv += 1,
                Some("vt") => nt += 1,
                Some("vn") => nn += 1,
                Some("f") => {
                    for vert in w {
                        for (k, part) in vert.split('/').enumerate() {
                            let Ok(ix) = part.parse::<i64>() else {
                                continue;
                            };
                            let count = [nv, nt, nn][k.min(2)];
                            let ok = if ix > 0 { ix <= count } else { -ix <= count };
                            if !ok || ix == 0 {
                                let (kind, plural) = [
                                    ("vertex", "vertices"),
                                    ("texture coordinate", "texture coordinates"),
                                    ("normal", "normals"),
                                ][k.min(2)];
                                return format!(
                                    "line {}: face {kind} index {ix} out of range ({count} {plural} defined before it)",
                                    i + 1
                                );
                            }
                        }
                    }
                }
                _ => {}
            }
        }
        return "face index out of range".into();
    }
    format!("cannot parse OBJ: {e}")
}
