//! glTF 2.0 loader (`.gltf` with external or data-URI resources, and `.glb`).
//!
//! The `gltf` crate parses and validates the JSON; buffers and images are resolved here so that
//! errors can name the resource that is wrong. Every accessor is checked against its buffer view
//! and buffer before the `gltf` readers touch it, because those readers assume well-formed data
//! (they `unreachable!()` on unexpected component types and slice with unchecked arithmetic).

mod animation;
mod buffers;
mod meshes;

use self::animation::load_animations;
use self::buffers::{load_buffers, load_image};
use self::meshes::{load_materials, load_meshes};
use crate::{Camera, Instance, Light, LightKind, Projection, Result, Scene, SceneError};
use glam::{Mat4, Quat, Vec3};
use std::path::Path;

/// Internal result: the reason string, turned into `SceneError::load(path, reason)` at the top.
type R<T> = std::result::Result<T, String>;

/// Loads a `.gltf` or `.glb` file into a validated [`Scene`].
pub fn load(path: &Path) -> Result<Scene> {
    let bytes = crate::io::source::read(path).map_err(|e| SceneError::load(path, io_reason(&e)))?;
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
    load_materials(doc, &mut scene);
    // (glTF mesh, primitive) -> index into scene.meshes, None for skipped primitives.
    let prim_map = load_meshes(doc, &buffers, path, &mut scene)?;

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
    // What each reached node holds, in the order reached (parents first), for the animations.
    let mut placed: Vec<Option<Placed>> = vec![None; doc.nodes().len()];
    let mut order = Vec::new();
    let mut stack: Vec<(gltf::Node, Mat4, Option<usize>)> = gscene
        .nodes()
        .map(|n| (n, Mat4::IDENTITY, None))
        .collect::<Vec<_>>();
    stack.reverse();
    let mut cameras: Vec<(usize, Camera)> = Vec::new();
    while let Some((node, parent, parent_index)) = stack.pop() {
        let ni = node.index();
        if std::mem::replace(&mut visited[ni], true) {
            return Err(format!(
                "node {ni} is reached twice in scene {} (the node hierarchy must be a tree)",
                gscene.index()
            ));
        }
        let local = local_transform(&node);
        let world = parent * local;
        if !world.is_finite() {
            return Err(format!("node {ni}: non-finite transform"));
        }
        let node_name = node
            .name()
            .map(str::to_string)
            .unwrap_or_else(|| format!("node {ni}"));
        let mut here = Placed {
            parent: parent_index,
            local,
            instances: Vec::new(),
            lights: Vec::new(),
        };
        if let Some(gmesh) = node.mesh() {
            if doc.as_json().nodes[ni].skin.is_some() {
                log::warn!(
                    "{}: skinned mesh {} '{}' on node '{node_name}' is drawn in its bind pose; \
                     skinning is not supported",
                    path.display(),
                    gmesh.index(),
                    gmesh.name().unwrap_or("")
                );
            }
            for &mesh in prim_map[gmesh.index()].iter().flatten() {
                here.instances.push(scene.instances.len());
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
            here.lights.push(scene.lights.len() - 1);
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
        placed[ni] = Some(here);
        order.push(ni);
        let children: Vec<_> = node.children().collect();
        for child in children.into_iter().rev() {
            stack.push((child, world, Some(ni)));
        }
    }
    cameras.sort_by_key(|(ni, _)| *ni);
    // Each camera node's index in the scene's cameras, for the animations that move them.
    let mut camera_of = vec![None; doc.nodes().len()];
    for (i, (ni, _)) in cameras.iter().enumerate() {
        camera_of[*ni] = Some(i);
    }
    scene.cameras = cameras.into_iter().map(|(_, c)| c).collect();
    load_animations(path, doc, &buffers, &mut scene, &placed, &order, &camera_of)?;
    Ok(scene)
}

/// A node the walk of the default scene reached.
#[derive(Clone)]
struct Placed {
    /// The parent node (glTF index); `None` for a root of the scene.
    parent: Option<usize>,
    /// The node's transform in its parent's frame.
    local: Mat4,
    /// The instances of its mesh (`Scene::instances` indices).
    instances: Vec<usize>,
    /// Its punctual light (`Scene::lights` index).
    lights: Vec<usize>,
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
    // `Image::source` unwraps these (a fuzzed file found it).
    for (ii, im) in root.images.iter().enumerate() {
        match (&im.buffer_view, &im.uri) {
            (Some(v), _) if v.value() >= root.buffer_views.len() => {
                return Err(format!(
                    "images[{ii}].bufferView: buffer view {} does not exist ({} buffer views)",
                    v.value(),
                    root.buffer_views.len()
                ));
            }
            (Some(_), _) if im.mime_type.is_none() => {
                return Err(format!(
                    "images[{ii}]: an image in a buffer view needs a mimeType"
                ));
            }
            (None, None) => {
                return Err(format!("images[{ii}]: neither a uri nor a bufferView"));
            }
            _ => {}
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
            let q = unit_quat(Quat::from_array(rotation));
            Mat4::from_scale_rotation_translation(scale.into(), q, translation.into())
        }
    }
}

/// `q` normalised, or the identity when it has no direction (zero or not finite).
fn unit_quat(q: Quat) -> Quat {
    if q.length_squared() > 0.0 && q.is_finite() {
        q.normalize()
    } else {
        Quat::IDENTITY
    }
}
