// bounce: one more bounce of light in voxel space. Each occupied voxel gathers irradiance with
// the diffuse cones from the filtered volume and re-emits albedo/pi of it on top of its direct
// light; `store` then writes the results into the finest level for re-filtering. For the
// fast shading (IRRADIANCE) it also keeps each leaf's irradiance and occlusion, which the
// gather then interpolates instead of tracing cones per pixel.

//!include shared/scene.wgsl
//!include shared/volume.wgsl
//!include shared/cone.wgsl
//!include voxels/leaves.wgsl
//!include shared/irradiance_record.wgsl

@group(0) @binding(0) var<uniform> cones: Cones;
// Per leaf slot (shared/irradiance_record.wgsl); written when IRRADIANCE.
@group(0) @binding(1) var<storage, read_write> leaf_irradiance: array<vec4<u32>>;

override IRRADIANCE: bool = false;
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
    var ao = 1.0;
    // Records turn their bundles by the layout the pixels' window filter averages
    // (shared/irradiance_record.wgsl).
    let records_angle = leaf_rotation(c) * 2.0 * PI / f32(max(cones.count, 2u) - 1u);
    if nw.w > 0.3 {
        let n = normalize(nw.xyz);
        // A fixed bundle orientation per voxel, varied between voxels to break up patterns. It
        // follows the voxel's coordinates, not its slot: slots are handed out by atomics in
        // whatever order the GPU runs, and renders must not change from run to run. (The
        // constants are Roberts' R3 sequence: neighbouring voxels get well spread angles.)
        let r3 = fract(dot(vec3<f32>(c), vec3<f32>(0.8191725134, 0.6710436067, 0.5497004779))) * 2.0 * PI;
        let g = gather_diffuse(center, n, select(r3, records_angle, IRRADIANCE), IRRADIANCE, ALL_CONES);
        e = g.irradiance;
        ao = g.ao;
    } else {
        // Two-sided voxel: half the light from each side.
        let n = vec3<f32>(0.0, 1.0, 0.0);
        let angle = select(0.0, records_angle, IRRADIANCE);
        let up = gather_diffuse(center, n, angle, IRRADIANCE, ALL_CONES);
        let down = gather_diffuse(center, -n, angle, IRRADIANCE, ALL_CONES);
        e = 0.5 * (up.irradiance + down.irradiance);
        ao = 0.5 * (up.ao + down.ao);
    }
    if IRRADIANCE {
        leaf_irradiance[s] = pack_irradiance(e, ao, nw);
    }
    let direct = leaf_direct[s];
    leaf_next[s] = vec4<f32>(direct.rgb + albedo.rgb / PI * e * direct.a, direct.a);
}
