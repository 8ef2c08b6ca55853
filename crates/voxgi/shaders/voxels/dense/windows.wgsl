// Sampling the dense volume's textures (@group(1)): `windows` cubes of `resolution` voxels
// stacked along z (`Volume::windows`; the dense volume has one, a clipmap one per level), each
// with its finest level and its directional chains. voxels/dense/sample.wgsl reads window 0;
// the clipmap's sample.wgsl picks windows by position and footprint.
//
// The resources: the volume's placement `vol`, `radiance0` (finest level, isotropic),
// `chains` (the directional mip chains, one level above the finest, as blocks stacked along
// z: +X, -X, +Y, -Y, +Z, -Z, each block the windows stacked; in isotropic mode one block)
// and `voxel_sampler` (trilinear, clamp to edge). With `vol.anisotropic` 2 two more blocks
// follow the six: the specular lobes' moments (shared/specular_lobe.wgsl, "The lobe chain").
//
// No branch: CPU drivers run every side of a branch that differs between SIMD lanes, and
// even a branch no lane takes costs more on lavapipe than the fetch it would skip.

//!include shared/volume.wgsl
//!include shared/specular_lobe.wgsl

@group(1) @binding(0) var<uniform> vol: Volume;
@group(1) @binding(1) var radiance0: texture_3d<f32>;
@group(1) @binding(2) var chains: texture_3d<f32>;
@group(1) @binding(3) var voxel_sampler: sampler;

// Samples at least WIDE_SAMPLE voxels across read only the directional chains.
const WIDE_SAMPLE: f32 = 2.0;

// Optical depth (L sigma, sigma) at `uvw` (in [0, 1]^3 over window `w`) filtered to `lod`
// levels above its finest (0 ..= levels - 1), seen along `dir`: the level nearest `lod`, not a
// blend of the two around it. Levels blended in depth saturate as the filter across a cone
// does (`chain_along`); blended as opacities, the finest level's depth would be lost.
fn window_depth(uvw: vec3<f32>, lod: f32, dir: vec3<f32>, win: u32) -> vec4<f32> {
    // Half a texel inside the window, so the filter never blends the next one's voxels.
    let inside = clamp(uvw.z, 0.5 / f32(vol.resolution), 1.0 - 0.5 / f32(vol.resolution));
    let z = (f32(win) + select(uvw.z, inside, vol.windows > 1u)) / f32(vol.windows);
    let fine = textureSampleLevel(radiance0, voxel_sampler, vec3<f32>(uvw.xy, z), 0.0);
    let cl = nearest_chain(lod - 1.0);
    let coarse = sample_chains(uvw, cl, dir, win);
    let s = select(fine, coarse, lod >= 0.5);
    if !LOBE_CHAIN {
        return s;
    }
    // The finest level has no lobes: a sample finer than the first chain level sees that
    // level's lobes wherever it sees a surface. Faded in as the chain once was, a quarter cone's
    // narrow samples near a metal saw its leaves black (diffuse albedo 0) and little of what
    // it reflects (docs/QUALITY.md, "Specular light in the bounces").
    return with_lobes(s, uvw, cl, dir, win, 1.0);
}

// The chain level (an integer) nearest chain level `cl`, inside the chains.
fn nearest_chain(cl: f32) -> f32 {
    return clamp(floor(cl + 0.5), 0.0, f32(vol.levels - 2u));
}

// Sample `s` (optical depth, seen along `dir`) with the light the lobes of chain level `cl` (an
// integer) send back along the cone, times `weight`: radiance per covered area, as opaque as
// the sample is along dir (L sigma gains L_lobe sigma).
fn with_lobes(s: vec4<f32>, uvw: vec3<f32>, cl: f32, dir: vec3<f32>, win: u32, weight: f32) -> vec4<f32> {
    let z = chain_z(uvw.z, cl);
    let blocks = f32(LOBE_DIRECTION + 1u) * f32(vol.windows);
    let m = textureSampleLevel(chains, voxel_sampler, vec3<f32>(uvw.xy, (z + f32(LOBE_EXITANCE * vol.windows + win)) / blocks), cl);
    let v = textureSampleLevel(chains, voxel_sampler, vec3<f32>(uvw.xy, (z + f32(LOBE_DIRECTION * vol.windows + win)) / blocks), cl);
    return vec4<f32>(s.rgb + weight * chain_lobe_light(m, v, dir) * s.a, s.a);
}

// True when the pipeline serves a volume with the lobe chain (`vol.anisotropic` 2): samples
// add the lobes' light. A constant, not the uniform, so that the other pipelines carry no
// branch (a third more gather time on lavapipe); the blocks are counted from the uniform, so
// a pipeline without it still reads the six directions right.
override LOBE_CHAIN: bool = false;

// True when the pipeline serves an isotropic volume: each sample then reads its one block along
// one axis (two fetches), not three axes' worth. Left false, the mode is read from `vol` at run
// time.
override ISOTROPIC_ONLY: bool = false;

// Directional blocks an anisotropic sample reads: 3, every axis by its weight (seed 000 §9),
// or 2, the two of largest weight (a third fewer fetches).
override SAMPLE_AXES: u32 = 3u;

// A window's z at chain level `cl` (an integer), kept half a texel inside it, so the trilinear
// filter never blends a neighbouring window's or block's texels.
fn chain_z(z: f32, cl: f32) -> f32 {
    let texels = max(f32(vol.resolution / 2u) * exp2(-cl), 1.0);
    return clamp(z, 0.5 / texels, 1.0 - 0.5 / texels);
}

// Block `b` (counted with its window, of `blocks` stacked along z) at chain level `c` (an
// integer), seen along `axis`: two filtered fetches at the centres of the two layers of texels
// around `uvw` along the axis, each turned to optical depth, interpolated between them. The
// chains store premultiplied opacity, so across the axis the sampler averages coverage (a
// texel beside an empty one passes half the rays it covers, not the few that its depth averaged
// with nothing lets through); along it a wall crossed keeps its whole depth. Each layer's
// position is kept half a texel inside the window, as the sampler's own would be clamped.
fn chain_along(uvw: vec3<f32>, c: f32, b: f32, blocks: f32, axis: u32) -> vec4<f32> {
    let n = max(f32(vol.resolution / 2u) * exp2(-c), 1.0);
    let lo = 0.5 / n;
    let p = uvw[axis] * n - 0.5;
    let layer = floor(p);
    var q0 = clamp(uvw, vec3<f32>(lo), vec3<f32>(1.0 - lo));
    var q1 = q0;
    q0[axis] = clamp((layer + 0.5) / n, lo, 1.0 - lo);
    q1[axis] = clamp((layer + 1.5) / n, lo, 1.0 - lo);
    let s0 = textureSampleLevel(chains, voxel_sampler, vec3<f32>(q0.xy, (q0.z + b) / blocks), c);
    let s1 = textureSampleLevel(chains, voxel_sampler, vec3<f32>(q1.xy, (q1.z + b) / blocks), c);
    return mix(to_depth(s0), to_depth(s1), p - layer);
}

// The directional chains of window `w` at chain level `cl` (an integer: the volume's level
// cl + 1).
fn sample_chains(uvw: vec3<f32>, cl: f32, dir: vec3<f32>, win: u32) -> vec4<f32> {
    let window = f32(win);
    let windows = f32(vol.windows);
    if ISOTROPIC_ONLY {
        return chain_along(uvw, cl, window, windows, main_axis(dir));
    }
    // In isotropic mode the one block serves every axis, read along the nearest (`axis_weights`).
    let aniso = vol.anisotropic != 0u;
    let block = select(
        vec3<f32>(0.0),
        vec3<f32>(select(1.0, 0.0, dir.x >= 0.0), select(3.0, 2.0, dir.y >= 0.0), select(5.0, 4.0, dir.z >= 0.0)),
        aniso,
    );
    // As `Filtering::blocks`: the lobe chain's blocks come after the six directions.
    let blocks = f32(select(select(1u, 6u, aniso), LOBE_DIRECTION + 1u, vol.anisotropic == 2u)) * windows;
    // Each direction's block holds every window: block b, window w at b * windows + w.
    let first = block * windows + window;
    let w = axis_weights(dir, aniso);
    if SAMPLE_AXES == 2u {
        // The two axes of largest weight, renormalised: the third weighs at most a third, and
        // its block is then assumed to hold the others' weighted mean.
        let drop_x = w.x <= w.y && w.x <= w.z;
        let drop_y = !drop_x && w.y <= w.z;
        let a0 = select(0u, 1u, drop_x);
        let b0 = select(first.x, first.y, drop_x);
        let w0 = select(w.x, w.y, drop_x);
        let a1 = select(select(1u, 2u, drop_y), 2u, drop_x);
        let b1 = select(select(first.y, first.z, drop_y), first.z, drop_x);
        let w1 = select(select(w.y, w.z, drop_y), w.z, drop_x);
        let s0 = chain_along(uvw, cl, b0, blocks, a0);
        let s1 = chain_along(uvw, cl, b1, blocks, a1);
        return (w0 * s0 + w1 * s1) / max(w0 + w1, 1e-6);
    }
    let x = chain_along(uvw, cl, first.x, blocks, 0u);
    let y = chain_along(uvw, cl, first.y, blocks, 1u);
    let zz = chain_along(uvw, cl, first.z, blocks, 2u);
    return w.x * x + w.y * y + w.z * zz;
}
