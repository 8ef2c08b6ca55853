//! Shared device and small helpers for building test scenes and probing images.

use std::sync::OnceLock;
use voxgi::headless::{self, GpuContext};
use voxgi::scene::glam::{Mat4, Vec3};
use voxgi::scene::{Camera, Material, Mesh, Scene};
use voxgi::{FrameParams, RenderOutput, Renderer, RendererOptions, Tonemap, ViewMode};

/// The one device all GPU tests share.
pub fn ctx() -> &'static GpuContext {
    static CTX: OnceLock<GpuContext> = OnceLock::new();
    CTX.get_or_init(|| {
        GpuContext::from_env().unwrap_or_else(|e| panic!("GPU tests need an adapter: {e}"))
    })
}

/// A flat square of side `size` at height `y`, normal +Y, as a two-triangle mesh.
pub fn quad_mesh(name: &str, center: Vec3, size: f32) -> Mesh {
    let h = size * 0.5;
    let p = |x: f32, z: f32| center + Vec3::new(x, 0.0, z);
    Mesh {
        name: name.into(),
        positions: vec![p(-h, -h), p(-h, h), p(h, h), p(h, -h)],
        normals: vec![Vec3::Y; 4],
        uvs: Vec::new(),
        // Counter-clockwise seen from +Y.
        indices: vec![0, 1, 2, 0, 2, 3],
        material: 0,
    }
}

/// A 20 m Lambertian plane at y = 0 with the given albedo and no lights.
pub fn plane_scene(albedo: f32) -> Scene {
    let mut s = Scene::default();
    s.add_mesh(
        quad_mesh("plane", Vec3::ZERO, 20.0),
        Material::diffuse("plane", [albedo; 3]),
        Mat4::IDENTITY,
    );
    s
}

/// Options for measuring direct light: no default light, no indirect light, a small volume
/// (the voxel passes still run).
pub fn measuring() -> RendererOptions {
    RendererOptions {
        default_light: false,
        bounces: 0,
        voxel_resolution: 32,
        ..RendererOptions::default()
    }
}

/// The frame parameters for measuring: the view from `camera`, no tone curve.
pub fn clamped(camera: &Camera) -> FrameParams {
    FrameParams {
        tonemap: Tonemap::Clamp,
        ..FrameParams::new(camera.clone())
    }
}

/// A renderer on the shared device.
pub fn renderer(scene: &Scene, options: &RendererOptions) -> Renderer {
    ctx().renderer(scene, options).expect("renderer")
}

/// One frame of `r`, read back.
pub fn frame(r: &mut Renderer, params: &FrameParams, w: u32, h: u32) -> RenderOutput {
    headless::render(ctx(), r, params, w, h).expect("render")
}

/// What most tests vary: the renderer's options and the view mode. The rest of the frame's
/// parameters keep their defaults, but for the tone curve: none (`clamped`).
#[derive(Clone, Debug)]
pub struct Setup {
    pub options: RendererOptions,
    pub view: ViewMode,
}

impl From<RendererOptions> for Setup {
    fn from(options: RendererOptions) -> Self {
        Setup {
            options,
            view: ViewMode::Final,
        }
    }
}

/// One frame from `camera` without a tone curve (the tests read linear radiance).
pub fn render(
    scene: &Scene,
    setup: impl Into<Setup>,
    camera: &Camera,
    w: u32,
    h: u32,
) -> RenderOutput {
    let setup = setup.into();
    let params = FrameParams {
        view: setup.view,
        ..clamped(camera)
    };
    render_with(scene, &setup.options, &params, w, h)
}

/// One frame with these parameters.
pub fn render_with(
    scene: &Scene,
    options: &RendererOptions,
    params: &FrameParams,
    w: u32,
    h: u32,
) -> RenderOutput {
    frame(&mut renderer(scene, options), params, w, h)
}

/// The direction of the camera ray through the centre of pixel (x, y), as the renderer's
/// projection makes it (`voxgi::reference::probe::pixel_ray`); the ray starts at the camera.
pub fn pixel_ray(cam: &Camera, w: u32, h: u32, x: u32, y: u32) -> Vec3 {
    assert!(
        matches!(cam.projection, voxgi::scene::Projection::Perspective { .. }),
        "perspective cameras only"
    );
    voxgi::reference::probe::pixel_ray(cam, (x, y), (w, h)).1
}

/// Where the ray through pixel (x, y) meets the plane y = 0.
pub fn pixel_on_ground(cam: &Camera, w: u32, h: u32, x: u32, y: u32) -> Vec3 {
    let d = pixel_ray(cam, w, h, x, y);
    let t = -cam.position.y / d.y;
    assert!(t > 0.0, "pixel ({x}, {y}) does not see the ground");
    cam.position + d * t
}

/// Relative difference, safe at zero.
pub fn rel(a: f32, b: f32) -> f32 {
    (a - b).abs() / b.abs().max(1e-6)
}

/// The largest difference between two images' 8-bit channels, in code values.
pub fn largest_difference(a: &[u8], b: &[u8]) -> u8 {
    assert_eq!(a.len(), b.len(), "images of different sizes");
    a.iter()
        .zip(b)
        .map(|(x, y)| x.abs_diff(*y))
        .max()
        .unwrap_or(0)
}

/// How far a hardware-filtered `sample_voxels` may lie from its exact CPU twin: the worst
/// probe and the mean over probes. Vulkan leaves a sampler's weights to
/// `subTexelPrecisionBits` (8 on desktop GPUs, rounded or truncated), so each of a fetch's
/// three weights may be off by 2^-8 of the step between its texels; the structures filter
/// optical depth, whose steps reach -ln(1 - 0.999) = 6.9 (empty next to opaque), and opacity
/// moves no more than optical depth: 3 / 256 * 6.9 at worst. Most steps are far smaller: the
/// mean stays under 2^-8 (a wrong level or texel moves it by more). The H200 measured 1.7e-2
/// at worst. A CPU adapter (lavapipe) filters in f32: there the twins agree to 2e-5, and 1e-4
/// keeps the test sharp.
pub fn filtering_tolerance() -> (f32, f32) {
    if ctx().info.device_type == wgpu::DeviceType::Cpu {
        (1e-4, 1e-4)
    } else {
        (3.0 / 256.0 * 6.91, 1.0 / 256.0)
    }
}

/// `../shared/scenes/<rel>`, or None (the test says it skips) when it is not there.
pub fn shared_scene(rel: &str) -> Option<std::path::PathBuf> {
    let p = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/scenes")
        .join(rel);
    if p.exists() {
        Some(p)
    } else {
        eprintln!("skipped: ../shared/scenes/{rel} is not present");
        None
    }
}
