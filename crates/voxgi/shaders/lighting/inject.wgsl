// inject: direct light from every light (with the shadow maps) and emission into the
// structure's leaves: Lambertian outgoing radiance albedo/pi * E + Le, premultiplied by opacity.

//!include shared/scene.wgsl
//!include shared/lights.wgsl
//!include voxels/leaf_store.wgsl

@group(0) @binding(0) var<uniform> light_count: vec4<u32>;
@group(0) @binding(1) var<storage, read> lights: array<Light>;
@group(0) @binding(2) var<storage, read> shadow_views: array<ShadowView>;
@group(0) @binding(3) var shadow_maps: texture_2d_array<f32>;
// Group 2: the structure's leaves, group 3: their radiance (voxels/<kind>/leaf_store.wgsl).

// false for progressive bounces: the leaves keep last frame's radiance for the bounce to build
// on, and only their direct light is renewed.
override STORE_RADIANCE: bool = true;

// Radiance leaving leaf `i`, with albedo a, averaged normal (xyz) and normal agreement (w).
fn leaf_direct_light(i: u32) -> vec4<f32> {
    let albedo = leaf_albedo(i);
    let nw = leaf_normal(i);
    let emission = leaf_emission(i);
    let center = leaf_center(i);
    var e = vec3<f32>(0.0);
    if nw.w > 0.3 {
        let n = normalize(nw.xyz);
        // Shade at the front of the voxel: its centre may lie up to half a diagonal behind the
        // surface, where the shadow map would see the surface itself as an occluder.
        let p = center + n * leaf_size() * 0.75;
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
            e += 0.5 * light_irradiance(l, center + dir_to_light * leaf_size(), dir_to_light, 1.5);
        }
    }
    let radiance = albedo.rgb / PI * e + emission;
    return vec4<f32>(radiance * albedo.a, albedo.a);
}

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let s = gid.x + gid.y * nwg.x * 64u;
    if s >= leaf_count() {
        return;
    }
    let r = leaf_direct_light(s);
    leaf_direct[s] = r;
    if STORE_RADIANCE {
        store_leaf_radiance(s, r);
    }
}
