//! The formats of the frame's targets, in one place: the passes that write a target and those
//! that read it name the same constant here, not each other.

/// G-buffer albedo target: rgb linear base colour, a metallic.
pub const ALBEDO_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
/// G-buffer normal target: rgb world-space unit normal (facing the viewer), a perceptual roughness.
pub const NORMAL_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
/// G-buffer emission target: rgb emitted radiance, a specular reflectance.
pub const EMISSION_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
/// G-buffer motion target: xy the screen motion since the last frame in pixels (without the
/// jitter), z the surface's distance from the last frame's camera, w 1 (0: background).
/// Half floats: the four G-buffer colour targets fit the 32 bytes a sample may have.
pub const MOTION_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
/// G-buffer depth target (cleared to 1, less-than test).
pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// Format of the HDR target the composite writes: linear radiance, RGBA f32 (read back by
/// headless rendering and tone mapped to the output).
pub const HDR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;

/// Format of the gather's indirect-light target: rgb the indirect radiance towards the camera,
/// a the ambient occlusion.
pub const INDIRECT_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
/// Cone-traced visibility of up to four area lights.
pub const VISIBILITY_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;
/// The gather pixels' geometry for the upsample's edge weights: normal (rgb) and distance to
/// the camera (a; 0 for background).
pub const GUIDE_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;

/// The temporal history's colour: rgb the accumulated linear radiance, a how many frames it
/// holds (its weight in the running mean).
pub const HISTORY_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;
/// The temporal history's geometry: rgb the surface normal, a its distance from the camera
/// (0: background), for the next frame's disocclusion test.
pub const HISTORY_GEOMETRY_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;

/// What a compute pass writes and a later one reads (or the frame's reader copies out).
pub(crate) const STORAGE_TARGET: wgpu::TextureUsages = wgpu::TextureUsages::STORAGE_BINDING
    .union(wgpu::TextureUsages::TEXTURE_BINDING)
    .union(wgpu::TextureUsages::COPY_SRC);

/// A single-level 2D texture of `width` x `height`.
pub(crate) fn texture_2d(
    device: &wgpu::Device,
    label: &str,
    format: wgpu::TextureFormat,
    usage: wgpu::TextureUsages,
    (width, height): (u32, u32),
) -> wgpu::Texture {
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
}
