// The dense volume's irradiance lookup for the fast shading (`IndirectShading::Leaves`): the
// record the last bounce kept for the leaf at a finest-voxel coordinate. The names, which
// shared/leaf_irradiance.wgsl uses:
//
//   fn irradiance_grid(p) -> vec3<f32>          p in finest-voxel units from the volume's corner
//   fn leaf_irradiance_at(c) -> vec4<u32>       the record of the leaf at voxel c (c may lie
//                                               outside the volume); zero where there is none
//
// At @group(3), after sample.wgsl's @group(1); `DenseVolume::irradiance_layout` is the twin.

//!include voxels/sample.wgsl

// Per voxel (x fastest): 0 empty, 2 + slot once allocated (build_shared.wgsl).
@group(3) @binding(0) var<storage, read> irradiance_occupancy: array<u32>;
// Per slot: irradiance (rgb, f16), occlusion (f16), normal and agreement (snorm8), written by
// the last bounce.
@group(3) @binding(1) var<storage, read> irradiance_leaves: array<vec4<u32>>;

fn irradiance_grid(p: vec3<f32>) -> vec3<f32> {
    return (p - vol.origin) / vol.voxel_size;
}

fn leaf_irradiance_at(c: vec3<i32>) -> vec4<u32> {
    let r = i32(vol.resolution);
    let inside = all(c >= vec3<i32>(0)) && all(c < vec3<i32>(r));
    let u = vec3<u32>(clamp(c, vec3<i32>(0), vec3<i32>(r - 1)));
    let occ = irradiance_occupancy[voxel_index(u, vol.resolution)];
    // A lock value (past the capacity) reads as a slot past the records.
    let slot = occ - 2u;
    let n = arrayLength(&irradiance_leaves);
    let found = inside && occ >= 2u && slot < n;
    return select(vec4<u32>(0u), irradiance_leaves[min(slot, n - 1u)], found);
}
