// splat: every point-cloud sample -> voxel fragments at the finest resolution (seed 004
// §4.3.4). A point's cubic region of influence, aligned with the grid and at most one voxel
// wide, overlaps up to eight voxels; each gets a fragment weighted by the overlap. The weight
// is the share of the point's area (the region's edge squared) that falls in the voxel, and
// the voxel's opacity is the sum of its points' shares (DENSITY in shared/fragment.wgsl):
// a densely sampled surface is opaque, a sparse one partly transparent.
//
// The region lies behind the point (its centre half an edge along -normal), not around it as
// in the thesis: the voxels a point fills are then those of the solid just behind the surface,
// as the voxels a mesh fills are those its surface crosses. Centred, a wall's points filled the
// voxel in front of it too, and a floor two voxels from the wall took its AO from a wall a voxel
// nearer (0.44 against the closed form's 0.60; docs/QUALITY.md).
//
// The region is split in integer units of 1/SUB voxel, so the overlaps of one point add up to
// its region's volume exactly, and the weights are rounded up or down by a hash of the
// fragment (unbiased where many equal points would all round the same way). The CPU twin is
// `voxel::cpu::splat`; both must do the same integer steps.

//!include shared/surfel.wgsl
//!include shared/fragment.wgsl

@group(0) @binding(0) var<uniform> grid: FragmentGrid;
@group(0) @binding(1) var<storage, read> points: array<Point>;
// Per point: the edge of its region of influence, metres (0: a point alone, one voxel).
@group(0) @binding(2) var<storage, read> regions: array<f32>;
@group(0) @binding(3) var<storage, read_write> fragments: array<Fragment>;
// [0]: fragments emitted (may exceed the capacity: the host then grows the buffer and redoes).
@group(0) @binding(4) var<storage, read_write> fragment_count: array<atomic<u32>>;
// Fragments are made in these voxels only.
@group(0) @binding(5) var<uniform> region: FragmentRegion;
// The points splatted: x the first, y the count (the static geometry's or the dynamic clouds').
@group(0) @binding(6) var<uniform> range: vec4<u32>;

const SUB: u32 = 1024u;

// A well-mixed 32-bit hash (PCG's output permutation).
fn hash(v: u32) -> u32 {
    let state = v * 747796405u + 2891336453u;
    let word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

fn flat(gid: vec3<u32>, nwg: vec3<u32>) -> u32 {
    return gid.x + gid.y * nwg.x * 64u;
}

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let local = flat(gid, nwg);
    if local >= range.y {
        return;
    }
    // The point's index in the whole buffer: its rounding hash is the same whichever pass
    // splats it.
    let i = range.x + local;
    let pt = points[i];
    // Voxel space by multiplications only (inverse from the host), so the CPU twin rounds alike.
    let p = (pt.position - grid.origin) * grid.inv_voxel_size;
    let e_in = regions[i] * grid.inv_voxel_size;
    let e = select(1.0, min(e_in, 1.0), e_in > 0.0);
    let eq = clamp(u32(round(e * f32(SUB))), 1u, SUB);
    let n_in = point_normal(pt);
    let behind = vec3<i32>(round(n_in * (0.5 * f32(eq))));
    let lo = vec3<i32>(floor(p * f32(SUB))) - vec3<i32>(i32(eq / 2u)) - behind;
    // Per axis: the first voxel and the region's overlap with it; the rest lies in the next.
    let c0 = lo >> vec3<u32>(10u);
    let o0 = vec3<u32>(min(lo + vec3<i32>(i32(eq)), (c0 + vec3<i32>(1)) << vec3<u32>(10u)) - lo);
    let o1 = vec3<u32>(eq) - o0;
    let albedo = point_albedo(pt);
    var n = n_in;
    if dot(n, n) == 0.0 {
        n = vec3<f32>(0.0, 1.0, 0.0);
    }
    let normal = pack2x16snorm(oct_encode(n));
    let emission = pack_rgb9e5(point_emission(pt));
    let albedo_packed = pack4x8unorm(vec4<f32>(albedo, 0.0));
    // The share of the area is overlap / (eq SUB^2) voxel faces; in 1/WEIGHT_ONE units.
    let den = eq * (SUB * SUB / WEIGHT_ONE);
    for (var k = 0u; k < 8u; k++) {
        let b = vec3<u32>(k & 1u, (k >> 1u) & 1u, (k >> 2u) & 1u);
        let o = select(o0, o1, b == vec3<u32>(1u));
        let cell = c0 + vec3<i32>(b);
        if any(o == vec3<u32>(0u)) || !region_holds(region, cell) {
            continue;
        }
        let volume = o.x * o.y * o.z;
        let surface = dot(vec3<f32>(cell) + 0.5 - p, n_in);
        let up = select(0u, 1u, hash(i * 8u + k) % den < volume % den);
        let weight = volume / den + up;
        if weight == 0u {
            continue;
        }
        let slot = atomicAdd(&fragment_count[0], 1u);
        if slot < arrayLength(&fragments) {
            fragments[slot] = Fragment(
                pack_coord(vec3<u32>(cell) + vec3<u32>(0u, 0u, grid.z_offset)),
                albedo_packed,
                normal,
                emission,
                pack_weight(weight, surface, true),
            );
        }
    }
}
