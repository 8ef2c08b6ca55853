//! The renderer: uploads a scene once, then records frames into the caller's encoder by calling
//! the passes in one fixed order from `Renderer::render`:
//!
//! shadow → [moments] → voxelize → splat → dense_build → inject → filter → (bounce → filter) × (bounces − 1)
//!        → gbuffer → gather → upsample → composite → [debug] → tonemap
//!
//! With the fast shading (`IndirectShading::Leaves`) one more bounce runs, which keeps every
//! leaf's irradiance and is neither stored nor filtered, and the gather reads those instead of
//! tracing diffuse cones.
//!
//! `debug` runs only for the voxel views (`ViewMode::is_voxel`) and replaces the composite's
//! output with the ray-marched volume. `tonemap` writes the caller's target.
//!
//! Voxel work follows what changed (DESIGN.md, seam 6). The static geometry is voxelized and
//! built once (on the first frame, after `invalidate`, a pool's growth or a voxel option's
//! change); the dynamic geometry is voxelized and merged in (`dense_update`) on frames after
//! it moved, undoing the previous merge. Injection, filtering and bounces run after geometry
//! or a light changed; with progressive bounces one bounce per frame until the light has
//! converged. Shadow maps re-render only the views of lights that changed or that see
//! something that moved. Camera motion alone does no voxel work. Overflow counters come back
//! asynchronously (`gpu::feedback`): a build that overflowed is redone a frame later with room
//! for everything, and no frame waits for the GPU.

use crate::brdf::BrdfTables;
use crate::fragments::splat::SplatPass;
use crate::fragments::voxelize::VoxelizePass;
use crate::fragments::{self, FragmentEstimate, Fragments, TriangleTable, triangle_table};
use crate::gpu::feedback::CounterReadback;
use crate::gpu::timer::GpuTimer;
use crate::gpu::{checked, readback, requirements};
use crate::gpu_scene::{GpuFrame, GpuScene, bounding_sphere, check_light, gpu_light};
use crate::lighting::atlas::{self as shadow, ShadowAtlas, ViewDirt};
use crate::lighting::bounce::{BouncePass, BounceSteps};
use crate::lighting::inject::InjectPass;
use crate::lighting::moments::MomentsPass;
use crate::lighting::shadow::ShadowPass;
use crate::options::{
    FrameParams, IndirectShading, RendererOptions, ShadowFilter, UNLIMITED_BOUNCES, validate_size,
};
use crate::scene_state::SceneState;
use crate::screen::composite::CompositePass;
use crate::screen::gather::{self, GatherPass};
use crate::screen::gbuffer::GbufferPass;
use crate::screen::tonemap::TonemapPass;
use crate::screen::upsample::UpsamplePass;
use crate::targets::{FrameTargets, Target};
use crate::view::{camera_view_proj, lit_scene};
use crate::voxel::dense::{DensePipelines, DenseVolume, SLOT_BYTES};
use crate::voxel::octree::{OctreePipelines, OctreePools, OctreeVolume};
use crate::voxel::{DebugView, Filtering, GpuCones, Grid, POOL_COUNTERS, VoxelKind, Voxels};
use crate::{Error, Result};
use glam::{Mat4, Vec3};
use std::sync::Arc;
use voxgi_scene::{Aabb, Camera, Light, Scene, pointcloud};
use wgpu::util::DeviceExt;

/// The timing scopes of the voxel update (what depends on the scene and its lights, not on the
/// camera), in the order they run; every other pass is the screen's.
pub const VOXEL_PASSES: [&str; 12] = [
    "shadow",
    "moments",
    "voxelize",
    "splat",
    "dense_build",
    "dense_update",
    "octree_build",
    "octree_update",
    "inject",
    "filter",
    "octree_filter",
    "bounce",
];

/// Every pass, by name.
struct Passes {
    shadow: ShadowPass,
    moments: MomentsPass,
    voxelize: VoxelizePass,
    splat: SplatPass,
    inject: InjectPass,
    bounce: BouncePass,
    gbuffer: GbufferPass,
    gather: GatherPass,
    upsample: UpsamplePass,
    composite: CompositePass,
    tonemap: TonemapPass,
}

/// Voxel statistics of a build, as the GPU counted them.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct VoxelCounts {
    /// Fragments voxelization emitted (kept or not).
    pub fragments: u64,
    /// Voxels at least one fragment fell into.
    pub occupied: u64,
}

/// `estimate_point_attributes` when a point cloud lacks any, on a copy of the scene. The
/// renderer and the path tracer both call it, so both see the same points.
pub(crate) fn complete_point_attributes(scene: &mut std::borrow::Cow<'_, Scene>) {
    if scene.point_clouds.iter().any(|pc| {
        !pc.positions.is_empty()
            && (pc.normals.is_empty() || pc.radii.is_empty() || pc.regions.is_empty())
    }) {
        prepare_points(scene.to_mut());
    }
}

/// How long `prepare_points` took for each attribute, summed over the clouds.
#[derive(Clone, Copy, Debug, Default)]
pub struct PointPreparation {
    /// Points whose attributes were estimated.
    pub points: usize,
    /// Normal estimation (PCA over 16 neighbours).
    pub normals: std::time::Duration,
    /// Regions of influence (8 neighbours).
    pub regions: std::time::Duration,
    /// Disc radii (8 neighbours).
    pub radii: std::time::Duration,
}

/// Fills in normals (k = 16), regions of influence and disc radii (k = 8) of point clouds that
/// lack them, as `Renderer::new` does (call it first to time it, or to keep the result for
/// several renderers). Normals face the cloud's local origin when that lies outside the
/// cloud's bounds (scanners put the sensor there), else the default camera.
pub fn prepare_points(scene: &mut Scene) -> PointPreparation {
    let mut timing = PointPreparation::default();
    let camera = scene
        .cameras
        .first()
        .cloned()
        .unwrap_or_else(|| scene.default_camera())
        .position;
    for pc in &mut scene.point_clouds {
        if pc.positions.is_empty()
            || (!pc.normals.is_empty() && !pc.radii.is_empty() && !pc.regions.is_empty())
        {
            continue;
        }
        let start = std::time::Instant::now();
        let mut local = Aabb::EMPTY;
        for &p in &pc.positions {
            local.grow(p);
        }
        let origin_outside = (0..3).any(|a| local.min[a] > 0.0 || local.max[a] < 0.0);
        // `estimate_normals` takes the viewpoint in world space.
        let viewpoint = if origin_outside {
            pc.transform.transform_point3(Vec3::ZERO)
        } else {
            camera
        };
        let what: Vec<&str> = [
            (pc.normals.is_empty(), "normals"),
            (pc.radii.is_empty(), "radii"),
            (pc.regions.is_empty(), "regions of influence"),
        ]
        .into_iter()
        .filter_map(|(missing, name)| missing.then_some(name))
        .collect();
        let what = what.join(", ");
        timing.points += pc.positions.len();
        let t = std::time::Instant::now();
        pointcloud::estimate_normals(pc, 16, viewpoint);
        timing.normals += t.elapsed();
        // Regions first: they take the file's radii, not estimated ones.
        let t = std::time::Instant::now();
        pointcloud::estimate_regions(pc, 8);
        timing.regions += t.elapsed();
        let t = std::time::Instant::now();
        pointcloud::estimate_radii(pc, 8);
        timing.radii += t.elapsed();
        log::info!(
            "point cloud '{}': estimated {what} of {} points in {:.2} s (normals facing {})",
            pc.name,
            pc.positions.len(),
            start.elapsed().as_secs_f64(),
            if origin_outside {
                "the cloud's origin"
            } else {
                "the default camera"
            }
        );
    }
    timing
}

/// A scene uploaded to the GPU, ready to render from any camera into the caller's targets.
///
/// The application owns the device: voxgi creates its resources on the `wgpu::Device` it is
/// given, records into the caller's `CommandEncoder` and installs no handlers on the device.
pub struct Renderer {
    device: wgpu::Device,
    queue: wgpu::Queue,
    options: RendererOptions,
    scene: GpuScene,
    atlas: ShadowAtlas,
    passes: Passes,
    brdf_tables: BrdfTables,
    /// The layout of the screen passes' `@group(0)` (`globals`).
    globals_layout: wgpu::BindGroupLayout,
    fragments: Fragments,
    /// The voxel structure: every pass reaches it through `VoxelStructure`; only its creation
    /// (and `volume()`, for tests) names its kind.
    volume: Voxels,
    structure_pipelines: StructurePipelines,
    /// Voxelize's triangle tables: the static instances' and the dynamic ones'.
    static_triangles: TriangleTable,
    dynamic_triangles: TriangleTable,
    cones: wgpu::Buffer,
    /// Voxel bounces per update (`voxel_bounce_count`: with cones the per-pixel gather adds the
    /// last bounce; with leaves the last of these keeps the records and is not stored).
    voxel_bounces: u32,
    /// What changed since the voxels and shadow maps were last brought up to date.
    pending: Pending,
    /// Progressive bounces still to run before the voxel light has converged.
    progressive_left: u32,
    /// Frames rendered, for `voxel_update_interval`.
    frame_index: u64,
    /// Instances, lights and animations as last set.
    state: SceneState,
    counters: CounterReadback,
    /// Counts every replacement of the fragments or the volume, so that counters read back
    /// from pools that are gone are not acted on.
    pools: u64,
    last_counts: Option<VoxelCounts>,
    timer: GpuTimer,
    targets: Option<FrameTargets>,
    center: Vec3,
    radius: f32,
    default_camera: Camera,
    /// What option changes need from the scene, kept instead of the scene itself.
    facts: SceneFacts,
}

/// What changed since the last voxel update.
#[derive(Default)]
struct Pending {
    /// Everything: the static geometry too, and every shadow view.
    rebuild: bool,
    /// Dynamic geometry moved.
    geometry: bool,
    /// A light changed.
    lights: bool,
    /// What of each shadow view (by atlas layer) to re-render; consumed every frame, unlike
    /// the rest, which waits for the next voxel update.
    views: Vec<ViewDirt>,
    /// What of each view changed since the last injection: the leaves reading only texels
    /// outside it keep their direct light.
    inject_views: Vec<ViewDirt>,
    /// Where dynamic geometry was or is now since the last injection (world space): leaves
    /// there are re-injected, their voxels may have changed.
    moved: Option<Aabb>,
}

impl Pending {
    /// Everything out of date, for an atlas of `views` views.
    fn everything(views: usize) -> Self {
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

/// What `set_options` needs to know of the scene to rebuild what an option feeds.
struct SceneFacts {
    /// Everything the scene draws at any time (what animations move, at all their poses).
    bounds: Aabb,
    /// Whether any instance is dynamic.
    dynamic: bool,
    estimate: FragmentEstimate,
    /// The largest albedo of any material (the unlimited-bounce count's convergence).
    max_albedo: f32,
    /// Which lights cast shadows, in the scene's order.
    casts: Vec<bool>,
    /// Whether any surface may have a specular lobe.
    glossy: bool,
}

impl Renderer {
    /// Uploads `scene` to `device`. A scene with nothing to draw (no triangles, no points) is
    /// an error; a scene with no light at all gets a default sun (when
    /// `options.default_light`) so it does not render black. Point clouds without normals or
    /// radii get estimated ones. The device must offer `required_limits`' minimum
    /// (`Error::DeviceLimits` names what it lacks).
    pub fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        scene: &Scene,
        options: &RendererOptions,
    ) -> Result<Self> {
        options.validate()?;
        requirements::check_device(device)?;
        scene.validate()?;
        if scene.triangle_count() == 0 && scene.point_count() == 0 {
            return Err(Error::EmptyScene);
        }
        let mut scene = lit_scene(scene, options.default_light);
        complete_point_attributes(&mut scene);
        let scene = scene.as_ref();
        let mut gpu_scene = checked(device, "scene upload", || {
            GpuScene::new(device, queue, scene, options)
        })??;
        let state = SceneState::new(scene, &gpu_scene.instance_draw);
        let bounds = state.swept_bounds(scene);
        let (center, radius) = bounding_sphere(bounds);
        let facts = SceneFacts {
            bounds,
            dynamic: scene.instances.iter().any(|i| i.dynamic),
            estimate: FragmentEstimate::of(scene),
            max_albedo: scene
                .materials
                .iter()
                .map(|m| m.base_color[0].max(m.base_color[1]).max(m.base_color[2]))
                .fold(0.0f32, f32::max),
            casts: scene.lights.iter().map(|l| l.cast_shadows).collect(),
            glossy: gather::has_glossy(scene, gpu_scene.point_count),
        };
        let atlas = plan_atlas(
            device,
            queue,
            &mut gpu_scene,
            &facts,
            options,
            center,
            radius,
        )?;
        let grid = grid(&facts, options);
        let fragments = new_fragments(device, &facts, options, grid, None)?;
        let mut structure_pipelines = StructurePipelines::default();
        let volume = new_volume(device, &mut structure_pipelines, &facts, options, grid)?;
        let passes = checked(device, "pipeline creation", || Passes {
            shadow: ShadowPass::new(device),
            moments: MomentsPass::new(device),
            voxelize: VoxelizePass::new(device),
            splat: SplatPass::new(device),
            inject: InjectPass::new(
                device,
                options.voxels,
                gpu_scene.light_count,
                atlas.views.len(),
                options.shadow_filter,
            ),
            bounce: BouncePass::new(device, options.voxels, options.anisotropic, leaves(options)),
            gbuffer: GbufferPass::new(device),
            gather: GatherPass::new(device, options, facts.glossy),
            upsample: UpsamplePass::new(device),
            composite: composite_pass(device, &gpu_scene, &facts, options),
            tonemap: TonemapPass::new(device),
        })?;
        let (static_triangles, dynamic_triangles) = checked(device, "voxelization table", || {
            Ok::<_, Error>((
                triangle_table(device, &gpu_scene, false)?,
                triangle_table(device, &gpu_scene, true)?,
            ))
        })??;
        let brdf_tables = BrdfTables::new(device, queue);
        let voxel_bounces = voxel_bounce_count(facts.max_albedo, options);
        let cones = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("cones"),
            contents: bytemuck::bytes_of(&cone_uniforms(options, &grid)),
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        });
        // From the swept bounds, so that it is the same at every time of an animation.
        let default_camera = scene
            .cameras
            .first()
            .cloned()
            .unwrap_or_else(|| Camera::viewing(bounds));
        let views = atlas.views.len();
        Ok(Renderer {
            device: device.clone(),
            queue: queue.clone(),
            options: options.clone(),
            scene: gpu_scene,
            atlas,
            passes,
            brdf_tables,
            globals_layout: crate::globals::layout(device),
            fragments,
            volume,
            structure_pipelines,
            static_triangles,
            dynamic_triangles,
            cones,
            voxel_bounces,
            pending: Pending::everything(views),
            progressive_left: 0,
            frame_index: 0,
            state,
            counters: CounterReadback::new("voxel counters readback", 1 + POOL_COUNTERS),
            pools: 0,
            last_counts: None,
            timer: GpuTimer::disabled(queue),
            targets: None,
            center,
            radius,
            default_camera,
            facts,
        })
    }

    /// Changes the options, rebuilding only what depends on the ones that changed: the fragments
    /// for the resolution, the volume for its resolution or anisotropy, the shadow atlas for
    /// its size or cone shadows, the gather, bounce and composite pipelines for what they are
    /// specialised on; cone and AO parameters and the bounce count are uniform writes. Voxel
    /// work is redone in the next frame only if something it depends on changed.
    /// `max_texture_size` and `default_light` shape the uploaded scene: changing them is an
    /// error (make a new renderer). `fragment_capacity` and `voxel_capacity` size a pool when
    /// it is made anew (here, for a new resolution or anisotropy), not the pools in use.
    pub fn set_options(&mut self, options: &RendererOptions) -> Result<()> {
        options.validate()?;
        let (old, new) = (&self.options, options);
        if old.max_texture_size != new.max_texture_size || old.default_light != new.default_light {
            return Err(Error::Setting(
                "max_texture_size and default_light shape the uploaded scene: make a new \
                 Renderer to change them"
                    .into(),
            ));
        }
        let device = &self.device;
        let kind = old.voxels != new.voxels;
        let volume = kind
            || old.voxel_resolution != new.voxel_resolution
            || old.anisotropic != new.anisotropic
            || old.ndf_mips != new.ndf_mips;
        let atlas = old.shadow_map_size != new.shadow_map_size
            || old.cone_shadows != new.cone_shadows
            || old.shadow_filter != new.shadow_filter
            || shadow::atlas_resolution(old, &self.scene.gpu_lights)
                != shadow::atlas_resolution(new, &self.scene.gpu_lights);
        let cones = volume
            || old.cones != new.cones
            || old.step_factor != new.step_factor
            || old.max_distance != new.max_distance
            || old.ao_radius != new.ao_radius
            || old.ao_lambda != new.ao_lambda
            || old.origin_offset != new.origin_offset
            || old.bounces != new.bounces
            || old.indirect != new.indirect;
        let grid = grid(&self.facts, new);
        // Build everything first, so a failure leaves the renderer as it was.
        let atlas_new = if atlas {
            Some(plan_atlas(
                device,
                &self.queue,
                &mut self.scene,
                &self.facts,
                new,
                self.center,
                self.radius,
            )?)
        } else {
            None
        };
        // The fragments depend on the grid only: a change of anisotropy keeps their grown pool.
        let fragments_new = if old.voxel_resolution != new.voxel_resolution {
            Some(new_fragments(device, &self.facts, new, grid, None)?)
        } else {
            None
        };
        let volume_new = if volume {
            Some(new_volume(
                device,
                &mut self.structure_pipelines,
                &self.facts,
                new,
                grid,
            )?)
        } else {
            None
        };
        let indirect = old.indirect != new.indirect;
        let filter = old.shadow_filter != new.shadow_filter;
        let gather = volume || old.gather_axes != new.gather_axes || indirect;
        let views = self.atlas.views.len();
        let (gather_new, bounce_new, composite_new, inject_new) =
            checked(device, "pipeline creation", || {
                (
                    gather.then(|| GatherPass::new(device, new, self.facts.glossy)),
                    (kind || old.anisotropic != new.anisotropic || indirect)
                        .then(|| BouncePass::new(device, new.voxels, new.anisotropic, leaves(new))),
                    (old.cone_shadows != new.cone_shadows || filter)
                        .then(|| composite_pass(device, &self.scene, &self.facts, new)),
                    (kind || filter).then(|| {
                        InjectPass::new(
                            device,
                            new.voxels,
                            self.scene.light_count,
                            views,
                            new.shadow_filter,
                        )
                    }),
                )
            })?;
        if let Some(a) = atlas_new {
            self.atlas = a;
        }
        if let Some(f) = fragments_new {
            self.fragments = f;
        }
        if let Some(v) = volume_new {
            self.volume = v;
            self.pools += 1;
        }
        if let Some(p) = gather_new {
            self.passes.gather = p;
        }
        if let Some(p) = bounce_new {
            self.passes.bounce = p;
        }
        if let Some(p) = composite_new {
            self.passes.composite = p;
        }
        if let Some(p) = inject_new {
            self.passes.inject = p;
        }
        if cones {
            self.queue.write_buffer(
                &self.cones,
                0,
                bytemuck::bytes_of(&cone_uniforms(new, &grid)),
            );
            self.voxel_bounces = voxel_bounce_count(self.facts.max_albedo, new);
        }
        // The gather's resolution needs no work here: the next frame makes targets to match.
        let progressive = old.progressive != new.progressive;
        self.options = options.clone();
        if volume || atlas || cones || progressive {
            self.invalidate();
        }
        Ok(())
    }

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
        let (old, new) = (
            inst.world_bounds(inst.transform),
            inst.world_bounds(transform),
        );
        if let Some(draw) = inst.draw {
            self.scene.set_transform(&self.queue, draw, transform);
            for i in 0..self.atlas.views.len() {
                let v = &self.atlas.views[i];
                let dirt = shadow::box_dirt(v, old.min, old.max)
                    .merge(shadow::box_dirt(v, new.min, new.max));
                self.pending.view(i, dirt);
            }
            let moved = old.union(&new);
            self.pending.moved = Some(self.pending.moved.map_or(moved, |m| m.union(&moved)));
            self.pending.geometry = true;
        }
        self.state.instances[instance].transform = transform;
        Ok(())
    }

    /// Changes light `index` (into the scene's lights) to `light`: its position, direction,
    /// colour, intensity, range, cone angles or area shape. Its kind (directional, point,
    /// spot, area) and whether it casts shadows are fixed once uploaded (an error: make a new
    /// `Renderer`). The light's shadow views re-render and the voxel light is redone.
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
        self.scene.gpu_lights[index] = g;
        self.state.lights[index] = light.clone();
        // Re-plan every view (a light's views follow its position and direction) and re-render
        // those that changed: the moved light's.
        let res = self.atlas.texture.width();
        let (views, _) = shadow::plan_views(
            &mut self.scene.gpu_lights,
            &self.facts.casts,
            self.center,
            self.radius,
            res,
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

    /// Sets the scene's time, in seconds: every animation moves its instances and lights to
    /// their state at `t` (`Scene::set_time`), through `set_instance_transform` and
    /// `set_light`. Only what changed is updated.
    pub fn set_time(&mut self, t: f32) -> Result<()> {
        let changes = self.state.set_time(t)?;
        for (i, m) in changes.instances {
            self.set_instance_transform(i, m)?;
        }
        for (l, light) in changes.lights {
            self.set_light(l, &light)?;
        }
        Ok(())
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

    /// Whether the voxels (or progressive bounces) still have work queued for a coming frame:
    /// false once everything set so far is in the voxels and the light has converged.
    pub fn voxels_settled(&self) -> bool {
        !self.voxel_work_pending()
    }

    /// Whether rendering again with the same frame parameters and target would give the same
    /// image: the voxels are settled and no voxel counter is still on its way back (one that
    /// overflowed would make the next frame rebuild). An application may then show its last
    /// image instead of rendering.
    pub fn is_idle(&self) -> bool {
        self.voxels_settled() && !self.counters.pending()
    }

    /// Whether a voxel counter read back is submitted but has not completed (`headless::render`
    /// waits for it before deciding that a frame is final).
    pub(crate) fn feedback_in_flight(&self) -> bool {
        self.counters.in_flight()
    }

    /// The scene's own camera, or a view of its bounds.
    pub fn default_camera(&self) -> &Camera {
        &self.default_camera
    }

    /// The options this renderer was made with.
    pub fn options(&self) -> &RendererOptions {
        &self.options
    }

    /// Bytes of GPU memory per resource.
    pub fn memory(&self) -> Vec<(&'static str, u64)> {
        let mut m = self.scene.memory();
        m.push(("shadow atlas", self.atlas.bytes()));
        m.extend(self.fragments.memory());
        m.extend(self.volume.get().memory());
        if let Some(t) = &self.targets {
            m.push(("render targets", t.bytes()));
        }
        m
    }

    fn frame_uniforms(&self, p: &FrameParams, width: u32, height: u32) -> GpuFrame {
        let view_proj = camera_view_proj(&p.camera, width, height, self.center, self.radius);
        GpuFrame {
            view_proj: view_proj.to_cols_array_2d(),
            inv_view_proj: view_proj.inverse().to_cols_array_2d(),
            camera_pos: p.camera.position.to_array(),
            light_count: self.scene.light_count,
            size: [width as f32, height as f32],
            inv_size: [1.0 / width as f32, 1.0 / height as f32],
            exposure: 2f32.powf(p.exposure),
            tonemap: p.tonemap.id(),
            shadow_softness: p.shadow_softness,
            // The debug pass draws the voxel views; composite writes the lit image underneath.
            view_mode: p.view.id(),
            background: [p.background[0], p.background[1], p.background[2], 1.0],
            cone_shadows: self.options.cone_shadows as u32,
            geometry_points: self.scene.geometry_points,
            _pad: [0; 2],
        }
    }

    /// Records the shadow views that must be re-rendered (all after a rebuild).
    fn record_shadows(&mut self, encoder: &mut wgpu::CommandEncoder) {
        let views = std::mem::take(&mut self.pending.views);
        if views.iter().any(|&v| v != ViewDirt::Clean) {
            self.passes.shadow.record(
                &self.device,
                encoder,
                &self.atlas,
                &self.scene,
                &views,
                &mut self.timer,
            );
            if self.options.shadow_filter == ShadowFilter::VsmEsm {
                self.passes.moments.record(
                    &self.device,
                    encoder,
                    &self.atlas,
                    &views,
                    &mut self.timer,
                );
            }
        }
        self.pending.views = vec![ViewDirt::Clean; self.atlas.views.len()];
    }

    /// Whether the next voxel update has work: something changed, or progressive bounces
    /// have not converged.
    fn voxel_work_pending(&self) -> bool {
        let p = &self.pending;
        p.rebuild || p.geometry || p.lights || self.progressive_left > 0
    }

    /// Records what the changes since the last voxel update need, in the fixed order:
    /// voxelize the static geometry and build (after a rebuild), voxelize the dynamic geometry
    /// and update (after it moved), inject, then filter and bounce; with progressive bounces,
    /// one bounce per update until converged.
    fn record_voxels(&mut self, encoder: &mut wgpu::CommandEncoder) {
        let timer = &mut self.timer;
        let p = &self.passes;
        let pending = std::mem::take(&mut self.pending);
        let geometry = pending.rebuild || pending.geometry;
        if pending.rebuild {
            self.fragments.record_clear(encoder);
            let t = &self.static_triangles;
            p.voxelize.record(
                &self.device,
                encoder,
                &self.scene,
                t,
                &self.fragments,
                timer,
            );
            // Point clouds are static: the renderer places them once.
            p.splat
                .record(&self.device, encoder, &self.scene, &self.fragments, timer);
            self.fragments.record_mark(encoder);
            self.volume
                .get()
                .record_build(&self.device, encoder, &self.fragments, timer);
        }
        if geometry && self.facts.dynamic {
            self.fragments.record_truncate(encoder);
            let t = &self.dynamic_triangles;
            p.voxelize.record(
                &self.device,
                encoder,
                &self.scene,
                t,
                &self.fragments,
                timer,
            );
            self.volume
                .get()
                .record_update(&self.device, encoder, &self.fragments, timer);
        }
        if geometry {
            // The kernels never write past their buffers, they only count: the counts come
            // back a frame or more later and grow the pools then (`receive_feedback`).
            if !self.counters.request(
                &self.device,
                encoder,
                &[
                    (&self.fragments.count, 1),
                    (self.volume.get().pool_counter(), POOL_COUNTERS),
                ],
                self.pools,
            ) {
                log::warn!(
                    "voxel counters: too many readbacks in flight; is the encoder submitted?"
                );
            }
        }
        let progressive = self.options.progressive;
        // One bounce, and the filtering its stored light needs.
        let bounce =
            |encoder: &mut wgpu::CommandEncoder, timer: &mut GpuTimer, steps: BounceSteps| {
                let volume = self.volume.get();
                p.bounce
                    .record(&self.device, encoder, volume, &self.cones, steps, timer);
                if steps.store {
                    volume.record_filter(&self.device, encoder, timer);
                }
            };
        if geometry || pending.lights {
            p.inject.prepare(
                &self.queue,
                pending.rebuild || pending.lights,
                // Stored bounces overwrite the radiance: it must start from the direct light
                // again.
                stored_bounces(&self.options, self.voxel_bounces) > 0,
                pending.moved,
                &pending.inject_views,
                self.atlas.texture.width(),
            );
            let inject = if progressive {
                InjectPass::record_direct_only
            } else {
                InjectPass::record
            };
            inject(
                &p.inject,
                &self.device,
                encoder,
                &self.scene,
                &self.atlas,
                self.volume.get(),
                timer,
            );
            if progressive {
                // One bounce per update from the previous update's light; after a change
                // this many updates make every leaf's light converge again (the first from
                // a cleared volume only reproduces the direct light).
                self.progressive_left = self.voxel_bounces + 1;
            } else {
                self.volume
                    .get()
                    .record_filter(&self.device, encoder, timer);
                let n = self.voxel_bounces;
                for i in 0..n {
                    // With leaves the last bounce's light is what the pixels read: it keeps
                    // the irradiance and need not be stored or filtered (the glossy cones
                    // then see the same light as with cones).
                    let last = leaves(&self.options) && i + 1 == n;
                    let steps = BounceSteps {
                        irradiance: last,
                        store: !last,
                    };
                    bounce(encoder, timer, steps);
                }
            }
        }
        if progressive && self.progressive_left > 0 {
            // Every step is stored (the next builds on it) and, with leaves, keeps the records
            // too, so pixels follow the light as it converges. Its bundles are then turned by
            // the records' layout and it traces occlusion at every step; the converged light
            // is the same as without (the last bounces add less than 0.1 %), not bit for bit.
            let steps = BounceSteps {
                irradiance: leaves(&self.options),
                store: true,
            };
            bounce(encoder, timer, steps);
            self.progressive_left -= 1;
        }
        // The shadow views were consumed by `record_shadows` this frame; injection's start over.
        self.pending.views = pending.views;
        self.pending.inject_views = vec![ViewDirt::Clean; self.atlas.views.len()];
    }

    /// Acts on voxel counters that have come back since the last call: when a build had more
    /// fragments or occupied voxels than room, the pools grow to fit and the voxels are rebuilt
    /// in the next frame. Never waits; `render` calls it first. Returns whether the next frame
    /// rebuilds the voxels.
    pub fn receive_feedback(&mut self) -> Result<bool> {
        // Non-blocking: runs the callbacks of maps that have completed.
        let _ = self.device.poll(wgpu::PollType::Poll);
        for (pools, words) in self.counters.take_ready() {
            if pools != self.pools {
                continue;
            }
            let counts = VoxelCounts {
                fragments: words[0] as u64,
                occupied: words[1] as u64,
            };
            let mut pools = [0u32; POOL_COUNTERS];
            pools.copy_from_slice(&words[1..1 + POOL_COUNTERS]);
            self.last_counts = Some(counts);
            let frags = self.fragments.capacity as u64;
            let grow_volume = self.volume.get().needs_growth(&pools);
            if counts.fragments <= frags && !grow_volume {
                continue;
            }
            // Build what grows first and swap it in only when all of it succeeded. A count
            // past this device's limits is an error here (once per overflowing build), not a
            // pool grown to the limit and rebuilt forever.
            let fragments = if counts.fragments > frags {
                let capacity = fragments::capacity(&self.device, counts.fragments)?;
                let grid = self.fragments.grid;
                Some(checked(&self.device, "voxel fragments", || {
                    Fragments::new(&self.device, grid, capacity)
                })?)
            } else {
                None
            };
            if grow_volume {
                self.volume.get_mut().grow(&self.device, &pools)?;
            }
            if let Some(f) = fragments {
                self.fragments = f;
            }
            self.pools += 1;
            log::info!(
                "voxels: {} fragments, {} occupied voxels: growing the pools to {} fragments \
                 and {} voxels and rebuilding",
                counts.fragments,
                counts.occupied,
                self.fragments.capacity,
                self.volume.get().leaf_capacity()
            );
            self.invalidate();
        }
        Ok(self.pending.rebuild)
    }

    /// Voxel statistics of the most recent build whose counters have come back.
    pub fn last_voxel_counts(&self) -> Option<VoxelCounts> {
        self.last_counts
    }

    /// Voxel statistics of the last build, read back now. This waits for the GPU: it is for
    /// tools and tests, never called by a frame.
    pub fn voxel_counts(&self) -> Result<VoxelCounts> {
        let read = |b: &wgpu::Buffer| -> Result<u64> {
            let bytes = readback::read_buffer_copy(&self.device, &self.queue, b)?;
            Ok(bytemuck::cast_slice::<u8, u32>(&bytes)[0] as u64)
        };
        Ok(VoxelCounts {
            fragments: read(&self.fragments.count)?,
            occupied: read(self.volume.get().pool_counter())?,
        })
    }

    /// The fragments of the last build, for tests and debugging.
    pub fn fragments(&self) -> &Fragments {
        &self.fragments
    }

    /// The voxel structure, for tests and debugging.
    pub fn volume(&self) -> &Voxels {
        &self.volume
    }

    /// Turns per-pass GPU timing on or off (when the device has `TIMESTAMP_QUERY`).
    pub fn enable_timing(&mut self, on: bool) {
        self.timer = GpuTimer::new(&self.device, &self.queue, on);
    }

    /// Milliseconds per pass of everything recorded since the last call, once it has been
    /// submitted. This waits for the GPU (for `voxgi bench`).
    pub fn pass_times(&mut self) -> Result<Vec<(&'static str, f64)>> {
        self.timer.read(&self.device)
    }

    /// Marks everything as changed: the next frame re-renders every shadow view and rebuilds
    /// the voxels, static geometry included.
    pub fn invalidate(&mut self) {
        self.pending = Pending::everything(self.atlas.views.len());
    }

    /// The linear HDR radiance of the last frame (before exposure and tone mapping),
    /// `Rgba32Float` at the last target's size, with `COPY_SRC` and `TEXTURE_BINDING` usage.
    pub fn hdr_texture(&self) -> Option<&wgpu::Texture> {
        self.targets.as_ref().map(|t| &t.hdr_texture)
    }

    /// Records one frame into `encoder` and writes the tone-mapped image into `target` (its
    /// whole extent). Submit the encoder before the next call: the frame's uniforms are written
    /// through the queue, so two frames in one submission would share the last one's; and a
    /// frame that records the voxel update counts on that encoder being submitted (dropped,
    /// the update is lost until the next `invalidate`).
    ///
    /// The target's texture needs `TextureUsages::RENDER_ATTACHMENT` (nothing else), in a
    /// renderable colour format: `Bgra8UnormSrgb` or `Rgba8UnormSrgb` (a swapchain's; the GPU
    /// encodes sRGB), `Rgba8Unorm` or `Bgra8Unorm` (voxgi applies the sRGB curve), or a float
    /// format such as `Rgba16Float` (tone-mapped linear values). Its previous contents are
    /// overwritten. The first frame in a new format creates that format's pipeline.
    ///
    /// On the first frame (and after `invalidate`, a pool's growth or a voxel option's change)
    /// this also records the voxel update. Nothing here waits for the GPU.
    pub fn render(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        target: &Target,
        params: &FrameParams,
    ) -> Result<()> {
        let (width, height) = (target.width, target.height);
        validate_size(width, height)?;
        params.validate(self.options.voxel_levels())?;
        self.receive_feedback()?;
        self.passes.tonemap.prepare(&self.device, target.format)?;
        let half = self.options.half_resolution;
        if self
            .targets
            .as_ref()
            .is_none_or(|t| t.width != width || t.height != height || t.half != half)
        {
            // Out of memory for large sizes is an error here, not the device's handler's.
            self.targets = Some(checked(&self.device, "render targets", || {
                FrameTargets::new(&self.device, width, height, half)
            })?);
        }
        self.record_shadows(encoder);
        let interval = self.options.voxel_update_interval.max(1) as u64;
        // A rebuild (the first frame among them) never waits for its turn.
        if self.voxel_work_pending()
            && (self.pending.rebuild || self.frame_index.is_multiple_of(interval))
        {
            self.record_voxels(encoder);
        }
        self.frame_index += 1;
        let frame = self.frame_uniforms(params, width, height);
        let t = self.targets.as_ref().expect("targets were just created");
        self.queue
            .write_buffer(&t.frame, 0, bytemuck::bytes_of(&frame));
        let globals = crate::globals::bind_group(
            &self.device,
            &self.globals_layout,
            &crate::globals::GlobalsSources {
                targets: t,
                cones: &self.cones,
                scene: &self.scene,
                atlas: &self.atlas,
                tables: &self.brdf_tables,
            },
        );
        let timer = &mut self.timer;
        let p = &self.passes;
        p.gbuffer
            .record(&self.device, encoder, t, &self.scene, timer);
        p.gather
            .record(&self.device, encoder, t, &globals, self.volume.get(), timer);
        p.upsample.record(&self.device, encoder, t, &globals, timer);
        p.composite
            .record(&self.device, encoder, t, &globals, timer);
        // Only for the voxel views: replaces the composite's output.
        if params.view.is_voxel() {
            self.volume.get().record_debug(
                &self.device,
                encoder,
                t,
                DebugView {
                    mode: params.view,
                    level: params.debug_level,
                    direction: params.debug_direction,
                },
                timer,
            );
        }
        p.tonemap
            .record(&self.device, encoder, t, &globals, target, timer);
        timer.resolve(encoder);
        Ok(())
    }
}

/// The volume's grid around the scene.
fn grid(facts: &SceneFacts, options: &RendererOptions) -> Grid {
    Grid::around(facts.bounds.min, facts.bounds.max, options.voxel_resolution)
}

/// The fragment buffer on `grid`, with room for `capacity` fragments, or for as many as the
/// options or the scene's estimate say.
fn new_fragments(
    device: &wgpu::Device,
    facts: &SceneFacts,
    options: &RendererOptions,
    grid: Grid,
    capacity: Option<u64>,
) -> Result<Fragments> {
    let wanted = capacity
        .or(options.fragment_capacity)
        .unwrap_or_else(|| facts.estimate.at(&grid));
    let capacity = fragments::capacity(
        device,
        wanted.min(crate::gpu::max_entries(device, fragments::FRAGMENT_BYTES)),
    )?;
    checked(device, "voxel fragments", || {
        Fragments::new(device, grid, capacity)
    })
}

/// The structures' own pipelines, each made when a structure of its kind is first made and
/// shared by every one made after it (a structure is remade whenever it grows).
#[derive(Default)]
struct StructurePipelines {
    dense: Option<Arc<DensePipelines>>,
    octree: Option<Arc<OctreePipelines>>,
}

/// The structure `options.voxels` names on `grid`, with pools for as many occupied voxels as
/// the options or the scene's estimate say.
fn new_volume(
    device: &wgpu::Device,
    pipelines: &mut StructurePipelines,
    facts: &SceneFacts,
    options: &RendererOptions,
    grid: Grid,
) -> Result<Voxels> {
    // Slots: at most one per voxel, usually far fewer than fragments, and the fragment
    // estimate is itself an upper bound. Start at a quarter; the first build's counters grow
    // the pools to the exact count if that is short.
    let wanted = options
        .voxel_capacity
        .unwrap_or_else(|| facts.estimate.at(&grid) / 4)
        .min((grid.resolution as u64).pow(3));
    match options.voxels {
        VoxelKind::Dense => {
            check_volume_fits(device, &grid)?;
            let slots = slot_capacity(
                device,
                wanted.min(crate::gpu::max_entries(device, SLOT_BYTES)),
            )?;
            let p = match &pipelines.dense {
                Some(p) => p.clone(),
                None => checked(device, "pipeline creation", || DensePipelines::new(device))?,
            };
            pipelines.dense = Some(p.clone());
            let v = checked(device, "voxel volume", || {
                DenseVolume::new(device, &p, grid, filtering(options), slots, facts.dynamic)
            })?;
            Ok(Voxels::Dense(v))
        }
        VoxelKind::Octree => {
            let p = match &pipelines.octree {
                Some(p) => p.clone(),
                None => checked(device, "pipeline creation", || OctreePipelines::new(device))?,
            };
            pipelines.octree = Some(p.clone());
            let l = device.limits();
            let pools = OctreePools::for_leaves(wanted)
                .within(l.max_storage_buffer_binding_size.min(l.max_buffer_size));
            let v = checked(device, "voxel octree", || {
                OctreeVolume::new(device, &p, grid, filtering(options), pools, facts.dynamic)
            })??;
            Ok(Voxels::Octree(v))
        }
    }
}

/// Plans the shadow views for the options (writing each light's views into `scene`'s
/// lights) and makes the atlas that holds them.
fn plan_atlas(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    scene: &mut GpuScene,
    facts: &SceneFacts,
    options: &RendererOptions,
    center: Vec3,
    radius: f32,
) -> Result<ShadowAtlas> {
    checked(device, "shadow atlas", || {
        let res = shadow::atlas_resolution(options, &scene.gpu_lights);
        let (views, owners) =
            shadow::plan_views(&mut scene.gpu_lights, &facts.casts, center, radius, res);
        queue.write_buffer(&scene.lights, 0, bytemuck::cast_slice(&scene.gpu_lights));
        let moments = options.shadow_filter == ShadowFilter::VsmEsm;
        ShadowAtlas::new(device, views, owners, res, moments)
    })
}

fn composite_pass(
    device: &wgpu::Device,
    scene: &GpuScene,
    facts: &SceneFacts,
    options: &RendererOptions,
) -> CompositePass {
    CompositePass::new(
        device,
        shadow::composite_reads_shadow_maps(&scene.gpu_lights, options.cone_shadows),
        facts.glossy,
        options.shadow_filter,
    )
}

/// Checks a slot capacity (occupied voxels) against the device's storage-buffer limit.
fn slot_capacity(device: &wgpu::Device, wanted: u64) -> Result<u32> {
    crate::gpu::pool_capacity(device, wanted, SLOT_BYTES, "occupied voxels")
}

/// Checks that the volume's per-voxel buffers fit the device's limits.
fn check_volume_fits(device: &wgpu::Device, grid: &Grid) -> Result<()> {
    let l = device.limits();
    let occupancy = (grid.resolution as u64).pow(3) * 4;
    if occupancy > l.max_storage_buffer_binding_size {
        return Err(Error::Setting(format!(
            "a {r}³ volume needs a {} MiB occupancy buffer, more than this GPU's {} MiB \
             storage-buffer limit; use a voxel resolution of at most {}",
            occupancy >> 20,
            l.max_storage_buffer_binding_size >> 20,
            ((l.max_storage_buffer_binding_size / 4) as f64)
                .cbrt()
                .log2()
                .floor()
                .exp2() as u32,
            r = grid.resolution
        )));
    }
    if grid.resolution > l.max_texture_dimension_3d {
        return Err(Error::Setting(format!(
            "a {}³ volume exceeds this GPU's 3D texture limit of {}",
            grid.resolution, l.max_texture_dimension_3d
        )));
    }
    Ok(())
}

/// How the structure filters its levels.
fn filtering(options: &RendererOptions) -> Filtering {
    Filtering {
        anisotropic: options.anisotropic,
        ndf: options.ndf_mips,
    }
}

/// Whether the pixels read the leaves' irradiance (the fast shading).
fn leaves(options: &RendererOptions) -> bool {
    options.indirect == IndirectShading::Leaves
}

/// Of `voxel_bounces` per update, those that store their light into the structure: all of them
/// with cones or progressive bounces, all but the last (which keeps the leaves' records) with
/// leaves.
fn stored_bounces(options: &RendererOptions, voxel_bounces: u32) -> u32 {
    if leaves(options) && !options.progressive {
        voxel_bounces.saturating_sub(1)
    } else {
        voxel_bounces
    }
}

/// Voxel-space bounces for a total of `options.bounces` indirect bounces: with cones the
/// per-pixel gather adds one; with leaves every bounce runs in voxel space, and at least one
/// runs (with no indirect light, for the occlusion it keeps).
fn voxel_bounce_count(max_albedo: f32, options: &RendererOptions) -> u32 {
    let in_voxels = |cones: u32| {
        if leaves(options) { cones + 1 } else { cones }
    };
    let bounces = options.bounces;
    if bounces != UNLIMITED_BOUNCES {
        return in_voxels(bounces.saturating_sub(1));
    }
    // Until the energy left, max albedo^k, is below 0.1 %.
    let rho = max_albedo.clamp(0.0, 0.99);
    if rho <= 0.0 {
        return in_voxels(0);
    }
    in_voxels(((1e-3f32.ln() / rho.ln()).ceil() as u32).clamp(1, 64))
}

/// The cone uniforms from the options and the volume.
pub fn cone_uniforms(options: &RendererOptions, grid: &Grid) -> GpuCones {
    let axes = options.cones.axes();
    let weights = options.cones.weights();
    let mut dirs = [[0f32; 4]; 16];
    for (i, (a, w)) in axes.iter().zip(&weights).enumerate().take(16) {
        dirs[i] = [a.x, a.y, a.z, *w];
    }
    GpuCones {
        dirs,
        count: axes.len().min(16) as u32,
        diffuse_tan: (options.cones.aperture() * 0.5).tan(),
        step_factor: options.step_factor,
        max_distance: options.max_distance.unwrap_or(grid.extent() * 3f32.sqrt()),
        ao_lambda: options.ao_lambda,
        ao_radius: options.ao_radius.unwrap_or(grid.extent() * 0.25),
        origin_offset: options.origin_offset,
        indirect: (options.bounces > 0) as u32,
    }
}
