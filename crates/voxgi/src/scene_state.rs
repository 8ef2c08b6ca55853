//! What the renderer keeps of the scene after uploading it, to apply updates: each instance's
//! transform, motion class and mesh bounds; the lights; the animations, and the space
//! everything animated sweeps (which the voxel grid and the shadow views must cover).

use crate::{Error, Result};
use glam::Mat4;
use voxgi_scene::animation::{Animation, AnimationTarget};
use voxgi_scene::{Aabb, Light, Scene};

/// One instance as the renderer knows it.
#[derive(Clone, Debug)]
pub struct InstanceState {
    /// For messages.
    pub name: String,
    /// Only dynamic instances may move (and area lights' emitters, with their light).
    pub dynamic: bool,
    /// The area light whose visible surface this is.
    pub light: Option<usize>,
    /// Its draw in `GpuScene::draws` (`None`: a mesh without triangles, nothing to move).
    pub draw: Option<u32>,
    /// Its mesh's bounds in object space.
    pub local: Aabb,
    /// Object to world, now.
    pub transform: Mat4,
}

impl InstanceState {
    /// The world bounds of the instance under `transform` (the box around the transformed
    /// corners of its mesh's bounds).
    pub fn world_bounds(&self, transform: Mat4) -> Aabb {
        self.local.transformed(transform)
    }
}

/// The scene's mutable state: instances, lights and animations.
pub struct SceneState {
    /// Every scene instance, in the scene's order.
    pub instances: Vec<InstanceState>,
    /// Every light (the default sun included when one was added), as last set.
    pub lights: Vec<Light>,
    /// The animations, over a copy of the scene without its geometry (instances and lights
    /// only: all that `Scene::set_time` touches).
    animated: Scene,
    /// Instances and lights that some animation moves.
    animated_instances: Vec<usize>,
    animated_lights: Vec<usize>,
}

impl SceneState {
    /// Whether an animation moves instance `i`.
    pub fn animates_instance(&self, i: usize) -> bool {
        self.animated_instances.binary_search(&i).is_ok()
    }

    /// Where the dynamic instances are now (empty when there are none).
    pub fn dynamic_bounds(&self) -> Aabb {
        self.instances
            .iter()
            .filter(|i| i.dynamic && i.draw.is_some())
            .fold(Aabb::EMPTY, |b, i| b.union(&i.world_bounds(i.transform)))
    }
}

/// What `SceneState::set_time` changed.
pub struct TimeChanges {
    /// Instances with a new transform: (index, transform).
    pub instances: Vec<(usize, Mat4)>,
    /// Lights with new values: (index, light).
    pub lights: Vec<(usize, Light)>,
}

impl SceneState {
    /// The state of `scene` (as uploaded: after the default light was added).
    pub fn new(scene: &Scene, draws: &[Option<u32>]) -> Self {
        let instances = scene
            .instances
            .iter()
            .enumerate()
            .map(|(i, inst)| {
                let mut local = Aabb::EMPTY;
                for &p in &scene.meshes[inst.mesh].positions {
                    local.grow(p);
                }
                InstanceState {
                    name: inst.name.clone(),
                    dynamic: inst.dynamic,
                    light: inst.light,
                    draw: draws.get(i).copied().flatten(),
                    local,
                    transform: inst.transform,
                }
            })
            .collect();
        let mut animated_instances = Vec::new();
        let mut animated_lights = Vec::new();
        for a in &scene.animations {
            match &a.target {
                AnimationTarget::Instances {
                    instances, lights, ..
                } => {
                    animated_instances.extend(instances.iter().copied());
                    animated_lights.extend(lights.iter().map(|(l, _)| *l));
                }
                AnimationTarget::Light { light, .. } => animated_lights.push(*light),
            }
        }
        animated_instances.sort_unstable();
        animated_instances.dedup();
        animated_lights.sort_unstable();
        animated_lights.dedup();
        SceneState {
            instances,
            lights: scene.lights.clone(),
            animated: Scene {
                instances: scene.instances.clone(),
                lights: scene.lights.clone(),
                animations: scene.animations.clone(),
                ..Default::default()
            },
            animated_instances,
            animated_lights,
        }
    }

    /// The animations.
    pub fn animations(&self) -> &[Animation] {
        &self.animated.animations
    }

    /// Samples the animations at time `t` and lists what changed since the last state set.
    pub fn set_time(&mut self, t: f32) -> Result<TimeChanges> {
        if !t.is_finite() {
            return Err(Error::Setting(format!("time {t} is not a finite number")));
        }
        self.animated.set_time(t);
        let instances = self
            .animated_instances
            .iter()
            .filter_map(|&i| {
                let m = self.animated.instances[i].transform;
                (m != self.instances[i].transform).then_some((i, m))
            })
            .collect();
        let lights = self
            .animated_lights
            .iter()
            .filter_map(|&l| {
                let light = &self.animated.lights[l];
                (*light != self.lights[l]).then(|| (l, light.clone()))
            })
            .collect();
        Ok(TimeChanges { instances, lights })
    }
}
