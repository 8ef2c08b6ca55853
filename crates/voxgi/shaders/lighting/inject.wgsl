// inject: direct light from every light (with the shadow maps) and emission into the
// structure's leaves: Lambertian outgoing radiance albedo/pi * E + Le, premultiplied by opacity.

//!include shared/scene.wgsl
//!include shared/lights.wgsl
//!include voxels/leaf_store.wgsl

struct InjectParams {
    light_count: u32,
    // 1: every leaf is recomputed (a light changed, or a rebuild); 0: only those whose inputs
    // may have changed, the others keep their direct light.
    all: u32,
    // 1: every leaf's radiance is stored (bounces overwrote it since the last injection); 0:
    // only those recomputed, the others still hold what the last injection stored.
    store_all: u32,
    _pad: u32,
    // Where dynamic geometry moved since the last injection (world space; min > max: nowhere).
    moved_min: vec4<f32>,
    moved_max: vec4<f32>,
}

@group(0) @binding(0) var<uniform> params: InjectParams;
@group(0) @binding(1) var<storage, read> lights: array<Light>;
@group(0) @binding(2) var<storage, read> shadow_views: array<ShadowView>;
@group(0) @binding(3) var shadow_maps: texture_2d_array<f32>;
@group(0) @binding(4) var shadow_moments: texture_2d_array<f32>;
// Per shadow view: the rectangle of texels (x, y from xy inclusive to zw exclusive) that
// changed since the last injection (empty when none did).
@group(0) @binding(5) var<storage, read> view_dirt: array<vec4<f32>>;
// Group 2: the structure's leaves, group 3: their radiance (voxels/<kind>/leaf_store.wgsl).

// false for progressive bounces: the leaves keep last frame's radiance for the bounce to build
// on, and only their direct light is renewed.
override STORE_RADIANCE: bool = true;

// Where leaf `i` is shaded for `light`: three quarters of a voxel in front of the surface its
// fragments lie on (the centre may lie up to half a diagonal behind a mesh's surface and a
// voxel behind a point's, where the shadow map would see the surface itself as an occluder);
// for a two-sided voxel, a voxel towards the light.
fn shading_point(i: u32, light: Light) -> vec3<f32> {
    let nw = leaf_normal(i);
    let center = leaf_center(i);
    if nw.w > 0.3 {
        return center + normalize(nw.xyz) * leaf_size() * (0.75 - leaf_surface(i));
    }
    return center + to_light(light, center) * leaf_size();
}

fn to_light(l: Light, p: vec3<f32>) -> vec3<f32> {
    if l.kind == LIGHT_DIRECTIONAL {
        return -l.direction;
    }
    return normalize(l.position - p);
}

// Radiance leaving leaf `i`, with albedo a, averaged normal (xyz) and normal agreement (w).
fn leaf_direct_light(i: u32) -> vec4<f32> {
    let albedo = leaf_albedo(i);
    let nw = leaf_normal(i);
    let emission = leaf_emission(i);
    let center = leaf_center(i);
    var e = vec3<f32>(0.0);
    if nw.w > 0.3 {
        let n = normalize(nw.xyz);
        for (var l = 0u; l < params.light_count; l++) {
            e += light_irradiance(lights[l], shading_point(i, lights[l]), n, 1.5);
        }
    } else {
        // Opposite faces share this voxel (a thin two-sided wall): one isotropic value cannot
        // keep the sides apart, so both get half the light of a surface facing it.
        for (var k = 0u; k < params.light_count; k++) {
            let l = lights[k];
            e += 0.5 * light_irradiance(l, shading_point(i, l), to_light(l, center), 1.5);
        }
    }
    let radiance = albedo.rgb / PI * e + emission;
    return vec4<f32>(radiance * albedo.a, albedo.a);
}

// Whether leaf `i`'s direct light may differ from what the last injection left: when it is
// new, when dynamic geometry moved through its voxel, or when a shadow lookup of
// `leaf_direct_light` reads a texel that changed (lights.wgsl's `irradiance_reads`, which
// follows the lookups exactly). Everything else it reads is as it was.
fn leaf_inputs_changed(i: u32) -> bool {
    if params.all != 0u || leaf_is_new(i) {
        return true;
    }
    let center = leaf_center(i);
    let margin = vec3<f32>(leaf_size());
    if all(center >= params.moved_min.xyz - margin) && all(center <= params.moved_max.xyz + margin) {
        return true;
    }
    let nw = leaf_normal(i);
    for (var l = 0u; l < params.light_count; l++) {
        let light = lights[l];
        if light.shadow_count == 0u {
            continue;
        }
        let p = shading_point(i, light);
        var n = to_light(light, center);
        if nw.w > 0.3 {
            n = normalize(nw.xyz);
        }
        if irradiance_reads(light, p, n, 1.5, view_dirt[shadow_view_index(light, p)]) {
            return true;
        }
    }
    return false;
}

// The leaves `mark` found changed: [0] how many, then their indices. `main` recomputes only
// these, so unchanged leaves cost a test and not the whole lighting code's run (on CPU drivers
// a SIMD group pays for every branch any of its lanes takes).
@group(0) @binding(6) var<storage, read_write> todo: array<atomic<u32>>;
// Group 1, `prepare` only: `main`'s indirect dispatch size.
@group(1) @binding(0) var<storage, read_write> args: array<u32>;

fn flat_index(gid: vec3<u32>, nwg: vec3<u32>) -> u32 {
    return gid.x + gid.y * nwg.x * 64u;
}

@compute @workgroup_size(64)
fn mark(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let s = flat_index(gid, nwg);
    if s >= leaf_count() {
        return;
    }
    if leaf_inputs_changed(s) {
        let k = atomicAdd(&todo[0], 1u);
        atomicStore(&todo[1u + k], s);
    } else if STORE_RADIANCE && params.store_all != 0u {
        store_leaf_radiance(s, leaf_direct[s]);
    }
}

@compute @workgroup_size(1)
fn prepare() {
    let groups = (atomicLoad(&todo[0]) + 63u) / 64u;
    let x = min(groups, 65535u);
    args[0] = max(x, 1u);
    args[1] = max((groups + 65534u) / 65535u, 1u);
    args[2] = 1u;
}

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = flat_index(gid, nwg);
    if i >= atomicLoad(&todo[0]) {
        return;
    }
    let s = atomicLoad(&todo[1u + i]);
    let r = leaf_direct_light(s);
    leaf_direct[s] = r;
    if STORE_RADIANCE {
        store_leaf_radiance(s, r);
    }
}
