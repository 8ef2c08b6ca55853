//! The renderer: uploads a scene once, then renders frames by calling the passes in one fixed
//! order from `Renderer::render`:
//!
//! shadow → voxelize → dense_build → inject → filter → (bounce → filter) × (bounces − 1)
//!        → gbuffer → gather → upsample → composite → [debug] → tonemap
//!
//! `debug` runs only for the voxel views (`ViewMode::is_voxel`) and replaces the composite's
//! output with the ray-marched volume.
//!
//! The voxel passes (and the shadow maps they read) run when the scene changed — on the first
//! frame, or every frame with `Settings::revoxelize_every_frame`.

use crate::brdf::BrdfTables;
use crate::gpu::timer::GpuTimer;
use crate::gpu::{layout, readback};
use crate::gpu_scene::{GpuFrame, GpuScene, scene_bounds};
use crate::output::RenderOutput;
use crate::passes::bounce::BouncePass;
use crate::passes::composite::{CompositePass, HDR_FORMAT};
use crate::passes::debug::DebugPass;
use crate::passes::filter::FilterPass;
use crate::passes::gather::{self, GUIDE_FORMAT, GatherPass, INDIRECT_FORMAT, VISIBILITY_FORMAT};
use crate::passes::gbuffer::{self, GbufferPass};
use crate::passes::inject::InjectPass;
use crate::passes::shadow::{self, ShadowAtlas, ShadowPass};
use crate::passes::tonemap::{LDR_FORMAT, TonemapPass};
use crate::passes::upsample::UpsamplePass;
use crate::passes::voxelize::VoxelizePass;
use crate::settings::UNLIMITED_BOUNCES;
use crate::settings::{Settings, Tonemap, ViewMode, validate_size};
use crate::voxel::dense::{DenseVolume, estimate_fragments, triangle_table};
use crate::voxel::{GpuCones, Grid};
use crate::{Error, GpuContext, Result};
use glam::{Mat4, Vec3};
use std::borrow::Cow;
use voxgi_scene::{Aabb, Camera, Projection, Scene, pointcloud};
use wgpu::util::DeviceExt;

/// Render targets of one output size.
pub struct FrameTargets {
    pub width: u32,
    pub height: u32,
    pub frame: wgpu::Buffer,
    pub albedo: wgpu::TextureView,
    pub normal: wgpu::TextureView,
    pub emission: wgpu::TextureView,
    pub depth: wgpu::TextureView,
    pub hdr: wgpu::TextureView,
    pub ldr: wgpu::TextureView,
    /// Indirect light (rgb) and ambient occlusion (a) at the gather's resolution, every
    /// pixel's interleaved samples filtered together (`upsample`); the composite upsamples it.
    pub indirect: wgpu::TextureView,
    /// The gather's target, at full or half resolution; `upsample` filters it into `indirect`.
    pub indirect_low: wgpu::TextureView,
    /// Cone-traced visibility of the first four area lights (one channel each), as the gather
    /// traced it.
    pub visibility_low: wgpu::TextureView,
    /// Normal and camera distance of each gather pixel (the upsample's edge weights).
    pub guide_low: wgpu::TextureView,
    half: bool,
    hdr_texture: wgpu::Texture,
    ldr_texture: wgpu::Texture,
}

impl FrameTargets {
    fn new(device: &wgpu::Device, width: u32, height: u32, half: bool) -> Self {
        let (lw, lh) = gather_size(width, height, half);
        let sized = |label: &str,
                     format: wgpu::TextureFormat,
                     usage: wgpu::TextureUsages,
                     (width, height): (u32, u32)| {
            device.create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size: wgpu::Extent3d {
                    width,
                    height,
                    depth_or_array_layers: 1,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage,
                view_formats: &[],
            })
        };
        let rt = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING;
        let st = wgpu::TextureUsages::STORAGE_BINDING
            | wgpu::TextureUsages::TEXTURE_BINDING
            | wgpu::TextureUsages::COPY_SRC;
        let view = |t: wgpu::Texture| t.create_view(&Default::default());
        let make = |label: &str, format, usage| sized(label, format, usage, (width, height));
        let low = |label: &str, format| sized(label, format, st, (lw, lh));
        let hdr_texture = make("hdr", HDR_FORMAT, st);
        let ldr_texture = make("ldr", LDR_FORMAT, st);
        FrameTargets {
            width,
            height,
            frame: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("frame"),
                size: size_of::<GpuFrame>() as u64,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }),
            albedo: view(make("gbuffer albedo", gbuffer::ALBEDO_FORMAT, rt)),
            normal: view(make("gbuffer normal", gbuffer::NORMAL_FORMAT, rt)),
            emission: view(make("gbuffer emission", gbuffer::EMISSION_FORMAT, rt)),
            depth: view(make("gbuffer depth", gbuffer::DEPTH_FORMAT, rt)),
            indirect: view(low("indirect", INDIRECT_FORMAT)),
            indirect_low: view(low("indirect gather", INDIRECT_FORMAT)),
            visibility_low: view(low("visibility gather", VISIBILITY_FORMAT)),
            guide_low: view(low("gather guide", GUIDE_FORMAT)),
            half,
            hdr: hdr_texture.create_view(&Default::default()),
            ldr: ldr_texture.create_view(&Default::default()),
            hdr_texture,
            ldr_texture,
        }
    }

    /// Bytes per pixel of the full-resolution targets (g-buffer, HDR, LDR) and of those at the
    /// gather's resolution (gathered and filtered indirect light, visibility, guide).
    const FULL_BYTES_PER_PIXEL: u64 = 8 + 8 + 8 + 4 + 16 + 4;
    const LOW_BYTES_PER_PIXEL: u64 = 8 + 8 + 4 + 8;

    pub fn bytes(&self) -> u64 {
        let (lw, lh) = self.gather_size();
        self.width as u64 * self.height as u64 * Self::FULL_BYTES_PER_PIXEL
            + lw as u64 * lh as u64 * Self::LOW_BYTES_PER_PIXEL
    }

    /// Four consecutive bindings from `first` for the passes that shade from the g-buffer:
    /// albedo, normal and emission (loaded) and depth.
    pub fn gbuffer_layout(first: u32, c: wgpu::ShaderStages) -> [wgpu::BindGroupLayoutEntry; 4] {
        [
            layout::texture_2d_load(first, c),
            layout::texture_2d_load(first + 1, c),
            layout::texture_2d_load(first + 2, c),
            layout::texture(
                first + 3,
                c,
                wgpu::TextureSampleType::Depth,
                wgpu::TextureViewDimension::D2,
            ),
        ]
    }

    /// The resources for `gbuffer_layout`, in its order.
    pub fn gbuffer_resources(&self) -> [wgpu::BindingResource<'_>; 4] {
        [
            wgpu::BindingResource::TextureView(&self.albedo),
            wgpu::BindingResource::TextureView(&self.normal),
            wgpu::BindingResource::TextureView(&self.emission),
            wgpu::BindingResource::TextureView(&self.depth),
        ]
    }

    /// Where the gather writes: the half-resolution target or the full one.
    pub fn gather_target(&self) -> &wgpu::TextureView {
        &self.indirect_low
    }

    pub fn gather_size(&self) -> (u32, u32) {
        gather_size(self.width, self.height, self.half)
    }
}

/// The gather's resolution: full, or half rounded up.
fn gather_size(width: u32, height: u32, half: bool) -> (u32, u32) {
    if half {
        (width.div_ceil(2), height.div_ceil(2))
    } else {
        (width, height)
    }
}

/// Fills in normals (k = 16) and disc radii (k = 8) of point clouds that lack them. Normals face
/// the cloud's local origin when that lies outside the cloud's bounds (scanners put the sensor
/// there), else the default camera.
fn estimate_point_attributes(scene: &mut Scene) {
    let camera = scene
        .cameras
        .first()
        .cloned()
        .unwrap_or_else(|| scene.default_camera())
        .position;
    for pc in &mut scene.point_clouds {
        if pc.positions.is_empty() || (!pc.normals.is_empty() && !pc.radii.is_empty()) {
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
        let what = match (pc.normals.is_empty(), pc.radii.is_empty()) {
            (true, true) => "normals and radii",
            (true, false) => "normals",
            _ => "radii",
        };
        pointcloud::estimate_normals(pc, 16, viewpoint);
        pointcloud::estimate_radii(pc, 8);
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
}

/// A scene uploaded to the GPU, ready to render from any camera.
pub struct Renderer {
    device: wgpu::Device,
    queue: wgpu::Queue,
    settings: Settings,
    scene: GpuScene,
    atlas: ShadowAtlas,
    shadow: ShadowPass,
    gbuffer: GbufferPass,
    composite: CompositePass,
    debug: DebugPass,
    tonemap: TonemapPass,
    voxelize: VoxelizePass,
    inject: InjectPass,
    filter: FilterPass,
    bounce: BouncePass,
    gather: GatherPass,
    upsample: UpsamplePass,
    brdf_tables: BrdfTables,
    volume: DenseVolume,
    triangles: (wgpu::Buffer, u32),
    cones: wgpu::Buffer,
    /// Voxel bounces per update (the per-pixel gather adds the last bounce).
    voxel_bounces: u32,
    /// The voxels (and shadow maps) must be rebuilt before the next frame.
    dirty: bool,
    timer: GpuTimer,
    errors: std::sync::Arc<std::sync::Mutex<Vec<String>>>,
    targets: Option<FrameTargets>,
    center: Vec3,
    radius: f32,
    default_camera: Camera,
}

impl Renderer {
    /// Uploads `scene`. A scene with nothing to draw (no triangles, no points) is an error; a
    /// scene with no light at all gets a default sun (when `settings.default_light`) so it does
    /// not render black. Point clouds without normals or radii get estimated ones.
    pub fn new(ctx: &GpuContext, scene: &Scene, settings: Settings) -> Result<Self> {
        settings.validate()?;
        scene.validate()?;
        if scene.triangle_count() == 0 && scene.point_count() == 0 {
            return Err(Error::EmptyScene);
        }
        let mut scene = lit_scene(scene, &settings);
        if scene
            .point_clouds
            .iter()
            .any(|pc| !pc.positions.is_empty() && (pc.normals.is_empty() || pc.radii.is_empty()))
        {
            estimate_point_attributes(scene.to_mut());
        }
        let scene = scene.as_ref();
        let device = ctx.device.clone();
        let queue = ctx.queue.clone();
        let (center, radius) = scene_bounds(scene);
        let (gpu_scene, atlas) = ctx.checked("scene upload", || -> Result<_> {
            let mut gpu_scene = GpuScene::new(&device, &queue, scene, &settings)?;
            let casts: Vec<bool> = scene.lights.iter().map(|l| l.cast_shadows).collect();
            let res = shadow::atlas_resolution(&settings, &gpu_scene.gpu_lights);
            let (views, owners) =
                shadow::plan_views(&mut gpu_scene.gpu_lights, &casts, center, radius, res);
            queue.write_buffer(
                &gpu_scene.lights,
                0,
                bytemuck::cast_slice(&gpu_scene.gpu_lights),
            );
            let atlas = ShadowAtlas::new(&device, views, owners, res);
            Ok((gpu_scene, atlas))
        })??;
        let glossy = gather::has_glossy(scene, gpu_scene.point_count);
        let passes = ctx.checked("pipeline creation", || {
            (
                ShadowPass::new(&device),
                GbufferPass::new(&device),
                CompositePass::new(
                    &device,
                    shadow::composite_reads_shadow_maps(
                        &gpu_scene.gpu_lights,
                        settings.cone_shadows,
                    ),
                    glossy,
                ),
                TonemapPass::new(&device),
                DebugPass::new(&device),
            )
        })?;
        let b = scene.bounds();
        let grid = Grid::around(b.min, b.max, settings.voxel_resolution);
        let estimate = estimate_fragments(scene, &grid);
        let capacity = fragment_capacity(&device, estimate.min(max_fragments(&device)))?;
        check_volume_fits(&device, &grid)?;
        // Slots: at most one per voxel, usually far fewer than fragments, and the fragment
        // estimate is itself an upper bound (Sponza at 256³: 3.4 M estimated, 0.84 M fragments,
        // 0.41 M occupied voxels). Start at a quarter; the first build grows the buffers to the
        // exact count if that is short.
        let slots = slot_capacity(
            &device,
            (estimate / 4)
                .min((grid.resolution as u64).pow(3))
                .min(max_slots(&device)),
        )?;
        let voxel_passes = ctx.checked("voxel pipelines", || {
            (
                VoxelizePass::new(&device),
                InjectPass::new(&device, gpu_scene.light_count),
                FilterPass::new(&device),
                BouncePass::new(&device, settings.anisotropic),
                GatherPass::new(&device, &settings, glossy),
                UpsamplePass::new(&device),
                DenseVolume::new(&device, grid, settings.anisotropic, capacity, slots),
                triangle_table(&device, &gpu_scene),
            )
        })?;
        let brdf_tables = BrdfTables::new(&device, &queue);
        let voxel_bounces = voxel_bounce_count(scene, settings.bounces);
        let cones = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("cones"),
            contents: bytemuck::bytes_of(&cone_uniforms(&settings, &grid)),
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        });
        let timer = GpuTimer::disabled(&queue);
        let default_camera = scene
            .cameras
            .first()
            .cloned()
            .unwrap_or_else(|| scene.default_camera());
        Ok(Renderer {
            device,
            queue,
            settings,
            scene: gpu_scene,
            atlas,
            shadow: passes.0,
            gbuffer: passes.1,
            composite: passes.2,
            tonemap: passes.3,
            debug: passes.4,
            voxelize: voxel_passes.0,
            inject: voxel_passes.1,
            filter: voxel_passes.2,
            bounce: voxel_passes.3,
            gather: voxel_passes.4,
            upsample: voxel_passes.5,
            brdf_tables,
            volume: voxel_passes.6,
            triangles: voxel_passes.7,
            cones,
            voxel_bounces,
            dirty: true,
            timer,
            errors: ctx.errors.clone(),
            targets: None,
            center,
            radius,
            default_camera,
        })
    }

    /// The scene's own camera, or a view of its bounds.
    pub fn default_camera(&self) -> &Camera {
        &self.default_camera
    }

    pub fn settings(&self) -> &Settings {
        &self.settings
    }

    /// Changes settings that need no re-upload (exposure, tone map, view, softness, background).
    pub fn set_display_settings(&mut self, s: &Settings) -> Result<()> {
        s.validate()?;
        self.settings.exposure = s.exposure;
        self.settings.tonemap = s.tonemap;
        self.settings.view = s.view;
        self.settings.shadow_softness = s.shadow_softness;
        self.settings.background = s.background;
        self.settings.debug_level = s.debug_level;
        self.settings.debug_direction = s.debug_direction;
        Ok(())
    }

    /// Bytes of GPU memory per resource.
    pub fn memory(&self) -> Vec<(&'static str, u64)> {
        let mut m = self.scene.memory();
        m.push(("shadow atlas", self.atlas.bytes()));
        m.extend(self.volume.memory());
        if let Some(t) = &self.targets {
            m.push(("render targets", t.bytes()));
        }
        m
    }

    fn frame_uniforms(&self, camera: &Camera, width: u32, height: u32) -> GpuFrame {
        let view_proj = camera_view_proj(camera, width, height, self.center, self.radius);
        let s = &self.settings;
        GpuFrame {
            view_proj: view_proj.to_cols_array_2d(),
            inv_view_proj: view_proj.inverse().to_cols_array_2d(),
            camera_pos: camera.position.to_array(),
            light_count: self.scene.light_count,
            size: [width as f32, height as f32],
            inv_size: [1.0 / width as f32, 1.0 / height as f32],
            exposure: 2f32.powf(s.exposure),
            tonemap: match s.tonemap {
                Tonemap::Aces => 0,
                Tonemap::Neutral => 1,
                Tonemap::Clamp => 2,
            },
            shadow_softness: s.shadow_softness,
            view_mode: match s.view {
                ViewMode::Final => 0,
                ViewMode::Albedo => 1,
                ViewMode::Normal => 2,
                ViewMode::Direct => 3,
                ViewMode::Ao => 4,
                ViewMode::Indirect => 5,
                // The debug pass draws these; composite writes the lit image underneath.
                ViewMode::VoxelAlbedo => 6,
                ViewMode::VoxelOpacity => 7,
                ViewMode::VoxelRadiance => 8,
            },
            background: [s.background[0], s.background[1], s.background[2], 1.0],
            cone_shadows: s.cone_shadows as u32,
            _pad: [0; 3],
        }
    }

    /// Shadow maps, voxelization, injection, filtering and voxel bounces: everything that
    /// depends on the scene and its lights but not on the camera.
    fn update_voxels(&mut self) -> Result<()> {
        for attempt in 0..2 {
            let mut encoder = self
                .device
                .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                    label: Some("voxels"),
                });
            let timer = &mut self.timer;
            self.shadow
                .record(&self.device, &mut encoder, &self.atlas, &self.scene, timer);
            self.volume.record_begin(&self.device, &mut encoder, timer);
            let triangles = (&self.triangles.0, self.triangles.1);
            self.voxelize.record(
                &self.device,
                &mut encoder,
                &self.scene,
                triangles,
                &self.volume,
                timer,
            );
            self.volume.record_build(&self.device, &mut encoder, timer);
            self.queue.submit([encoder.finish()]);
            // More fragments or occupied voxels than room: grow to fit and voxelize again
            // (the kernels never write past their buffers, they only count).
            let (emitted, occupied) = self.voxel_counts()?;
            let v = &self.volume;
            if emitted <= v.fragment_capacity as u64 && occupied <= v.slot_capacity as u64 {
                break;
            }
            if attempt == 1 {
                return Err(Error::Gpu {
                    context: "voxelize".into(),
                    reason: format!(
                        "{emitted} fragments / {occupied} voxels still overflow after growing"
                    ),
                });
            }
            let capacity =
                fragment_capacity(&self.device, emitted.max(v.fragment_capacity as u64))?;
            let slots = slot_capacity(&self.device, occupied.max(v.slot_capacity as u64))?;
            log::info!("voxels: {emitted} fragments, {occupied} occupied: growing the buffers");
            let (grid, aniso) = (v.grid, v.anisotropic);
            self.volume = DenseVolume::new(&self.device, grid, aniso, capacity, slots);
        }
        let mut encoder = self
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("light"),
            });
        let timer = &mut self.timer;
        self.inject.record(
            &self.device,
            &mut encoder,
            &self.scene,
            &self.atlas,
            &self.volume,
            timer,
        );
        self.filter
            .record(&self.device, &mut encoder, &self.volume, timer);
        for _ in 0..self.voxel_bounces {
            self.bounce
                .record(&self.device, &mut encoder, &self.volume, &self.cones, timer);
            self.filter
                .record(&self.device, &mut encoder, &self.volume, timer);
        }
        self.queue.submit([encoder.finish()]);
        self.dirty = false;
        Ok(())
    }

    /// Voxel statistics of the last build: (fragments emitted, occupied voxels).
    pub fn voxel_counts(&self) -> Result<(u64, u64)> {
        let buf = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("counter readback"),
            size: 16,
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
            mapped_at_creation: false,
        });
        let mut enc = self.device.create_command_encoder(&Default::default());
        enc.copy_buffer_to_buffer(&self.volume.counters, 0, &buf, 0, 16);
        self.queue.submit([enc.finish()]);
        let bytes = readback::read_buffer(&self.device, &buf)?;
        let c: &[u32] = bytemuck::cast_slice(&bytes);
        Ok((c[0] as u64, c[1] as u64))
    }

    /// The dense volume, for tests and debugging.
    pub fn volume(&self) -> &DenseVolume {
        &self.volume
    }

    /// The device and queue this renderer uses.
    pub fn device(&self) -> (&wgpu::Device, &wgpu::Queue) {
        (&self.device, &self.queue)
    }

    /// Turns per-pass GPU timing on or off (when the device supports timestamps).
    pub fn enable_timing(&mut self, on: bool) {
        self.timer = if on {
            GpuTimer::new(&self.device, &self.queue, true)
        } else {
            GpuTimer::disabled(&self.queue)
        };
    }

    /// Milliseconds per pass of everything recorded since the last call.
    pub fn pass_times(&mut self) -> Result<Vec<(&'static str, f64)>> {
        self.timer.read(&self.device)
    }

    /// Marks lights or geometry as changed: the next frame rebuilds shadows and voxels.
    pub fn invalidate(&mut self) {
        self.dirty = true;
    }

    /// Renders one frame into the targets without reading it back (for benchmarks and
    /// viewers).
    pub fn render_frame(&mut self, camera: &Camera, width: u32, height: u32) -> Result<()> {
        validate_size(width, height)?;
        if !(camera.position.is_finite() && camera.forward.is_finite() && camera.up.is_finite()) {
            return Err(Error::Setting(
                "camera position and direction must be finite".into(),
            ));
        }
        let half = self.settings.half_resolution;
        if self
            .targets
            .as_ref()
            .is_none_or(|t| t.width != width || t.height != height || t.half != half)
        {
            self.targets = Some(FrameTargets::new(&self.device, width, height, half));
        }
        if self.dirty || self.settings.revoxelize_every_frame {
            self.update_voxels()?;
        }
        let frame = self.frame_uniforms(camera, width, height);
        let t = self.targets.as_ref().expect("targets were just created");
        self.queue
            .write_buffer(&t.frame, 0, bytemuck::bytes_of(&frame));
        let mut encoder = self
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("frame"),
            });
        let timer = &mut self.timer;
        self.gbuffer
            .record(&self.device, &mut encoder, t, &self.scene, timer);
        self.gather.record(
            &self.device,
            &mut encoder,
            t,
            &self.scene,
            &self.volume,
            &self.cones,
            &self.brdf_tables,
            timer,
        );
        self.upsample.record(&self.device, &mut encoder, t, timer);
        self.composite.record(
            &self.device,
            &mut encoder,
            t,
            &self.scene,
            &self.atlas,
            &self.brdf_tables,
            timer,
        );
        // Only for the voxel views: replaces the composite's output.
        if self.settings.view.is_voxel() {
            self.debug.record(
                &self.device,
                &mut encoder,
                t,
                &self.volume,
                self.settings.view,
                self.settings.debug_level,
                self.settings.debug_direction,
                timer,
            );
        }
        self.tonemap.record(&self.device, &mut encoder, t, timer);
        timer.resolve(&mut encoder);
        self.queue.submit([encoder.finish()]);

        Ok(())
    }

    /// Renders one frame from `camera` at `width` x `height` and reads it back.
    pub fn render(&mut self, camera: &Camera, width: u32, height: u32) -> Result<RenderOutput> {
        self.render_frame(camera, width, height)?;
        let t = self
            .targets
            .as_ref()
            .expect("render_frame made the targets");
        let hdr_bytes = readback::read_texture(&self.device, &self.queue, &t.hdr_texture)?;
        GpuContext::take_error(&self.errors, "frame")?;
        let ldr = readback::read_texture(&self.device, &self.queue, &t.ldr_texture)?;
        Ok(RenderOutput {
            width,
            height,
            hdr: bytemuck::cast_slice(&hdr_bytes).to_vec(),
            ldr,
        })
    }
}

/// The most fragments one storage binding can hold on this device.
fn max_fragments(device: &wgpu::Device) -> u64 {
    device.limits().max_storage_buffer_binding_size / crate::voxel::dense::FRAGMENT_BYTES
}

/// The most slots one storage binding can hold on this device.
fn max_slots(device: &wgpu::Device) -> u64 {
    device.limits().max_storage_buffer_binding_size / crate::voxel::dense::SLOT_BYTES
}

/// Checks a slot capacity against the device's storage-buffer limit.
fn slot_capacity(device: &wgpu::Device, wanted: u64) -> Result<u32> {
    let limit = device.limits().max_storage_buffer_binding_size / crate::voxel::dense::SLOT_BYTES;
    let cap = wanted.max(1024);
    if cap > limit.min(u32::MAX as u64) {
        return Err(Error::Setting(format!(
            "the scene occupies about {cap} voxels at this resolution, more than this GPU's \
             storage-buffer limit allows ({limit}); lower the voxel resolution"
        )));
    }
    Ok(cap as u32)
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

/// Checks a fragment capacity against the device's storage-buffer limit.
fn fragment_capacity(device: &wgpu::Device, wanted: u64) -> Result<u32> {
    let limit =
        device.limits().max_storage_buffer_binding_size / crate::voxel::dense::FRAGMENT_BYTES;
    let cap = wanted.max(1024);
    if cap > limit.min(u32::MAX as u64) {
        return Err(Error::Setting(format!(
            "the scene needs about {cap} voxel fragments at this resolution, more than this \
             GPU's storage-buffer limit allows ({limit}); lower the voxel resolution"
        )));
    }
    Ok(cap as u32)
}

/// Voxel-space bounces for a total of `bounces` indirect bounces (the gather adds one).
fn voxel_bounce_count(scene: &Scene, bounces: u32) -> u32 {
    if bounces != UNLIMITED_BOUNCES {
        return bounces.saturating_sub(1);
    }
    // Until the energy left, max albedo^k, is below 0.1 %.
    let rho = scene
        .materials
        .iter()
        .map(|m| m.base_color[0].max(m.base_color[1]).max(m.base_color[2]))
        .fold(0.0f32, f32::max)
        .clamp(0.0, 0.99);
    if rho <= 0.0 {
        return 0;
    }
    ((1e-3f32.ln() / rho.ln()).ceil() as u32).clamp(1, 64)
}

/// The cone uniforms from the settings and the volume.
pub fn cone_uniforms(settings: &Settings, grid: &Grid) -> GpuCones {
    let axes = settings.cones.axes();
    let weights = settings.cones.weights();
    let mut dirs = [[0f32; 4]; 16];
    for (i, (a, w)) in axes.iter().zip(&weights).enumerate().take(16) {
        dirs[i] = [a.x, a.y, a.z, *w];
    }
    GpuCones {
        dirs,
        count: axes.len().min(16) as u32,
        diffuse_tan: (settings.cones.aperture() * 0.5).tan(),
        step_factor: settings.step_factor,
        max_distance: settings.max_distance.unwrap_or(grid.extent() * 3f32.sqrt()),
        ao_lambda: settings.ao_lambda,
        ao_radius: settings.ao_radius.unwrap_or(grid.extent() * 0.25),
        origin_offset: settings.origin_offset,
        indirect: (settings.bounces > 0) as u32,
    }
}

/// The camera's view-projection matrix for a `width` x `height` image of a scene with bounding
/// sphere (`center`, `radius`): right-handed, depth 0..1, the far plane just past the scene.
/// The rasterizer and the path tracer both use it, so they see exactly the same view.
pub(crate) fn camera_view_proj(
    camera: &Camera,
    width: u32,
    height: u32,
    center: Vec3,
    radius: f32,
) -> Mat4 {
    let aspect = width as f32 / height as f32;
    let dist = (camera.position - center).length();
    let zfar = camera
        .zfar
        .unwrap_or(dist + radius * 1.05)
        .max(camera.znear * 2.0);
    let view = Mat4::look_to_rh(camera.position, camera.forward, camera.up);
    let proj = match camera.projection {
        Projection::Perspective { yfov } => Mat4::perspective_rh(yfov, aspect, camera.znear, zfar),
        Projection::Orthographic { ymag, .. } => Mat4::orthographic_rh(
            -ymag * aspect,
            ymag * aspect,
            -ymag,
            ymag,
            camera.znear,
            zfar,
        ),
    };
    proj * view
}

/// The scene as rendered: with a default sun added when it has no light at all and
/// `settings.default_light` is set, so it does not render black.
pub(crate) fn lit_scene<'a>(scene: &'a Scene, settings: &Settings) -> Cow<'a, Scene> {
    if scene.is_unlit() && settings.default_light {
        log::warn!("the scene has no lights and nothing emissive: adding a default sun");
        let mut lit = scene.clone();
        lit.lights.push(Scene::default_sun());
        Cow::Owned(lit)
    } else {
        Cow::Borrowed(scene)
    }
}
