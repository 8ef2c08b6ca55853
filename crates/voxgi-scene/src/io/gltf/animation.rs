//! Animations: channels on node translation, rotation and scale with STEP, LINEAR and
//! CUBICSPLINE samplers. voxgi plays every animation of a file at once, so all of them drive
//! one node hierarchy ([`Motion::Nodes`]); each animated node with meshes or lights below it
//! (down to the next animated node) becomes one [`Animation`], named after the glTF
//! animations that move it, and its instances are dynamic. Times before the first and after
//! the last keyframe hold the end values (glTF has no repeat). A camera on an animated node
//! (or below one) moves with it. Skinning, morph targets and their weights are not supported:
//! the loader warns and draws the meshes unposed.

use super::meshes::{check_accessor, collect};
use super::{Placed, R, unit_quat};
use crate::animation::{
    Animation, AnimationTarget, CameraMotion, Interpolation, Keyable, Motion, MotionNode, Repeat,
    Track,
};
use crate::{Light, Scene};
use glam::{Mat4, Quat, Vec3};
use gltf::accessor::{DataType, Dimensions};
use gltf::json::validation::Checked;
use std::collections::BTreeSet;
use std::path::Path;
use std::sync::Arc;

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
/// animated node) moves them as one target, whose instances become dynamic; a camera below an
/// animated node (`camera_of`: each node's camera index in `scene.cameras`) moves with it.
pub(super) fn load_animations(
    path: &Path,
    doc: &gltf::Document,
    buffers: &[Vec<u8>],
    scene: &mut Scene,
    placed: &[Option<Placed>],
    order: &[usize],
    camera_of: &[Option<usize>],
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
    // (camera index, its animated node, its node's transform in that node's frame)
    let mut moved_cameras: Vec<(usize, usize, Mat4)> = Vec::new();
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
        if let Some(c) = camera_of.get(ni).copied().flatten() {
            moved_cameras.push((c, a, rel[ni]));
        }
    }
    let nodes: Arc<[MotionNode]> = nodes.into();
    let mut used = vec![false; root.animations.len()];
    // The name of the target animated node `a` moves (the glTF animations that move it, now
    // counted as used).
    let mut named = |a: usize| {
        for &ai in &sources[a] {
            used[ai] = true;
        }
        sources[a]
            .iter()
            .map(|&ai| names[ai].as_str())
            .collect::<Vec<_>>()
            .join(", ")
    };
    for (a, (instances, inner, lights)) in groups.into_iter().enumerate() {
        if instances.is_empty() && lights.is_empty() {
            continue;
        }
        let name = named(a);
        scene.animations.push(Animation {
            name,
            target: AnimationTarget::Instances {
                instances,
                outer: Mat4::IDENTITY,
                inner,
                lights,
                clouds: Vec::new(),
                motion: Motion::Nodes {
                    nodes: nodes.clone(),
                    node: a,
                },
            },
        });
    }
    for (camera, a, inner) in moved_cameras {
        let Some(rest) = scene.cameras.get(camera).cloned() else {
            continue;
        };
        let name = named(a);
        scene.animations.push(Animation {
            name,
            target: AnimationTarget::Camera {
                camera,
                rest,
                outer: Mat4::IDENTITY,
                motion: CameraMotion::Rigid {
                    motion: Motion::Nodes {
                        nodes: nodes.clone(),
                        node: a,
                    },
                    inner,
                },
            },
        });
    }
    for (ai, name) in names.iter().enumerate() {
        if moves_nodes[ai] && !used[ai] {
            log::warn!(
                "{}: animation {ai} '{name}' moves no mesh, light or camera (only nodes without \
                 them, such as skin joints; skinning is not supported)",
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
