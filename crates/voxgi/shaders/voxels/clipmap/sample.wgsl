// The clipmap's side of the voxel contract (voxels/dense/sample.wgsl lists it): levels of
// `resolution`³ voxels around the camera, each twice the extent of the one inside it, stored as
// the windows of the dense volume's textures (voxels/dense/windows.wgsl), each with its own
// directional mips.
//
// A sample reads the finest level that holds it wholly: its position at least MARGIN voxels
// plus its diameter inside the level's window (the filter of a sample of diameter d at its
// mip reaches about d around it), where the next coarser level holds it wholly too. Within
// BAND voxels of that limit it hands over to the next coarser level, linearly, so neither a
// camera move nor a cone crossing a level's border shows a step (`sample_depth`). Reads only @group(1): windows.wgsl's resources and `clip` at binding 4.
// `Clipmap::sampling_layout` is its twin.

//!include voxels/dense/windows.wgsl
//!include voxels/levels.wgsl

@group(1) @binding(4) var<uniform> clip: ClipLevels;

// Voxels a sample's trilinear filter needs inside a window, beyond its diameter.
const MARGIN: f32 = 1.5;
// Voxels over which a level hands over to the next coarser one.
const BAND: f32 = 4.0;

fn voxels_voxel_size() -> f32 {
    return clip.levels[0].w;
}

// The level that holds p with room for a cone's first samples (`level_holding`).
fn voxels_voxel_size_at(p: vec3<f32>) -> f32 {
    return clip.levels[level_holding(p, 0.0, MARGIN + BAND + 1.0)].w;
}

// Inside the coarsest level and the scene's cube: past the cube there is nothing (a cone
// stops there as it does at the dense volume's faces, not at a coarse voxel astride them).
fn voxels_contains(p: vec3<f32>) -> bool {
    let in_scene = all(p >= clip.scene_lo.xyz) && all(p <= clip.scene_hi.xyz);
    return in_scene && inside_by(p, clip.count - 1u) >= 0.0;
}

fn sample_voxels(pos: vec3<f32>, diameter: f32, dir: vec3<f32>) -> vec4<f32> {
    return from_depth(sample_depth(pos, diameter, dir));
}

// Texture coordinates of p over level k's window.
fn level_uvw(p: vec3<f32>, k: u32) -> vec3<f32> {
    let l = clip.levels[k];
    return (p - l.xyz) / (l.w * f32(clip.resolution));
}

// How far inside level k's window p lies, in its voxels (negative outside), counting only
// the faces inside the scene's bounds: past the others there is nothing the level lacks.
fn inside_by(p: vec3<f32>, k: u32) -> f32 {
    let l = clip.levels[k];
    let n = f32(clip.resolution);
    let q = (p - l.xyz) / l.w;
    let open_lo = l.xyz > clip.bounds_lo.xyz + 0.5 * l.w;
    let open_hi = l.xyz + n * l.w < clip.bounds_hi.xyz - 0.5 * l.w;
    let far = vec3<f32>(1e9);
    let m = min(select(far, q, open_lo), select(far, vec3<f32>(n) - q, open_hi));
    // Outside the window itself nothing of it holds p.
    let outside = any(q < vec3<f32>(0.0)) || any(q > vec3<f32>(n));
    return select(min(m.x, min(m.y, m.z)), -1.0, outside);
}

// How far past the room a sample of `diameter` at p needs level k's window holds it, in
// metres (negative where it does not).
fn level_reach(p: vec3<f32>, diameter: f32, k: u32) -> f32 {
    return level_reach_with(p, diameter, MARGIN, k);
}

// How far past `room` voxels plus the diameter level k's window holds p, in metres.
fn level_reach_with(p: vec3<f32>, diameter: f32, room: f32, k: u32) -> f32 {
    return (inside_by(p, k) - room - diameter / clip.levels[k].w) * clip.levels[k].w;
}

// The finest level with at least `room` voxels plus the diameter around p, its reach carried
// as `sample_depth` carries it (the coarsest when none has).
fn level_holding(p: vec3<f32>, diameter: f32, room: f32) -> u32 {
    var k = clip.count - 1u;
    var reach = level_reach_with(p, diameter, room, k);
    for (var j = i32(clip.count) - 2; j >= 0; j--) {
        reach = min(level_reach_with(p, diameter, room, u32(j)), reach - BAND * clip.levels[j + 1].w);
        k = select(k, u32(j), reach >= 0.0);
    }
    return k;
}

// Level k's optical depth at p for a sample of `diameter`. Weighed at the window's faces as
// the dense volume's samples are at its faces (`border_weight`): a level reads that near its
// faces only where no coarser level takes over, past the scene's bounds, where there is nothing.
fn level_depth(p: vec3<f32>, diameter: f32, dir: vec3<f32>, k: u32) -> vec4<f32> {
    let lod = clamp(log2(max(diameter / clip.levels[k].w, 1.0)), 0.0, f32(vol.levels - 1u));
    let uvw = clamp(level_uvw(p, k), vec3<f32>(0.0), vec3<f32>(1.0));
    return window_depth(uvw, lod, dir, k) * border_weight(uvw, lod, f32(clip.resolution));
}

// Optical depth per sample diameter: (L sigma, sigma).
//
// A level takes a sample over from the next coarser across BAND of its voxels, and only where
// that one holds the sample wholly, itself BAND of its voxels past its own hand-over (its reach,
// `level_reach`, counts at most as far past that): two levels blend, never three, and the
// picture has no step where windows lie closer than their bands (a small resolution, or a
// window waiting its turn to move).
fn sample_depth(pos: vec3<f32>, diameter: f32, dir: vec3<f32>) -> vec4<f32> {
    // The finest level that holds the sample at all, and how far it is from handing over.
    var k = clip.count - 1u;
    var reach = level_reach(pos, diameter, k);
    var w = clamp(reach / (BAND * clip.levels[k].w), 0.0, 1.0);
    for (var j = i32(clip.count) - 2; j >= 0; j--) {
        let s = clip.levels[j].w;
        reach = min(level_reach(pos, diameter, u32(j)), reach - BAND * clip.levels[j + 1].w);
        let take = reach > 0.0;
        k = select(k, u32(j), take);
        w = select(w, clamp(reach / (BAND * s), 0.0, 1.0), take);
    }
    let coarser = min(k + 1u, clip.count - 1u);
    let fine = level_depth(pos, diameter, dir, k);
    // Past the coarsest level there is nothing: it fades out at its window's edge.
    let outer = select(level_depth(pos, diameter, dir, coarser), vec4<f32>(0.0), k == coarser);
    return mix(outer, fine, w);
}

// Samples however wide may fall in a level where they are narrow: the same as sample_depth.
fn sample_depth_wide(pos: vec3<f32>, diameter: f32, dir: vec3<f32>) -> vec4<f32> {
    return sample_depth(pos, diameter, dir);
}
