//! Scene updates between frames: moving instances, changing lights and the animations' time,
//! and the record of what they made out of date (`Pending`) for the next frame's voxel update
//! and shadow views.

use super::Renderer;
use crate::gpu_scene::{check_light, gpu_light};
use crate::lighting::atlas::{self as shadow, ViewDirt};
use crate::{Error, Result};
use glam::Mat4;
use voxgi_scene::prepare::PointsAhead;
use voxgi_scene::{Aabb, Light};

/// What changed since the last voxel update.
#[derive(Default)]
pub(super) struct Pending {
    /// Everything: the static geometry too, and every shadow view.
    pub(super) rebuild: bool,
    /// The structure already holds the static geometry's build (counted before the first
    /// frame, `sizing`): a rebuild skips voxelizing and building it again.
    pub(super) built: bool,
    /// Dynamic geometry moved.
    pub(super) geometry: bool,
    /// A light changed.
    pub(super) lights: bool,
    /// What of each shadow view (by atlas layer) to re-render; consumed every frame, unlike
    /// the rest, which waits for the next voxel update.
    pub(super) views: Vec<ViewDirt>,
    /// What of each view changed since the last injection: the leaves reading only texels
    /// outside it keep their direct light.
    pub(super) inject_views: Vec<ViewDirt>,
    /// Where dynamic geometry was or is now since the last injection (world space): leaves
    /// there are re-injected, their voxels may have changed.
    pub(super) moved: Option<Aabb>,
}

impl Pending {
    /// Everything out of date, for an atlas of `views` views.
    pub(super) fn everything(views: usize) -> Self {
        Pending {
            rebuild: true,
            views: vec![ViewDirt::All; views],
            inject_views: vec![ViewDirt::All; views],
            ..Default::default()
        }
    }

    /// Marks view `i` out of date within `dirt`, for the shadow pass and for injection.
    fn view(&mut self, i: usize, dirt: ViewDirt) {
        self.views[i] = self.views[i].merge(dirt);
        self.inject_views[i] = self.inject_views[i].merge(dirt);
    }
}

impl Renderer {
    /// Moves instance `instance` (an index into the scene's instances) to `transform`. Only
    /// dynamic instances move (`Instance::dynamic`); moving a static one is an error, as is a
    /// transform that is not finite. The next voxel update re-voxelizes the dynamic geometry,
    /// and the shadow views that see the instance's old or new place re-render. Geometry moved
    /// outside the volume (the scene's bounds, with every pose of its animations) is not
    /// voxelized there.
    pub fn set_instance_transform(&mut self, instance: usize, transform: Mat4) -> Result<()> {
        let count = self.state.instances.len();
        let inst = self.state.instances.get(instance).ok_or_else(|| {
            Error::Setting(format!(
                "instance {instance} does not exist (the scene has {count})"
            ))
        })?;
        if !transform.is_finite() {
            return Err(Error::Setting(format!(
                "instance '{}': the transform is not finite",
                inst.name
            )));
        }
        if transform == inst.transform {
            return Ok(());
        }
        if !inst.dynamic {
            return Err(Error::Setting(format!(
                "instance '{}' is static: only dynamic instances move (mark it dynamic in the \
                 scene: `dynamic = true` on its include)",
                inst.name
            )));
        }
        if let Some(moved) = self.place(instance, transform) {
            self.geometry_moved(moved);
        }
        Ok(())
    }

    /// Moves point cloud `cloud` (an index into the scene's point clouds) to `transform`, as
    /// `set_instance_transform` moves an instance: only dynamic clouds move
    /// (`PointCloud::dynamic`, `dynamic = true` on its include); a static one or a transform
    /// that is not finite is an error. Its surfels are written anew where it is now; the next
    /// voxel update splats it there (an area light's surface is only drawn), and the shadow
    /// views that see its old or new place re-render.
    pub fn set_cloud_transform(&mut self, cloud: usize, transform: Mat4) -> Result<()> {
        let count = self.state.clouds.len();
        let c = self.state.clouds.get(cloud).ok_or_else(|| {
            Error::Setting(format!(
                "point cloud {cloud} does not exist (the scene has {count})"
            ))
        })?;
        if !transform.is_finite() {
            return Err(Error::Setting(format!(
                "point cloud '{}': the transform is not finite",
                c.name
            )));
        }
        if transform == c.transform {
            return Ok(());
        }
        if !c.dynamic {
            return Err(Error::Setting(format!(
                "point cloud '{}' is static: only dynamic clouds move (mark it dynamic in the \
                 scene: `dynamic = true` on its include)",
                c.name
            )));
        }
        let geometry = c.light.is_none();
        let Some(moved) = self.place_cloud(cloud, transform) else {
            return Ok(());
        };
        if geometry {
            self.geometry_moved(moved);
        } else {
            // An area light's surface: not voxelized, but it shadows the other lights, whose
            // light in the voxels follows.
            self.pending.lights = true;
        }
        Ok(())
    }

    /// Marks out of date the shadow views (and their injection) that saw `old` or see `new`
    /// (world boxes): where something moved or changed.
    fn dirty_views(&mut self, old: Aabb, new: Aabb) {
        for v in 0..self.atlas.views.len() {
            let view = &self.atlas.views[v];
            let dirt = shadow::box_dirt(view, old.min, old.max)
                .merge(shadow::box_dirt(view, new.min, new.max));
            self.pending.view(v, dirt);
        }
    }

    /// Dynamic geometry changed within `moved` (world space): the next voxel update redoes it
    /// and re-injects the leaves there.
    fn geometry_moved(&mut self, moved: Aabb) {
        self.pending.moved = Some(self.pending.moved.map_or(moved, |m| m.union(&moved)));
        self.pending.geometry = true;
    }

    /// Puts point cloud `c` at `transform`: its surfels written anew there, and the shadow
    /// views that saw its old place or see its new one out of date. Returns where it was and
    /// is (world space); `None` for a cloud the renderer keeps no points of (a static one).
    fn place_cloud(&mut self, c: usize, transform: Mat4) -> Option<Aabb> {
        let cs = &self.state.clouds[c];
        let points = cs.points.clone()?;
        let (old, new) = (
            cs.local.transformed(cs.transform),
            cs.local.transformed(transform),
        );
        self.scene.set_cloud(&self.queue, c, &points, transform);
        self.state.clouds[c].transform = transform;
        self.dirty_views(old, new);
        Some(old.union(&new))
    }

    /// Gives dynamic point cloud `cloud` new points: `points`' positions and attributes, in
    /// the cloud's own space (it stays where `set_cloud_transform` or its animation put it;
    /// `points.transform` is not read). At most as many points as the cloud had when the
    /// renderer was made (upload a cloud that grows at its largest); attributes it lacks
    /// (normals, radii, regions of influence) are estimated as at upload, on the CPU, here
    /// (`set_points_ahead` takes them estimated elsewhere, e.g. on another thread). The next
    /// voxel update splats them; a changed cloud has no motion vectors (its points are not the
    /// last frame's). Returns how long the estimation took.
    pub fn set_points(
        &mut self,
        cloud: usize,
        points: &voxgi_scene::PointCloud,
    ) -> Result<voxgi_scene::prepare::PointPreparation> {
        let old = self.check_points(cloud, points)?;
        self.apply_points(cloud, PointsAhead::new(points.clone()), &old)
    }

    /// `set_points` for points whose attributes were estimated ahead
    /// (`voxgi_scene::prepare::PointsAhead::new`, which may run on any thread while frames
    /// render, the surface spread too): here only the normals are turned to face the viewer
    /// (and the spread computed where a degenerate neighbourhood's normal waited for that),
    /// and the surfels written.
    pub fn set_points_ahead(
        &mut self,
        cloud: usize,
        ahead: PointsAhead,
    ) -> Result<voxgi_scene::prepare::PointPreparation> {
        let old = self.check_points(cloud, ahead.points())?;
        self.apply_points(cloud, ahead, &old)
    }

    /// `set_points_ahead` once the points passed `check_points` (`old`: the cloud's points
    /// until now).
    fn apply_points(
        &mut self,
        cloud: usize,
        ahead: PointsAhead,
        old: &voxgi_scene::PointCloud,
    ) -> Result<voxgi_scene::prepare::PointPreparation> {
        let c = &self.state.clouds[cloud];
        let (mut pc, spread, prepared) = ahead.finish(c.transform, self.default_camera.position);
        pc.dynamic = true;
        pc.light = old.light;
        pc.name = old.name.clone();
        let (transform, old_local) = (c.transform, c.local);
        let local = crate::scene_state::cloud_extent(&pc);
        let park = super::parking(&super::grid(&self.facts, &self.options));
        let room = self.scene.cloud_ranges[cloud].len();
        self.scene
            .set_cloud_points(&self.queue, cloud, &pc, spread, park);
        let zero = vec![[0.0f32; 4]; room];
        self.scene.set_cloud_motion(&self.queue, cloud, &zero);
        let geometry = pc.light.is_none();
        let cs = &mut self.state.clouds[cloud];
        cs.points = Some(std::sync::Arc::new(pc));
        cs.local = local;
        cs.drawn = transform;
        cs.moving = false;
        let (old, new) = (
            old_local.transformed(transform),
            local.transformed(transform),
        );
        self.dirty_views(old, new);
        if geometry {
            self.geometry_moved(old.union(&new));
        } else {
            self.pending.lights = true;
        }
        Ok(prepared)
    }

    /// Whether `points` may replace cloud `cloud`'s: the cloud exists and is dynamic, they fit
    /// its room, every attribute has one value a point (or none), every point is finite.
    /// Returns the cloud's points now.
    fn check_points(
        &self,
        cloud: usize,
        points: &voxgi_scene::PointCloud,
    ) -> Result<std::sync::Arc<voxgi_scene::PointCloud>> {
        let count = self.state.clouds.len();
        let c = self.state.clouds.get(cloud).ok_or_else(|| {
            Error::Setting(format!(
                "point cloud {cloud} does not exist (the scene has {count})"
            ))
        })?;
        let Some(old) = c.points.clone().filter(|_| c.dynamic) else {
            return Err(Error::Setting(format!(
                "point cloud '{}' is static: only dynamic clouds change (mark it dynamic in \
                 the scene: `dynamic = true` on its include)",
                c.name
            )));
        };
        let n = points.positions.len();
        let room = self.scene.cloud_ranges[cloud].len();
        if n > room {
            return Err(Error::Setting(format!(
                "point cloud '{}': {n} points, more than the {room} it was uploaded with (upload \
                 it at its largest)",
                c.name
            )));
        }
        let attribute = |what: &str, len: usize| {
            if len == 0 || len == n {
                Ok(())
            } else {
                Err(Error::Setting(format!(
                    "point cloud '{}': {len} {what} for {n} points",
                    c.name
                )))
            }
        };
        attribute("colours", points.colors.len())?;
        attribute("normals", points.normals.len())?;
        attribute("radii", points.radii.len())?;
        attribute("regions", points.regions.len())?;
        attribute("emissions", points.emission.len())?;
        if let Some(i) = points.positions.iter().position(|p| !p.is_finite()) {
            return Err(Error::Setting(format!(
                "point cloud '{}': point {i} is not finite",
                c.name
            )));
        }
        Ok(old)
    }

    /// Changes light `index` (into the scene's lights) to `light`: its position, direction,
    /// colour, intensity, range, cone angles or area shape. Its kind (directional, point,
    /// spot, area) and whether it casts shadows are fixed once uploaded (an error: make a new
    /// `Renderer`). The light's shadow views re-render and the voxel light is redone; an area
    /// light's visible surface (its emitter instance, unless an animation moves it) moves with
    /// it, no voxel work (emitters are not voxelized).
    pub fn set_light(&mut self, index: usize, light: &Light) -> Result<()> {
        let count = self.state.lights.len();
        let old = self.state.lights.get(index).ok_or_else(|| {
            Error::Setting(format!(
                "light {index} does not exist (the scene has {count})"
            ))
        })?;
        if old == light {
            return Ok(());
        }
        let mut g = gpu_light(light);
        let was = self.scene.gpu_lights[index];
        check_light(light)?;
        if g.kind != was.kind || light.cast_shadows != old.cast_shadows {
            return Err(Error::Setting(format!(
                "light '{}': its kind and whether it casts shadows are fixed once uploaded; make \
                 a new Renderer to change them",
                light.name
            )));
        }
        g.shadow_first = was.shadow_first;
        g.shadow_count = was.shadow_count;
        g.sample_first = was.sample_first;
        self.scene.gpu_lights[index] = g;
        let emitter_move = old.emitter_move(light);
        self.state.lights[index] = light.clone();
        if let Some(m) = emitter_move {
            self.move_emitters(index, m);
        }
        // Re-plan every view (a light's views follow its position and direction) and re-render
        // those that changed: the moved light's.
        let res = self.atlas.texture.width();
        let (views, _) = shadow::plan_views(
            &mut self.scene.gpu_lights,
            &self.facts.casts,
            self.center,
            self.radius,
            res,
            self.atlas.samples,
        );
        for (i, (new, old)) in views.iter().zip(&self.atlas.views).enumerate() {
            if bytemuck::bytes_of(new) != bytemuck::bytes_of(old) {
                self.pending.view(i, ViewDirt::All);
            }
        }
        self.atlas.update_views(&self.queue, views);
        self.queue.write_buffer(
            &self.scene.lights,
            0,
            bytemuck::cast_slice(&self.scene.gpu_lights),
        );
        self.pending.lights = true;
        Ok(())
    }

    /// Moves the visible surfaces of area light `light` by `m` (from its old frame to its new),
    /// static or not: they are drawn and cast shadows on the other lights' views, but they are
    /// not voxelized, so no voxel work follows. An emitter an animation moves is left to it.
    fn move_emitters(&mut self, light: usize, m: Mat4) {
        for i in 0..self.state.instances.len() {
            let inst = &self.state.instances[i];
            if inst.light == Some(light) && !self.state.animates_instance(i) {
                self.place(i, m * inst.transform);
            }
        }
        for c in 0..self.state.clouds.len() {
            let cloud = &self.state.clouds[c];
            if cloud.light == Some(light) && !self.state.animates_cloud(c) {
                self.place_cloud(c, m * cloud.transform);
            }
        }
    }

    /// Puts instance `i` at `transform`: its draw's transform written, and the shadow views
    /// that saw its old place or see its new one out of date. Returns where it was and is
    /// (world space), when it has a draw.
    fn place(&mut self, i: usize, transform: Mat4) -> Option<Aabb> {
        let inst = &self.state.instances[i];
        let (old, new) = (
            inst.world_bounds(inst.transform),
            inst.world_bounds(transform),
        );
        let draw = inst.draw;
        self.state.instances[i].transform = transform;
        let draw = draw?;
        self.scene.set_transform(&self.queue, draw, transform);
        self.dirty_views(old, new);
        Some(old.union(&new))
    }

    /// Writes the motion of the dynamic clouds since the last frame (`GpuScene::point_motion`,
    /// for the motion vectors): where they moved, and zero again where they stopped. Returns
    /// whether any moved.
    pub(super) fn advance_cloud_motion(&mut self) -> bool {
        let mut moved = false;
        for c in 0..self.state.clouds.len() {
            let cs = &self.state.clouds[c];
            let Some(points) = &cs.points else {
                continue;
            };
            let now_moving = cs.transform != cs.drawn;
            if !now_moving && !cs.moving {
                continue;
            }
            let (then, now) = (cs.drawn, cs.transform);
            let mut motion: Vec<[f32; 4]> = points
                .positions
                .iter()
                .map(|&p| {
                    let d = if now_moving {
                        then.transform_point3(p) - now.transform_point3(p)
                    } else {
                        glam::Vec3::ZERO
                    };
                    [d.x, d.y, d.z, 0.0]
                })
                .collect();
            // Slots a smaller set of points (`set_points`) left empty do not move.
            motion.resize(self.scene.cloud_ranges[c].len(), [0.0; 4]);
            self.scene.set_cloud_motion(&self.queue, c, &motion);
            let cs = &mut self.state.clouds[c];
            cs.drawn = now;
            cs.moving = now_moving;
            moved |= now_moving;
        }
        moved
    }

    /// Sets the scene's time, in seconds: every animation moves its instances, point clouds
    /// and lights to their state at `t` (`Scene::set_time`), through `set_instance_transform`,
    /// `set_cloud_transform` and `set_light`, and every point sequence whose frame changes
    /// gives its cloud the new frame's points (`set_points`; the next frame is read ahead in
    /// the background, so playing forward seldom waits for a file). Only what changed is
    /// updated. Returns the sequences' new frames and what each cost; an unreadable frame is
    /// an error naming its file.
    pub fn set_time(&mut self, t: f32) -> Result<Vec<SequenceFrame>> {
        let changes = self.state.set_time(t)?;
        for (i, m) in changes.instances {
            self.set_instance_transform(i, m)?;
        }
        for (c, m) in changes.clouds {
            self.set_cloud_transform(c, m)?;
        }
        for (l, light) in changes.lights {
            self.set_light(l, &light)?;
        }
        let mut frames = Vec::with_capacity(changes.frames.len());
        for f in changes.frames {
            let start = web_time::Instant::now();
            let points = f.points.points().positions.len();
            let prepared = match self.set_points_ahead(f.cloud, f.points) {
                Ok(p) => p,
                Err(e) => {
                    // The frames not shown are loaded again by the next call.
                    self.state.forget_frames();
                    return Err(e);
                }
            };
            frames.push(SequenceFrame {
                cloud: f.cloud,
                frame: f.frame,
                points,
                waited: f.waited,
                prepared,
                set: start.elapsed(),
            });
        }
        Ok(frames)
    }

    /// The lights as last set (the scene's, and the default sun when one was added), in the
    /// order `set_light` indexes them.
    pub fn lights(&self) -> &[Light] {
        &self.state.lights
    }

    /// The scene's animations (as `Scene::animations`).
    pub fn animations(&self) -> &[voxgi_scene::animation::Animation] {
        self.state.animations()
    }
}

/// A point sequence's frame that `Renderer::set_time` gave its cloud, and what it cost on the
/// CPU (the splat is the next voxel update's).
#[derive(Clone, Debug)]
pub struct SequenceFrame {
    /// The cloud (an index into the scene's point clouds).
    pub cloud: usize,
    /// The frame it shows now.
    pub frame: usize,
    /// Its points.
    pub points: usize,
    /// Waiting for the file (near zero when it was read ahead).
    pub waited: web_time::Duration,
    /// The attribute estimation: on the thread that read the file ahead, or while the caller
    /// waited (`waited`, a frame not read ahead: the first, or after a jump in time).
    pub prepared: voxgi_scene::prepare::PointPreparation,
    /// `set_points_ahead` on the caller's thread: the normals' orientation, the surfels and
    /// their upload (and the surface spread where a degenerate neighbourhood's normal waited
    /// for the viewpoint, and the whole estimation when the frame was not read ahead).
    pub set: web_time::Duration,
}
