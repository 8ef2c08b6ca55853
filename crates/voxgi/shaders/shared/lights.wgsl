// Direct light from every light type, with filtered shadows. Expects the including shader to
// declare `lights`, `shadow_views`, `shadow_maps` (a texture_2d_array<f32> of distances) and
// `shadow_moments` (their prefiltered moments, lighting/moments.wgsl).

//!include shared/scene.wgsl
//!include shared/brdf.wgsl
//!include shared/light_model.wgsl

// Golden-angle (Vogel) disc: even coverage for any tap count, the same pattern every pixel so
// images are deterministic.
fn vogel(i: u32, n: u32) -> vec2<f32> {
    let r = sqrt((f32(i) + 0.5) / f32(n));
    let a = f32(i) * 2.39996323;
    return r * vec2<f32>(cos(a), sin(a));
}

// Which of a light's views sees p: the cube face of the dominant axis for 6-view lights.
fn shadow_view_index(light: Light, p: vec3<f32>) -> u32 {
    if light.shadow_count < 6u {
        return light.shadow_first;
    }
    return cube_face(light.shadow_first, p);
}

// Which face of the cube of views from `first` to `first + 5` sees p.
fn cube_face(first: u32, p: vec3<f32>) -> u32 {
    let d = p - shadow_views[first].origin;
    let a = abs(d);
    var face = 0u;
    if a.x >= a.y && a.x >= a.z {
        face = select(1u, 0u, d.x > 0.0);
    } else if a.y >= a.z {
        face = select(3u, 2u, d.y > 0.0);
    } else {
        face = select(5u, 4u, d.z > 0.0);
    }
    return first + face;
}

fn shadow_uv(view: ShadowView, p: vec3<f32>) -> vec3<f32> {
    let clip = view.view_proj * vec4<f32>(p, 1.0);
    let ndc = clip.xyz / clip.w;
    return vec3<f32>(ndc.x * 0.5 + 0.5, 0.5 - ndc.y * 0.5, clip.w);
}

fn shadow_distance(view: ShadowView, p: vec3<f32>) -> f32 {
    if view.kind == SHADOW_ORTHO {
        return dot(p - view.origin, view.dir);
    }
    return length(p - view.origin);
}

// World size of one shadow texel at distance `dist` from the view's origin.
fn shadow_texel_world(view: ShadowView, dist: f32) -> f32 {
    if view.kind == SHADOW_ORTHO {
        return view.texel;
    }
    return view.texel * dist;
}

fn shadow_texel(view: ShadowView, t: vec2<i32>) -> f32 {
    let r = i32(view.resolution);
    let c = clamp(t, vec2<i32>(0), vec2<i32>(r - 1)) + vec2<i32>(view.offset);
    return textureLoad(shadow_maps, c, i32(view.layer), 0).r;
}

// The specular material of the surface texel `t` of `view` sees (lighting/shadow.wgsl's
// `material_code`: 0 for none, and always in an atlas of distances alone): F0 (rgb) and
// roughness (a), or all zero.
fn shadow_material(view: ShadowView, t: vec2<i32>) -> vec4<f32> {
    let r = i32(view.resolution);
    let c = clamp(t, vec2<i32>(0), vec2<i32>(r - 1)) + vec2<i32>(view.offset);
    let code = u32(textureLoad(shadow_maps, c, i32(view.layer), 0).g);
    if code == 0u {
        return vec4<f32>(0.0);
    }
    let q = code - 1u;
    return vec4<f32>(vec4<u32>(q & 63u, (q >> 6u) & 63u, (q >> 12u) & 63u, q >> 18u)) / 63.0;
}

// The distance a planar receiver (through p, normal n) would have at shadow-map position uv:
// comparing occluders against this instead of p's own distance stops wide filters from letting
// a tilted surface shadow itself (receiver-plane depth bias, exact for planes).
fn receiver_distance(view: ShadowView, uv: vec2<f32>, p: vec3<f32>, n: vec3<f32>) -> f32 {
    let ndc = vec2<f32>(uv.x * 2.0 - 1.0, 1.0 - uv.y * 2.0);
    let a4 = view.inv_view_proj * vec4<f32>(ndc, 0.0, 1.0);
    let b4 = view.inv_view_proj * vec4<f32>(ndc, 1.0, 1.0);
    let a = a4.xyz / a4.w;
    let b = b4.xyz / b4.w;
    let dir = normalize(b - a);
    let denom = dot(dir, n);
    if abs(denom) < 1e-4 {
        return 3.0e38;
    }
    let x = a + dir * (dot(p - a, n) / denom);
    if view.kind == SHADOW_ORTHO {
        return dot(x - view.origin, view.dir);
    }
    if dot(x - view.origin, dir) < 0.0 {
        return 3.0e38;
    }
    return length(x - view.origin);
}

// The receiver plane's distance as a linear function of uv around uv0: value and gradient.
// Evaluating the exact plane once per axis instead of once per tap keeps wide filters cheap.
struct ReceiverPlane {
    uv0: vec2<f32>,
    d0: f32,
    grad: vec2<f32>,
}

fn receiver_plane(view: ShadowView, uv0: vec2<f32>, p: vec3<f32>, n: vec3<f32>) -> ReceiverPlane {
    let h = 1.0 / view.resolution;
    let d0 = receiver_distance(view, uv0, p, n);
    let du = receiver_distance(view, uv0 + vec2<f32>(h, 0.0), p, n) - d0;
    let dv = receiver_distance(view, uv0 + vec2<f32>(0.0, h), p, n) - d0;
    // A plane seen edge-on has no useful gradient: fall back to the point's own distance.
    if abs(du) > 1e20 || abs(dv) > 1e20 || d0 > 1e20 {
        return ReceiverPlane(uv0, shadow_distance(view, p), vec2<f32>(0.0));
    }
    return ReceiverPlane(uv0, d0, vec2<f32>(du, dv) / h);
}

fn plane_at(rp: ReceiverPlane, uv: vec2<f32>) -> f32 {
    return rp.d0 + dot(rp.grad, uv - rp.uv0);
}

// Bilinearly weighted comparison at one uv against the receiver plane: 1 lit, 0 shadowed.
fn shadow_tap(view: ShadowView, uv: vec2<f32>, rp: ReceiverPlane, bias: f32) -> f32 {
    if any(uv < vec2<f32>(0.0)) || any(uv > vec2<f32>(1.0)) {
        return 1.0;
    }
    let dist = plane_at(rp, uv) - bias;
    let st = uv * view.resolution - 0.5;
    let i = vec2<i32>(floor(st));
    let f = fract(st);
    let s00 = select(0.0, 1.0, dist <= shadow_texel(view, i));
    let s10 = select(0.0, 1.0, dist <= shadow_texel(view, i + vec2<i32>(1, 0)));
    let s01 = select(0.0, 1.0, dist <= shadow_texel(view, i + vec2<i32>(0, 1)));
    let s11 = select(0.0, 1.0, dist <= shadow_texel(view, i + vec2<i32>(1, 1)));
    return mix(mix(s00, s10, f.x), mix(s01, s11, f.x), f.y);
}

// The VSM/ESM shadow filter (`ShadowFilter::VsmEsm`) for point, spot and directional lights:
// one bilinear lookup of the prefiltered moments instead of PCF's twelve comparisons.
override SHADOW_MOMENTS: bool = false;
// The exponential map's sharpness over distances normalised by the view's far plane: large
// enough that an occluder 5 % of the range in front darkens to exp(-4), small enough that
// exp(ESM_C) stays a finite f32 (the maps store exp(ESM_C (d - 1)) <= 1).
const ESM_C: f32 = 80.0;
// Chebyshev's bound is cut below this and rescaled (light-bleeding reduction): where a far
// receiver sees two occluder layers the bound stays high, which min(VSM, ESM) leaves to the
// ESM; this trims what both let through.
const VSM_BLEED: f32 = 0.2;
// Smallest variance, in normalised distance squared: a flat occluder's moments have none, and
// f32 rounding of E[d^2] - E[d]^2 must not make the bound flicker.
const VSM_MIN_VARIANCE: f32 = 1e-7;
// The prefilter's disc reaches this many texels from its centre (lighting/moments.wgsl).
const MOMENT_RADIUS: f32 = 2.0;

// The moments of view `view` bilinearly interpolated at uv (f32 textures need not be
// filterable: four loads).
fn moments_at(view: ShadowView, uv: vec2<f32>) -> vec4<f32> {
    let st = uv * view.resolution - 0.5;
    let i = vec2<i32>(floor(st));
    let f = fract(st);
    let r = i32(view.resolution);
    let l = i32(view.layer);
    let m00 = textureLoad(shadow_moments, clamp(i, vec2<i32>(0), vec2<i32>(r - 1)), l, 0);
    let m10 = textureLoad(shadow_moments, clamp(i + vec2<i32>(1, 0), vec2<i32>(0), vec2<i32>(r - 1)), l, 0);
    let m01 = textureLoad(shadow_moments, clamp(i + vec2<i32>(0, 1), vec2<i32>(0), vec2<i32>(r - 1)), l, 0);
    let m11 = textureLoad(shadow_moments, clamp(i + vec2<i32>(1, 1), vec2<i32>(0), vec2<i32>(r - 1)), l, 0);
    return mix(mix(m00, m10, f.x), mix(m01, m11, f.x), f.y);
}

// min(VSM, ESM) (Salm, §2.3): the variance map's Chebyshev bound leaks where occluder depths
// vary (behind several layers), the exponential map's soft step leaks near contact; each
// leaks where the other does not. The receiver distance is the biased one PCF compares.
fn moments_visibility(s: ShadowSetup) -> f32 {
    if any(s.uv < vec2<f32>(0.0)) || any(s.uv > vec2<f32>(1.0)) {
        return 1.0;
    }
    let m = moments_at(s.view, s.uv);
    let d = clamp(s.dist / s.view.far, 0.0, 1.0);
    let variance = max(m.y - m.x * m.x, VSM_MIN_VARIANCE);
    let dd = d - m.x;
    let bound = clamp((variance / (variance + dd * dd) - VSM_BLEED) / (1.0 - VSM_BLEED), 0.0, 1.0);
    let vsm = select(bound, 1.0, d <= m.x);
    let esm = clamp(exp(-ESM_C * (d - 1.0)) * m.z, 0.0, 1.0);
    return min(vsm, esm);
}

const PCF_TAPS: u32 = 12u;
const PCSS_SEARCH_TAPS: u32 = 12u;
const PCSS_TAPS: u32 = 24u;

// What every shadow lookup of a light from p (normal n) starts from: the view, p's place
// in it, the compared distance and bias, and the receiver plane. The light must cast shadows.
struct ShadowSetup {
    view: ShadowView,
    uv: vec2<f32>,
    d0: f32,
    dist: f32,
    bias: f32,
    texel_uv: f32,
    rp: ReceiverPlane,
}

fn shadow_setup(light: Light, p: vec3<f32>, n: vec3<f32>) -> ShadowSetup {
    return view_setup(shadow_views[shadow_view_index(light, p)], p, n);
}

fn view_setup(view: ShadowView, p: vec3<f32>, n: vec3<f32>) -> ShadowSetup {
    let d0 = shadow_distance(view, p);
    let texel = shadow_texel_world(view, max(d0, view.near));
    // Light direction at p, for the slope of the receiver as the light sees it.
    var to_light = -view.dir;
    if view.kind != SHADOW_ORTHO {
        to_light = normalize(view.origin - p);
    }
    let cos_t = clamp(abs(dot(n, to_light)), 0.05, 1.0);
    let tan_t = sqrt(1.0 - cos_t * cos_t) / cos_t;
    // Within one texel a tilted receiver's distance varies by texel * tan: allow that, plus a
    // texel for the rasterizer's rounding.
    let bias = texel * (1.0 + min(tan_t, 8.0));
    let uv = shadow_uv(view, p).xy;
    return ShadowSetup(view, uv, d0, d0 - bias, bias, 1.0 / view.resolution, receiver_plane(view, uv, p, n));
}

// Percentage-closer soft shadows (area lights): the blocker search's radius in uv, from the
// light's size and p's distance.
fn pcss_search(light: Light, view: ShadowView, d0: f32) -> f32 {
    let tan_to_uv = 1.0 / (view.texel * view.resolution);
    return clamp(light.size * tan_to_uv / max(0.25 * d0, view.near), 2.0 / view.resolution, 0.25);
}

// The blocker search: how many taps found an occluder (x) and their mean distance (y).
fn pcss_blockers(s: ShadowSetup, search: f32) -> vec2<f32> {
    var blockers = 0.0;
    var blocker_sum = 0.0;
    for (var i = 0u; i < PCSS_SEARCH_TAPS; i++) {
        let o = s.uv + vogel(i, PCSS_SEARCH_TAPS) * search;
        let t = vec2<i32>(floor(o * s.view.resolution));
        let z = shadow_texel(s.view, t);
        if z < plane_at(s.rp, o) - s.bias {
            blockers += 1.0;
            blocker_sum += z;
        }
    }
    return vec2<f32>(blockers, blocker_sum / max(blockers, 1.0));
}

// The penumbra's filter radius in uv: the width similar triangles give for blockers at mean
// distance `zb` (`blockers.y`).
fn pcss_radius(light: Light, s: ShadowSetup, blockers: vec2<f32>) -> f32 {
    let tan_to_uv = 1.0 / (s.view.texel * s.view.resolution);
    let zb = max(blockers.y, s.view.near);
    return clamp(light.size * (s.dist - zb) / (zb * s.dist) * tan_to_uv, s.texel_uv, 0.25);
}

// Visibility of a light from p (normal n), in [0, 1].
fn light_visibility(light: Light, p: vec3<f32>, n: vec3<f32>, softness: f32) -> f32 {
    if light.shadow_count == 0u {
        return 1.0;
    }
    let s = shadow_setup(light, p, n);
    if is_area_light(light) {
        // Percentage-closer soft shadows: the penumbra width follows the light's size and the
        // blocker/receiver distances, as similar triangles give it.
        let blockers = pcss_blockers(s, pcss_search(light, s.view, s.d0));
        if blockers.x == 0.0 {
            return 1.0;
        }
        let radius = pcss_radius(light, s, blockers);
        var lit = 0.0;
        for (var i = 0u; i < PCSS_TAPS; i++) {
            lit += shadow_tap(s.view, s.uv + vogel(i, PCSS_TAPS) * radius, s.rp, s.bias);
        }
        return lit / f32(PCSS_TAPS);
    }
    if SHADOW_MOMENTS {
        return moments_visibility(s);
    }
    let radius = softness * s.texel_uv;
    var lit = 0.0;
    for (var i = 0u; i < PCF_TAPS; i++) {
        lit += shadow_tap(s.view, s.uv + vogel(i, PCF_TAPS) * radius, s.rp, s.bias);
    }
    return lit / f32(PCF_TAPS);
}

// One frame's estimate of the fraction of an area light's unshadowed irradiance at p (normal
// n) that arrives, from the point of the light the sample view cube `s` (of the light's
// SAMPLE_POINTS) looks out of, whose hard shadow gives its visibility V. With G the point's
// geometry term (the two cosines over the squared distance) and E = the integral of G over
// the light (`polygon_irradiance`), the point uniform over the light's area A:
//     1 - (1 - V) G A / E,
// whose mean is exactly the integral of V G over that of G, the path tracer's shadowed share.
// Written so, a point that sees the light (or lies behind p's horizon, G = 0) counts as 1: lit
// surfaces carry no noise, only shadows do.
fn sampled_visibility(light: Light, p: vec3<f32>, n: vec3<f32>, s: u32) -> f32 {
    let e = polygon_irradiance(light, p, n);
    if e <= 0.0 {
        return 1.0;
    }
    let first = light.sample_first + 6u * s;
    let view = shadow_views[cube_face(first, p)];
    let to = shadow_views[first].origin - p;
    let r2 = max(dot(to, to), 1e-8);
    let l = to * inverseSqrt(r2);
    let g = max(dot(n, l), 0.0) * max(dot(light.direction, -l), 0.0) / r2;
    if g <= 0.0 {
        return 1.0;
    }
    let setup = view_setup(view, p, n);
    let v = shadow_tap(view, setup.uv, setup.rp, setup.bias);
    return 1.0 - (1.0 - v) * g * light.area / e;
}

// Vertex i of an area light's polygon, relative to p: a rectangle's four corners, or a 16-gon
// with a disc's area.
fn polygon_vertex(light: Light, p: vec3<f32>, i: u32) -> vec3<f32> {
    let c = light.position - p;
    if light.kind == LIGHT_RECT {
        let su = select(-1.0, 1.0, i == 1u || i == 2u);
        let sv = select(-1.0, 1.0, i >= 2u);
        return c + su * light.axis_u + sv * light.axis_v;
    }
    let k = f32(DISC_SIDES);
    let scale = sqrt(PI / (k * 0.5 * sin(2.0 * PI / k)));
    let a = f32(i) / k * 2.0 * PI;
    return c + scale * (cos(a) * light.axis_u + sin(a) * light.axis_v);
}

const DISC_SIDES: u32 = 16u;

// Irradiance at p (normal n) from a uniform one-sided polygonal emitter of unit radiance: the
// Lambert formula over the polygon clipped to the upper hemisphere. Exact for unoccluded
// Lambertian receivers.
fn polygon_irradiance(light: Light, p: vec3<f32>, n: vec3<f32>) -> f32 {
    return polygon_integral(light, p, transpose(tangent_frame(n)));
}

// The Lambert formula E = 1/2 sum_i angle_i (z . unit(v_i x v_i+1)) for the light's polygon
// relative to p, each vertex mapped by m, clipped to z >= 0: with m a rotation taking n to z,
// the irradiance; with the inverse of a linearly transformed cosine's matrix (in the frame of
// n and v), pi times the integral of that distribution over the light. The clipping
// (Sutherland-Hodgman) streams its vertices into the sum: no local arrays, which CPU drivers
// zero-initialise in memory on every call whether or not a pixel clips.
fn polygon_integral(light: Light, p: vec3<f32>, m: mat3x3<f32>) -> f32 {
    if light.kind == LIGHT_RECT {
        let v0 = normalize(m * polygon_vertex(light, p, 0u));
        let v1 = normalize(m * polygon_vertex(light, p, 1u));
        let v2 = normalize(m * polygon_vertex(light, p, 2u));
        let v3 = normalize(m * polygon_vertex(light, p, 3u));
        if min(min(v0.z, v1.z), min(v2.z, v3.z)) >= 0.0 {
            return 0.5 * abs(edge_integral(v0, v1) + edge_integral(v1, v2) + edge_integral(v2, v3) + edge_integral(v3, v0));
        }
    }
    let count = select(DISC_SIDES, 4u, light.kind == LIGHT_RECT);
    var sum = 0.0;
    var first = vec3<f32>(0.0);
    var prev = vec3<f32>(0.0);
    var emitted = 0u;
    var b = m * polygon_vertex(light, p, 0u);
    for (var i = 0u; i < count; i++) {
        let a = b;
        b = m * polygon_vertex(light, p, (i + 1u) % count);
        let da = a.z;
        let db = b.z;
        // Up to two vertices per edge: its start if above the horizon, and where it crosses.
        for (var k = 0u; k < 2u; k++) {
            let emit = select((da >= 0.0) != (db >= 0.0), da >= 0.0, k == 0u);
            if emit {
                let q = normalize(select(a + (b - a) * (da / (da - db)), a, k == 0u));
                if emitted == 0u {
                    first = q;
                } else {
                    sum += edge_integral(prev, q);
                }
                prev = q;
                emitted++;
            }
        }
    }
    if emitted < 3u {
        return 0.0;
    }
    sum += edge_integral(prev, first);
    return 0.5 * abs(sum);
}

// One edge's term of the Lambert formula: the angle the edge (a, b unit vectors) subtends
// times the cosine of its great circle's normal with z.
fn edge_integral(a: vec3<f32>, b: vec3<f32>) -> f32 {
    let c = cross(a, b);
    let len = length(c);
    return select(0.0, atan2(len, dot(a, b)) * c.z / len, len > 1e-9);
}

// Irradiance at p (normal n) from an area light of unit radiance, unshadowed: the polygon's,
// and none behind the one-sided emitter's plane or within `clearance` metres in front of it
// (where a position from a depth buffer puts the light's own surface).
fn area_irradiance(light: Light, p: vec3<f32>, n: vec3<f32>, clearance: f32) -> f32 {
    if dot(p - light.position, light.direction) <= clearance {
        return 0.0;
    }
    return polygon_irradiance(light, p, n);
}

// Irradiance (W/m^2) arriving at `surface` with normal n from one light, shadows included,
// their lookups made from p (`surface` lifted off its own occluders in the shadow map). Used
// where only Lambertian reflection matters (light injection into voxels). The light's geometry
// is the surface's, not p's: p lies nearer a light in the surface's own plane (a lamp flush
// with the ceiling, the walls' top rows under it), which made the voxels brighter than the
// surfaces they hold (docs/QUALITY.md, "The voxels' direct light").
fn light_irradiance(light: Light, surface: vec3<f32>, p: vec3<f32>, n: vec3<f32>, softness: f32) -> vec3<f32> {
    if is_area_light(light) {
        let e = area_irradiance(light, surface, n, 0.0);
        if e <= 0.0 {
            return vec3<f32>(0.0);
        }
        return light.radiance * e * light_visibility(light, p, n, softness);
    }
    var l: vec3<f32>;
    var e: vec3<f32>;
    if light.kind == LIGHT_DIRECTIONAL {
        l = -light.direction;
        e = light.radiance;
    } else {
        let to = light.position - surface;
        let d2 = max(dot(to, to), 1e-8);
        let d = sqrt(d2);
        l = to / d;
        e = light.radiance / d2 * range_window(d, light.range);
        if light.kind == LIGHT_SPOT {
            e *= spot_falloff(dot(-l, light.direction), light.cos_inner, light.cos_outer);
        }
    }
    let n_dot_l = dot(n, l);
    if n_dot_l <= 0.0 || all(e <= vec3<f32>(0.0)) {
        return vec3<f32>(0.0);
    }
    return e * n_dot_l * light_visibility(light, p, n, softness);
}
