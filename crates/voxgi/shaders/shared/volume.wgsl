// The voxel volume's placement and the cone-tracing parameters. Twins: `GpuVolume` and
// `GpuCones` in src/voxel/mod.rs.

struct Volume {
    // World position of the volume's minimum corner.
    origin: vec3<f32>,
    // Voxels per side at the finest level.
    resolution: u32,
    // World size of a finest voxel.
    voxel_size: f32,
    // Mip levels including the finest.
    levels: u32,
    // 1: six directional values per voxel above the finest level, 0: one.
    anisotropic: u32,
    fragment_capacity: u32,
}

const MAX_CONES: u32 = 16u;

struct Cones {
    // Tangent-space axis (z = normal) and weight (the cone's share of the cosine-weighted
    // hemisphere, summing to 1 over all cones).
    dirs: array<vec4<f32>, 16>,
    count: u32,
    // Tangent of the diffuse cones' half-angle.
    diffuse_tan: f32,
    // Sample step as a fraction of the cone diameter.
    step_factor: f32,
    // Cones stop after this distance (metres).
    max_distance: f32,
    // Ambient occlusion: falloff 1/(1 + lambda r), rays stop at ao_radius.
    ao_lambda: f32,
    ao_radius: f32,
    // Offset of the cone origin along the normal, in finest voxels.
    origin_offset: f32,
    // 0: the per-pixel gather adds indirect light, 1: it does not (bounces = 0).
    indirect: u32,
}

// Voxel linear index <-> coordinates (x fastest).
fn voxel_coord(i: u32, res: u32) -> vec3<u32> {
    return vec3<u32>(i % res, (i / res) % res, i / (res * res));
}

fn voxel_index(c: vec3<u32>, res: u32) -> u32 {
    return c.x + res * (c.y + res * c.z);
}

fn voxel_center(c: vec3<u32>, vol: Volume) -> vec3<f32> {
    return vol.origin + (vec3<f32>(c) + 0.5) * vol.voxel_size;
}
