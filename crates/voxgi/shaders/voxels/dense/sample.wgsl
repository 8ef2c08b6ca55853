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
// Everything here reads @group(1) only, through voxels/dense/windows.wgsl (the volume is its
// one window). `DenseVolume::sampling_layout` is its twin.

//!include voxels/dense/windows.wgsl

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

// Optical depth per sample diameter: (L sigma, sigma).
fn sample_depth(pos: vec3<f32>, diameter: f32, dir: vec3<f32>) -> vec4<f32> {
    let uvw = volume_uvw(pos);
    let lod = clamp(log2(max(diameter / vol.voxel_size, 1.0)), 0.0, f32(vol.levels - 1u));
    let s = window_depth(uvw, lod, dir, 0u) * border_weight(uvw, lod, f32(vol.resolution));
    return select(vec4<f32>(0.0), s, inside_volume(uvw));
}

// sample_depth for a diameter of at least WIDE_SAMPLE voxels.
fn sample_depth_wide(pos: vec3<f32>, diameter: f32, dir: vec3<f32>) -> vec4<f32> {
    let uvw = volume_uvw(pos);
    let lod = clamp(log2(diameter / vol.voxel_size), 1.0, f32(vol.levels - 1u));
    let cl = nearest_chain(lod - 1.0);
    var s = sample_chains(uvw, cl, dir, 0u);
    if LOBE_CHAIN {
        s = with_lobes(s, uvw, cl, dir, 0u, 1.0);
    }
    return select(vec4<f32>(0.0), s * border_weight(uvw, lod, f32(vol.resolution)), inside_volume(uvw));
}

// Texture coordinates of a world position over the whole volume.
fn volume_uvw(pos: vec3<f32>) -> vec3<f32> {
    return (pos - vol.origin) / (vol.voxel_size * f32(vol.resolution));
}

// Outside the volume there is nothing (no clamp-to-border sampler in core WebGPU).
fn inside_volume(uvw: vec3<f32>) -> bool {
    return all(uvw >= vec3<f32>(0.0)) && all(uvw <= vec3<f32>(1.0));
}
