//! The renderer: uploads a scene once, then renders frames by calling the passes in a fixed
//! order — shadow, gbuffer, composite, tonemap — from `Renderer::render`.

use crate::gpu::readback;
use crate::gpu_scene::{GpuFrame, GpuScene, scene_bounds};
use crate::output::RenderOutput;
use crate::passes::composite::{CompositePass, HDR_FORMAT};
use crate::passes::gbuffer::{self, GbufferPass};
use crate::passes::shadow::{self, ShadowAtlas, ShadowPass};
use crate::passes::tonemap::{LDR_FORMAT, TonemapPass};
use crate::settings::{Settings, Tonemap, ViewMode, validate_size};
use crate::{Error, GpuContext, Result};
use glam::{Mat4, Vec3};
use std::borrow::Cow;
use voxgi_scene::{Camera, Projection, Scene};

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
    hdr_texture: wgpu::Texture,
    ldr_texture: wgpu::Texture,
}

impl FrameTargets {
    fn new(device: &wgpu::Device, width: u32, height: u32) -> Self {
        let make = |label: &str, format: wgpu::TextureFormat, usage: wgpu::TextureUsages| {
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
            hdr: hdr_texture.create_view(&Default::default()),
            ldr: ldr_texture.create_view(&Default::default()),
            hdr_texture,
            ldr_texture,
        }
    }

    /// Bytes per pixel of all targets together.
    pub const BYTES_PER_PIXEL: u64 = 8 + 8 + 8 + 4 + 16 + 4;
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
    tonemap: TonemapPass,
    targets: Option<FrameTargets>,
    center: Vec3,
    radius: f32,
    default_camera: Camera,
}

impl Renderer {
    /// Uploads `scene`. A scene with nothing to draw is an error; a scene with no light at all
    /// gets a default sun (when `settings.default_light`) so it does not render black.
    pub fn new(ctx: &GpuContext, scene: &Scene, settings: Settings) -> Result<Self> {
        settings.validate()?;
        scene.validate()?;
        if scene.triangle_count() == 0 {
            return Err(Error::EmptyScene);
        }
        let scene = lit_scene(scene, &settings);
        let scene = scene.as_ref();
        let device = ctx.device.clone();
        let queue = ctx.queue.clone();
        let (center, radius) = scene_bounds(scene);
        let (gpu_scene, atlas) = ctx.checked("scene upload", || -> Result<_> {
            let mut gpu_scene = GpuScene::new(&device, &queue, scene, &settings)?;
            let casts: Vec<bool> = scene.lights.iter().map(|l| l.cast_shadows).collect();
            let (views, owners) = shadow::plan_views(
                &mut gpu_scene.gpu_lights,
                &casts,
                center,
                radius,
                settings.shadow_map_size,
            );
            queue.write_buffer(
                &gpu_scene.lights,
                0,
                bytemuck::cast_slice(&gpu_scene.gpu_lights),
            );
            let atlas = ShadowAtlas::new(&device, views, owners, settings.shadow_map_size);
            Ok((gpu_scene, atlas))
        })??;
        let passes = ctx.checked("pipeline creation", || {
            (
                ShadowPass::new(&device),
                GbufferPass::new(&device),
                CompositePass::new(&device),
                TonemapPass::new(&device),
            )
        })?;
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
        Ok(())
    }

    /// Bytes of GPU memory per resource.
    pub fn memory(&self) -> Vec<(&'static str, u64)> {
        let mut m = self.scene.memory();
        m.push(("shadow atlas", self.atlas.bytes()));
        if let Some(t) = &self.targets {
            m.push((
                "render targets",
                t.width as u64 * t.height as u64 * FrameTargets::BYTES_PER_PIXEL,
            ));
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
            },
            background: [s.background[0], s.background[1], s.background[2], 1.0],
        }
    }

    /// Renders one frame from `camera` at `width` x `height` and reads it back.
    pub fn render(&mut self, camera: &Camera, width: u32, height: u32) -> Result<RenderOutput> {
        validate_size(width, height)?;
        if !(camera.position.is_finite() && camera.forward.is_finite() && camera.up.is_finite()) {
            return Err(Error::Setting(
                "camera position and direction must be finite".into(),
            ));
        }
        if self
            .targets
            .as_ref()
            .is_none_or(|t| t.width != width || t.height != height)
        {
            self.targets = Some(FrameTargets::new(&self.device, width, height));
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
        // The fixed pass order.
        self.shadow
            .record(&self.device, &mut encoder, &self.atlas, &self.scene);
        self.gbuffer
            .record(&self.device, &mut encoder, t, &self.scene);
        self.composite
            .record(&self.device, &mut encoder, t, &self.scene, &self.atlas);
        self.tonemap.record(&self.device, &mut encoder, t);
        self.queue.submit([encoder.finish()]);

        let hdr_bytes = readback::read_texture(&self.device, &self.queue, &t.hdr_texture)?;
        let ldr = readback::read_texture(&self.device, &self.queue, &t.ldr_texture)?;
        Ok(RenderOutput {
            width,
            height,
            hdr: bytemuck::cast_slice(&hdr_bytes).to_vec(),
            ldr,
        })
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
