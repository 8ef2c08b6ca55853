//! The frame uniform (`Frame` in shaders/shared/scene.wgsl): camera, output size, exposure and
//! view, written once per frame and bound by every screen pass through the globals.

use crate::options::FrameParams;
use crate::view::camera_view_proj;
use bytemuck::{Pod, Zeroable};
use glam::Vec3;

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

/// What the frame uniform takes from the scene and the options rather than from the frame's
/// parameters.
#[derive(Clone, Copy, Debug)]
pub struct FrameScene {
    /// The scene's bounding sphere (the camera's clip planes fit it).
    pub center: Vec3,
    /// Radius of the bounding sphere, metres.
    pub radius: f32,
    /// Lights in the lights buffer.
    pub light_count: u32,
    /// Whether area lights are shadowed by cones (`RendererOptions::cone_shadows`).
    pub cone_shadows: bool,
    /// `GpuScene::geometry_points`.
    pub geometry_points: u32,
}

impl GpuFrame {
    /// The uniform for a `width` x `height` frame of `p`.
    pub fn new(p: &FrameParams, s: &FrameScene, width: u32, height: u32) -> Self {
        let view_proj = camera_view_proj(&p.camera, width, height, s.center, s.radius);
        GpuFrame {
            view_proj: view_proj.to_cols_array_2d(),
            inv_view_proj: view_proj.inverse().to_cols_array_2d(),
            camera_pos: p.camera.position.to_array(),
            light_count: s.light_count,
            size: [width as f32, height as f32],
            inv_size: [1.0 / width as f32, 1.0 / height as f32],
            exposure: 2f32.powf(p.exposure),
            tonemap: p.tonemap.id(),
            shadow_softness: p.shadow_softness,
            // The debug pass draws the voxel views; composite writes the lit image underneath.
            view_mode: p.view.id(),
            background: [p.background[0], p.background[1], p.background[2], 1.0],
            cone_shadows: s.cone_shadows as u32,
            geometry_points: s.geometry_points,
            _pad: [0; 2],
        }
    }
}
