//! The frame uniform (`Frame` in shaders/shared/scene.wgsl): camera, output size, exposure and
//! view, written once per frame and bound by every screen pass through the globals. The
//! renderer fills it from the frame's parameters (`renderer/order.rs`).

use bytemuck::{Pod, Zeroable};

/// Mirrors `Frame` in shaders/shared/scene.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuFrame {
    /// World to clip space, column-major.
    pub view_proj: [[f32; 4]; 4],
    /// Clip to world space (the inverse of `view_proj`), for unprojecting depth.
    pub inv_view_proj: [[f32; 4]; 4],
    /// Camera position in world space, metres.
    pub camera_pos: [f32; 3],
    /// Number of lights in the lights buffer.
    pub light_count: u32,
    /// Output size in pixels (width, height).
    pub size: [f32; 2],
    /// Reciprocal of `size`, 1/pixels.
    pub inv_size: [f32; 2],
    /// Exposure scale 2^EV, applied before tone mapping.
    pub exposure: f32,
    /// Tone curve: `Tonemap::id` (`TONEMAP_*` in the WGSL).
    pub tonemap: u32,
    /// Filter radius of punctual-light shadows, in shadow-map texels.
    pub shadow_softness: f32,
    /// Output selection for debugging: `ViewMode::id` (`VIEW_*` in the WGSL).
    pub view_mode: u32,
    /// Background radiance where nothing is hit: linear RGB, alpha 1.
    pub background: [f32; 4],
    /// 1: area lights' shadows by a cone traced through the voxels instead of the shadow map; 0
    /// otherwise.
    pub cone_shadows: u32,
    /// `GpuScene::geometry_points`: the points from this index on show area lights.
    pub geometry_points: u32,
    /// Padding to a multiple of 16 bytes; zero.
    pub _pad: [u32; 2],
}
