// The clipmap's levels: where each window lies. Twin: `GpuClipLevels` in
// src/voxel/clipmap/mod.rs. Level k's voxels are 2^k times the finest; its window of
// `resolution`³ voxels is window k of the dense volume's stacked textures, and moves with the
// camera in steps of an eighth of itself.

const MAX_CLIP_LEVELS: u32 = 8u;

struct ClipLevels {
    // Per level: its window's minimum corner (xyz), metres, and its voxel edge (w).
    levels: array<vec4<f32>, 8>,
    // The scene's cube, lowest and highest corner (xyz): cones stop at it, as at the dense
    // volume's faces.
    scene_lo: vec4<f32>,
    scene_hi: vec4<f32>,
    // The scene's bounds (xyz), inside the cube: past them there is nothing, so a window's
    // face that lies on or beyond them needs no margin.
    bounds_lo: vec4<f32>,
    bounds_hi: vec4<f32>,
    // Levels in use.
    count: u32,
    // Voxels per side of every window.
    resolution: u32,
    // A bit per level the last voxel work rebuilt alone (the others kept their leaves).
    rebuilt: u32,
    // The rebuilt level whose window's occupancy before the build is kept (voxels/carry.wgsl),
    // or none (MAX_CLIP_LEVELS).
    kept: u32,
    // Where its voxels lay before, against where they lie now: old = new + kept_by (xyz).
    kept_by: vec4<i32>,
}
