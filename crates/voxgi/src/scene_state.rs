//! What the renderer keeps of the scene after uploading it, to apply updates: each instance's
//! transform, motion class and mesh bounds; each point cloud's (and a dynamic one's points,
//! to place them again); the lights; the animations, and the space everything animated sweeps
//! (which the voxel grid and the shadow views must cover).

use crate::{Error, Result};
use glam::Mat4;
use std::sync::Arc;
use voxgi_scene::animation::{Animation, AnimationTarget};
use voxgi_scene::sequence::{NewFrame, SequencePlayer};
use voxgi_scene::{Aabb, Light, PointCloud, Scene};

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

/// One point cloud as the renderer knows it.
#[derive(Clone, Debug)]
pub struct CloudState {
    /// Only dynamic clouds move.
    pub dynamic: bool,
    /// The area light whose visible surface it is (drawn, not voxelized).
    pub light: Option<usize>,
    /// Its points' bounds in its own space.
    pub local: Aabb,
    /// A dynamic cloud or an area light's surface as uploaded (its points in its own space),
    /// to place it again.
    pub points: Option<Arc<PointCloud>>,
    /// The cloud's name, for messages.
    pub name: String,
    /// Its space to world, now.
    pub transform: Mat4,
    /// Its space to world when the last frame drew it, and whether that frame's motion
    /// (`GpuScene::point_motion`) was not zero.
    pub drawn: Mat4,
    pub moving: bool,
}

/// The scene's mutable state: instances, point clouds, lights and animations.
pub struct SceneState {
    /// Every scene instance, in the scene's order.
    pub instances: Vec<InstanceState>,
    /// Every point cloud, in the scene's order.
    pub clouds: Vec<CloudState>,
    /// Every light (the default sun included when one was added), as last set.
    pub lights: Vec<Light>,
    /// The animations, over a copy of the scene without its geometry (instances and lights
    /// only: all that `Scene::set_time` touches).
    animated: Scene,
    /// Instances, clouds and lights that some animation moves.
    animated_instances: Vec<usize>,
    animated_clouds: Vec<usize>,
    animated_lights: Vec<usize>,
    /// The point sequences, playing in their clouds.
    player: SequencePlayer,
}

impl SceneState {
    /// Whether an animation moves point cloud `c`.
    pub fn animates_cloud(&self, c: usize) -> bool {
        self.animated_clouds.binary_search(&c).is_ok()
    }

    /// Whether an animation moves instance `i`.
    pub fn animates_instance(&self, i: usize) -> bool {
        self.animated_instances.binary_search(&i).is_ok()
    }

    /// Where the dynamic instances and geometry clouds are now (empty when there are none).
    pub fn dynamic_bounds(&self) -> Aabb {
        let clouds = self
            .clouds
            .iter()
            .filter(|c| c.dynamic && c.light.is_none())
            .fold(Aabb::EMPTY, |b, c| {
                b.union(&c.local.transformed(c.transform))
            });
        self.instances
            .iter()
            .filter(|i| i.dynamic && i.draw.is_some())
            .fold(clouds, |b, i| b.union(&i.world_bounds(i.transform)))
    }
}

/// What `SceneState::set_time` changed.
pub struct TimeChanges {
    /// Instances with a new transform: (index, transform).
    pub instances: Vec<(usize, Mat4)>,
    /// Point clouds with a new transform: (index, transform).
    pub clouds: Vec<(usize, Mat4)>,
    /// Lights with new values: (index, light).
    pub lights: Vec<(usize, Light)>,
    /// Point sequences' clouds with a new frame, loaded.
    pub frames: Vec<NewFrame>,
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
        let clouds = scene
            .point_clouds
            .iter()
            .map(|pc| {
                let local = cloud_extent(pc);
                CloudState {
                    dynamic: pc.dynamic,
                    light: pc.light,
                    local,
                    // To place it again: a dynamic cloud, or an area light's surface (which
                    // moves with its light).
                    points: (pc.dynamic || pc.light.is_some()).then(|| Arc::new(pc.clone())),
                    name: pc.name.clone(),
                    transform: pc.transform,
                    drawn: pc.transform,
                    moving: false,
                }
            })
            .collect();
        let animated_clouds = scene.animated_clouds();
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
                // The camera comes with each frame's parameters.
                AnimationTarget::Camera { .. } => {}
            }
        }
        animated_instances.sort_unstable();
        animated_instances.dedup();
        animated_lights.sort_unstable();
        animated_lights.dedup();
        SceneState {
            instances,
            clouds,
            lights: scene.lights.clone(),
            animated: scene.without_geometry(),
            animated_instances,
            animated_clouds,
            animated_lights,
            player: SequencePlayer::new(&scene.sequences),
        }
    }

    /// Forgets which frames the point sequences' clouds show: the next `set_time` loads them.
    pub fn forget_frames(&mut self) {
        self.player.forget();
    }

    /// The animations.
    pub fn animations(&self) -> &[Animation] {
        &self.animated.animations
    }

    /// Samples the animations at time `t` and lists what changed since the last state set,
    /// with the point sequences' frames that changed, loaded (an error names a bad file).
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
        let clouds = self
            .animated_clouds
            .iter()
            .filter_map(|&c| {
                let m = self.animated.point_clouds[c].transform;
                (m != self.clouds[c].transform).then_some((c, m))
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
        Ok(TimeChanges {
            instances,
            clouds,
            lights,
            frames: self.player.frames_at(t)?,
        })
    }
}

/// Where cloud `pc`'s samples reach in its own space: its points, grown by the largest disc
/// radius (its surfels in the shadow maps) or region edge (its voxel fragments lie up to one
/// edge behind a point), so that a moved cloud's box holds all it changed.
pub fn cloud_extent(pc: &PointCloud) -> Aabb {
    let mut b = Aabb::EMPTY;
    for &p in &pc.positions {
        b.grow(p);
    }
    let reach = pc
        .radii
        .iter()
        .chain(&pc.regions)
        .fold(0.0f32, |m, &r| if r.is_finite() { m.max(r) } else { m });
    if !b.is_empty() {
        b.min -= glam::Vec3::splat(reach);
        b.max += glam::Vec3::splat(reach);
    }
    b
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_clouds_extent_holds_its_largest_disc_and_region() {
        let pc = PointCloud {
            positions: vec![glam::Vec3::ZERO, glam::Vec3::new(1.0, 0.0, 0.0)],
            radii: vec![0.05, 0.2],
            regions: vec![0.1, 0.1],
            ..Default::default()
        };
        let b = cloud_extent(&pc);
        assert_eq!(b.min, glam::Vec3::splat(-0.2));
        assert_eq!(b.max, glam::Vec3::new(1.2, 0.2, 0.2));
        assert!(
            cloud_extent(&PointCloud::default()).min.x > 0.0,
            "empty stays empty"
        );
    }
}
