//! glTF 2.0 loader (`.gltf` with external or data-URI resources, and `.glb`).
//!
//! The `gltf` crate parses and validates the JSON; buffers and images are resolved here so that
//! errors can name the resource that is wrong. Every accessor is checked against its buffer view
//! and buffer before the `gltf` readers touch it, because those readers assume well-formed data
//! (they `unreachable!()` on unexpected component types and slice with unchecked arithmetic).
//!
//! Animations: channels on node translation, rotation and scale with STEP, LINEAR and
//! CUBICSPLINE samplers. voxgi plays every animation of a file at once, so all of them drive
//! one node hierarchy ([`Motion::Nodes`]); each animated node with meshes or lights below it
//! (down to the next animated node) becomes one [`Animation`], named after the glTF
//! animations that move it, and its instances are dynamic. Times before the first and after
//! the last keyframe hold the end values (glTF has no repeat). Skinning, morph targets and
//! their weights, and animated cameras are not supported: the loader warns and draws the
//! meshes unposed.

use crate::animation::{
    Animation, AnimationTarget, Interpolation, Keyable, Motion, MotionNode, Repeat, Track,
};
use crate::{
    AlphaMode, Camera, Instance, Light, LightKind, Material, Mesh, Projection, Result, Scene,
    SceneError, Texture, compute_normals, limits,
};
use glam::{Mat4, Quat, Vec2, Vec3};
use gltf::accessor::{DataType, Dimensions};
use gltf::json::validation::Checked;
use gltf::mesh::Mode;
use std::collections::BTreeSet;
use std::path::Path;
use std::sync::Arc;

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
            name: node_name.clone(),
            instances: Vec::new(),
            lights: Vec::new(),
            camera: false,
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
            here.camera = true;
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
    scene.cameras = cameras.into_iter().map(|(_, c)| c).collect();
    load_animations(path, doc, &buffers, &mut scene, &placed, &order)?;
    Ok(scene)
}

/// A node the walk of the default scene reached.
#[derive(Clone)]
struct Placed {
    /// The parent node (glTF index); `None` for a root of the scene.
    parent: Option<usize>,
    /// The node's transform in its parent's frame.
    local: Mat4,
    name: String,
    /// The instances of its mesh (`Scene::instances` indices).
    instances: Vec<usize>,
    /// Its punctual light (`Scene::lights` index).
    lights: Vec<usize>,
    camera: bool,
}

/// A node's animated parts, each with the glTF animation it came from.
#[derive(Default)]
struct NodeTracks {
    translation: Option<(Track<Vec3>, usize)>,
    rotation: Option<(Track<Quat>, usize)>,
    scale: Option<(Track<Vec3>, usize)>,
}

impl NodeTracks {
    fn any(&self) -> bool {
        self.translation.is_some() || self.rotation.is_some() || self.scale.is_some()
    }

    fn sources(&self) -> impl Iterator<Item = usize> + '_ {
        [
            self.translation.as_ref().map(|t| t.1),
            self.rotation.as_ref().map(|t| t.1),
            self.scale.as_ref().map(|t| t.1),
        ]
        .into_iter()
        .flatten()
    }
}

/// Reads the file's animations into `scene.animations`: all of them drive one hierarchy of the
/// animated nodes, and each animated node with meshes or lights below it (before the next
/// animated node) moves them as one target, whose instances become dynamic.
fn load_animations(
    path: &Path,
    doc: &gltf::Document,
    buffers: &[Vec<u8>],
    scene: &mut Scene,
    placed: &[Option<Placed>],
    order: &[usize],
) -> R<()> {
    use gltf::json::animation::Property;
    let root = doc.as_json();
    if root.animations.is_empty() {
        return Ok(());
    }
    let names: Vec<String> = root
        .animations
        .iter()
        .enumerate()
        .map(|(ai, a)| a.name.clone().unwrap_or_else(|| format!("animation {ai}")))
        .collect();
    let mut tracks: Vec<NodeTracks> = (0..root.nodes.len())
        .map(|_| NodeTracks::default())
        .collect();
    let mut moves_nodes = vec![false; root.animations.len()];
    for (ai, anim) in root.animations.iter().enumerate() {
        let what_anim = format!("animation {ai} '{}'", names[ai]);
        for (ci, ch) in anim.channels.iter().enumerate() {
            let ni = ch.target.node.value();
            if ni >= root.nodes.len() {
                return Err(format!(
                    "{what_anim}: channel {ci}: node {ni} does not exist ({} nodes)",
                    root.nodes.len()
                ));
            }
            let Checked::Valid(property) = ch.target.path else {
                log::warn!(
                    "{}: {what_anim}: channel {ci} animates something other than translation, \
                     rotation, scale or weights of node {ni}; ignored",
                    path.display()
                );
                continue;
            };
            let prop_name = match property {
                Property::Translation => "translation",
                Property::Rotation => "rotation",
                Property::Scale => "scale",
                Property::MorphTargetWeights => "weights",
            };
            let what = format!("{what_anim}: channel {ci} (node {ni} {prop_name})");
            if property == Property::MorphTargetWeights {
                log::warn!(
                    "{}: {what}: morph-target weights are not supported, ignored",
                    path.display()
                );
                continue;
            }
            let si = ch.sampler.value();
            let sampler = anim.samplers.get(si).ok_or_else(|| {
                format!(
                    "{what}: sampler {si} does not exist ({} samplers)",
                    anim.samplers.len()
                )
            })?;
            let what = format!("{what}, sampler {si}");
            let Checked::Valid(interpolation) = sampler.interpolation else {
                return Err(format!(
                    "{what}: unknown interpolation (LINEAR, STEP or CUBICSPLINE)"
                ));
            };
            let accessor = |i: usize, role: &str| {
                doc.accessors().nth(i).ok_or_else(|| {
                    format!(
                        "{what}: {role} accessor {i} does not exist ({} accessors)",
                        root.accessors.len()
                    )
                })
            };
            let input = accessor(sampler.input.value(), "input")?;
            let output = accessor(sampler.output.value(), "output")?;
            let times = read_accessor::<f32>(
                &input,
                buffers,
                &[(DataType::F32, Dimensions::Scalar)],
                "animation input",
            )
            .map_err(|e| format!("{what}: {e}"))?;
            let in_out = format!(
                "{what} (input accessor {}, output accessor {})",
                input.index(),
                output.index()
            );
            let node = &mut tracks[ni];
            let replaced = match property {
                Property::Translation | Property::Scale => {
                    let v = read_accessor::<[f32; 3]>(
                        &output,
                        buffers,
                        &[(DataType::F32, Dimensions::Vec3)],
                        "animation output",
                    )
                    .map_err(|e| format!("{what}: {e}"))?;
                    let v = v.into_iter().map(Vec3::from).collect();
                    let t = keyed(times, v, interpolation).map_err(|e| format!("{in_out}: {e}"))?;
                    let slot = if property == Property::Translation {
                        &mut node.translation
                    } else {
                        &mut node.scale
                    };
                    slot.replace((t, ai)).map(|old| old.1)
                }
                _ => {
                    let mut v =
                        read_rotations(&output, buffers).map_err(|e| format!("{what}: {e}"))?;
                    // CUBICSPLINE keeps its tangents as given; only the values are rotations.
                    let cubic = interpolation == gltf::animation::Interpolation::CubicSpline;
                    for (k, q) in v.iter_mut().enumerate() {
                        if cubic && k % 3 != 1 {
                            continue;
                        }
                        // Files round unit quaternions; a zero one is no rotation at all.
                        if q.is_finite() {
                            if q.length_squared() == 0.0 {
                                return Err(format!(
                                    "{in_out}: output {k} is the zero quaternion, not a rotation"
                                ));
                            }
                            *q = q.normalize();
                        }
                    }
                    let t = keyed(times, v, interpolation).map_err(|e| format!("{in_out}: {e}"))?;
                    node.rotation.replace((t, ai)).map(|old| old.1)
                }
            };
            if let Some(old) = replaced {
                log::warn!(
                    "{}: node {ni} {prop_name} is animated by both '{}' and '{}'; voxgi plays \
                     all animations at once, so the later one is used",
                    path.display(),
                    names[old],
                    names[ai]
                );
            }
            moves_nodes[ai] = true;
        }
    }

    // The hierarchy: every animated node, parents before children, with the fixed transform
    // from its nearest animated ancestor; `rel` is each reached node's transform in the frame
    // of its nearest animated ancestor-or-self (the file's space when there is none).
    let mut nodes: Vec<MotionNode> = Vec::new();
    let mut sources: Vec<BTreeSet<usize>> = Vec::new();
    let mut anchor: Vec<Option<usize>> = vec![None; root.nodes.len()];
    let mut rel = vec![Mat4::IDENTITY; root.nodes.len()];
    let mut listed = vec![false; root.nodes.len()];
    for &ni in order {
        let Some(p) = &placed[ni] else { continue };
        let (up, up_rel) = p
            .parent
            .map_or((None, Mat4::IDENTITY), |q| (anchor[q], rel[q]));
        if tracks[ni].any() {
            let mut own: BTreeSet<usize> = tracks[ni].sources().collect();
            if let Some(u) = up {
                own.extend(sources[u].iter().copied());
            }
            nodes.push(motion_node(path, doc, ni, &mut tracks[ni], up, up_rel));
            sources.push(own);
            anchor[ni] = Some(nodes.len() - 1);
            listed[ni] = true;
        } else {
            anchor[ni] = up;
            rel[ni] = up_rel * p.local;
        }
    }
    // Animated nodes outside the default scene move nothing but still count for the duration.
    for ni in 0..root.nodes.len() {
        if !listed[ni] && tracks[ni].any() {
            nodes.push(motion_node(
                path,
                doc,
                ni,
                &mut tracks[ni],
                None,
                Mat4::IDENTITY,
            ));
            sources.push(BTreeSet::new());
        }
    }

    type Group = (Vec<usize>, Vec<Mat4>, Vec<(usize, Light)>);
    let mut groups: Vec<Group> = vec![(Vec::new(), Vec::new(), Vec::new()); nodes.len()];
    for &ni in order {
        let (Some(p), Some(a)) = (&placed[ni], anchor[ni]) else {
            continue;
        };
        let g = &mut groups[a];
        for &i in &p.instances {
            g.0.push(i);
            g.1.push(rel[ni]);
            if let Some(inst) = scene.instances.get_mut(i) {
                inst.dynamic = true;
            }
        }
        for &l in &p.lights {
            if let Some(light) = scene.lights.get(l) {
                g.2.push((l, light_at(light, rel[ni])));
            }
        }
        if p.camera {
            log::warn!(
                "{}: the camera on node '{}' stays in its rest pose (cameras are not animated)",
                path.display(),
                p.name
            );
        }
    }
    let nodes: Arc<[MotionNode]> = nodes.into();
    let mut used = vec![false; root.animations.len()];
    for (a, (instances, inner, lights)) in groups.into_iter().enumerate() {
        if instances.is_empty() && lights.is_empty() {
            continue;
        }
        for &ai in &sources[a] {
            used[ai] = true;
        }
        let name = sources[a]
            .iter()
            .map(|&ai| names[ai].as_str())
            .collect::<Vec<_>>()
            .join(", ");
        scene.animations.push(Animation {
            name,
            target: AnimationTarget::Instances {
                instances,
                outer: Mat4::IDENTITY,
                inner,
                lights,
                motion: Motion::Nodes {
                    nodes: nodes.clone(),
                    node: a,
                },
            },
        });
    }
    for (ai, name) in names.iter().enumerate() {
        if moves_nodes[ai] && !used[ai] {
            log::warn!(
                "{}: animation {ai} '{name}' moves no mesh or light (only nodes without them, \
                 such as skin joints; skinning is not supported)",
                path.display()
            );
        }
    }
    Ok(())
}

/// The hierarchy entry for animated node `ni`, taking its tracks; `parent` and `offset` as in
/// [`MotionNode`].
fn motion_node(
    path: &Path,
    doc: &gltf::Document,
    ni: usize,
    tracks: &mut NodeTracks,
    parent: Option<usize>,
    offset: Mat4,
) -> MotionNode {
    let (rest_scale, rest_rotation, rest_translation) =
        match doc.nodes().nth(ni).map(|n| n.transform()) {
            Some(gltf::scene::Transform::Decomposed {
                translation,
                rotation,
                scale,
            }) => (
                Vec3::from(scale),
                unit_quat(Quat::from_array(rotation)),
                Vec3::from(translation),
            ),
            Some(gltf::scene::Transform::Matrix { matrix }) => {
                // glTF forbids matrices on animated nodes; the closest TRS keeps what it can.
                log::warn!(
                    "{}: node {ni} is animated but has a matrix (glTF requires TRS there); its \
                     decomposition is used",
                    path.display()
                );
                let (s, r, t) = Mat4::from_cols_array_2d(&matrix).to_scale_rotation_translation();
                (s, unit_quat(r), t)
            }
            None => (Vec3::ONE, Quat::IDENTITY, Vec3::ZERO),
        };
    MotionNode {
        parent,
        offset,
        rest_translation,
        rest_rotation,
        rest_scale,
        translation: tracks.translation.take().map(|t| t.0),
        rotation: tracks.rotation.take().map(|t| t.0),
        scale: tracks.scale.take().map(|t| t.0),
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

/// A punctual light placed by `m`, as the node walk places it by a node's world transform.
fn light_at(light: &Light, m: Mat4) -> Light {
    Light {
        position: m.transform_point3(Vec3::ZERO),
        direction: m
            .transform_vector3(Vec3::NEG_Z)
            .try_normalize()
            .unwrap_or(Vec3::NEG_Z),
        ..light.clone()
    }
}

/// A sampler's keyframes as a track: one output per time for STEP and LINEAR, three for
/// CUBICSPLINE (in-tangent, value, out-tangent).
fn keyed<T: Keyable>(
    times: Vec<f32>,
    outputs: Vec<T>,
    interpolation: gltf::animation::Interpolation,
) -> R<Track<T>> {
    use gltf::animation::Interpolation as I;
    let n = times.len();
    match interpolation {
        I::Step | I::Linear => {
            if outputs.len() != n {
                return Err(format!(
                    "{n} keyframe times but {} output values",
                    outputs.len()
                ));
            }
            let interp = if interpolation == I::Step {
                Interpolation::Step
            } else {
                Interpolation::Linear
            };
            Track::new(times, outputs, interp, Repeat::Clamp)
        }
        I::CubicSpline => {
            if outputs.len() != 3 * n {
                return Err(format!(
                    "CUBICSPLINE output has {} values for {n} keyframe times; it needs 3 per \
                     keyframe (in-tangent, value, out-tangent)",
                    outputs.len()
                ));
            }
            let (mut a, mut v, mut b) = (
                Vec::with_capacity(n),
                Vec::with_capacity(n),
                Vec::with_capacity(n),
            );
            for k in outputs.chunks_exact(3) {
                a.push(k[0]);
                v.push(k[1]);
                b.push(k[2]);
            }
            Track::hermite(times, v, a, b, Repeat::Clamp)
        }
    }
}

/// Reads all of an accessor of element type `T` after checking it (`allowed` types only).
fn read_accessor<T: gltf::accessor::Item + Default + Clone>(
    acc: &gltf::Accessor,
    buffers: &[Vec<u8>],
    allowed: &[(DataType, Dimensions)],
    what: &str,
) -> R<Vec<T>> {
    check_accessor(acc, buffers, allowed, what)?;
    let get = |b: gltf::Buffer| buffers.get(b.index()).map(Vec::as_slice);
    collect(acc, gltf::accessor::Iter::<T>::new(acc.clone(), get), what)
}

/// Rotation outputs: float quaternions or normalised integers (glTF's `normalized` rule).
fn read_rotations(acc: &gltf::Accessor, buffers: &[Vec<u8>]) -> R<Vec<Quat>> {
    let what = "animation output";
    let q = |v: [f32; 4]| Quat::from_array(v);
    let one = |t: DataType| [(t, Dimensions::Vec4)];
    Ok(match acc.data_type() {
        DataType::I8 => read_accessor::<[i8; 4]>(acc, buffers, &one(DataType::I8), what)?
            .into_iter()
            .map(|c| q(c.map(|c| (f32::from(c) / 127.0).max(-1.0))))
            .collect(),
        DataType::U8 => read_accessor::<[u8; 4]>(acc, buffers, &one(DataType::U8), what)?
            .into_iter()
            .map(|c| q(c.map(|c| f32::from(c) / 255.0)))
            .collect(),
        DataType::I16 => read_accessor::<[i16; 4]>(acc, buffers, &one(DataType::I16), what)?
            .into_iter()
            .map(|c| q(c.map(|c| (f32::from(c) / 32767.0).max(-1.0))))
            .collect(),
        DataType::U16 => read_accessor::<[u16; 4]>(acc, buffers, &one(DataType::U16), what)?
            .into_iter()
            .map(|c| q(c.map(|c| f32::from(c) / 65535.0)))
            .collect(),
        _ => read_accessor::<[f32; 4]>(acc, buffers, &one(DataType::F32), what)?
            .into_iter()
            .map(q)
            .collect(),
    })
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
            let q = unit_quat(Quat::from_array(rotation));
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
