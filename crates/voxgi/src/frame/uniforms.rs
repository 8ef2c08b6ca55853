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
    /// This frame's sub-pixel camera offset in pixels (`sequence::jitter`; zero without
    /// temporal accumulation). `view_proj` includes it.
    pub jitter: [f32; 2],
    /// The previous frame's world-to-clip matrix, without its jitter (this frame's own when
    /// there is no history): motion vectors point back through it.
    pub prev_view_proj: [[f32; 4]; 4],
    /// This frame's world-to-clip matrix without the jitter: motion vectors compare it with
    /// `prev_view_proj`, so they hold the motion of the scene, not of the samples.
    pub view_proj_unjittered: [[f32; 4]; 4],
    /// The previous frame's camera position (the disocclusion test's distances).
    pub prev_camera_pos: [f32; 3],
    /// What the temporal pass may do with the history: `HISTORY_*` in the WGSL (none, a
    /// moving view that is clamped to the frame, or a still that is averaged).
    pub history: u32,
    /// How far this frame turns the diffuse cones about the normal and in zenith, as
    /// fractions of a cone's cell (`sequence::cone_turn`; zero without temporal
    /// accumulation).
    pub cone_turn: [f32; 2],
    /// The frame's index in the sequence of area-light sample points: its sample views show
    /// points `4 light_sample` to `4 light_sample + 3` (`sequence::light_points`).
    pub light_sample: u32,
    /// Padding to a multiple of 16 bytes; zero.
    pub _pad: u32,
}

/// `GpuFrame::history`: no history to use (the first frame, a cut, accumulation off).
pub const HISTORY_NONE: u32 = 0;
/// `GpuFrame::history`: the view or the scene changed since the last frame: the history is
/// reprojected and clamped to this frame's neighbourhood.
pub const HISTORY_MOVING: u32 = 1;
/// `GpuFrame::history`: nothing changed since the last frame: the history is averaged with
/// this frame as it is, converging to the mean of every frame since the last change.
pub const HISTORY_STILL: u32 = 2;
