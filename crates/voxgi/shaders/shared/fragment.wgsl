// Voxel fragments: the one interface between geometry (meshes, points) and voxel structures.
// 20 bytes: voxel coordinates, albedo + coverage, normal, emission, weight. A structure is
// built from these and nothing else. The fragment buffer's length is its capacity: a pass that makes
// fragments counts every one in `fragment_count[0]` and stores those that fit.

// Where the finest voxels lie: the grid every structure shares. Twin: `GpuFragmentGrid` in
// src/fragments/mod.rs.
struct FragmentGrid {
    // World position of the grid's minimum corner.
    origin: vec3<f32>,
    // Voxels per side.
    resolution: u32,
    // World size of a voxel.
    voxel_size: f32,
    // 1 / voxel_size, rounded once on the host (shaders multiply, so their CPU twins agree).
    inv_voxel_size: f32,
    // Added to a fragment's z: the grid is window `z_offset / resolution` of a structure with
    // several (a clipmap's levels), stacked along z; 0 for the others.
    z_offset: u32,
    _pad: u32,
}

// The voxels a pass makes fragments in, bounds included (empty when hi < lo on an axis), but
// for those of the box kept_lo..kept_hi (none when kept_hi < kept_lo on an axis: the voxels a
// moved clipmap window keeps from its old place). Twin: `GpuRegion` in src/fragments/grid.rs.
struct FragmentRegion {
    lo: vec3<u32>,
    hi: vec3<u32>,
    kept_lo: vec3<u32>,
    kept_hi: vec3<u32>,
}

// Whether voxel `cell` lies in the box lo..hi, bounds included.
fn in_box(cell: vec3<i32>, lo: vec3<u32>, hi: vec3<u32>) -> bool {
    return all(cell >= vec3<i32>(lo)) && all(cell <= vec3<i32>(hi));
}

// Whether `r` makes fragments in voxel `cell`.
fn region_holds(r: FragmentRegion, cell: vec3<i32>) -> bool {
    return in_box(cell, r.lo, r.hi) && !in_box(cell, r.kept_lo, r.kept_hi);
}

struct Fragment {
    // x | y << 10 | z << 20, finest-level voxel coordinates.
    coord: u32,
    // pack4x8unorm(albedo.rgb, opacity), albedo linear.
    albedo: u32,
    // pack2x16snorm of the octahedral encoding of the unit normal.
    normal: u32,
    // Emitted radiance as RGB9E5.
    emission: u32,
    // Bits 0-15: the fragment's share of its voxel's surface, in 1/WEIGHT_ONE voxel faces: a
    // mesh fragment stands for the whole surface it has in the voxel (WEIGHT_ONE), a point for
    // the part of its area its region of influence puts in the voxel (splat.wgsl). Bits 16-23:
    // how far the voxel's centre lies in front of the surface along the normal, in
    // 1/SURFACE_UNITS voxels (two's complement; negative: behind). Bit 31 (DENSITY): the
    // fragment's opacity is its share (points, seed 004 §4.3.4), not its coverage (meshes).
    weight: u32,
}

const SURFACE_UNITS: f32 = 64.0;

// The fragment's `weight` word: share `w` (at most WEIGHT_ONE), the centre's signed distance
// `d` from the surface (voxels, clamped to +-2), DENSITY when `density`.
fn pack_weight(w: u32, d: f32, density: bool) -> u32 {
    let q = u32(i32(round(clamp(d, -2.0, 1.98) * SURFACE_UNITS))) & 0xffu;
    return min(w, 0xffffu) | (q << 16u) | select(0u, DENSITY, density);
}

// The centre's signed distance from the surface, in SURFACE_UNITS (sign-extended).
fn fragment_surface(f: Fragment) -> i32 {
    return (i32(f.weight << 8u)) >> 24u;
}

const WEIGHT_ONE: u32 = 4096u;
const DENSITY: u32 = 0x80000000u;
// The surface share at which a voxel of points is opaque: half a voxel face. A surface that
// crosses a voxel's grid plane splits its points between the two voxels beside it, and one of
// them holds at least half: so every ray across a point-sampled surface meets an opaque voxel,
// as it meets one of the voxels a mesh's conservative voxelization fills.
const DENSITY_OPAQUE: f32 = 0.5;

fn pack_coord(c: vec3<u32>) -> u32 {
    return c.x | (c.y << 10u) | (c.z << 20u);
}

fn unpack_coord(v: u32) -> vec3<u32> {
    return vec3<u32>(v & 1023u, (v >> 10u) & 1023u, (v >> 20u) & 1023u);
}

fn oct_encode(n: vec3<f32>) -> vec2<f32> {
    let p = n.xy / (abs(n.x) + abs(n.y) + abs(n.z));
    if n.z >= 0.0 {
        return p;
    }
    return (vec2<f32>(1.0) - abs(p.yx)) * select(vec2<f32>(-1.0), vec2<f32>(1.0), p >= vec2<f32>(0.0));
}

fn oct_decode(e: vec2<f32>) -> vec3<f32> {
    var n = vec3<f32>(e, 1.0 - abs(e.x) - abs(e.y));
    if n.z < 0.0 {
        let xy = (vec2<f32>(1.0) - abs(n.yx)) * select(vec2<f32>(-1.0), vec2<f32>(1.0), n.xy >= vec2<f32>(0.0));
        n = vec3<f32>(xy, n.z);
    }
    return normalize(n);
}

// Shared-exponent RGB: 9-bit mantissas, 5-bit exponent (bias 15), as in the GL format.
fn pack_rgb9e5(c_in: vec3<f32>) -> u32 {
    let c = clamp(c_in, vec3<f32>(0.0), vec3<f32>(65408.0));
    let m = max(c.r, max(c.g, c.b));
    if m < 1e-9 {
        return 0u;
    }
    var e = max(-16, i32(floor(log2(m)))) + 1;
    var scale = exp2(f32(e - 9));
    if u32(floor(m / scale + 0.5)) >= 512u {
        e += 1;
        scale = exp2(f32(e - 9));
    }
    let q = vec3<u32>(floor(c / scale + 0.5));
    return min(q.r, 511u) | (min(q.g, 511u) << 9u) | (min(q.b, 511u) << 18u) | (u32(e + 15) << 27u);
}

fn unpack_rgb9e5(v: u32) -> vec3<f32> {
    let e = i32(v >> 27u) - 15;
    let scale = exp2(f32(e - 9));
    return vec3<f32>(f32(v & 511u), f32((v >> 9u) & 511u), f32((v >> 18u) & 511u)) * scale;
}

// A voxel's attributes are weighted integer sums of its fragments' (so the result does not
// depend on the order atomics add them: deterministic), then averages. FRAGMENT_SUMS u32 per
// voxel: weight, weight x albedo rgb (8-bit units), weight x normal xyz (1/NORMAL_UNITS units,
// two's complement), weight x emission rgb (1/EMISSION_SCALE units), the weight of the
// density fragments (points), weight x the centre's distance from the surface (SURFACE_UNITS,
// two's complement); the coverage (how much of the voxel a mesh fragment's solid
// fills, 8-bit units) is kept as a maximum beside them. The units bound what a voxel holds
// before a sum wraps: 1024 mesh fragments (the normal sums, i32), and emission x fragments
// below 16384 W/(m² sr); points weigh a fraction of a mesh fragment each.
const FRAGMENT_SUMS: u32 = 12u;
const NORMAL_UNITS: f32 = 512.0;
const EMISSION_SCALE: f32 = 64.0;

fn fragment_weight(f: Fragment) -> u32 {
    return f.weight & 0xffffu;
}

fn fragment_sums(f: Fragment) -> array<u32, 12> {
    let w = fragment_weight(f);
    let albedo = unpack4x8unorm(f.albedo);
    let n = vec3<i32>(round(oct_decode(unpack2x16snorm(f.normal)) * NORMAL_UNITS)) * i32(w);
    let e = vec3<u32>(round(unpack_rgb9e5(f.emission) * EMISSION_SCALE)) * w;
    return array<u32, 12>(
        w,
        u32(round(albedo.r * 255.0)) * w,
        u32(round(albedo.g * 255.0)) * w,
        u32(round(albedo.b * 255.0)) * w,
        bitcast<u32>(n.x),
        bitcast<u32>(n.y),
        bitcast<u32>(n.z),
        e.r,
        e.g,
        e.b,
        select(0u, w, (f.weight & DENSITY) != 0u),
        bitcast<u32>(fragment_surface(f) * i32(w)),
    );
}

fn fragment_coverage(f: Fragment) -> u32 {
    return u32(round(unpack4x8unorm(f.albedo).a * 255.0));
}

// What a voxel's sums resolve to: albedo (rgb) and opacity, mean normal (xyz) and how well the
// fragments' normals agree (w, the length of their mean: 1 one orientation, ~0 opposite faces;
// Toksvig's measure of the normal distribution's spread), emitted radiance, and how far the
// centre lies in front of the surface along the normal (voxels; negative: behind).
struct VoxelAttributes {
    albedo: vec4<f32>,
    normal: vec4<f32>,
    emission: vec3<f32>,
    surface: f32,
}

fn resolve_sums(sum: array<u32, 12>, coverage: u32) -> VoxelAttributes {
    let weight = f32(max(sum[0], 1u));
    let albedo = vec3<f32>(f32(sum[1]), f32(sum[2]), f32(sum[3])) / (255.0 * weight);
    let nsum = vec3<f32>(
        f32(bitcast<i32>(sum[4])),
        f32(bitcast<i32>(sum[5])),
        f32(bitcast<i32>(sum[6])),
    ) / (NORMAL_UNITS * weight);
    let e = vec3<f32>(f32(sum[7]), f32(sum[8]), f32(sum[9])) / (EMISSION_SCALE * weight);
    let len = min(length(nsum), 1.0);
    // A voxel static geometry touches blocks all rays through it: opacity 1 (conservative).
    // Dynamic geometry fills the voxels its surface crosses by how much of them lies inside
    // it (voxelize.wgsl), so it moves through the grid smoothly instead of a voxel at a time.
    // Points make a voxel as opaque as the surface they put in it (DENSITY_OPAQUE).
    let density = f32(sum[10]) / (DENSITY_OPAQUE * f32(WEIGHT_ONE));
    let opacity = max(f32(coverage) / 255.0, min(density, 1.0));
    return VoxelAttributes(
        vec4<f32>(albedo, opacity),
        vec4<f32>(select(vec3<f32>(0.0), nsum / length(nsum), len > 1e-4), len),
        e,
        f32(bitcast<i32>(sum[11])) / (SURFACE_UNITS * weight),
    );
}
