// cone_probe: the gather's diffuse cones at given surface points, traced one by one, for
// comparing each cone with the path tracer's light over the same cone (reference.wgsl's probe
// mode). One invocation per (point, cone slot); slots past the cone count do nothing.

//!include shared/scene.wgsl
//!include shared/cone.wgsl

// A surface point (xyz) and the bundle's turn's first coordinate (w); its normal (xyz) and
// the turn's second coordinate (w) (shared/cone.wgsl, diffuse_cone).
struct ProbePoint {
    p: vec4<f32>,
    n: vec4<f32>,
}

@group(0) @binding(0) var<uniform> cones: Cones;
@group(0) @binding(1) var<storage, read> points: array<ProbePoint>;
// Per point, 16 cone slots of two entries: the cone's direction and weight (diffuse_cone),
// then what trace_cone gathers along it (premultiplied radiance, opacity), the mean of its
// four quarters.
@group(0) @binding(2) var<storage, read_write> results: array<vec4<f32>>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let point = id.x / 16u;
    let i = id.x % 16u;
    if point >= arrayLength(&points) || i >= cones.count {
        return;
    }
    let q = points[point];
    let n = normalize(q.n.xyz);
    let c = diffuse_cone(tangent_frame(n), vec2<f32>(q.p.w, q.n.w), i);
    let vs = voxels_voxel_size_at(q.p.xyz);
    let origin = q.p.xyz + n * vs * cones.origin_offset;
    results[2u * id.x] = c;
    // The mean of the four quarters the gather's cones trace over a block, or the whole
    // footprint.
    var r = vec4<f32>(0.0);
    if cones.quarters != 0u {
        for (var part = 0u; part < 4u; part++) {
            r += 0.25 * trace_cone(origin, n, c.xyz, cones.diffuse_tan, cones.max_distance, vs, part);
        }
    } else {
        r = trace_cone(origin, n, c.xyz, cones.diffuse_tan, cones.max_distance, vs, WHOLE_FOOTPRINT);
    }
    results[2u * id.x + 1u] = r;
}
