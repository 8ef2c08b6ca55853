// bounce: one more bounce of light in voxel space. Each occupied voxel gathers irradiance with
// the diffuse cones from the filtered volume and re-emits albedo/pi of it on top of its direct
// light; `store` then writes the results into the finest level for re-filtering.

//!include shared/scene.wgsl
//!include shared/volume.wgsl
//!include shared/cone.wgsl
//!include voxels/leaves.wgsl

@group(0) @binding(0) var<uniform> cones: Cones;
// Group 1: the voxel structure's sampling, group 2: its leaves.

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let s = gid.x + gid.y * nwg.x * 64u;
    if s >= leaf_count() {
        return;
    }
    let c = leaf_coord(s);
    let albedo = leaf_albedo(s);
    let nw = leaf_normal(s);
    let center = leaf_center(s);
    var e = vec3<f32>(0.0);
    if nw.w > 0.3 {
        let n = normalize(nw.xyz);
        // A fixed bundle orientation per voxel, varied between voxels to break up patterns. It
        // follows the voxel's coordinates, not its slot: slots are handed out by atomics in
        // whatever order the GPU runs, and renders must not change from run to run. (The
        // constants are Roberts' R3 sequence: neighbouring voxels get well spread angles.)
        let angle = fract(dot(vec3<f32>(c), vec3<f32>(0.8191725134, 0.6710436067, 0.5497004779))) * 2.0 * PI;
        e = gather_diffuse(center, n, angle, false, ALL_CONES).irradiance;
    } else {
        // Two-sided voxel: half the light from each side.
        let n = vec3<f32>(0.0, 1.0, 0.0);
        e = 0.5 * (gather_diffuse(center, n, 0.0, false, ALL_CONES).irradiance + gather_diffuse(center, -n, 0.0, false, ALL_CONES).irradiance);
    }
    let direct = leaf_direct[s];
    leaf_next[s] = vec4<f32>(direct.rgb + albedo.rgb / PI * e * direct.a, direct.a);
}
