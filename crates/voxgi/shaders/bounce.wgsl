// bounce: one more bounce of light in voxel space. Each occupied voxel gathers irradiance with
// the diffuse cones from the filtered volume and re-emits albedo/pi of it on top of its direct
// light; `store` then writes the results into the finest level for re-filtering.

//!include shared/scene.wgsl
//!include shared/volume.wgsl
//!include shared/cone.wgsl

@group(0) @binding(0) var<uniform> cones: Cones;
// Group 1: the voxel structure. The leaves below are the dense volume's occupied voxels (its
// slots), placed by its `vol`: the one part of this pass that is not yet structure-neutral.
@group(2) @binding(0) var albedo_tex: texture_3d<f32>;
@group(2) @binding(1) var normal_tex: texture_3d<f32>;
@group(2) @binding(2) var<storage, read> slot_voxel: array<u32>;
@group(2) @binding(3) var<storage, read> counters: array<u32>;
@group(2) @binding(4) var<storage, read> slot_direct: array<vec4<f32>>;
@group(2) @binding(5) var<storage, read_write> slot_next: array<vec4<f32>>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let s = gid.x + gid.y * nwg.x * 64u;
    if s >= min(counters[0], arrayLength(&slot_voxel)) {
        return;
    }
    let c = voxel_coord(slot_voxel[s], vol.resolution);
    let albedo = textureLoad(albedo_tex, c, 0);
    let nw = textureLoad(normal_tex, c, 0);
    let center = voxel_center(c, vol);
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
    let direct = slot_direct[s];
    slot_next[s] = vec4<f32>(direct.rgb + albedo.rgb / PI * e * direct.a, direct.a);
}
