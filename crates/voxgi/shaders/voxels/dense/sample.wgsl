// The dense mip-mapped volume's side of the voxel contract: the names cone tracing, the gather
// and the bounce may use (docs/ARCHITECTURE.md, "The voxel contract"; the test
// `every_structure_defines_the_voxel_contract` checks the signatures):
//
//   const WIDE_SAMPLE: f32                       samples at least this many voxels across may
//                                                skip the finest level (sample_depth_wide)
//   fn voxels_voxel_size() -> f32                finest voxel edge, metres
//   fn voxels_voxel_size_at(p) -> f32            the finest voxel edge held about p (cones
//                                                start at it: shared/cone.wgsl)
//   fn voxels_contains(p) -> bool                p lies inside the structure's bounds
//   fn sample_depth(p, d, dir) -> vec4<f32>      optical depth (L sigma, sigma) per sample
//                                                diameter, filtered to diameter d, seen along dir
//   fn sample_depth_wide(p, d, dir)              the same for d >= WIDE_SAMPLE voxels
//   fn sample_voxels(p, d, dir) -> vec4<f32>     premultiplied radiance and opacity
//
// Everything here reads @group(1) only: the volume's placement `vol`, `radiance0` (finest
// level, isotropic), `chains` (the directional mip chains, one level above the finest, as
// blocks stacked along z: +X, -X, +Y, -Y, +Z, -Z; in isotropic mode one block) and
// `voxel_sampler` (trilinear, clamp to edge). `DenseVolume::sampling_layout` is its twin.
//
// No branch: CPU drivers run every side of a branch that differs between SIMD lanes, and
// even a branch no lane takes costs more on lavapipe than the fetch it would skip.

//!include shared/volume.wgsl

@group(1) @binding(0) var<uniform> vol: Volume;
@group(1) @binding(1) var radiance0: texture_3d<f32>;
@group(1) @binding(2) var chains: texture_3d<f32>;
@group(1) @binding(3) var voxel_sampler: sampler;

fn voxels_voxel_size() -> f32 {
    return vol.voxel_size;
}

fn voxels_voxel_size_at(p: vec3<f32>) -> f32 {
    return vol.voxel_size;
}

fn voxels_contains(p: vec3<f32>) -> bool {
    return inside_volume(volume_uvw(p));
}

fn sample_voxels(pos: vec3<f32>, diameter: f32, dir: vec3<f32>) -> vec4<f32> {
    return from_depth(sample_depth(pos, diameter, dir));
}

// Samples at least WIDE_SAMPLE voxels across read only the directional chains.
const WIDE_SAMPLE: f32 = 2.0;

// Optical depth per sample diameter: (L sigma, sigma).
fn sample_depth(pos: vec3<f32>, diameter: f32, dir: vec3<f32>) -> vec4<f32> {
    let uvw = volume_uvw(pos);
    let lod = clamp(log2(max(diameter / vol.voxel_size, 1.0)), 0.0, f32(vol.levels - 1u));
    let fine = textureSampleLevel(radiance0, voxel_sampler, uvw, 0.0);
    let coarse = sample_chains(uvw, max(lod - 1.0, 0.0), dir);
    // Only between the finest level and the first coarse one is the finest level read.
    return select(vec4<f32>(0.0), mix(fine, coarse, min(lod, 1.0)), inside_volume(uvw));
}

// sample_depth for a diameter of at least WIDE_SAMPLE voxels.
fn sample_depth_wide(pos: vec3<f32>, diameter: f32, dir: vec3<f32>) -> vec4<f32> {
    let uvw = volume_uvw(pos);
    let lod = clamp(log2(diameter / vol.voxel_size), 1.0, f32(vol.levels - 1u));
    return select(vec4<f32>(0.0), sample_chains(uvw, lod - 1.0, dir), inside_volume(uvw));
}

// Texture coordinates of a world position over the whole volume.
fn volume_uvw(pos: vec3<f32>) -> vec3<f32> {
    return (pos - vol.origin) / (vol.voxel_size * f32(vol.resolution));
}

// Outside the volume there is nothing (no clamp-to-border sampler in core WebGPU).
fn inside_volume(uvw: vec3<f32>) -> bool {
    return all(uvw >= vec3<f32>(0.0)) && all(uvw <= vec3<f32>(1.0));
}

// True when the pipeline serves an isotropic volume: each sample then makes one fetch, not
// three equal ones (half the gather's time on lavapipe). Left false, the mode is read from
// `vol` at run time.
override ISOTROPIC_ONLY: bool = false;

// Directional blocks an anisotropic sample reads: 3, every axis by its weight (seed 000 §9),
// or 2, the two of largest weight (a third fewer fetches).
override SAMPLE_AXES: u32 = 3u;

// The directional chains at chain level `cl` (the volume's level cl + 1).
fn sample_chains(uvw: vec3<f32>, cl: f32, dir: vec3<f32>) -> vec4<f32> {
    // Keep z half a texel inside the block at the coarser of the two levels read, so the
    // trilinear filter never blends a neighbouring direction's block.
    let upper = min(floor(cl) + 1.0, f32(vol.levels - 2u));
    let texels = max(f32(vol.resolution / 2u) * exp2(-upper), 1.0);
    let z = clamp(uvw.z, 0.5 / texels, 1.0 - 0.5 / texels);
    if ISOTROPIC_ONLY {
        return textureSampleLevel(chains, voxel_sampler, vec3<f32>(uvw.xy, z), cl);
    }
    // In isotropic mode the one block serves every axis.
    let aniso = vol.anisotropic != 0u;
    let block = select(
        vec3<f32>(0.0),
        vec3<f32>(select(1.0, 0.0, dir.x >= 0.0), select(3.0, 2.0, dir.y >= 0.0), select(5.0, 4.0, dir.z >= 0.0)),
        aniso,
    );
    let blocks = select(1.0, 6.0, aniso);
    // Weighted by the squared direction cosines (they sum to 1).
    let w = dir * dir;
    if SAMPLE_AXES == 2u {
        // The two axes of largest weight, renormalised: the third weighs at most a third, and
        // its block is then assumed to hold the others' weighted mean.
        let drop_x = w.x <= w.y && w.x <= w.z;
        let drop_y = !drop_x && w.y <= w.z;
        let b0 = select(block.x, block.y, drop_x);
        let w0 = select(w.x, w.y, drop_x);
        let b1 = select(select(block.y, block.z, drop_y), block.z, drop_x);
        let w1 = select(select(w.y, w.z, drop_y), w.z, drop_x);
        let s0 = textureSampleLevel(chains, voxel_sampler, vec3<f32>(uvw.xy, (z + b0) / blocks), cl);
        let s1 = textureSampleLevel(chains, voxel_sampler, vec3<f32>(uvw.xy, (z + b1) / blocks), cl);
        return (w0 * s0 + w1 * s1) / max(w0 + w1, 1e-6);
    }
    let x = textureSampleLevel(chains, voxel_sampler, vec3<f32>(uvw.xy, (z + block.x) / blocks), cl);
    let y = textureSampleLevel(chains, voxel_sampler, vec3<f32>(uvw.xy, (z + block.y) / blocks), cl);
    let zz = textureSampleLevel(chains, voxel_sampler, vec3<f32>(uvw.xy, (z + block.z) / blocks), cl);
    return w.x * x + w.y * y + w.z * zz;
}
