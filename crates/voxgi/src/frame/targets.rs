//! Render targets of one output size, and their formats: the g-buffer, the gather's targets
//! and the HDR image. Passes read and write them; only `tonemap` touches the caller's texture.

use super::formats::{
    ALBEDO_FORMAT, DEPTH_FORMAT, EMISSION_FORMAT, GUIDE_FORMAT, HDR_FORMAT, INDIRECT_FORMAT,
    MOTION_FORMAT, NORMAL_FORMAT, STORAGE_TARGET, VISIBILITY_FORMAT, texture_2d,
};
use super::history::History;
use super::uniforms::GpuFrame;
use crate::gpu::layout;

/// Render targets of one output size.
pub struct FrameTargets {
    /// Output width in pixels.
    pub width: u32,
    /// Output height in pixels.
    pub height: u32,
    /// The frame's `GpuFrame` uniform, written before each frame.
    pub frame: wgpu::Buffer,
    /// G-buffer albedo (`ALBEDO_FORMAT`: rgb base colour, a metallic).
    pub albedo: wgpu::TextureView,
    /// G-buffer normal (`NORMAL_FORMAT`: rgb world normal, a roughness).
    pub normal: wgpu::TextureView,
    /// G-buffer emission (`EMISSION_FORMAT`: rgb emitted radiance, a specular).
    pub emission: wgpu::TextureView,
    /// G-buffer motion (`MOTION_FORMAT`: screen motion since the last frame, distance from
    /// the last frame's camera).
    pub motion: wgpu::TextureView,
    /// G-buffer depth (`DEPTH_FORMAT`).
    pub depth: wgpu::TextureView,
    /// Linear radiance (the composite's output, the debug views' too); `tonemap` reads it.
    pub hdr: wgpu::TextureView,
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
    /// Whether the gather runs at half resolution (each dimension halved, rounded up).
    pub half: bool,
    /// The texture behind `hdr`, for reading the frame back.
    pub hdr_texture: wgpu::Texture,
    /// The temporal history, with temporal accumulation on.
    pub history: Option<History>,
}

impl FrameTargets {
    /// Targets for a `width` x `height` output; the gather's targets at half that (rounded up) when
    /// `half`; with a temporal history when `temporal`.
    pub fn new(device: &wgpu::Device, width: u32, height: u32, half: bool, temporal: bool) -> Self {
        let (lw, lh) = gather_size(width, height, half);
        let sized =
            |label: &str, format, usage, size| texture_2d(device, label, format, usage, size);
        let rt = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING;
        let st = STORAGE_TARGET;
        let view = |t: wgpu::Texture| t.create_view(&Default::default());
        let make = |label: &str, format, usage| sized(label, format, usage, (width, height));
        let low = |label: &str, format| sized(label, format, st, (lw, lh));
        let hdr_texture = make("hdr", HDR_FORMAT, st);
        FrameTargets {
            width,
            height,
            frame: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("frame"),
                size: size_of::<GpuFrame>() as u64,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }),
            albedo: view(make("gbuffer albedo", ALBEDO_FORMAT, rt)),
            normal: view(make("gbuffer normal", NORMAL_FORMAT, rt)),
            emission: view(make("gbuffer emission", EMISSION_FORMAT, rt)),
            motion: view(make("gbuffer motion", MOTION_FORMAT, rt)),
            depth: view(make("gbuffer depth", DEPTH_FORMAT, rt)),
            indirect: view(low("indirect", INDIRECT_FORMAT)),
            indirect_low: view(low("indirect gather", INDIRECT_FORMAT)),
            visibility_low: view(low("visibility gather", VISIBILITY_FORMAT)),
            guide_low: view(low("gather guide", GUIDE_FORMAT)),
            half,
            hdr: hdr_texture.create_view(&Default::default()),
            hdr_texture,
            history: temporal.then(|| History::new(device, width, height)),
        }
    }

    /// Bytes per pixel of the full-resolution targets (g-buffer, HDR) and of those at the
    /// gather's resolution (gathered and filtered indirect light, visibility, guide).
    const FULL_BYTES_PER_PIXEL: u64 = 8 + 8 + 8 + 8 + 4 + 16;
    const LOW_BYTES_PER_PIXEL: u64 = 8 + 8 + 4 + 8;

    /// GPU memory of the targets in bytes.
    pub fn bytes(&self) -> u64 {
        let (lw, lh) = self.gather_size();
        let full = Self::FULL_BYTES_PER_PIXEL
            + if self.history.is_some() {
                History::BYTES_PER_PIXEL
            } else {
                0
            };
        self.width as u64 * self.height as u64 * full
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

    /// The gather's resolution in pixels: the output size, or half of it rounded up.
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

/// The caller's texture a frame is written to: a view of it, its format and size.
///
/// The texture needs `TextureUsages::RENDER_ATTACHMENT` and a renderable colour format: an
/// sRGB one such as `Bgra8UnormSrgb` or `Rgba8UnormSrgb` (swapchains; encoded to sRGB by the
/// GPU), a fixed-point one without sRGB such as `Rgba8Unorm`, `Bgra8Unorm` or `Rgb10a2Unorm`
/// (voxgi applies the sRGB curve itself), or a float one such as `Rgba16Float` (tone-mapped
/// linear values). Other formats are an error naming the format.
#[derive(Clone, Copy, Debug)]
pub struct Target<'a> {
    /// A view of the caller's texture (one mip level, one layer).
    pub view: &'a wgpu::TextureView,
    /// The view's format (which may be the sRGB form of the texture's, as a swapchain view
    /// often is); the tonemap pass makes a pipeline for each format it is given.
    pub format: wgpu::TextureFormat,
    /// The view's width in pixels.
    pub width: u32,
    /// The view's height in pixels.
    pub height: u32,
}

impl<'a> Target<'a> {
    /// A target from a view of the texture and the texture's format and size in pixels.
    pub fn new(
        view: &'a wgpu::TextureView,
        format: wgpu::TextureFormat,
        width: u32,
        height: u32,
    ) -> Self {
        Target {
            view,
            format,
            width,
            height,
        }
    }
}

/// The format to configure a window's or a canvas's surface with, of those it offers: an 8-bit
/// format without an sRGB view (voxgi applies the sRGB curve itself, the same bits `voxgi
/// render` writes, and a UI drawn over it that blends in gamma space, as egui does, wants
/// exactly that), else the first offered.
pub fn surface_format(offered: &[wgpu::TextureFormat]) -> Option<wgpu::TextureFormat> {
    offered
        .iter()
        .copied()
        .find(|f| {
            matches!(
                f,
                wgpu::TextureFormat::Bgra8Unorm | wgpu::TextureFormat::Rgba8Unorm
            )
        })
        .or_else(|| offered.first().copied())
}
