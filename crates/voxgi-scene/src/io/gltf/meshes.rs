//! Materials, meshes, accessors and primitives: the document's materials and mesh primitives
//! into the scene, the bounds and type checks every accessor passes before the `gltf` readers
//! touch it, and a primitive's attributes and indices read into a [`Mesh`].

use super::R;
use super::buffers::view_bytes;
use crate::{AlphaMode, Material, Mesh, Scene, compute_normals, limits};
use glam::{Vec2, Vec3};
use gltf::accessor::{DataType, Dimensions};
use gltf::mesh::Mode;
use std::path::Path;

/// The document's materials into `scene.materials`, in the document's order (so a
/// primitive's material index is the scene's).
pub(super) fn load_materials(doc: &gltf::Document, scene: &mut Scene) {
    let image_of = |t: gltf::texture::Texture| t.source().index();
    for m in doc.materials() {
        let pbr = m.pbr_metallic_roughness();
        let strength = m.emissive_strength().unwrap_or(1.0);
        let e = m.emissive_factor();
        scene.materials.push(Material {
            name: m
                .name()
                .map(str::to_string)
                .unwrap_or_else(|| format!("material {}", m.index().unwrap_or(0))),
            base_color: pbr.base_color_factor(),
            base_color_texture: pbr.base_color_texture().map(|i| image_of(i.texture())),
            emissive: [e[0] * strength, e[1] * strength, e[2] * strength],
            emissive_texture: m.emissive_texture().map(|i| image_of(i.texture())),
            roughness: pbr.roughness_factor(),
            metallic: pbr.metallic_factor(),
            // KHR_materials_specular is not read: glTF's default specular factor is 1.
            specular: 1.0,
            alpha_mode: match m.alpha_mode() {
                gltf::material::AlphaMode::Opaque => AlphaMode::Opaque,
                gltf::material::AlphaMode::Mask => AlphaMode::Mask(m.alpha_cutoff().unwrap_or(0.5)),
                gltf::material::AlphaMode::Blend => AlphaMode::Blend,
            },
            double_sided: m.double_sided(),
        });
    }
}

/// Every mesh primitive into `scene.meshes` (a primitive without a material gets one default
/// material, added on first use); returns, per glTF mesh and primitive, the index into
/// `scene.meshes`, `None` for skipped primitives. `path` names the file in warnings.
pub(super) fn load_meshes(
    doc: &gltf::Document,
    buffers: &[Vec<u8>],
    path: &Path,
    scene: &mut Scene,
) -> R<Vec<Vec<Option<usize>>>> {
    let mut default_material = None;

    let mut prim_map: Vec<Vec<Option<usize>>> = Vec::new();
    for gmesh in doc.meshes() {
        if gmesh
            .primitives()
            .any(|p| p.morph_targets().next().is_some())
        {
            log::warn!(
                "{}: mesh {} '{}' has morph targets; it is drawn in its base shape (morph targets \
                 are not supported)",
                path.display(),
                gmesh.index(),
                gmesh.name().unwrap_or("")
            );
        }
        let nprims = gmesh.primitives().len();
        let mut row = Vec::with_capacity(nprims);
        for prim in gmesh.primitives() {
            let what = format!("mesh {} primitive {}", gmesh.index(), prim.index());
            let Some(mut mesh) = load_primitive(&prim, buffers, &what)? else {
                row.push(None);
                continue;
            };
            let base_name = gmesh
                .name()
                .map(str::to_string)
                .unwrap_or_else(|| format!("mesh {}", gmesh.index()));
            mesh.name = if nprims > 1 {
                format!("{base_name} primitive {}", prim.index())
            } else {
                base_name
            };
            mesh.material = match prim.material().index() {
                Some(i) => i,
                None => *default_material.get_or_insert_with(|| {
                    scene.materials.push(Material::default());
                    scene.materials.len() - 1
                }),
            };
            scene.meshes.push(mesh);
            row.push(Some(scene.meshes.len() - 1));
        }
        prim_map.push(row);
    }
    Ok(prim_map)
}

/// Checks that reading `count` elements of `acc` stays inside its buffer view and buffer, and
/// that its type is one of `allowed`, so the `gltf` readers can neither panic nor read short.
pub(super) fn check_accessor(
    acc: &gltf::Accessor,
    buffers: &[Vec<u8>],
    allowed: &[(DataType, Dimensions)],
    what: &str,
) -> R<()> {
    let ai = acc.index();
    if !allowed
        .iter()
        .any(|&(t, d)| t == acc.data_type() && d == acc.dimensions())
    {
        return Err(format!(
            "accessor {ai} ({what}): type {:?} {:?} is not allowed here",
            acc.dimensions(),
            acc.data_type()
        ));
    }
    let count = acc.count();
    if count == 0 {
        return Err(format!("accessor {ai} ({what}): count is 0"));
    }
    if count > limits::MAX_ELEMENTS {
        return Err(format!(
            "accessor {ai} ({what}): count {count} exceeds the limit of {}",
            limits::MAX_ELEMENTS
        ));
    }
    let size = acc.size();
    // Bytes needed for `n` elements `stride` apart, starting at `offset` inside `view`.
    let fits = |view: &gltf::buffer::View, offset: usize, n: usize, elem: usize, label: &str| {
        let data = view_bytes(view, buffers).map_err(|e| format!("accessor {ai}: {e}"))?;
        let stride = view.stride().unwrap_or(elem);
        if stride < elem {
            return Err(format!(
                "accessor {ai} ({what}): buffer view {} has byteStride {stride}, less than the \
                 element size {elem}",
                view.index()
            ));
        }
        let need = stride
            .checked_mul(n - 1)
            .and_then(|x| x.checked_add(elem))
            .and_then(|x| x.checked_add(offset));
        match need {
            Some(need) if need <= data.len() => Ok(()),
            _ => Err(format!(
                "accessor {ai} ({what}): {label}{n} elements of {elem} bytes (stride {stride}) \
                 from offset {offset} need more than the {} bytes of buffer view {}",
                data.len(),
                view.index()
            )),
        }
    };
    if let Some(view) = acc.view() {
        fits(&view, acc.offset(), count, size, "")?;
    }
    if let Some(sparse) = acc.sparse() {
        let n = sparse.count();
        if n == 0 || n > count {
            return Err(format!(
                "accessor {ai} ({what}): sparse count {n} must be in 1..={count}"
            ));
        }
        let idx = sparse.indices();
        fits(
            &idx.view(),
            idx.offset(),
            n,
            idx.index_type().size(),
            "sparse indices: ",
        )?;
        let vals = sparse.values();
        fits(&vals.view(), vals.offset(), n, size, "sparse values: ")?;
    }
    Ok(())
}

/// Reads an accessor through `read`, falling back to zeros when it has no data (allowed by the
/// spec for accessors without a buffer view), and checks that the element count came out right.
pub(super) fn collect<T: Default + Clone, I: Iterator<Item = T>>(
    acc: &gltf::Accessor,
    iter: Option<I>,
    what: &str,
) -> R<Vec<T>> {
    let n = acc.count();
    let v: Vec<T> = match iter {
        Some(it) => it.take(n).collect(),
        None => vec![T::default(); n],
    };
    if v.len() != n {
        return Err(format!(
            "accessor {} ({what}): read {} of {n} elements",
            acc.index(),
            v.len()
        ));
    }
    Ok(v)
}

fn load_primitive(prim: &gltf::Primitive, buffers: &[Vec<u8>], what: &str) -> R<Option<Mesh>> {
    let mode = prim.mode();
    if !matches!(
        mode,
        Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan
    ) {
        log::warn!("{what}: skipping {mode:?} primitive (only triangles are rendered)");
        return Ok(None);
    }
    let f32x3 = [(DataType::F32, Dimensions::Vec3)];
    let pos_acc = prim
        .get(&gltf::Semantic::Positions)
        .ok_or_else(|| format!("{what}: no POSITION attribute"))?;
    check_accessor(&pos_acc, buffers, &f32x3, "POSITION")?;
    let reader = prim.reader(|b| buffers.get(b.index()).map(|v| v.as_slice()));
    let positions: Vec<Vec3> = collect(
        &pos_acc,
        reader.read_positions().map(|it| it.map(Vec3::from)),
        "POSITION",
    )?;
    let n = positions.len();
    if let Some(p) = positions.iter().position(|p| !p.is_finite()) {
        return Err(format!(
            "accessor {} (POSITION): vertex {p} is not finite",
            pos_acc.index()
        ));
    }

    let raw_indices: Vec<u32> = match prim.indices() {
        Some(acc) => {
            check_accessor(
                &acc,
                buffers,
                &[
                    (DataType::U8, Dimensions::Scalar),
                    (DataType::U16, Dimensions::Scalar),
                    (DataType::U32, Dimensions::Scalar),
                ],
                "indices",
            )?;
            let v = collect(&acc, reader.read_indices().map(|r| r.into_u32()), "indices")?;
            if let Some(&bad) = v.iter().find(|&&i| i as usize >= n) {
                return Err(format!(
                    "accessor {}: index {bad} out of range for {n} vertices",
                    acc.index()
                ));
            }
            v
        }
        None => (0..n as u32).collect(),
    };
    let indices = match mode {
        Mode::Triangles => {
            if !raw_indices.len().is_multiple_of(3) {
                return Err(format!(
                    "{what}: {} indices is not a multiple of 3",
                    raw_indices.len()
                ));
            }
            raw_indices
        }
        Mode::TriangleStrip => {
            let mut out = Vec::with_capacity(raw_indices.len().saturating_sub(2) * 3);
            for (k, w) in raw_indices.windows(3).enumerate() {
                // Every other triangle of a strip swaps its first two vertices to keep winding.
                if k % 2 == 0 {
                    out.extend_from_slice(&[w[0], w[1], w[2]]);
                } else {
                    out.extend_from_slice(&[w[1], w[0], w[2]]);
                }
            }
            out
        }
        _ => {
            let mut out = Vec::with_capacity(raw_indices.len().saturating_sub(2) * 3);
            if let Some((&first, rest)) = raw_indices.split_first() {
                for w in rest.windows(2) {
                    out.extend_from_slice(&[first, w[0], w[1]]);
                }
            }
            out
        }
    };

    let normals = match prim.get(&gltf::Semantic::Normals) {
        Some(acc) => {
            check_accessor(&acc, buffers, &f32x3, "NORMAL")?;
            if acc.count() != n {
                return Err(format!(
                    "accessor {} (NORMAL): count {} differs from POSITION count {n}",
                    acc.index(),
                    acc.count()
                ));
            }
            let v: Vec<Vec3> = collect(
                &acc,
                reader.read_normals().map(|it| it.map(Vec3::from)),
                "NORMAL",
            )?;
            v.into_iter()
                .map(|v| v.try_normalize().unwrap_or(Vec3::Y))
                .collect()
        }
        None => compute_normals(&positions, &indices),
    };
    let uvs = match prim.get(&gltf::Semantic::TexCoords(0)) {
        Some(acc) => {
            check_accessor(
                &acc,
                buffers,
                &[
                    (DataType::F32, Dimensions::Vec2),
                    (DataType::U8, Dimensions::Vec2),
                    (DataType::U16, Dimensions::Vec2),
                ],
                "TEXCOORD_0",
            )?;
            if acc.count() != n {
                return Err(format!(
                    "accessor {} (TEXCOORD_0): count {} differs from POSITION count {n}",
                    acc.index(),
                    acc.count()
                ));
            }
            collect(
                &acc,
                reader
                    .read_tex_coords(0)
                    .map(|r| r.into_f32().map(Vec2::from)),
                "TEXCOORD_0",
            )?
        }
        None => Vec::new(),
    };
    Ok(Some(Mesh {
        name: String::new(),
        positions,
        normals,
        uvs,
        indices,
        material: 0,
    }))
}
