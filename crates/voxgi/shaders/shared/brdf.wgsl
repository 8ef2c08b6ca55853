// The material model shared by the rasterizer, the cone tracer and the reference path tracer:
// Lambert diffuse plus GGX specular (Smith height-correlated visibility, Schlick Fresnel).

struct Surface {
    albedo: vec3<f32>,
    metallic: f32,
    roughness: f32,
    specular: f32,
}

fn f0_of(s: Surface) -> vec3<f32> {
    return mix(vec3<f32>(0.04 * s.specular), s.albedo, s.metallic);
}

// Perceptual roughness -> GGX alpha, floored so point lights keep a finite highlight.
fn ggx_alpha(roughness: f32) -> f32 {
    let r = clamp(roughness, 0.045, 1.0);
    return r * r;
}

fn d_ggx(n_dot_h: f32, a: f32) -> f32 {
    let a2 = a * a;
    let d = n_dot_h * n_dot_h * (a2 - 1.0) + 1.0;
    return a2 / (PI * d * d);
}

// Smith height-correlated visibility term, G / (4 n.l n.v).
fn v_smith(n_dot_v: f32, n_dot_l: f32, a: f32) -> f32 {
    let a2 = a * a;
    let gv = n_dot_l * sqrt(n_dot_v * n_dot_v * (1.0 - a2) + a2);
    let gl = n_dot_v * sqrt(n_dot_l * n_dot_l * (1.0 - a2) + a2);
    return 0.5 / max(gv + gl, 1e-7);
}

// Schlick's Fresnel with the grazing reflectance F90 tied to F0 (as Unreal does): no real
// material reflects under 2 % at normal incidence, so a smaller F0 means "no specular layer"
// and the lobe fades to zero, making specular = 0 a pure Lambertian surface at all angles.
fn f_schlick(f0: vec3<f32>, v_dot_h: f32) -> vec3<f32> {
    let f = pow(1.0 - v_dot_h, 5.0);
    return f0 + (vec3<f32>(f90_of(f0)) - f0) * f;
}

fn f90_of(f0: vec3<f32>) -> f32 {
    return clamp(50.0 * max(f0.r, max(f0.g, f0.b)), 0.0, 1.0);
}

// The specular lobe's directional albedo from the table's (a, b) at the view's (n.v,
// roughness) (voxgi::brdf::specular_albedo): Schlick's Fresnel splits it as f0 a + f90 b.
fn specular_albedo(f0: vec3<f32>, ab: vec2<f32>) -> vec3<f32> {
    return f0 * ab.x + vec3<f32>(f90_of(f0) * ab.y);
}

fn brdf_diffuse(s: Surface) -> vec3<f32> {
    return s.albedo * (1.0 - s.metallic) / PI;
}

// GGX specular BRDF value for light direction l and view direction v (both unit, pointing away
// from the surface). `alpha_scale` widens the lobe's normalisation for area lights.
fn brdf_specular(s: Surface, n: vec3<f32>, v: vec3<f32>, l: vec3<f32>) -> vec3<f32> {
    let h = normalize(v + l);
    let n_dot_l = max(dot(n, l), 0.0);
    let n_dot_v = max(dot(n, v), 1e-4);
    let a = ggx_alpha(s.roughness);
    return d_ggx(max(dot(n, h), 0.0), a) * v_smith(n_dot_v, n_dot_l, a)
        * f_schlick(f0_of(s), max(dot(v, h), 0.0));
}

// An orthonormal frame whose third column is n (Duff et al. 2017, "Building an Orthonormal
// Basis, Revisited"): branchless.
fn tangent_frame(n: vec3<f32>) -> mat3x3<f32> {
    let s = select(-1.0, 1.0, n.z >= 0.0);
    let a = -1.0 / (s + n.z);
    let b = n.x * n.y * a;
    let t = vec3<f32>(1.0 + s * n.x * n.x * a, s * b, -s * n.x);
    let bt = vec3<f32>(b, s + n.y * n.y * a, -n.y);
    return mat3x3<f32>(t, bt, n);
}

// GGX visible-normal sampling by spherical caps (Dupuy & Benyoub 2023), in the tangent frame.
fn sample_vndf(v: vec3<f32>, a: f32, u: vec2<f32>) -> vec3<f32> {
    let vh = normalize(vec3<f32>(a * v.x, a * v.y, v.z));
    let phi = 2.0 * PI * u.x;
    let z = (1.0 - u.y) * (1.0 + vh.z) - vh.z;
    let sin_t = sqrt(clamp(1.0 - z * z, 0.0, 1.0));
    let c = vec3<f32>(sin_t * cos(phi), sin_t * sin(phi), z);
    let h = c + vh;
    return normalize(vec3<f32>(a * h.x, a * h.y, max(h.z, 1e-6)));
}
