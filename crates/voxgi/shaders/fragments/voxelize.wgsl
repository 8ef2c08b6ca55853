// voxelize: every mesh triangle -> voxel fragments at the finest resolution.
//
// Conservative and exact: a fragment is emitted for every voxel whose closed box the triangle
// touches (Akenine-Moller's separating-axis test), so thin and axis-aligned triangles leave no
// holes and the result does not depend on rasterization rules. Two kinds of table entry: a
// small triangle (at most a few columns along its dominant axis, where its plane spans at most
// three voxels) takes one thread (`small`, 64 a workgroup: most of a detailed mesh's
// triangles, which would leave 63 threads of a workgroup idle and, on a CPU driver, pay a
// workgroup's start each); any other triangle, or a share of a large one's columns, takes a
// workgroup (`main`), whose threads divide its columns.

//!include shared/scene.wgsl
//!include shared/fragment.wgsl

@group(0) @binding(0) var<uniform> grid: FragmentGrid;
@group(0) @binding(1) var<storage, read> vertices: array<Vertex>;
@group(0) @binding(2) var<storage, read> indices: array<u32>;
@group(0) @binding(3) var<storage, read> draws: array<Draw>;
@group(0) @binding(4) var<storage, read> materials: array<Material>;
@group(0) @binding(5) var textures: texture_2d_array<f32>;
@group(0) @binding(6) var texture_sampler: sampler;
// Entry 0: the number of small entries (x). Then the small entries, then the workgroups':
// draw index, first index, base vertex, and the share of the triangle's columns
// (chunk | chunks << 16; 0: all of them).
@group(0) @binding(7) var<storage, read> triangles: array<vec4<u32>>;
@group(0) @binding(8) var<storage, read_write> fragments: array<Fragment>;
// [0]: fragments emitted (may exceed the capacity: the host then grows the buffer and redoes).
@group(0) @binding(9) var<storage, read_write> fragment_count: array<atomic<u32>>;
// Fragments are made in these voxels only.
@group(0) @binding(10) var<uniform> region: FragmentRegion;
// Per draw, the world box its mesh fills: lowest corner, highest corner (`GpuScene::draw_bounds`).
@group(0) @binding(11) var<storage, read> draw_bounds: array<vec4<f32>>;
// The entries this dispatch pair runs (`TableSpan` in fragments/mod.rs, chosen by the dynamic
// offset): the draws the host found near the region, so the rest of a large world's table
// costs no thread at all.
struct TableSpan {
    small_first: u32,
    small_count: u32,
    large_first: u32,
    large_count: u32,
}
@group(0) @binding(12) var<uniform> span: TableSpan;

// The dynamic geometry's pass: a fragment's voxel is filled only by the part of it that lies
// behind the surface (inside the solid), and the voxel behind it, inside, is filled wholly.
// Static geometry fills every voxel it touches (a wall stays opaque whatever its thickness).
override DYNAMIC_COVERAGE: bool = false;
// Columns one table entry takes (`fragments::CHUNK_COLUMNS`); the last takes the rest.
override CHUNK_COLUMNS: u32 = 32768u;

// `surface`: how far the voxel's centre lies in front of the triangle's plane (voxels).
fn emit(cell: vec3<i32>, albedo: vec3<f32>, coverage: f32, n: vec3<f32>, emission: vec3<f32>, surface: f32) {
    let slot = atomicAdd(&fragment_count[0], 1u);
    if slot < arrayLength(&fragments) {
        fragments[slot] = Fragment(
            pack_coord(vec3<u32>(cell) + vec3<u32>(0u, 0u, grid.z_offset)),
            pack4x8unorm(vec4<f32>(albedo, coverage)),
            pack2x16snorm(oct_encode(n)),
            pack_rgb9e5(emission),
            pack_weight(WEIGHT_ONE, surface, false),
        );
    }
}

// Does the triangle (relative to the box centre) overlap the box of half-size h along axis a?
fn separated(a: vec3<f32>, v0: vec3<f32>, v1: vec3<f32>, v2: vec3<f32>, h: f32) -> bool {
    let p0 = dot(v0, a);
    let p1 = dot(v1, a);
    let p2 = dot(v2, a);
    let r = h * (abs(a.x) + abs(a.y) + abs(a.z));
    return min(p0, min(p1, p2)) > r || max(p0, max(p1, p2)) < -r;
}

// Triangle / axis-aligned box overlap by the 13 separating axes (Akenine-Moller 2001).
fn tri_box_overlap(center: vec3<f32>, h: f32, a: vec3<f32>, b: vec3<f32>, c: vec3<f32>) -> bool {
    let v0 = a - center;
    let v1 = b - center;
    let v2 = c - center;
    let e0 = v1 - v0;
    let e1 = v2 - v1;
    let e2 = v0 - v2;
    var axes = array<vec3<f32>, 3>(vec3<f32>(1.0, 0.0, 0.0), vec3<f32>(0.0, 1.0, 0.0), vec3<f32>(0.0, 0.0, 1.0));
    var edges = array<vec3<f32>, 3>(e0, e1, e2);
    for (var i = 0u; i < 3u; i++) {
        if separated(axes[i], v0, v1, v2, h) {
            return false;
        }
        for (var j = 0u; j < 3u; j++) {
            let ax = cross(axes[i], edges[j]);
            if dot(ax, ax) > 1e-20 && separated(ax, v0, v1, v2, h) {
                return false;
            }
        }
    }
    let n = cross(e0, e1);
    return !separated(n, v0, v1, v2, h);
}

// One small triangle per thread.
@compute @workgroup_size(64)
fn small(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let t = gid.x + gid.y * nwg.x * 64u;
    if t >= span.small_count {
        return;
    }
    voxelize_entry(triangles[1u + span.small_first + t], 0u, 1u);
}

// One triangle, or a share of its columns, per workgroup.
@compute @workgroup_size(64)
fn main(
    @builtin(workgroup_id) wg: vec3<u32>,
    @builtin(num_workgroups) nwg: vec3<u32>,
    @builtin(local_invocation_index) lane: u32,
) {
    let i = wg.x + wg.y * nwg.x;
    if i >= span.large_count {
        return;
    }
    voxelize_entry(triangles[1u + triangles[0].x + span.large_first + i], lane, 64u);
}

// Whether draw `d`'s triangles may make fragments in the region: its box, in voxels and grown
// by two (the host's rounding of its corners; the voxel behind a dynamic surface), meets the
// region and does not lie inside its kept box. A box with NaN corners (a transform of NaNs)
// fails every comparison and is kept.
fn draw_in_region(d: u32) -> bool {
    let lo = (draw_bounds[2u * d].xyz - grid.origin) * grid.inv_voxel_size - 2.0;
    let hi = (draw_bounds[2u * d + 1u].xyz - grid.origin) * grid.inv_voxel_size + 2.0;
    let outside = any(hi < vec3<f32>(region.lo)) || any(lo >= vec3<f32>(region.hi + 1u));
    let kept = all(lo >= vec3<f32>(region.kept_lo)) && all(hi < vec3<f32>(region.kept_hi + 1u));
    return !(outside || kept);
}

// Voxelizes table entry `info`: its columns from `first` on, every `stride`-th.
fn voxelize_entry(info: vec4<u32>, first: u32, stride: u32) {
    // Most of a large world's triangles lie outside a window, and all but a slab's outside
    // the voxels a moved window does not keep: skipped before their vertices are read.
    if !draw_in_region(info.x) {
        return;
    }
    let draw = draws[info.x];
    let m = materials[draw.material];
    let ia = indices[info.y] + info.z;
    let ib = indices[info.y + 1u] + info.z;
    let ic = indices[info.y + 2u] + info.z;
    let va = vertices[ia];
    let vb = vertices[ib];
    let vc = vertices[ic];
    let wa = (draw.model * vec4<f32>(va.position, 1.0)).xyz;
    let wb = (draw.model * vec4<f32>(vb.position, 1.0)).xyz;
    let wc = (draw.model * vec4<f32>(vc.position, 1.0)).xyz;
    // Voxel space: the finest voxel is the unit cube.
    let inv = 1.0 / grid.voxel_size;
    let a = (wa - grid.origin) * inv;
    let b = (wb - grid.origin) * inv;
    let c = (wc - grid.origin) * inv;
    let cr = cross(b - a, c - a);
    let area2 = length(cr);
    if area2 < 1e-12 {
        return;
    }
    var n = cr / area2;
    // Orient the geometric normal like the shading normals, which files get right more often
    // than winding.
    let sn = (draw.normal_matrix * vec4<f32>(va.normal + vb.normal + vc.normal, 0.0)).xyz;
    if dot(n, sn) < 0.0 {
        n = -n;
    }

    // Texture level of detail: about one texel per voxel.
    let uv_area2 = abs((vb.u - va.u) * (vc.v - va.v) - (vc.u - va.u) * (vb.v - va.v));
    let tex_size = f32(textureDimensions(textures).x);
    let texels_per_voxel = sqrt(uv_area2 / area2) * tex_size;
    let lod = max(log2(max(texels_per_voxel, 1e-6)), 0.0);

    // Dominant axis w and the two others (u, v).
    let an = abs(n);
    var w = 2u;
    if an.x >= an.y && an.x >= an.z {
        w = 0u;
    } else if an.y >= an.z {
        w = 1u;
    }
    let u = (w + 1u) % 3u;
    let v = (w + 2u) % 3u;
    let lo = max(vec3<i32>(floor(min(a, min(b, c)))), vec3<i32>(region.lo));
    let hi = min(vec3<i32>(floor(max(a, max(b, c)))), vec3<i32>(region.hi));
    // Nothing, or only voxels a moved window keeps.
    if any(hi < lo) || (in_box(lo, region.kept_lo, region.kept_hi) && in_box(hi, region.kept_lo, region.kept_hi)) {
        return;
    }
    let nu = u32(hi[u] - lo[u] + 1);
    let nv = u32(hi[v] - lo[v] + 1);
    let total = nu * nv;
    let chunk = info.w & 0xffffu;
    let chunks = max(info.w >> 16u, 1u);
    let begin = chunk * CHUNK_COLUMNS;
    let end = select(min(total, begin + CHUNK_COLUMNS), total, chunk + 1u >= chunks);
    let d = dot(n, a);
    for (var k = begin + first; k < end; k += stride) {
        let cu = lo[u] + i32(k % nu);
        let cv = lo[v] + i32(k / nu);
        // The plane's depth over the column's square (|n_w| is the largest component, so the
        // span is at most two voxels).
        var zmin = 1e30;
        var zmax = -1e30;
        for (var q = 0u; q < 4u; q++) {
            let pu = f32(cu) + f32(q & 1u);
            let pv = f32(cv) + f32(q >> 1u);
            let z = (d - n[u] * pu - n[v] * pv) / n[w];
            zmin = min(zmin, z);
            zmax = max(zmax, z);
        }
        // Clamped into the triangle's own depth range, not intersected with it: a triangle
        // within rounding of a voxel face (a wall on the scene bounds) can get a plane depth a
        // float step outside its vertices' range, and the intersection is then empty. Extra
        // candidates are harmless, the box test decides.
        let z0 = clamp(i32(floor(zmin)), lo[w], hi[w]);
        let z1 = clamp(i32(floor(zmax)), lo[w], hi[w]);
        for (var cz = z0; cz <= min(z1, z0 + 3); cz++) {
            var cell = vec3<i32>(0);
            cell[u] = cu;
            cell[v] = cv;
            cell[w] = cz;
            let center = vec3<f32>(cell) + 0.5;
            if in_box(cell, region.kept_lo, region.kept_hi) || !tri_box_overlap(center, 0.5, a, b, c) {
                continue;
            }
            // Attributes at the voxel centre's projection onto the triangle (barycentrics
            // clamped to the triangle).
            let q = center - n * dot(center - a, n);
            let l1 = dot(cross(q - a, c - a), n) / area2;
            let l2 = dot(cross(b - a, q - a), n) / area2;
            var bary = max(vec3<f32>(1.0 - l1 - l2, l1, l2), vec3<f32>(0.0));
            bary /= max(bary.x + bary.y + bary.z, 1e-6);
            let uv = bary.x * vec2<f32>(va.u, va.v) + bary.y * vec2<f32>(vb.u, vb.v) + bary.z * vec2<f32>(vc.u, vc.v);
            var albedo = m.base_color;
            if m.base_texture >= 0 {
                albedo *= textureSampleLevel(textures, texture_sampler, uv, m.base_texture, lod);
            }
            if albedo.a < m.alpha_cutoff {
                continue;
            }
            var emission = m.emissive;
            if m.emissive_texture >= 0 {
                emission *= textureSampleLevel(textures, texture_sampler, uv, m.emissive_texture, lod).rgb;
            }
            // Voxels bounce light diffusely: metals' diffuse albedo is zero.
            let diffuse = albedo.rgb * (1.0 - m.metallic);
            let surface = dot(center - a, n);
            if !DYNAMIC_COVERAGE {
                emit(cell, diffuse, 1.0, n, emission, surface);
                continue;
            }
            // The share of the voxel behind the plane (the normal points out of the solid):
            // exact for axis-aligned planes, linear in the plane's offset for the others.
            let behind = clamp(0.5 - dot(center - a, n) / (abs(n.x) + abs(n.y) + abs(n.z)), 0.0, 1.0);
            emit(cell, diffuse, behind, n, emission, surface);
            var inner = cell;
            inner[w] -= select(-1, 1, n[w] > 0.0);
            if region_holds(region, inner) {
                // Inside the solid: no surface of its own, so shaded at its centre (a surface
                // distance of 0 puts the shading point inside, where the light does not reach).
                emit(inner, diffuse, 1.0, n, emission, 0.0);
            }
        }
    }
}
