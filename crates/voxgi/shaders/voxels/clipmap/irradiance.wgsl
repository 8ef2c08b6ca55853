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

// The level `irradiance_grid` chose: its leaves only, never the next window's in the stack.
var<private> lookup_level: u32;

fn irradiance_grid(p: vec3<f32>) -> vec3<f32> {
    let k = level_holding(p, 0.0, LOOKUP_ROOM);
    lookup_level = k;
    let local = level_uvw(p, k) * f32(clip.resolution);
    return local + vec3<f32>(0.0, 0.0, f32(k * clip.resolution));
}

fn leaf_irradiance_at(c: vec3<i32>) -> vec4<u32> {
    let r = i32(clip.resolution);
    let bottom = vec3<i32>(0, 0, r * i32(lookup_level));
    let top = bottom + vec3<i32>(r);
    let inside = all(c >= bottom) && all(c < top);
    let u = vec3<u32>(clamp(c, bottom, top - 1));
    let occ = irradiance_occupancy[voxel_index(u, clip.resolution)];
    // A lock value (past the capacity) reads as a slot past the records.
    let slot = occ - 2u;
    let n = arrayLength(&irradiance_leaves);
    let found = inside && occ >= 2u && slot < n;
    return select(vec4<u32>(0u), irradiance_leaves[min(slot, n - 1u)], found);
}
