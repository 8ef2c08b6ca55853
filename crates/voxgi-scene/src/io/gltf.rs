//! glTF 2.0 loader (`.gltf` with external or data-URI resources, and `.glb`).
//!
//! The `gltf` crate parses and validates the JSON; buffers and images are resolved here so that
//! errors can name the resource that is wrong. Every accessor is checked against its buffer view
//! and buffer before the `gltf` readers touch it, because those readers assume well-formed data
//! (they `unreachable!()` on unexpected component types and slice with unchecked arithmetic).

use crate::{
    AlphaMode, Camera, Instance, Light, LightKind, Material, Mesh, Projection, Result, Scene,
    SceneError, Texture, compute_normals, limits,
};
use glam::{Mat4, Quat, Vec2, Vec3};
use gltf::accessor::{DataType, Dimensions};
use gltf::mesh::Mode;
use std::path::Path;

/// Internal result: the reason string, turned into `SceneError::load(path, reason)` at the top.
type R<T> = std::result::Result<T, String>;

/// Loads a `.gltf` or `.glb` file into a validated [`Scene`].
pub fn load(path: &Path) -> Result<Scene> {
    let bytes = std::fs::read(path).map_err(|e| SceneError::load(path, io_reason(&e)))?;
    // The loader checks everything it hands to the `gltf` crate, but a panic in a dependency on
    // a hostile file must still come back as an error, not abort the caller.
    let outcome =
        std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| load_bytes(path, &bytes)));
    let scene = match outcome {
        Ok(Ok(scene)) => scene,
        Ok(Err(reason)) => return Err(SceneError::load(path, reason)),
        Err(panic) => {
            let msg = panic
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| panic.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "unknown panic".into());
            return Err(SceneError::load(
                path,
                format!("malformed glTF (the glTF parser failed: {msg})"),
            ));
        }
    };
    scene.validate().map_err(|e| e.in_file(path))?;
    Ok(scene)
}

fn io_reason(e: &std::io::Error) -> String {
    match e.kind() {
        std::io::ErrorKind::NotFound => "no such file".into(),
        _ => e.to_string(),
    }
}

fn load_bytes(path: &Path, bytes: &[u8]) -> R<Scene> {
    if bytes.is_empty() {
        return Err("empty file".into());
    }
    let is_glb = bytes.starts_with(b"glTF");
    let gltf = gltf::Gltf::from_slice_without_validation(bytes).map_err(|e| {
        if is_glb {
            format!("invalid binary glTF: {e}")
        } else if path
            .extension()
            .is_some_and(|x| x.eq_ignore_ascii_case("glb"))
        {
            format!("not a binary glTF (no 'glTF' magic) and not glTF JSON either: {e}")
        } else {
            format!("invalid glTF: {e}")
        }
    })?;
    let doc = &gltf.document;
    validate_json(doc.as_json())?;
    let base = path.parent().unwrap_or(Path::new("."));
    let buffers = load_buffers(doc, base, gltf.blob.as_deref())?;

    let mut scene = Scene {
        name: path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default(),
        ..Default::default()
    };

    for image in doc.images() {
        scene.textures.push(load_image(&image, base, &buffers)?);
    }
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
    let mut default_material = None;

    // (glTF mesh, primitive) -> index into scene.meshes, None for skipped primitives.
    let mut prim_map: Vec<Vec<Option<usize>>> = Vec::new();
    for gmesh in doc.meshes() {
        let nprims = gmesh.primitives().len();
        let mut row = Vec::with_capacity(nprims);
        for prim in gmesh.primitives() {
            let what = format!("mesh {} primitive {}", gmesh.index(), prim.index());
            let Some(mut mesh) = load_primitive(&prim, &buffers, &what)? else {
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

    let Some(gscene) = doc.default_scene().or_else(|| doc.scenes().next()) else {
        log::warn!(
            "{}: the file has no scenes; nothing is placed",
            path.display()
        );
        return Ok(scene);
    };

    // Depth-first over the default scene with an explicit stack; a node reached twice means a
    // cycle or a shared child, which glTF forbids (and which would otherwise never terminate).
    let mut visited = vec![false; doc.nodes().len()];
    let mut stack: Vec<(gltf::Node, Mat4)> = gscene
        .nodes()
        .map(|n| (n, Mat4::IDENTITY))
        .collect::<Vec<_>>();
    stack.reverse();
    let mut cameras: Vec<(usize, Camera)> = Vec::new();
    while let Some((node, parent)) = stack.pop() {
        let ni = node.index();
        if std::mem::replace(&mut visited[ni], true) {
            return Err(format!(
                "node {ni} is reached twice in scene {} (the node hierarchy must be a tree)",
                gscene.index()
            ));
        }
        let world = parent * local_transform(&node);
        if !world.is_finite() {
            return Err(format!("node {ni}: non-finite transform"));
        }
        let node_name = node
            .name()
            .map(str::to_string)
            .unwrap_or_else(|| format!("node {ni}"));
        if let Some(gmesh) = node.mesh() {
            for &mesh in prim_map[gmesh.index()].iter().flatten() {
                scene.instances.push(Instance {
                    name: node_name.clone(),
                    mesh,
                    transform: world,
                    dynamic: false,
                    light: None,
                });
            }
        }
        let position = world.transform_point3(Vec3::ZERO);
        let forward = world
            .transform_vector3(Vec3::NEG_Z)
            .try_normalize()
            .unwrap_or(Vec3::NEG_Z);
        if let Some(l) = node.light() {
            let kind = match l.kind() {
                gltf::khr_lights_punctual::Kind::Directional => LightKind::Directional,
                gltf::khr_lights_punctual::Kind::Point => LightKind::Point,
                gltf::khr_lights_punctual::Kind::Spot {
                    inner_cone_angle,
                    outer_cone_angle,
                } => LightKind::Spot {
                    inner_angle: inner_cone_angle,
                    outer_angle: outer_cone_angle,
                },
            };
            scene.lights.push(Light {
                name: l
                    .name()
                    .map(str::to_string)
                    .unwrap_or_else(|| node_name.clone()),
                kind,
                color: l.color(),
                intensity: l.intensity(),
                position,
                direction: forward,
                range: l.range(),
                cast_shadows: true,
            });
        }
        if let Some(c) = node.camera() {
            let up = world.transform_vector3(Vec3::Y);
            let up = (up - forward * up.dot(forward))
                .try_normalize()
                .unwrap_or_else(|| forward.any_orthonormal_vector());
            let (projection, znear, zfar, aspect) = match c.projection() {
                gltf::camera::Projection::Perspective(p) => (
                    Projection::Perspective { yfov: p.yfov() },
                    p.znear(),
                    p.zfar(),
                    p.aspect_ratio(),
                ),
                gltf::camera::Projection::Orthographic(o) => (
                    Projection::Orthographic {
                        xmag: o.xmag(),
                        ymag: o.ymag(),
                    },
                    o.znear(),
                    Some(o.zfar()),
                    None,
                ),
            };
            cameras.push((
                ni,
                Camera {
                    name: c
                        .name()
                        .map(str::to_string)
                        .unwrap_or_else(|| node_name.clone()),
                    position,
                    forward,
                    up,
                    projection,
                    znear,
                    zfar,
                    aspect,
                },
            ));
        }
        let children: Vec<_> = node.children().collect();
        for child in children.into_iter().rev() {
            stack.push((child, world));
        }
    }
    cameras.sort_by_key(|(ni, _)| *ni);
    scene.cameras = cameras.into_iter().map(|(_, c)| c).collect();
    Ok(scene)
}

/// Runs the `gltf` crate's schema validation, after checking what its own validation indexes
/// without a bounds check (a primitive's POSITION accessor). Missing POSITION `min`/`max`, which
/// the spec requires but many exporters omit, is tolerated since the loader never uses them.
fn validate_json(root: &gltf::json::Root) -> R<()> {
    use gltf::json::validation::{Error as VError, Validate};
    for (mi, m) in root.meshes.iter().enumerate() {
        for (pi, p) in m.primitives.iter().enumerate() {
            for (sem, acc) in &p.attributes {
                if acc.value() >= root.accessors.len() {
                    let sem = match sem {
                        gltf::json::validation::Checked::Valid(s) => format!("{s:?}"),
                        gltf::json::validation::Checked::Invalid => "?".into(),
                    };
                    return Err(format!(
                        "meshes[{mi}].primitives[{pi}].attributes[{sem}]: accessor {} does not \
                         exist ({} accessors)",
                        acc.value(),
                        root.accessors.len()
                    ));
                }
            }
        }
    }
    let mut errors = Vec::new();
    root.validate(root, gltf::json::Path::new, &mut |path, err| {
        let path = path();
        let p = path.as_str();
        let min_max = p.ends_with(".min") || p.ends_with(".max");
        if !(min_max && matches!(err, VError::Missing)) {
            errors.push(format!("{p}: {err}"));
        }
    });
    if errors.is_empty() {
        Ok(())
    } else {
        Err(format!("invalid glTF: {}", errors.join("; ")))
    }
}

fn local_transform(node: &gltf::Node) -> Mat4 {
    match node.transform() {
        gltf::scene::Transform::Matrix { matrix } => Mat4::from_cols_array_2d(&matrix),
        gltf::scene::Transform::Decomposed {
            translation,
            rotation,
            scale,
        } => {
            // glTF requires unit quaternions; files round them (0.383, 0.924), so normalise.
            let q = Quat::from_array(rotation);
            let q = if q.length_squared() > 0.0 && q.is_finite() {
                q.normalize()
            } else {
                Quat::IDENTITY
            };
            Mat4::from_scale_rotation_translation(scale.into(), q, translation.into())
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Buffers and images

fn load_buffers(doc: &gltf::Document, base: &Path, blob: Option<&[u8]>) -> R<Vec<Vec<u8>>> {
    let mut out = Vec::new();
    for b in doc.buffers() {
        let i = b.index();
        let data = match b.source() {
            gltf::buffer::Source::Bin => blob
                .ok_or_else(|| {
                    format!("buffer {i}: refers to the GLB binary chunk, but the file has none")
                })?
                .to_vec(),
            gltf::buffer::Source::Uri(uri) => {
                read_uri(uri, base).map_err(|e| format!("buffer {i} ({}): {e}", short(uri)))?
            }
        };
        if data.len() < b.length() {
            return Err(format!(
                "buffer {i}: byteLength is {} but only {} bytes are present",
                b.length(),
                data.len()
            ));
        }
        out.push(data);
    }
    Ok(out)
}

/// A URI for messages: data URIs are cut short.
fn short(uri: &str) -> String {
    if uri.starts_with("data:") {
        let head: String = uri.chars().take(40).collect();
        format!("{head}...")
    } else {
        uri.to_string()
    }
}

fn read_uri(uri: &str, base: &Path) -> R<Vec<u8>> {
    if let Some(rest) = uri.strip_prefix("data:") {
        let (meta, payload) = rest
            .split_once(',')
            .ok_or("data URI without a ',' separator")?;
        if !meta.ends_with(";base64") {
            return Err("only base64 data URIs are supported".into());
        }
        return base64_decode(payload);
    }
    if uri.contains("://") {
        return Err("only relative file paths and data URIs are supported".into());
    }
    let rel = percent_decode(uri)?;
    let full = base.join(rel);
    std::fs::read(&full).map_err(|e| io_reason(&e))
}

fn percent_decode(s: &str) -> R<String> {
    let b = s.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'%' {
            let hex = b
                .get(i + 1..i + 3)
                .and_then(|h| std::str::from_utf8(h).ok())
                .and_then(|h| u8::from_str_radix(h, 16).ok())
                .ok_or_else(|| format!("bad percent escape in URI '{s}'"))?;
            out.push(hex);
            i += 3;
        } else {
            out.push(b[i]);
            i += 1;
        }
    }
    String::from_utf8(out).map_err(|_| format!("URI '{s}' is not UTF-8 after decoding"))
}

fn base64_decode(s: &str) -> R<Vec<u8>> {
    fn val(c: u8) -> Option<u32> {
        Some(match c {
            b'A'..=b'Z' => c - b'A',
            b'a'..=b'z' => c - b'a' + 26,
            b'0'..=b'9' => c - b'0' + 52,
            b'+' | b'-' => 62,
            b'/' | b'_' => 63,
            _ => return None,
        } as u32)
    }
    let mut out = Vec::with_capacity(s.len() / 4 * 3);
    let (mut acc, mut bits) = (0u32, 0u32);
    let mut padding = false;
    for &c in s.as_bytes() {
        if c.is_ascii_whitespace() {
            continue;
        }
        if c == b'=' {
            padding = true;
            continue;
        }
        if padding {
            return Err("invalid base64 in data URI (data after '=' padding)".into());
        }
        let v = val(c)
            .ok_or_else(|| format!("invalid base64 in data URI (character {:?})", char::from(c)))?;
        acc = (acc << 6) | v;
        bits += 6;
        if bits >= 8 {
            bits -= 8;
            out.push((acc >> bits) as u8);
            acc &= (1 << bits) - 1;
        }
    }
    if bits >= 6 {
        return Err("invalid base64 in data URI (truncated)".into());
    }
    Ok(out)
}

fn load_image(image: &gltf::Image, base: &Path, buffers: &[Vec<u8>]) -> R<Texture> {
    let i = image.index();
    let bytes: Vec<u8> = match image.source() {
        gltf::image::Source::View { view, .. } => view_bytes(&view, buffers)
            .map_err(|e| format!("image {i}: {e}"))?
            .to_vec(),
        gltf::image::Source::Uri { uri, .. } => {
            read_uri(uri, base).map_err(|e| format!("image {i} ({}): {e}", short(uri)))?
        }
    };
    let reader = || {
        image::ImageReader::new(std::io::Cursor::new(&bytes[..]))
            .with_guessed_format()
            .map_err(|e| format!("image {i}: {e}"))
    };
    let r = reader()?;
    if r.format().is_none() {
        return Err(format!(
            "image {i}: unknown image format (voxgi reads PNG and JPEG)"
        ));
    }
    let (w, h) = r.into_dimensions().map_err(|e| format!("image {i}: {e}"))?;
    let max = limits::MAX_TEXTURE_DIM;
    if w > max || h > max {
        return Err(format!(
            "image {i}: {w}x{h} is larger than the {max}x{max} limit"
        ));
    }
    let mut r = reader()?;
    let mut lim = image::Limits::default();
    // Room for the largest allowed image at 16 bits per channel RGBA.
    lim.max_alloc = Some(u64::from(max) * u64::from(max) * 8);
    r.limits(lim);
    // to_rgba8 converts any decoded layout (L8, LA8, RGB8, 16-bit, float) to RGBA8: grey is
    // replicated, missing alpha is opaque, wider channels are rescaled.
    let rgba = r
        .decode()
        .map_err(|e| format!("image {i}: {e}"))?
        .to_rgba8();
    Ok(Texture {
        name: image
            .name()
            .map(str::to_string)
            .unwrap_or_else(|| format!("image {i}")),
        width: rgba.width(),
        height: rgba.height(),
        rgba8: rgba.into_raw(),
    })
}

fn view_bytes<'b>(view: &gltf::buffer::View, buffers: &'b [Vec<u8>]) -> R<&'b [u8]> {
    let b = view.buffer().index();
    let data = &buffers[b];
    let start = view.offset();
    let end = start.checked_add(view.length());
    end.and_then(|end| data.get(start..end)).ok_or_else(|| {
        format!(
            "buffer view {} (bytes {start}..{start}+{}) extends beyond buffer {b} ({} bytes)",
            view.index(),
            view.length(),
            data.len()
        )
    })
}

// ---------------------------------------------------------------------------------------------
// Accessors and primitives

/// Checks that reading `count` elements of `acc` stays inside its buffer view and buffer, and
/// that its type is one of `allowed`, so the `gltf` readers can neither panic nor read short.
fn check_accessor(
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
fn collect<T: Default + Clone, I: Iterator<Item = T>>(
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
