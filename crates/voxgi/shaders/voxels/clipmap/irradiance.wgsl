// The clipmap's irradiance lookup for the fast shading (voxels/dense/irradiance.wgsl lists the
// names): the finest level that holds the pixel's window of leaves, in its voxels; the leaf at
// c is looked up in the stacked windows, as the dense volume's are. At @group(3), after
// sample.wgsl's @group(1); the dense volume's `irradiance_layout` is the twin.

//!include voxels/sample.wgsl

// Per voxel of the stacked windows (x fastest): 0 empty, 2 + slot once allocated.
@group(3) @binding(0) var<storage, read> irradiance_occupancy: array<u32>;
// Per slot: the record the last bounce kept.
@group(3) @binding(1) var<storage, read> irradiance_leaves: array<vec4<u32>>;

// The fast shading reads a window of 5 x 5 x 2 leaves around the pixel.
const LOOKUP_ROOM: f32 = 4.0;

fn irradiance_grid(p: vec3<f32>) -> vec3<f32> {
    let k = level_holding(p, 0.0, LOOKUP_ROOM);
    let local = level_uvw(p, k) * f32(clip.resolution);
    return local + vec3<f32>(0.0, 0.0, f32(k * clip.resolution));
}

fn leaf_irradiance_at(c: vec3<i32>) -> vec4<u32> {
    let r = i32(clip.resolution);
    let top = vec3<i32>(r, r, r * i32(clip.count));
    let inside = all(c >= vec3<i32>(0)) && all(c < top);
    let u = vec3<u32>(clamp(c, vec3<i32>(0), top - 1));
    let occ = irradiance_occupancy[voxel_index(u, clip.resolution)];
    // A lock value (past the capacity) reads as a slot past the records.
    let slot = occ - 2u;
    let n = arrayLength(&irradiance_leaves);
    let found = inside && occ >= 2u && slot < n;
    return select(vec4<u32>(0u), irradiance_leaves[min(slot, n - 1u)], found);
}
