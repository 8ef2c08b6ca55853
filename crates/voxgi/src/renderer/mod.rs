//! The renderer: creation and the public API. It uploads a scene once, then records frames
//! into the caller's encoder. The rest of it lives with its subject: the pass order in
//! `order.rs`, scene updates and what they make out of date in `updates.rs`, the structure's
//! creation in each kind's `KindInfo::create` (`voxel::registry`), bounce counts and cone uniforms in `lighting::{bounces, cones}`.
//!
//! Voxel work follows what changed (DESIGN.md, seam 6). The static geometry is voxelized and
//! built once (on the first frame, after `invalidate`, a pool's growth or a voxel option's
//! change); the dynamic geometry is voxelized and merged in on frames after it moved, undoing
//! the previous merge. Camera motion alone does no voxel work. Overflow counters come back
//! asynchronously (`gpu::feedback`): a build that overflowed is redone a frame later with room
//! for everything, and no frame waits for the GPU.

mod order;
pub use order::PreparedStep;
mod sizing;
mod temporal;

pub use temporal::STILL_FRAMES as TEMPORAL_STILL_FRAMES;
mod updates;
pub use updates::SequenceFrame;

use crate::brdf::BrdfTables;
use crate::fragments::splat::SplatPass;
use crate::fragments::voxelize::VoxelizePass;
use crate::fragments::{self, FragmentEstimate, Fragments, TriangleTable, triangle_table};
use crate::frame::targets::FrameTargets;
use crate::gpu::feedback::CounterReadback;
use crate::gpu::timer::GpuTimer;
use crate::gpu::{checked, readback, requirements};
use crate::gpu_scene::{GpuScene, bounding_sphere};
use crate::lighting::atlas::{self as shadow, ShadowAtlas, plan_atlas};
use crate::lighting::blend::{BlendPass, BlendState};
use crate::lighting::bounce::{BounceGlobals, BouncePass};
use crate::lighting::bounces::{leaves, voxel_bounce_count};
use crate::lighting::cones::cone_uniforms;
use crate::lighting::inject::InjectPass;
use crate::lighting::moments::MomentsPass;
use crate::lighting::shadow::ShadowPass;
use crate::options::RendererOptions;
use crate::scene_state::SceneState;
use crate::screen::composite::CompositePass;
use crate::screen::gather::{self, GatherPass};
use crate::screen::gbuffer::GbufferPass;
use crate::screen::temporal::TemporalPass;
use crate::screen::tonemap::TonemapPass;
use crate::screen::upsample::UpsamplePass;
use crate::settings::{Changes, changes_between};
use crate::view::lit_scene;
use crate::voxel::{Filtering, Grid, POOL_COUNTERS, StructureDesc, VoxelKind, VoxelStructure};
use crate::{Error, Result};
use glam::Vec3;
use sizing::Sizing;
use updates::Pending;
use voxgi_scene::{Aabb, Camera, Scene};
use wgpu::util::DeviceExt;

/// Every pass, by name.
struct Passes {
    shadow: ShadowPass,
    moments: MomentsPass,
    voxelize: VoxelizePass,
    splat: SplatPass,
    inject: InjectPass,
    bounce: BouncePass,
    blend: BlendPass,
    gbuffer: GbufferPass,
    gather: GatherPass,
    upsample: UpsamplePass,
    composite: CompositePass,
    temporal: TemporalPass,
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
    /// The screen passes' bind groups, made on the first frame after what they bind was
    /// replaced.
    binds: Option<order::FrameBinds>,
    /// The bounce pass's bind groups and the leaves' kept irradiance, made on the first bounce
    /// after the structure, the pass or the options were made anew.
    bounce_globals: Option<BounceGlobals>,
    /// The bind groups of voxelize and splat, made on the first voxel update after the
    /// fragments were made anew.
    fragment_binds: Option<Vec<order::FragmentBinds>>,
    /// The shadow and moments passes' bind groups, made on the first shadow render after the
    /// atlas was made anew.
    shadow_binds: Option<order::ShadowBinds>,
    fragments: Fragments,
    /// The voxel structure: every pass reaches it through `VoxelStructure`; only its creation
    /// names its kind.
    volume: Box<dyn VoxelStructure>,
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
    /// With `bounce_slices` > 1: updates still to run after the last change before every leaf
    /// has gathered again (in each bounce, after the bounce before it had).
    slices_left: u32,
    /// The slice of leaves whose bounces gather in the next update.
    bounce_turn: u32,
    /// The leaves' shown light (`lighting::blend`); `None` until a blend step needs it.
    blend: Option<BlendState>,
    /// Blend steps left before the shown light is the last update's.
    blend_left: u32,
    /// Frames rendered, for `voxel_update_interval`.
    frame_index: u64,
    /// Voxel work `prepare` recorded for the next frame.
    prepared: Option<order::Prepared>,
    /// The world-to-clip matrix of the last frame, without its jitter (`depth`).
    drawn_view_proj: glam::Mat4,
    /// Instances, lights and animations as last set.
    state: SceneState,
    counters: CounterReadback,
    /// Counts every replacement of the fragments or the volume, so that counters read back
    /// from pools that are gone are not acted on.
    pools: u64,
    last_counts: Option<VoxelCounts>,
    timer: GpuTimer,
    targets: Option<FrameTargets>,
    /// The temporal history's bookkeeping between frames.
    temporal: temporal::TemporalState,
    /// The sphere around the scene's bulk: the voxels' and the shadow maps' domain.
    center: Vec3,
    radius: f32,
    /// The sphere around everything drawn, strays included: the camera's far plane.
    view: (Vec3, f32),
    default_camera: Camera,
    /// What option changes need from the scene, kept instead of the scene itself.
    facts: SceneFacts,
}

/// What `set_options` needs to know of the scene to rebuild what an option feeds.
struct SceneFacts {
    /// Everything the scene draws at any time (what animations move, at all their poses).
    bounds: Aabb,
    /// Whether any instance or geometry point cloud is dynamic.
    dynamic: bool,
    estimate: FragmentEstimate,
    /// The largest albedo of any material (the unlimited-bounce count's convergence).
    max_albedo: f32,
    /// Which lights cast shadows, in the scene's order.
    casts: Vec<bool>,
    /// Whether any surface may have a specular lobe.
    glossy: bool,
    /// Whether any material is metallic (`GpuScene::metals`).
    metals: bool,
}

impl SceneFacts {
    /// Whether the voxels keep specular lobes: `specular_bounces` and a metal to reflect (in a
    /// scene without one the lobes would all be zero: no slot, block or sample pays for them).
    fn lobes(&self, options: &RendererOptions) -> bool {
        options.specular_bounces && self.metals
    }

    /// The structure `options` ask for on `grid`. Its pools start with room for the options'
    /// voxel capacity, or a quarter of the fragment estimate (slots: at most one per voxel,
    /// usually far fewer than fragments, and the estimate is itself an upper bound); the first
    /// build's counters grow them to the exact count if that is short.
    fn structure_desc(&self, options: &RendererOptions, grid: Grid) -> StructureDesc {
        StructureDesc {
            grid,
            bounds: self.bounds,
            filtering: Filtering {
                anisotropic: options.anisotropic,
                ndf: options.ndf_mips && options.anisotropic,
                lobes: self.lobes(options),
            },
            leaves: options
                .voxel_capacity
                .unwrap_or_else(|| self.estimate.at(&grid) / 4)
                .min((grid.resolution as u64).pow(3)),
            dynamic: self.dynamic,
            levels: options.clipmap_levels,
            voxel_size: options.voxel_size,
        }
    }
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
        voxgi_scene::prepare::complete_point_attributes(&mut scene);
        let scene = scene.as_ref();
        let mut gpu_scene = checked(device, "scene upload", || {
            GpuScene::new(device, queue, scene, options)
        })??;
        let state = SceneState::new(scene, &gpu_scene.instance_draw);
        for d in scene.degenerate() {
            log::warn!("{d}");
        }
        // Its extent was checked by `validate`.
        let (bounds, left_out) = scene.bulk_bounds();
        if !left_out.is_empty() {
            log::warn!(
                "{} far outside the rest of the scene (more than 10 times its size away): the \
                 voxels and the shadow maps cover the rest, so {} no indirect light and \
                 no shadows",
                left_out.join(", "),
                if left_out.len() == 1 {
                    "it gets"
                } else {
                    "they get"
                }
            );
        }
        let (center, radius) = bounding_sphere(bounds);
        let facts = SceneFacts {
            bounds,
            dynamic: scene.instances.iter().any(|i| i.dynamic)
                || scene
                    .point_clouds
                    .iter()
                    .any(|pc| pc.dynamic && pc.light.is_none() && !pc.positions.is_empty()),
            estimate: FragmentEstimate::of(scene),
            max_albedo: scene
                .materials
                .iter()
                .map(|m| m.base_color[0].max(m.base_color[1]).max(m.base_color[2]))
                .fold(0.0f32, f32::max),
            casts: scene.lights.iter().map(|l| l.cast_shadows).collect(),
            glossy: gather::has_glossy(scene, gpu_scene.point_count),
            metals: gpu_scene.metals,
        };
        let across = (facts.bounds.max - facts.bounds.min).max_element();
        if let Some(w) = coarse_voxels(across, &grid(&facts, options), options.voxels) {
            log::warn!("{w}");
        }
        let atlas = plan_atlas(
            device,
            queue,
            &mut gpu_scene,
            &facts.casts,
            options,
            center,
            radius,
        )?;
        let grid = grid(&facts, options);
        for (c, pc) in scene.point_clouds.iter().enumerate() {
            gpu_scene.park_spare(queue, c, pc.positions.len(), parking(&grid));
        }
        let mut volume =
            (options.voxels.info().create)(device, &facts.structure_desc(options, grid), None)?;
        let fragments = allocate_fragments(device, &facts, options, volume.as_ref())?;
        volume.bind_fragments(device, &fragments);
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
            bounce: BouncePass::new(
                device,
                options.voxels,
                options.anisotropic,
                facts.lobes(options),
                leaves(options),
            ),
            blend: BlendPass::new(device, options.voxels),
            gbuffer: GbufferPass::new(device),
            gather: GatherPass::new(device, options, facts.glossy, facts.lobes(options)),
            upsample: UpsamplePass::new(device),
            composite: composite_pass(device, &gpu_scene, &facts, options),
            temporal: TemporalPass::new(device),
            tonemap: TonemapPass::new(device),
        })?;
        let (static_triangles, dynamic_triangles) = checked(device, "voxelization table", || {
            Ok::<_, Error>((
                triangle_table(device, &gpu_scene, false, &grid, volume.grid().voxel_size)?,
                triangle_table(device, &gpu_scene, true, &grid, volume.grid().voxel_size)?,
            ))
        })??;
        let mut fragments = fragments;
        let mut built = false;
        if sizing::in_doubt(device, &facts.estimate, facts.bounds, volume.as_ref()) {
            let sizing = Sizing {
                device,
                queue,
                scene: &gpu_scene,
                triangles: &static_triangles,
                voxelize: &passes.voxelize,
                splat: &passes.splat,
            };
            let (grown, whole) = sizing.fit(&fragments, &mut volume)?;
            if let Some(f) = grown {
                fragments = f;
            }
            built = whole;
        }
        let brdf_tables = BrdfTables::new(device, queue);
        let voxel_bounces = voxel_bounce_count(facts.max_albedo, options);
        let cones = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("cones"),
            contents: bytemuck::bytes_of(&cone_uniforms(options, &grid)),
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        });
        let default_camera = scene.default_camera();
        let views = atlas.views.len();
        Ok(Renderer {
            device: device.clone(),
            queue: queue.clone(),
            options: options.clone(),
            scene: gpu_scene,
            atlas,
            passes,
            brdf_tables,
            globals_layout: crate::frame::globals::layout(device),
            binds: None,
            bounce_globals: None,
            fragment_binds: None,
            shadow_binds: None,
            fragments,
            volume,
            static_triangles,
            dynamic_triangles,
            cones,
            voxel_bounces,
            pending: Pending {
                built,
                ..Pending::everything(views)
            },
            progressive_left: 0,
            slices_left: 0,
            bounce_turn: 0,
            blend: None,
            blend_left: 0,
            frame_index: 0,
            prepared: None,
            drawn_view_proj: glam::Mat4::IDENTITY,
            state,
            counters: CounterReadback::new("voxel counters readback", 1 + POOL_COUNTERS),
            pools: 0,
            last_counts: None,
            timer: GpuTimer::disabled(queue),
            targets: None,
            temporal: Default::default(),
            center,
            radius,
            view: crate::gpu_scene::view_sphere(scene),
            default_camera,
            facts,
        })
    }

    /// Changes the options, rebuilding only what depends on the ones that changed: the fragments
    /// for the resolution, the volume for its resolution or anisotropy, the shadow atlas for
    /// its size or cone shadows, the gather, bounce and composite pipelines for what they are
    /// specialised on; cone and AO parameters and the bounce count are uniform writes. The next
    /// frame's voxel work follows the settings table (`settings::Changes`): a structure or
    /// shadow-map change voxelizes everything again, a lighting change (bounces, cones, AO,
    /// indirect shading, progressive) relights the voxels it has, the others need none.
    /// `max_texture_size` and `default_light` shape the uploaded scene: changing them is an
    /// error (make a new renderer). `fragment_capacity` and `voxel_capacity` size a pool when
    /// it is made anew (here, for a new resolution or anisotropy), not the pools in use.
    pub fn set_options(&mut self, options: &RendererOptions) -> Result<()> {
        options.validate()?;
        let (old, new) = (&self.options, options);
        let changes = changes_between(old, new);
        if changes == Some(Changes::Scene) {
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
            || old.clipmap_levels != new.clipmap_levels
            || old.voxel_size != new.voxel_size
            || old.anisotropic != new.anisotropic
            || old.ndf_mips != new.ndf_mips
            || self.facts.lobes(old) != self.facts.lobes(new);
        let atlas = old.shadow_map_size != new.shadow_map_size
            || (old.specular_bounces != new.specular_bounces && self.scene.metals)
            || old.cone_shadows != new.cone_shadows
            || old.shadow_filter != new.shadow_filter
            // Area lights' sample views come and go with temporal accumulation.
            || (old.temporal != new.temporal && self.scene.gpu_lights.iter().any(|l| l.is_area()))
            || shadow::atlas_resolution(old, &self.scene.gpu_lights)
                != shadow::atlas_resolution(new, &self.scene.gpu_lights);
        let cones = volume
            || old.cones != new.cones
            || old.step_factor != new.step_factor
            || old.cone_quarters != new.cone_quarters
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
                &self.facts.casts,
                new,
                self.center,
                self.radius,
            )?)
        } else {
            None
        };
        let mut volume_new = if volume {
            Some((new.voxels.info().create)(
                device,
                &self.facts.structure_desc(new, grid),
                Some(self.volume.as_ref()),
            )?)
        } else {
            None
        };
        // Large triangles take more voxelize workgroups on a finer grid.
        let tables_new = match &volume_new {
            Some(v) => Some(checked(device, "voxelization table", || {
                let finest = v.grid().voxel_size;
                Ok::<_, Error>((
                    triangle_table(device, &self.scene, false, &grid, finest)?,
                    triangle_table(device, &self.scene, true, &grid, finest)?,
                ))
            })??),
            None => None,
        };
        // The fragments depend on the grids only: a change of anisotropy keeps their grown
        // pool.
        let grids_changed = volume_new
            .as_ref()
            .is_some_and(|v| v.fragment_grids() != self.fragments.grids);
        let mut fragments_new = if grids_changed {
            let v = volume_new
                .as_ref()
                .expect("grids changed with a new structure");
            Some(allocate_fragments(device, &self.facts, new, v.as_ref())?)
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
                    gather.then(|| {
                        GatherPass::new(device, new, self.facts.glossy, self.facts.lobes(new))
                    }),
                    (kind
                        || old.anisotropic != new.anisotropic
                        || self.facts.lobes(old) != self.facts.lobes(new)
                        || indirect)
                        .then(|| {
                            BouncePass::new(
                                device,
                                new.voxels,
                                new.anisotropic,
                                self.facts.lobes(new),
                                leaves(new),
                            )
                        }),
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
        // Counted before anything is swapped in: an impossible resolution leaves the renderer
        // as it was.
        let mut built = false;
        if let Some(v) = volume_new.as_mut()
            && sizing::in_doubt(device, &self.facts.estimate, self.facts.bounds, v.as_ref())
        {
            let sizing = Sizing {
                device,
                queue: &self.queue,
                scene: &self.scene,
                triangles: tables_new.as_ref().map_or(&self.static_triangles, |t| &t.0),
                voxelize: &self.passes.voxelize,
                splat: &self.passes.splat,
            };
            let (grown, whole) =
                sizing.fit(fragments_new.as_ref().unwrap_or(&self.fragments), v)?;
            if grown.is_some() {
                fragments_new = grown;
            }
            built = whole;
        }
        if let Some(a) = atlas_new {
            self.atlas = a;
        }
        if let Some((s, d)) = tables_new {
            self.static_triangles = s;
            self.dynamic_triangles = d;
        }
        let rebind = volume_new.is_some() || fragments_new.is_some();
        if let Some(f) = fragments_new {
            self.fragments = f;
        }
        if let Some(v) = volume_new {
            self.volume = v;
            self.pools += 1;
            // Its leaves are others: blending starts afresh (and a new kind needs its pass).
            self.blend = None;
            if kind {
                self.passes.blend = checked(device, "pipeline creation", || {
                    BlendPass::new(device, new.voxels)
                })?;
            }
        }
        if rebind {
            self.volume.bind_fragments(&self.device, &self.fragments);
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
        self.options = options.clone();
        // The passes, the structure and the atlas may be new: their bind groups are made again.
        self.binds = None;
        self.bounce_globals = None;
        // Made anew, the bounces keep nothing: one more update (if the last change was still
        // spreading over slices) gathers at every leaf.
        self.slices_left = self.slices_left.min(1);
        self.fragment_binds = None;
        self.shadow_binds = None;
        // What the history holds was rendered with the old options, and the voxels' light
        // under them is no state to blend from: the new options' light shows at once.
        self.temporal.reset();
        self.blend = None;
        // A structure or an atlas made anew holds nothing yet, whatever the table says.
        if volume || atlas || changes == Some(Changes::Voxels) {
            self.invalidate();
            self.pending.built = built;
        } else if changes == Some(Changes::Lighting) {
            self.pending.lights = true;
        }
        Ok(())
    }

    /// Whether the voxels (or progressive bounces) still have work queued for a coming frame:
    /// false once everything set so far is in the voxels and the light has converged.
    pub fn voxels_settled(&self) -> bool {
        !self.voxel_work_pending()
    }

    /// Whether rendering again with the same frame parameters and target would give the same
    /// image: the voxels are settled, no voxel counter is still on its way back (one that
    /// overflowed would make the next frame rebuild) and, with temporal accumulation, the
    /// still view has accumulated `TEMPORAL_STILL_FRAMES` frames. An application may then
    /// show its last image instead of rendering.
    pub fn is_idle(&self) -> bool {
        self.voxels_settled()
            && !self.counters.pending()
            && (!self.options.temporal || self.temporal.converged())
    }

    /// Whether a voxel counter read back is submitted but has not completed: a frame drawn
    /// before it is back may be followed by a rebuild (`headless::render` waits for it before
    /// deciding that a frame is final; so does the viewer's export).
    pub fn feedback_in_flight(&self) -> bool {
        self.counters.in_flight()
    }

    /// The scene's own camera, or a view of its bounds.
    pub fn default_camera(&self) -> &Camera {
        &self.default_camera
    }

    /// Whether the voxels keep specular lobes (`specular_bounces` in a scene with a metal):
    /// what every pipeline that samples them is compiled for.
    pub(crate) fn lobes(&self) -> bool {
        self.facts.lobes(&self.options)
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
        m.extend(self.volume.memory());
        if let Some(b) = self.bounce_globals.as_ref().filter(|b| b.memory() > 0) {
            m.push(("bounce kept irradiance", b.memory()));
        }
        if let Some(b) = &self.blend {
            m.push(("voxel blend", b.bytes()));
        }
        if let Some(t) = &self.targets {
            m.push(("render targets", t.bytes()));
        }
        m
    }

    /// Acts on voxel counters that have come back since the last call: when a build had more
    /// fragments or occupied voxels than room, the pools grow to fit and the voxels are rebuilt
    /// in the next frame. Never waits; `render` calls it first. Returns whether the next frame
    /// rebuilds the voxels.
    pub fn receive_feedback(&mut self) -> Result<bool> {
        // Errors of resources made since the last frame, where the device reports them late.
        crate::gpu::late_error(&self.device)?;
        // Non-blocking: runs the callbacks of maps that have completed.
        let _ = self.device.poll(wgpu::PollType::Poll);
        for (pools, words) in self.counters.take_ready() {
            if pools != self.pools {
                continue;
            }
            let mut pools = [0u32; POOL_COUNTERS];
            pools.copy_from_slice(&words[1..1 + POOL_COUNTERS]);
            let counts = VoxelCounts {
                fragments: words[0] as u64,
                occupied: self.volume.occupied(&pools),
            };
            self.last_counts = Some(counts);
            let frags = self.fragments.capacity as u64;
            let grow_volume = self.volume.needs_growth(&pools);
            if counts.fragments <= frags && !grow_volume {
                continue;
            }
            // Build what grows first and swap it in only when all of it succeeded. A count
            // past this device's limits is an error here (once per overflowing build), not a
            // pool grown to the limit and rebuilt forever.
            let fragments = if counts.fragments > frags {
                let capacity = fragments::capacity(&self.device, counts.fragments)?;
                let grids = self.fragments.grids.clone();
                Some(checked(&self.device, "voxel fragments", || {
                    Fragments::new(&self.device, &grids, capacity)
                })?)
            } else {
                None
            };
            if grow_volume {
                self.volume.grow(&self.device, &pools)?;
                self.bounce_globals = None;
            }
            if let Some(f) = fragments {
                self.fragments = f;
                self.fragment_binds = None;
            }
            self.volume.bind_fragments(&self.device, &self.fragments);
            self.pools += 1;
            log::info!(
                "voxels: {} fragments, {} occupied voxels: growing the pools to {} fragments \
                 and {} voxels and rebuilding",
                counts.fragments,
                counts.occupied,
                self.fragments.capacity,
                self.volume.leaf_capacity()
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
        let read = |b: &wgpu::Buffer| -> Result<[u32; POOL_COUNTERS]> {
            let bytes = readback::read_buffer_copy(&self.device, &self.queue, b)?;
            let mut words = [0u32; POOL_COUNTERS];
            let n = (bytes.len() / 4).min(POOL_COUNTERS);
            words[..n].copy_from_slice(&bytemuck::cast_slice::<u8, u32>(&bytes)[..n]);
            Ok(words)
        };
        Ok(VoxelCounts {
            fragments: read(&self.fragments.count)?[0] as u64,
            occupied: self.volume.occupied(&read(self.volume.pool_counter())?),
        })
    }

    /// How many leaves the last voxel update's injection lit anew (those whose direct light
    /// may have changed), read back now. This waits for the GPU: it is for tools and tests.
    pub fn relit_leaves(&self) -> Result<u64> {
        let bytes =
            readback::read_buffer_copy(&self.device, &self.queue, self.passes.inject.recomputed())?;
        Ok(bytemuck::cast_slice::<u8, u32>(&bytes)[0] as u64)
    }

    /// The fragments of the last build, for tests and debugging.
    pub fn fragments(&self) -> &Fragments {
        &self.fragments
    }

    /// The voxel structure, for tests and debugging (`structure` for its own type).
    pub fn volume(&self) -> &dyn VoxelStructure {
        self.volume.as_ref()
    }

    /// The voxel structure as its own type `T`, if it is one (for a kind's own tests).
    pub fn structure<T: 'static>(&self) -> Option<&T> {
        self.volume.as_any().downcast_ref()
    }

    /// Turns per-pass GPU timing on or off (when the device has `TIMESTAMP_QUERY`).
    pub fn enable_timing(&mut self, on: bool) {
        self.timer = GpuTimer::new(&self.device, &self.queue, on);
    }

    /// Keeps the pass scopes of every frame read by `pass_times` from now on, for
    /// `write_pass_trace` (with timing on).
    pub fn keep_pass_trace(&mut self) {
        self.timer.keep_trace();
    }

    /// Writes the kept pass scopes as a Chrome trace (open it in chrome://tracing or Perfetto).
    pub fn write_pass_trace(&self, path: &std::path::Path) -> Result<()> {
        self.timer.write_trace(path)
    }

    /// Milliseconds per pass of everything recorded since the last call, once it has been
    /// submitted. This waits for the GPU (for `voxgi bench`).
    pub fn pass_times(&mut self) -> Result<Vec<(&'static str, f64)>> {
        self.timer.read(&self.device)
    }

    /// The shadow maps: one R32Float layer (Rg32Float in a scene with metals: the distance and the
    /// specular material) per shadow view (the area lights' sample views share
    /// layers, a quarter each), the occluder's distance
    /// from the light (for inspection; `gpu::readback::read_texture_3d` reads every layer).
    pub fn shadow_maps(&self) -> &wgpu::Texture {
        &self.atlas.texture
    }

    /// Marks everything as changed: the next frame re-renders every shadow view and rebuilds
    /// the voxels, static geometry included.
    pub fn invalidate(&mut self) {
        self.pending = Pending::everything(self.atlas.views.len());
        self.atlas.forget_statics();
    }

    /// The linear HDR radiance of the last frame (before exposure and tone mapping; with
    /// temporal accumulation, the accumulated image the frame showed), `Rgba32Float` at the
    /// last target's size, with `COPY_SRC` and `TEXTURE_BINDING` usage. Its alpha is not
    /// the image's (the history keeps its frame count there).
    pub fn hdr_texture(&self) -> Option<&wgpu::Texture> {
        let t = self.targets.as_ref()?;
        Some(match &t.history {
            Some(h) => &h.color[self.temporal.written()],
            None => &t.hdr_texture,
        })
    }

    /// The last frame's depth and the world-to-clip matrix it was drawn with, for an
    /// application's own overlays (a ground grid, gizmos) hidden behind the scene as they
    /// should be. The depth is the G-buffer's (`Depth32Float`, 0 near to 1 far, 1 where
    /// nothing was drawn) at the last target's size, with `TEXTURE_BINDING` usage; with
    /// temporal accumulation it was drawn a sub-pixel jitter off the matrix (without it),
    /// which an overlay can ignore. `None` before the first frame.
    pub fn depth(&self) -> Option<(&wgpu::TextureView, glam::Mat4)> {
        let t = self.targets.as_ref()?;
        Some((&t.depth, self.drawn_view_proj))
    }

    /// Forgets the temporal history: the next frame shows only itself. Call it on a camera
    /// cut (a jump to an unrelated view); reprojection already discards what a moving camera
    /// uncovers, but a cut would otherwise show the old view's light for a frame or two where
    /// surfaces happen to line up.
    pub fn reset_history(&mut self) {
        self.temporal.reset();
    }
}

/// The fragment buffer for `volume`'s grids, sized by the scene's estimate on them.
fn allocate_fragments(
    device: &wgpu::Device,
    facts: &SceneFacts,
    options: &RendererOptions,
    volume: &dyn VoxelStructure,
) -> Result<Fragments> {
    let grids = volume.fragment_grids();
    let wanted = match options.fragment_capacity {
        Some(n) => n,
        None => sizing::estimate_on(&facts.estimate, facts.bounds, &grids),
    };
    fragments::allocate(device, &grids, wanted)
}

/// The volume's grid around the scene.
fn grid(facts: &SceneFacts, options: &RendererOptions) -> Grid {
    Grid::around(facts.bounds.min, facts.bounds.max, options.voxel_resolution)
}

/// Voxels wider than this cannot tell a doorway from a wall or a person from the air: the
/// indirect light near the camera is then a blur of the whole block.
const COARSE_VOXEL: f32 = 1.0;

/// The warning for a structure of one fixed grid `grid` (dense, octree) over a scene `across`
/// metres wide whose voxels are coarser than `COARSE_VOXEL`: the scene is too large for it,
/// and the clipmap is the answer.
pub fn coarse_voxels(across: f32, grid: &Grid, kind: VoxelKind) -> Option<String> {
    (kind != VoxelKind::CLIPMAP && grid.voxel_size > COARSE_VOXEL).then(|| {
        format!(
            "the scene is {across:.0} m across, so the {} structure's {}³ voxels are {:.1} m \
             wide and the indirect light near the camera is coarse: voxels = \"clipmap\" \
             (--voxels clipmap) keeps fine voxels near the camera and coarse ones far away",
            kind.name(),
            grid.resolution,
            grid.voxel_size
        )
    })
}

/// Where a cloud's unused point slots wait: 64 sides of the scene's grid below its corner,
/// outside the voxels of every structure on the same bounds (a coarser dense grid reaches
/// farther out by at most half a side, a clipmap's coarsest level with the automatic voxel
/// size by a side and a half), so the splat makes no fragment of them.
pub(crate) fn parking(grid: &Grid) -> glam::Vec3 {
    grid.origin - glam::Vec3::splat(64.0 * grid.extent())
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
