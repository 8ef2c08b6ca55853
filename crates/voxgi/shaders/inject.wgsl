// inject: direct light from every light (with the shadow maps) and emission into the finest
// voxels: Lambertian outgoing radiance albedo/pi * E + Le, premultiplied by opacity.

//!include shared/scene.wgsl
//!include shared/volume.wgsl
//!include shared/lights.wgsl

@group(0) @binding(0) var<uniform> vol: Volume;
@group(0) @binding(1) var<storage, read> lights: array<Light>;
@group(0) @binding(2) var<storage, read> shadow_views: array<ShadowView>;
@group(0) @binding(3) var shadow_maps: texture_2d_array<f32>;
@group(0) @binding(4) var albedo_tex: texture_3d<f32>;
@group(0) @binding(5) var normal_tex: texture_3d<f32>;
@group(0) @binding(6) var emission_tex: texture_3d<f32>;
@group(0) @binding(7) var<storage, read> slot_voxel: array<u32>;
// [1]: number of slots.
@group(0) @binding(8) var<storage, read> counters: array<u32>;
// Per slot: direct radiance (rgb) and opacity, kept for the bounces.
@group(0) @binding(9) var<storage, read_write> slot_direct: array<vec4<f32>>;
@group(0) @binding(10) var radiance_out: texture_storage_3d<rgba16float, write>;
@group(0) @binding(11) var<uniform> light_count: vec4<u32>;

// Radiance leaving a voxel with albedo a, averaged normal (xyz) and normal agreement (w).
fn voxel_direct(c: vec3<u32>) -> vec4<f32> {
    let albedo = textureLoad(albedo_tex, c, 0);
    let nw = textureLoad(normal_tex, c, 0);
    let emission = textureLoad(emission_tex, c, 0).rgb;
    let center = voxel_center(c, vol);
    var e = vec3<f32>(0.0);
    if nw.w > 0.3 {
        let n = normalize(nw.xyz);
        // Shade at the front of the voxel: its centre may lie up to half a diagonal behind the
        // surface, where the shadow map would see the surface itself as an occluder.
        let p = center + n * vol.voxel_size * 0.75;
        for (var i = 0u; i < light_count.x; i++) {
            e += light_irradiance(lights[i], p, n, 1.5);
        }
    } else {
        // Opposite faces share this voxel (a thin two-sided wall): one isotropic value cannot
        // keep the sides apart, so both get half the light of a surface facing it.
        for (var i = 0u; i < light_count.x; i++) {
            let l = lights[i];
            var dir_to_light = -l.direction;
            if l.kind != LIGHT_DIRECTIONAL {
                dir_to_light = normalize(l.position - center);
            }
            e += 0.5 * light_irradiance(l, center + dir_to_light * vol.voxel_size, dir_to_light, 1.5);
        }
    }
    let radiance = albedo.rgb / PI * e + emission;
    return vec4<f32>(radiance * albedo.a, albedo.a);
}

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let s = gid.x + gid.y * nwg.x * 64u;
    if s >= min(counters[0], arrayLength(&slot_voxel)) {
        return;
    }
    let c = voxel_coord(slot_voxel[s], vol.resolution);
    let r = voxel_direct(c);
    slot_direct[s] = r;
    textureStore(radiance_out, c, to_depth(r));
}
