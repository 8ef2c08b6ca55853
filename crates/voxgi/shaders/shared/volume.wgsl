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
    // 1: six directional values per voxel above the finest level, 0: one; 2: six and the
    // specular lobes' two (voxels/dense/windows.wgsl).
    anisotropic: u32,
    // Cubes of `resolution` voxels stacked along z in every texture and buffer (1; a clipmap's
    // levels are its windows).
    windows: u32,
}

// The half-angle tangent of the cone being traced (shared/cone.wgsl sets it): samples that
// hold specular lobes see them as wide as the cone does. Other samples are read as by a
// diffuse cone's.
var<private> cone_tan_half: f32 = 0.57735;

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
    // 1: the per-pixel gather adds indirect light, 0: it does not (bounces = 0).
    indirect: u32,
    // 1: each diffuse cone traces one quarter of its footprint (shared/cone.wgsl,
    // trace_cone); 0: the whole footprint.
    quarters: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

// How much of a leaf the first directional level counts along direction `dir` (0..6: +X, -X,
// +Y, -Y, +Z, -Z, the way a cone travels), from its mean normal (xyz) and its normals'
// agreement (w): the twin of `voxel::cpu::ndf_weight`, which says why.
fn ndf_weight(normal: vec4<f32>, dir: u32) -> f32 {
    let len = length(normal.xyz);
    let sign = select(-1.0, 1.0, (dir & 1u) == 0u);
    let facing = -sign * normal[dir / 2u] / max(len, 1e-4);
    let w = 1.0 + clamp(normal.w, 0.0, 1.0) * (min(1.0 + facing, 1.0) - 1.0);
    return select(w, 1.0, len < 1e-4);
}

// The leaf slot (or list entry) a thread of a leaf dispatch takes: workgroups of 64 in rows of
// at most 65535 (`VoxelStructure::bindings().leaf_dispatch` and the lists sized like it).
fn dispatch_index(gid: vec3<u32>, nwg: vec3<u32>) -> u32 {
    return gid.x + gid.y * nwg.x * 64u;
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

// The share of a sample's trilinear filter (at level of detail `lod` of a volume `resolution`
// finest voxels a side) that lies inside the volume, each axis's: the textures clamp to their
// edge (core WebGPU has no clamp-to-border sampler), so a sample within half a texel of a face
// read the edge texel, geometry on the face, as if it went on outside (the open front of the
// Cornell box read brighter and more opaque than it is). The depth outside is none, and depth
// filters linearly.
fn border_weight(uvw: vec3<f32>, lod: f32, resolution: f32) -> f32 {
    let u = min(uvw, vec3<f32>(1.0) - uvw) * resolution * exp2(-lod);
    let f = clamp(u + 0.5, vec3<f32>(0.5), vec3<f32>(1.0));
    return f.x * f.y * f.z;
}

// The finest radiance level holds optical depth, not opacity: (L sigma, sigma) per texel
// length, with sigma = -ln(1 - alpha). Depth is what interpolation along a cone may average:
// opacity interpolated between an opaque texel and an empty one thins a wall into a ramp that a
// cone crosses with e^-2 of its light left however finely it steps. Across a cone opacity is
// what averages right (a texel beside an empty one passes half the rays, its depth halved far
// fewer), so the levels above hold premultiplied opacity and samples read them along each
// direction's axis in depth (voxels/dense/windows.wgsl, `chain_along`). Compositing and the
// filter work on premultiplied opacity; these convert at the texture's edge.
const MAX_OPACITY: f32 = 0.999;

// Premultiplied (L alpha, alpha) to stored (L sigma, sigma).
fn to_depth(v: vec4<f32>) -> vec4<f32> {
    let a = clamp(v.a, 0.0, MAX_OPACITY);
    let sigma = -log(1.0 - a);
    return vec4<f32>(v.rgb * (sigma / max(a, 1e-6)), sigma);
}

// Stored (L sigma, sigma) to premultiplied (L alpha, alpha).
fn from_depth(v: vec4<f32>) -> vec4<f32> {
    let sigma = max(v.a, 0.0);
    let a = 1.0 - exp(-sigma);
    return vec4<f32>(v.rgb * (a / max(sigma, 1e-6)), a);
}

// The axis a sample along `dir` reads an isotropic block along: dir's largest component (ties:
// x, then y).
fn main_axis(dir: vec3<f32>) -> u32 {
    let a = abs(dir);
    return select(select(2u, 1u, a.y >= a.z), 0u, a.x >= a.y && a.x >= a.z);
}

// The weights of the three axes a sample along `dir` reads: the squared direction cosines
// (they sum to 1; seed 000 §9) where the blocks are directional; an isotropic block is read
// along `main_axis` alone.
fn axis_weights(dir: vec3<f32>, directional: bool) -> vec3<f32> {
    let along = vec3<u32>(main_axis(dir)) == vec3<u32>(0u, 1u, 2u);
    return select(select(vec3<f32>(0.0), vec3<f32>(1.0), along), dir * dir, directional);
}
