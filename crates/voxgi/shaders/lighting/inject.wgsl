// inject: direct light from every light (with the shadow maps) and emission into the
// structure's leaves: Lambertian outgoing radiance albedo/pi * E + Le, premultiplied by opacity,
// and beside it what a metal reflects of the lights specularly (shared/specular_lobe.wgsl).

//!include shared/scene.wgsl
//!include shared/lights.wgsl
//!include shared/specular_lobe.wgsl
//!include voxels/leaf_store.wgsl

struct InjectParams {
    light_count: u32,
    // 1: every leaf is recomputed (a light changed, or a rebuild); 0: only those whose inputs
    // may have changed, the others keep their direct light.
    all: u32,
    // 1: every leaf's radiance is stored (bounces overwrote it since the last injection); 0:
    // only those recomputed, the others still hold what the last injection stored.
    store_all: u32,
    // 1: the shadow maps hold the surfaces' specular materials (a scene with metals).
    materials: u32,
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
        return center + normalize(nw.xyz) * leaf_size(i) * (0.75 - leaf_surface(i));
    }
    return center + to_light(light, center) * leaf_size(i);
}

// The surface leaf `i`'s fragments lie on (a one-sided voxel's): where its light's geometry is
// evaluated (`light_irradiance`); a two-sided voxel's is its centre.
fn surface_point(i: u32) -> vec3<f32> {
    let nw = leaf_normal(i);
    if nw.w > 0.3 {
        return leaf_center(i) - normalize(nw.xyz) * leaf_size(i) * leaf_surface(i);
    }
    return leaf_center(i);
}

fn to_light(l: Light, p: vec3<f32>) -> vec3<f32> {
    if l.kind == LIGHT_DIRECTIONAL {
        return -l.direction;
    }
    return normalize(l.position - p);
}

// A leaf's direct light: its radiance (rgb, premultiplied by opacity, and opacity) and its
// specular lobe (`pack_lobe`).
struct Direct {
    light: vec4<f32>,
    lobe: vec4<f32>,
}

// Light leaving leaf `i`, with albedo a, averaged normal (xyz) and normal agreement (w).
fn leaf_direct_light(i: u32) -> Direct {
    let albedo = leaf_albedo(i);
    let nw = leaf_normal(i);
    let emission = leaf_emission(i);
    let center = leaf_center(i);
    var e = vec3<f32>(0.0);
    var spec = Specular();
    if nw.w > 0.3 {
        let n = normalize(nw.xyz);
        let surface = surface_point(i);
        for (var l = 0u; l < params.light_count; l++) {
            let p = shading_point(i, lights[l]);
            let el = light_irradiance(lights[l], surface, p, n, 1.5);
            e += el;
            reflect_light(&spec, lights[l], p, n, el);
        }
    } else {
        spec.faces = true;
        // Opposite faces share this voxel (a thin two-sided wall): one isotropic value cannot
        // keep the sides apart, so both get half the light of a surface facing it (and no
        // lobe: it would leave from both sides).
        for (var k = 0u; k < params.light_count; k++) {
            let l = lights[k];
            e += 0.5 * light_irradiance(l, center, shading_point(i, l), to_light(l, center), 1.5);
        }
    }
    let radiance = albedo.rgb / PI * e + emission;
    return Direct(vec4<f32>(radiance * albedo.a, albedo.a), spec_lobe(spec));
}

// The lights' specular reflections summed: exitance, the reflected directions weighted by
// their luminance, and their luminance-weighted solid angles; and whether the surface faces a
// light (`NO_LOBE_FACING`).
struct Specular {
    m: vec3<f32>,
    dir: vec3<f32>,
    weight: f32,
    solid_angle: f32,
    faces: bool,
}

// Adds what the surface at p (normal n) reflects of `light`, whose irradiance there is `e`:
// the material the light's shadow map sees at p (a lit surface is what it sees), its Fresnel
// term at the light's angle, about the mirror direction, as wide as GGX's reflected lobe
// (4 pi alpha^2 cos: the half-vector lobe's pi alpha^2, widened by the reflection's Jacobian)
// and the light's own solid angle together. Lights without shadow maps reflect nothing here.
fn reflect_light(spec: ptr<function, Specular>, light: Light, p: vec3<f32>, n: vec3<f32>, e: vec3<f32>) {
    if params.materials == 0u {
        return;
    }
    let l = to_light(light, p);
    let c = max(dot(n, l), 0.0);
    (*spec).faces = (*spec).faces || c > 0.0;
    if light.shadow_count == 0u || all(e <= vec3<f32>(0.0)) {
        return;
    }
    let view = shadow_views[shadow_view_index(light, p)];
    let mat = shadow_material(view, vec2<i32>(floor(shadow_uv(view, p).xy * view.resolution)));
    if all(mat.rgb <= vec3<f32>(0.0)) {
        return;
    }
    let m = e * lobe_albedo(mat.rgb, mat.a, c);
    let w = dot(m, vec3<f32>(0.2126, 0.7152, 0.0722));
    let alpha = mat.a * mat.a;
    var source = 0.0;
    if is_area_light(light) {
        let to = light.position - p;
        let d2 = max(dot(to, to), 1e-8);
        source = light.area * abs(dot(light.direction, to)) / (d2 * sqrt(d2));
    }
    (*spec).m += m;
    (*spec).dir += w * reflect(-l, n);
    (*spec).weight += w;
    (*spec).solid_angle += w * (4.0 * PI * alpha * alpha * c + source);
}

// The share of the light from direction cosine `c` the GGX lobe of F0 `f0` and `roughness`
// reflects at all (its directional albedo; by reciprocity the same seen from there), in
// Karis's analytic fit (Unreal's mobile EnvBRDFApprox): the screen's glossy light reads a
// table of voxgi's own BRDF (brdf.rs) instead, which inject does not bind (docs/QUALITY.md,
// "Glossy reflections", compares the two).
fn lobe_albedo(f0: vec3<f32>, roughness: f32, c: f32) -> vec3<f32> {
    let r = roughness * vec4<f32>(-1.0, -0.0275, -0.572, 0.022) + vec4<f32>(1.0, 0.0425, 1.04, -0.04);
    let a004 = min(r.x * r.x, exp2(-9.28 * c)) * r.x + r.y;
    let ab = vec2<f32>(-1.04, 1.04) * a004 + r.zw;
    return f0 * ab.x + ab.y;
}

// The lobe of the summed reflections: the directions' disagreement widens it (directions that
// cancel out add a hemisphere's worth).
fn spec_lobe(spec: Specular) -> vec4<f32> {
    if spec.weight <= 0.0 {
        return select(vec4<f32>(0.0), NO_LOBE_FACING, spec.faces);
    }
    let len = length(spec.dir);
    let agreement = len / spec.weight;
    let solid_angle = spec.solid_angle / spec.weight + 2.0 * PI * (1.0 - agreement);
    let dir = select(vec3<f32>(0.0, 1.0, 0.0), spec.dir / len, len > 0.0);
    return pack_lobe(spec.m, dir, solid_angle / (2.0 * PI));
}

// Whether leaf `i`'s direct light may differ from what the last injection left: when it is
// new (and did not keep its voxel's light through the build: `leaf_direct_kept`), when dynamic
// geometry moved through its voxel, or when a shadow lookup of
// `leaf_direct_light` reads a texel that changed (lights.wgsl's `irradiance_reads`, which
// follows the lookups exactly). Everything else it reads is as it was.
fn leaf_inputs_changed(i: u32) -> bool {
    if params.all != 0u || (leaf_is_new(i) && !leaf_direct_kept(i)) {
        return true;
    }
    let center = leaf_center(i);
    // A mesh's fragments lie in the voxels its surface crosses (centres within 0.87 of a voxel
    // of it), a point's up to a voxel behind it (centres within 1.5 voxels of the point).
    let margin = vec3<f32>(1.5 * leaf_size(i));
    if all(center >= params.moved_min.xyz - margin) && all(center <= params.moved_max.xyz + margin) {
        return true;
    }
    let nw = leaf_normal(i);
    let surface = surface_point(i);
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
        let v = shadow_view_index(light, p);
        if irradiance_reads(light, v, surface, p, n, 1.5) || material_read(v, p) {
            return true;
        }
    }
    return false;
}

// Whether `reflect_light` reads a changed texel of view `v`'s materials at p (the texel p lies
// in, which the distance lookups need not read).
fn material_read(v: u32, p: vec3<f32>) -> bool {
    let dirt = view_dirt[v];
    if params.materials == 0u || dirt.x >= dirt.z {
        return false;
    }
    let view = shadow_views[v];
    return texel_dirty(view, vec2<i32>(floor(shadow_uv(view, p).xy * view.resolution)), dirt);
}

// How near view `view` can see what moved: texels change only where moved geometry was or is
// in front, so a changed texel held or holds this distance or more. Less by a voxel for the
// rasterizer's rounding and surfels' discs (which lie behind their points from the light).
// With nothing moved (dirt from elsewhere), no bound.
fn moved_distance(view: ShadowView) -> f32 {
    let lo = params.moved_min.xyz;
    let hi = params.moved_max.xyz;
    if any(lo > hi) {
        return -3.0e38;
    }
    return box_distance(view, lo, hi) - leaf_size_max();
}

// The leaves `mark` found changed: [0] how many, then their indices. `main` recomputes only
// these, so unchanged leaves cost a test and not the whole lighting code's run (on CPU drivers
// a SIMD group pays for every branch any of its lanes takes).
@group(0) @binding(6) var<storage, read_write> todo: array<atomic<u32>>;
// Group 1, `prepare` only: `main`'s indirect dispatch size.
@group(1) @binding(0) var<storage, read_write> args: array<u32>;

@compute @workgroup_size(64)
fn mark(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let s = leaf_slot(dispatch_index(gid, nwg));
    if s == NO_LEAF {
        return;
    }
    if leaf_inputs_changed(s) {
        let k = atomicAdd(&todo[0], 1u);
        atomicStore(&todo[1u + k], s);
    } else if STORE_RADIANCE && (params.store_all != 0u || leaf_is_new(s)) {
        // A new leaf's voxel holds nothing yet, even where it kept its light.
        store_leaf_radiance(s, leaf_direct[direct_index(s)]);
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
    let i = dispatch_index(gid, nwg);
    if i >= atomicLoad(&todo[0]) {
        return;
    }
    let s = atomicLoad(&todo[1u + i]);
    let r = leaf_direct_light(s);
    leaf_direct[direct_index(s)] = r.light;
    if leaf_lobes() {
        leaf_direct[2u * s + 1u] = r.lobe;
    }
    if STORE_RADIANCE {
        store_leaf_radiance(s, r.light);
    }
}

// Whether `light_visibility(light, p, n, softness)` reads a texel of the shadow view it looks
// up, `view`, inside the texel rectangle `dirt` (x, y from xy inclusive to zw exclusive) that
// can change what it computes. Follows its reads tap by tap: the blocker
// search's texels and, when it found blockers, each filter tap's 2x2 texels (the radius
// depends on the blockers, which are then what they were).
//
// No texel of `dirt` held or holds an occluder nearer than `near` (`moved_distance`). A texel
// counts in a tap only where it lies nearer than the receiver plane there (a blocker, a
// shadowing comparison): a changed texel read where the plane is no farther than `near` was
// and is neither, and changes nothing. The moments (VSM/ESM) average
// every texel: there any changed texel read counts.
fn shadow_reads(light: Light, view: ShadowView, p: vec3<f32>, n: vec3<f32>, softness: f32, dirt: vec4<f32>) -> bool {
    // First whether the lookup can reach the rectangle at all (PCSS's search and filter radii
    // are at most 0.25, PCF's is `softness` texels; a bilinear tap a texel more, the moments'
    // disc MOMENT_RADIUS more): most leaves are far from it, and the rest of the test costs a
    // lookup's setup.
    let res = view.resolution;
    let reach = select(softness, 0.25 * res, is_area_light(light)) + 2.0 + MOMENT_RADIUS;
    let at = shadow_uv(view, p).xy * res;
    if any(at + reach < dirt.xy) || any(at - reach >= dirt.zw) {
        return false;
    }
    let s = view_setup(view, p, n);
    let near = moved_distance(view);
    var radius = softness * s.texel_uv;
    var taps = PCF_TAPS;
    if is_area_light(light) {
        let search = pcss_search(light, view, s.d0);
        for (var i = 0u; i < PCSS_SEARCH_TAPS; i++) {
            let o = s.uv + vogel(i, PCSS_SEARCH_TAPS) * search;
            if may_block(s, o, near) && texel_dirty(view, vec2<i32>(floor(o * view.resolution)), dirt) {
                return true;
            }
        }
        let blockers = pcss_blockers(s, search);
        if blockers.x == 0.0 {
            return false;
        }
        radius = pcss_radius(light, s, blockers);
        taps = PCSS_TAPS;
    } else if SHADOW_MOMENTS {
        // One bilinear lookup of moments, each the 5x5 disc around its texel: a moment texel
        // changes where any depth texel of its disc did.
        let grown = dirt + vec4<f32>(-MOMENT_RADIUS, -MOMENT_RADIUS, MOMENT_RADIUS, MOMENT_RADIUS);
        return tap_dirty(view, s.uv, grown);
    }
    for (var i = 0u; i < taps; i++) {
        let o = s.uv + vogel(i, taps) * radius;
        if may_block(s, o, near) && tap_dirty(view, o, dirt) {
            return true;
        }
    }
    return false;
}

// Whether a texel at `near` or farther can be a blocker or shadow a comparison at uv: whether
// the receiver plane there, less the bias, lies beyond it (with a margin for the rounding of
// the lookup's own sum).
fn may_block(s: ShadowSetup, uv: vec2<f32>, near: f32) -> bool {
    let d = plane_at(s.rp, uv) - s.bias;
    return d + abs(d) * 1e-5 > near;
}

// Whether `shadow_texel(view, t)` reads inside `dirt`.
fn texel_dirty(view: ShadowView, t: vec2<i32>, dirt: vec4<f32>) -> bool {
    let r = i32(view.resolution);
    let c = vec2<f32>(clamp(t, vec2<i32>(0), vec2<i32>(r - 1)));
    return all(c >= dirt.xy) && all(c < dirt.zw);
}

// Whether `shadow_tap(view, uv, ..)` reads inside `dirt`.
fn tap_dirty(view: ShadowView, uv: vec2<f32>, dirt: vec4<f32>) -> bool {
    if any(uv < vec2<f32>(0.0)) || any(uv > vec2<f32>(1.0)) {
        return false;
    }
    let i = vec2<i32>(floor(uv * view.resolution - 0.5));
    return texel_dirty(view, i, dirt)
        || texel_dirty(view, i + vec2<i32>(1, 0), dirt)
        || texel_dirty(view, i + vec2<i32>(0, 1), dirt)
        || texel_dirty(view, i + vec2<i32>(1, 1), dirt);
}

// Whether `light_irradiance(light, surface, p, n, softness)` reads a changed texel of the view it
// looks up, `v` (see `shadow_reads`); false when it returns before any lookup.
fn irradiance_reads(light: Light, v: u32, surface: vec3<f32>, p: vec3<f32>, n: vec3<f32>, softness: f32) -> bool {
    let dirt = view_dirt[v];
    if light.shadow_count == 0u || dirt.x >= dirt.z {
        return false;
    }
    // (Area lights: the polygon integral that could rule the light out costs more than the
    // lookups' test.)
    if !is_area_light(light) {
        var l = -light.direction;
        if light.kind != LIGHT_DIRECTIONAL {
            l = normalize(light.position - surface);
        }
        // Clearly facing away only: light_irradiance's own test rounds differently.
        if dot(n, l) < -1e-4 {
            return false;
        }
    }
    return shadow_reads(light, shadow_views[v], p, n, softness, dirt);
}

// The nearest distance view `view` stores (`occluder_distance` in lighting/shadow.wgsl) of
// anything inside the world box lo..hi: the box's nearest corner along an orthographic view's
// direction, the box's nearest point to a perspective view's origin.
fn box_distance(view: ShadowView, lo: vec3<f32>, hi: vec3<f32>) -> f32 {
    if view.kind == SHADOW_ORTHO {
        let d = view.dir;
        let corner = select(hi, lo, d >= vec3<f32>(0.0));
        return dot(corner - view.origin, d);
    }
    return length(clamp(view.origin, lo, hi) - view.origin);
}
