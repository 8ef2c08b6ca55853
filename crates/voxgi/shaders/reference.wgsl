// reference: the ground-truth path tracer (and the AO reference). One invocation per pixel adds
// `sample_count` samples to a float accumulation buffer (rgb: the sum, a: how many samples the
// pixel has, which also numbers its next sample); the host divides by the count.
//
// Same scene, same materials (shared/brdf.wgsl) and same light model (shared/light_model.wgsl)
// as the rasterizer, so any difference between the two images is the real-time approximation's
// error. Next-event estimation for every light; area lights are sampled uniformly by area and
// combined with BSDF sampling by multiple importance sampling (power heuristic), so an area
// light's emitter surface is counted exactly once. Punctual and directional lights are NEE only.
// Other emissive surfaces are found by BSDF sampling.

//!include shared/scene.wgsl
//!include shared/brdf.wgsl
//!include shared/light_model.wgsl

struct Params {
    inv_view_proj: mat4x4<f32>,
    background: vec3<f32>,
    light_count: u32,
    width: u32,
    height: u32,
    // The first column and row traced: a dispatch covers columns x0..x1 and rows y0..y1 of
    // the image.
    x0: u32,
    sample_count: u32,
    seed: u32,
    // Number of indirect bounces: 0 direct only, 1, or a large cap for unlimited.
    bounces: u32,
    // 0 radiance, 1 ambient occlusion, 2 the cone probe (`probe`: one invocation per cone of
    // `queries`, width of them in row 0).
    mode: u32,
    ao_radius: f32,
    // Russian roulette from this path depth on (a huge value disables it).
    rr_depth: u32,
    x1: u32,
    y0: u32,
    y1: u32,
}

// A BVH node: inner nodes (count 0) have children `first` and `first + 1`; leaves hold triangles
// `first .. first + count`.
struct Node {
    lo: vec3<f32>,
    first: u32,
    hi: vec3<f32>,
    count: u32,
}

// A world-space triangle, or a point-cloud sample's disc (kind PRIM_DISC: p0 its centre, p1
// its unit normal, p2.x its radius).
struct Tri {
    p0: vec3<f32>,
    material: u32,
    p1: vec3<f32>,
    // The area light this triangle shows, or NO_INDEX.
    light: u32,
    p2: vec3<f32>,
    kind: u32,
}

const PRIM_DISC: u32 = 1u;

// Its shading attributes: vertex normals with the UVs packed in the w components. A disc's:
// n0 its normal, n1 its albedo, n2 its emitted radiance.
struct TriShading {
    n0: vec4<f32>,
    n1: vec4<f32>,
    n2: vec4<f32>,
    // (v1, u2, v2, unused)
    uv: vec4<f32>,
}

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> nodes: array<Node>;
@group(0) @binding(2) var<storage, read> tris: array<Tri>;
@group(0) @binding(3) var<storage, read> shading: array<TriShading>;
@group(0) @binding(4) var<storage, read> materials: array<Material>;
@group(0) @binding(5) var<storage, read> lights: array<Light>;
@group(0) @binding(6) var textures: texture_2d_array<f32>;
@group(0) @binding(7) var texture_sampler: sampler;
@group(0) @binding(8) var<storage, read_write> accum: array<vec4<f32>>;

// A cone of the cone tracer, for the probe mode (reference/probe.rs, `ConeQuery`).
struct ConeQuery {
    origin: vec3<f32>,
    tan_half: f32,
    dir: vec3<f32>,
    max_distance: f32,
    normal: vec3<f32>,
    _pad: f32,
}

@group(0) @binding(9) var<storage, read> queries: array<ConeQuery>;

// ---------------------------------------------------------------------------------------------
// Random numbers: PCG (O'Neill), seeded by hashing pixel, sample index and seed.

var<private> rng: u32;

fn pcg_hash(v: u32) -> u32 {
    let state = v * 747796405u + 2891336453u;
    let word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

fn rand() -> f32 {
    rng = rng * 747796405u + 2891336453u;
    var w = ((rng >> ((rng >> 28u) + 4u)) ^ rng) * 277803737u;
    w = (w >> 22u) ^ w;
    return f32(w >> 8u) * (1.0 / 16777216.0);
}

fn rand2() -> vec2<f32> {
    let a = rand();
    return vec2<f32>(a, rand());
}

// ---------------------------------------------------------------------------------------------
// Ray casting.

const NO_HIT: u32 = 0xffffffffu;
const STACK_SIZE: u32 = 64u;

struct Hit {
    t: f32,
    tri: u32,
    b: vec2<f32>,
}

fn material_alpha(m: Material, uv: vec2<f32>) -> f32 {
    var a = m.base_color.a;
    if m.base_texture >= 0 {
        a *= textureSampleLevel(textures, texture_sampler, uv, m.base_texture, 0.0).a;
    }
    return a;
}

fn tri_uv(i: u32, b: vec2<f32>) -> vec2<f32> {
    let s = shading[i];
    let uv0 = vec2<f32>(s.n0.w, s.n1.w);
    let uv1 = vec2<f32>(s.n2.w, s.uv.x);
    let uv2 = s.uv.yz;
    return uv0 * (1.0 - b.x - b.y) + uv1 * b.x + uv2 * b.y;
}

// A disc, both sides: t (or -1).
fn intersect_disc(tri: Tri, o: vec3<f32>, d: vec3<f32>, tmax: f32) -> vec3<f32> {
    let n = tri.p1;
    let dn = dot(d, n);
    if abs(dn) < 1e-12 {
        return vec3<f32>(-1.0, 0.0, 0.0);
    }
    let t = dot(tri.p0 - o, n) / dn;
    let q = o + d * t - tri.p0;
    if t <= 0.0 || t >= tmax || dot(q, q) > tri.p2.x * tri.p2.x {
        return vec3<f32>(-1.0, 0.0, 0.0);
    }
    return vec3<f32>(t, 0.0, 0.0);
}

// Möller-Trumbore, both sides. Returns t (or -1) and the barycentrics of p1, p2.
fn intersect_tri(i: u32, o: vec3<f32>, d: vec3<f32>, tmax: f32) -> vec3<f32> {
    let tri = tris[i];
    if tri.kind == PRIM_DISC {
        let r = intersect_disc(tri, o, d, tmax);
        // An area light's surface is its shape: where the discs that show it reach past its
        // edge (a point-sampled box's faces overlap at its edges) they are not there, so that
        // the light is exactly what is sampled and nothing beyond it shades grazing light.
        if r.x > 0.0 && tri.light != NO_INDEX && !within_area_light(lights[tri.light], o + d * r.x) {
            return vec3<f32>(-1.0, 0.0, 0.0);
        }
        return r;
    }
    let e1 = tri.p1 - tri.p0;
    let e2 = tri.p2 - tri.p0;
    let pv = cross(d, e2);
    let det = dot(e1, pv);
    if abs(det) < 1e-12 {
        return vec3<f32>(-1.0, 0.0, 0.0);
    }
    let inv = 1.0 / det;
    let tv = o - tri.p0;
    let u = dot(tv, pv) * inv;
    if u < 0.0 || u > 1.0 {
        return vec3<f32>(-1.0, 0.0, 0.0);
    }
    let qv = cross(tv, e1);
    let v = dot(d, qv) * inv;
    if v < 0.0 || u + v > 1.0 {
        return vec3<f32>(-1.0, 0.0, 0.0);
    }
    let t = dot(e2, qv) * inv;
    if t <= 0.0 || t >= tmax {
        return vec3<f32>(-1.0, 0.0, 0.0);
    }
    // Alpha-masked materials: cut-out texels let the ray through.
    let m = materials[tri.material];
    if m.alpha_cutoff > 0.0 && material_alpha(m, tri_uv(i, vec2<f32>(u, v))) < m.alpha_cutoff {
        return vec3<f32>(-1.0, 0.0, 0.0);
    }
    return vec3<f32>(t, u, v);
}

fn box_entry(n: Node, o: vec3<f32>, inv_d: vec3<f32>, tmax: f32) -> f32 {
    let t0 = (n.lo - o) * inv_d;
    let t1 = (n.hi - o) * inv_d;
    let tn = max(max(min(t0.x, t1.x), min(t0.y, t1.y)), max(min(t0.z, t1.z), 0.0));
    let tf = min(min(max(t0.x, t1.x), max(t0.y, t1.y)), min(max(t0.z, t1.z), tmax));
    return select(FAR_AWAY, tn, tn <= tf);
}

// The nearest hit closer than tmax; with `any_hit`, the first hit found (for shadow rays).
fn trace(o: vec3<f32>, d: vec3<f32>, tmax_in: f32, any_hit: bool) -> Hit {
    var hit = Hit(tmax_in, NO_HIT, vec2<f32>(0.0));
    let inv_d = 1.0 / select(d, vec3<f32>(1e-20), abs(d) < vec3<f32>(1e-20));
    var stack: array<u32, STACK_SIZE>;
    var sp = 0u;
    var node = 0u;
    if box_entry(nodes[0], o, inv_d, hit.t) == FAR_AWAY {
        return hit;
    }
    loop {
        let n = nodes[node];
        if n.count > 0u {
            for (var i = n.first; i < n.first + n.count; i++) {
                let r = intersect_tri(i, o, d, hit.t);
                if r.x > 0.0 {
                    hit = Hit(r.x, i, r.yz);
                    if any_hit {
                        return hit;
                    }
                }
            }
        } else {
            let a = n.first;
            let b = n.first + 1u;
            let ta = box_entry(nodes[a], o, inv_d, hit.t);
            let tb = box_entry(nodes[b], o, inv_d, hit.t);
            let near = select(b, a, ta <= tb);
            let far = select(a, b, ta <= tb);
            let t_near = min(ta, tb);
            let t_far = max(ta, tb);
            if t_near < FAR_AWAY {
                if t_far < FAR_AWAY && sp < STACK_SIZE {
                    stack[sp] = far;
                    sp++;
                }
                node = near;
                continue;
            }
        }
        // Pop the next node still in front of the nearest hit.
        var found = false;
        while sp > 0u {
            sp--;
            let c = stack[sp];
            if box_entry(nodes[c], o, inv_d, hit.t) < FAR_AWAY {
                node = c;
                found = true;
                break;
            }
        }
        if !found {
            break;
        }
    }
    return hit;
}

// Offsets a ray origin off the surface along the geometric normal, on the side of `dir`.
fn offset_origin(p: vec3<f32>, ng: vec3<f32>, dir: vec3<f32>) -> vec3<f32> {
    let eps = 1e-4 * (1.0 + max(max(abs(p.x), abs(p.y)), abs(p.z)));
    return p + ng * select(-eps, eps, dot(ng, dir) > 0.0);
}

// Whether nothing blocks the segment from p (geometric normal ng) to p + dir * dist. The
// origin is offset off the surface, and the segment stops short of its end by the same margin,
// so neither the surface at p nor a surface at the far end (an area light's emitter) blocks it.
fn visible(p: vec3<f32>, ng: vec3<f32>, dir: vec3<f32>, dist: f32) -> bool {
    let o = offset_origin(p, ng, dir);
    if dist >= FAR_AWAY {
        return trace(o, dir, FAR_AWAY, true).tri == NO_HIT;
    }
    let q = p + dir * dist;
    let to = q - o;
    let len = length(to);
    let eps = 1e-4 * (1.0 + max(max(abs(q.x), abs(q.y)), abs(q.z)));
    if len <= eps {
        return true;
    }
    return trace(o, to / len, len - eps, true).tri == NO_HIT;
}

// ---------------------------------------------------------------------------------------------
// Sampling.

fn cosine_hemisphere(u: vec2<f32>) -> vec3<f32> {
    let r = sqrt(u.x);
    let phi = 2.0 * PI * u.y;
    return vec3<f32>(r * cos(phi), r * sin(phi), sqrt(max(0.0, 1.0 - u.x)));
}

fn g1_ggx(n_dot_v: f32, a: f32) -> f32 {
    let a2 = a * a;
    return 2.0 * n_dot_v / (n_dot_v + sqrt(a2 + (1.0 - a2) * n_dot_v * n_dot_v));
}

fn luminance(c: vec3<f32>) -> f32 {
    return dot(c, vec3<f32>(0.2126, 0.7152, 0.0722));
}

// Probability of choosing the specular lobe: by an estimate of the two lobes' albedos.
fn specular_probability(s: Surface, n_dot_v: f32) -> f32 {
    let ws = luminance(f_schlick(f0_of(s), n_dot_v));
    let wd = luminance(s.albedo * (1.0 - s.metallic));
    if ws + wd <= 0.0 {
        return 0.0;
    }
    return ws / (ws + wd);
}

// The pdf (solid angle) of sampling l at a surface, both lobes together.
fn bsdf_pdf(s: Surface, n: vec3<f32>, v: vec3<f32>, l: vec3<f32>) -> f32 {
    let n_dot_l = dot(n, l);
    let n_dot_v = max(dot(n, v), 1e-4);
    if n_dot_l <= 0.0 {
        return 0.0;
    }
    let ps = specular_probability(s, n_dot_v);
    let h = normalize(v + l);
    let a = ggx_alpha(s.roughness);
    let pdf_s = g1_ggx(n_dot_v, a) * d_ggx(max(dot(n, h), 0.0), a) / (4.0 * n_dot_v);
    return (1.0 - ps) * n_dot_l / PI + ps * pdf_s;
}

fn bsdf_eval(s: Surface, n: vec3<f32>, v: vec3<f32>, l: vec3<f32>) -> vec3<f32> {
    if dot(n, l) <= 0.0 {
        return vec3<f32>(0.0);
    }
    return brdf_diffuse(s) + brdf_specular(s, n, v, l);
}

struct BsdfSample {
    l: vec3<f32>,
    // f * cos / pdf
    weight: vec3<f32>,
    pdf: f32,
}

fn sample_bsdf(s: Surface, n: vec3<f32>, v: vec3<f32>) -> BsdfSample {
    let frame = tangent_frame(n);
    let n_dot_v = max(dot(n, v), 1e-4);
    let ps = specular_probability(s, n_dot_v);
    var l: vec3<f32>;
    if rand() < ps {
        let vt = transpose(frame) * v;
        let h = frame * sample_vndf(vec3<f32>(vt.xy, max(vt.z, 1e-4)), ggx_alpha(s.roughness), rand2());
        l = reflect(-v, h);
    } else {
        l = frame * cosine_hemisphere(rand2());
    }
    let pdf = bsdf_pdf(s, n, v, l);
    if pdf <= 0.0 {
        return BsdfSample(l, vec3<f32>(0.0), 0.0);
    }
    return BsdfSample(l, bsdf_eval(s, n, v, l) * dot(n, l) / pdf, pdf);
}

fn power_heuristic(a: f32, b: f32) -> f32 {
    let a2 = a * a;
    return a2 / max(a2 + b * b, 1e-30);
}

// ---------------------------------------------------------------------------------------------
// Surfaces.

struct SurfaceHit {
    p: vec3<f32>,
    // Geometric normal, facing the incoming ray.
    ng: vec3<f32>,
    // Shading normal, on the same side as ng.
    n: vec3<f32>,
    s: Surface,
    emission: vec3<f32>,
    // The area light whose emitting side was hit, or NO_INDEX.
    light: u32,
}

// Whether p, on or near an area light's plane, lies within its rectangle or disc.
fn within_area_light(l: Light, p: vec3<f32>) -> bool {
    let q = p - l.position;
    if l.kind == LIGHT_RECT {
        // q's coordinates in the (axis_u, axis_v) basis, by the dual basis.
        let uv = dot(cross(l.axis_u, l.axis_v), l.direction);
        let a = dot(cross(q, l.axis_v), l.direction) / uv;
        let b = dot(cross(l.axis_u, q), l.direction) / uv;
        return abs(a) <= 1.0 && abs(b) <= 1.0;
    }
    let r2 = dot(l.axis_u, l.axis_u);
    let flat = q - l.direction * dot(q, l.direction);
    return dot(flat, flat) <= r2;
}

// The area light `shown` (a primitive's `light`, or NO_INDEX) when the ray d meets its emitting
// side: an area light's surface emits on its light's side only. NO_INDEX otherwise.
fn emitting_light(shown: u32, d: vec3<f32>) -> u32 {
    if shown != NO_INDEX && dot(d, lights[shown].direction) < 0.0 {
        return shown;
    }
    return NO_INDEX;
}

fn surface_at(h: Hit, o: vec3<f32>, d: vec3<f32>) -> SurfaceHit {
    let tri = tris[h.tri];
    let sh = shading[h.tri];
    if tri.kind == PRIM_DISC {
        // A point: matte, as the rasterizer's surfels (metallic 0, roughness 1, specular 0.5).
        let ng = select(-tri.p1, tri.p1, dot(tri.p1, d) < 0.0);
        let s = Surface(sh.n1.xyz, 0.0, 1.0, 0.5);
        // A disc of an area light's surface is only hit within the light's shape (see
        // intersect_tri).
        let light = emitting_light(tri.light, d);
        let emission = select(sh.n2.xyz, vec3<f32>(0.0), tri.light != light);
        return SurfaceHit(o + d * h.t, ng, ng, s, emission, light);
    }
    let w = vec3<f32>(1.0 - h.b.x - h.b.y, h.b.x, h.b.y);
    var ng = normalize(cross(tri.p1 - tri.p0, tri.p2 - tri.p0));
    var n = normalize(sh.n0.xyz * w.x + sh.n1.xyz * w.y + sh.n2.xyz * w.z);
    if any(n != n) {
        n = ng;
    }
    let front = dot(ng, d) < 0.0;
    if !front {
        ng = -ng;
    }
    // Back faces show their reverse side, as in the rasterizer.
    if dot(n, ng) < 0.0 {
        n = -n;
    }
    let uv = tri_uv(h.tri, h.b);
    let m = materials[tri.material];
    var base = m.base_color;
    if m.base_texture >= 0 {
        base *= textureSampleLevel(textures, texture_sampler, uv, m.base_texture, 0.0);
    }
    var emission = m.emissive;
    if m.emissive_texture >= 0 {
        emission *= textureSampleLevel(textures, texture_sampler, uv, m.emissive_texture, 0.0).rgb;
    }
    let light = emitting_light(tri.light, d);
    if tri.light != light {
        emission = vec3<f32>(0.0);
    }
    let s = Surface(base.rgb, m.metallic, m.roughness, m.specular);
    return SurfaceHit(o + d * h.t, ng, n, s, emission, light);
}

// Solid-angle pdf of sampling point q (at distance dist along l) uniformly on an area light.
fn area_light_pdf(light: Light, l: vec3<f32>, dist: f32) -> f32 {
    let cos_l = dot(-l, light.direction);
    if cos_l <= 0.0 || light.area <= 0.0 {
        return 0.0;
    }
    return dist * dist / (cos_l * light.area);
}

fn concentric_disc(u: vec2<f32>) -> vec2<f32> {
    let o = 2.0 * u - 1.0;
    if o.x == 0.0 && o.y == 0.0 {
        return vec2<f32>(0.0);
    }
    var r: f32;
    var theta: f32;
    if abs(o.x) > abs(o.y) {
        r = o.x;
        theta = 0.25 * PI * (o.y / o.x);
    } else {
        r = o.y;
        theta = 0.5 * PI - 0.25 * PI * (o.x / o.y);
    }
    return r * vec2<f32>(cos(theta), sin(theta));
}

// Next-event estimation: light from every light reaching x, reflected towards v.
fn direct_light(x: SurfaceHit, v: vec3<f32>) -> vec3<f32> {
    var sum = vec3<f32>(0.0);
    for (var i = 0u; i < params.light_count; i++) {
        let light = lights[i];
        if is_area_light(light) {
            // One-sided: nothing behind the emitter's plane is lit.
            if dot(x.p - light.position, light.direction) <= 0.0 {
                continue;
            }
            let u = rand2();
            var q: vec3<f32>;
            if light.kind == LIGHT_RECT {
                q = light.position + (2.0 * u.x - 1.0) * light.axis_u + (2.0 * u.y - 1.0) * light.axis_v;
            } else {
                let c = concentric_disc(u);
                q = light.position + c.x * light.axis_u + c.y * light.axis_v;
            }
            let to = q - x.p;
            let dist = length(to);
            let l = to / dist;
            let n_dot_l = dot(x.n, l);
            let pdf_l = area_light_pdf(light, l, dist);
            if n_dot_l <= 0.0 || dot(x.ng, l) <= 0.0 || pdf_l <= 0.0 {
                continue;
            }
            if !visible(x.p, x.ng, l, dist) {
                continue;
            }
            let w = power_heuristic(pdf_l, bsdf_pdf(x.s, x.n, v, l));
            sum += bsdf_eval(x.s, x.n, v, l) * n_dot_l * light.radiance * (w / pdf_l);
        } else {
            let ls = punctual_light(light, x.p);
            let n_dot_l = dot(x.n, ls.l);
            if n_dot_l <= 0.0 || dot(x.ng, ls.l) <= 0.0 || all(ls.e <= vec3<f32>(0.0)) {
                continue;
            }
            if !visible(x.p, x.ng, ls.l, ls.dist) {
                continue;
            }
            sum += bsdf_eval(x.s, x.n, v, ls.l) * n_dot_l * ls.e;
        }
    }
    return sum;
}

// ---------------------------------------------------------------------------------------------
// Paths.

fn camera_ray(px: vec2<u32>) -> array<vec3<f32>, 2> {
    let uv = (vec2<f32>(px) + rand2()) / vec2<f32>(f32(params.width), f32(params.height));
    let ndc = vec2<f32>(uv.x * 2.0 - 1.0, 1.0 - uv.y * 2.0);
    let a4 = params.inv_view_proj * vec4<f32>(ndc, 0.0, 1.0);
    let b4 = params.inv_view_proj * vec4<f32>(ndc, 1.0, 1.0);
    let a = a4.xyz / a4.w;
    let b = b4.xyz / b4.w;
    return array<vec3<f32>, 2>(a, normalize(b - a));
}

// Indirect bounces are counted as the cone tracer counts them: with `bounces` = N, direct light
// (NEE plus MIS-weighted hits on area-light emitters) is gathered at the first N + 1 surfaces of
// the path, and other emissive surfaces and the background count up to path vertex N + 1 (the
// camera sees them at vertex 1). So N = 0 is exactly what the rasterizer computes.
//
// The light arriving along (o, d) at path vertex `first` - 1: 1 for a camera ray; 2 for a ray
// leaving a surface the camera sees (the probe), where an area light's emitter counts nothing,
// its light at that surface being the direct term. w: the distance to the first hit, -1 for
// none.
fn path(o_in: vec3<f32>, d_in: vec3<f32>, first: u32) -> vec4<f32> {
    var o = o_in;
    var d = d_in;
    var beta = vec3<f32>(1.0);
    var sum = vec3<f32>(0.0);
    var prev_pdf = 0.0;
    var first_t = -1.0;
    let last = params.bounces + 1u;
    for (var depth = first; depth <= last + 1u; depth++) {
        let h = trace(o, d, FAR_AWAY, false);
        if h.tri == NO_HIT {
            if depth <= last {
                sum += beta * params.background;
            }
            break;
        }
        if depth == first {
            first_t = h.t;
        }
        let x = surface_at(h, o, d);
        if x.light != NO_INDEX {
            // The emitter of an area light: direct light of the previous vertex, weighted
            // against that vertex's light sample; seen by the camera, counted in full.
            var w = 1.0;
            if depth > first {
                let light = lights[x.light];
                w = power_heuristic(prev_pdf, area_light_pdf(light, d, h.t));
            } else if first > 1u {
                w = 0.0;
            }
            sum += beta * x.emission * w;
        } else if depth <= last {
            sum += beta * x.emission;
        }
        if depth >= last + 1u {
            break;
        }
        let v = -d;
        sum += beta * direct_light(x, v);
        let bs = sample_bsdf(x.s, x.n, v);
        if bs.pdf <= 0.0 || dot(bs.l, x.ng) <= 0.0 {
            break;
        }
        beta *= bs.weight;
        prev_pdf = bs.pdf;
        if depth >= params.rr_depth {
            let q = min(max(beta.x, max(beta.y, beta.z)), 0.95);
            if rand() >= q {
                break;
            }
            beta /= q;
        }
        o = offset_origin(x.p, x.ng, bs.l);
        d = bs.l;
    }
    return vec4<f32>(sum, first_t);
}

fn radiance(px: vec2<u32>) -> vec3<f32> {
    let ray = camera_ray(px);
    return path(ray[0], ray[1], 1u).rgb;
}

// The probe mode: the light inside cone `i` of `queries`, from directions drawn uniformly over
// its solid angle, each followed as a path leaving a surface the camera sees. Three sums per
// cone, the last entry of each its weight: accum[3i] (radiance, 1), accum[3i + 1] (radiance
// times the cosine to the normal, that cosine), accum[3i + 2] (escaped, hit distance if hit,
// hit, 1). A direction below the surface is blocked at distance 0 and carries no light.
fn probe(i: u32) {
    let q = queries[i];
    let base = u32(accum[3u * i].w);
    let cos_max = 1.0 / sqrt(1.0 + q.tan_half * q.tan_half);
    let frame = tangent_frame(q.dir);
    var light = vec4<f32>(0.0);
    var cosine = vec4<f32>(0.0);
    var reach = vec4<f32>(0.0);
    for (var k = 0u; k < params.sample_count; k++) {
        rng = pcg_hash(pcg_hash(pcg_hash(i ^ pcg_hash(params.seed)) + base + k) ^ 0x9e3779b9u);
        let u = rand2();
        let c = 1.0 - u.x * (1.0 - cos_max);
        let s = sqrt(max(1.0 - c * c, 0.0));
        let phi = 2.0 * PI * u.y;
        let d = normalize(frame * vec3<f32>(s * cos(phi), s * sin(phi), c));
        let cos_n = dot(d, q.normal);
        var l = vec4<f32>(0.0);
        if cos_n > 0.0 {
            l = path(offset_origin(q.origin, q.normal, d), d, 2u);
            if !(all(l.rgb == l.rgb) && all(l.rgb < vec3<f32>(FAR_AWAY))) {
                l = vec4<f32>(0.0, 0.0, 0.0, l.w);
            }
        }
        let hit = l.w >= 0.0 && l.w <= q.max_distance;
        light += vec4<f32>(l.rgb, 1.0);
        cosine += vec4<f32>(l.rgb * max(cos_n, 0.0), max(cos_n, 0.0));
        reach += vec4<f32>(select(1.0, 0.0, hit), select(0.0, l.w, hit), select(0.0, 1.0, hit), 1.0);
    }
    accum[3u * i] += light;
    accum[3u * i + 1u] += cosine;
    accum[3u * i + 2u] += reach;
}

// Ambient occlusion: 1 when a cosine-distributed ray from the first hit escapes within
// `ao_radius`, else 0; pixels that see nothing are 1.
fn ambient_occlusion(px: vec2<u32>) -> f32 {
    let ray = camera_ray(px);
    let h = trace(ray[0], ray[1], FAR_AWAY, false);
    if h.tri == NO_HIT {
        return 1.0;
    }
    let x = surface_at(h, ray[0], ray[1]);
    let l = tangent_frame(x.n) * cosine_hemisphere(rand2());
    if dot(l, x.ng) <= 0.0 {
        return 0.0;
    }
    return select(0.0, 1.0, visible(x.p, x.ng, l, params.ao_radius));
}

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let px = id.xy + vec2<u32>(params.x0, params.y0);
    if px.x >= params.x1 || px.y >= params.y1 {
        return;
    }
    if params.mode == 2u {
        probe(px.x);
        return;
    }
    let pixel = px.y * params.width + px.x;
    // Each pixel numbers its own samples, so pixels traced in different frames (a split view
    // whose divider moved) still draw distinct random sequences.
    let base = u32(accum[pixel].w);
    var sum = vec3<f32>(0.0);
    for (var k = 0u; k < params.sample_count; k++) {
        let sample = base + k;
        rng = pcg_hash(pcg_hash(pcg_hash(pixel ^ pcg_hash(params.seed)) + sample) ^ 0x9e3779b9u);
        var c: vec3<f32>;
        if params.mode == 1u {
            c = vec3<f32>(ambient_occlusion(px));
        } else {
            c = radiance(px);
        }
        // A NaN or infinity from a degenerate sample would poison the pixel forever.
        if all(c == c) && all(c < vec3<f32>(FAR_AWAY)) {
            sum += c;
        }
    }
    accum[pixel] += vec4<f32>(sum, f32(params.sample_count));
}
