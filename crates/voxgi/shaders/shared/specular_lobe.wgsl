// What a leaf reflects specularly of the lights: its lobe (`specular_bounces`). inject writes it
// beside the leaf's direct light (leaf_direct[2i + 1]); the levels above the finest keep it
// (voxels/<kind>/ filters) in two more blocks ("The lobe chain" below), its wide share folded
// into the six directions at the first level (`lobe_radiance`), so a cone that looks at a lit
// metal from where its reflection goes sees the light it reflects. The finest level stays
// isotropic: cones that read it (the nearest samples of narrow cones) see no lobe.
//
// A lobe is one vec4: the specular radiant exitance M (rgb, W/m^2: the lights' irradiance
// times the lobe's directional albedo), and in w an integer below 2^24 (exact in f32): the lobe's mean direction
// octahedrally in nine bits a coordinate, and in six bits how widely it spreads (`t`, 0: a
// mirror's beam, 1: as wide as a Lambertian surface's light).

//!include shared/fragment.wgsl

struct Lobe {
    // Specular radiant exitance.
    m: vec3<f32>,
    // Mean reflected direction (unit).
    dir: vec3<f32>,
    // Spread: 0 narrow ... 1 cosine-wide.
    t: f32,
}

fn pack_lobe(m: vec3<f32>, dir: vec3<f32>, t: f32) -> vec4<f32> {
    let e = vec2<u32>(round((oct_encode(dir) * 0.5 + 0.5) * 511.0));
    let q = u32(round(clamp(t, 0.0, 1.0) * 63.0));
    return vec4<f32>(m, f32(e.x | (e.y << 9u) | (q << 18u)));
}

fn unpack_lobe(v: vec4<f32>) -> Lobe {
    let w = u32(v.w);
    let e = vec2<f32>(vec2<u32>(w & 511u, (w >> 9u) & 511u)) / 511.0 * 2.0 - 1.0;
    return Lobe(v.rgb, oct_decode(e), f32(w >> 18u) / 63.0);
}

// The radiance a cone travelling along direction block `block` (+X, -X, +Y, -Y, +Z, -Z: the
// chains' order) reads of a leaf with lobe `lobe` and normal `n`, opacity aside, the lobe
// folded into the six directions (the filters fold a lobe's wide share this way; folding the
// whole lobe lit what lies beside a narrow one's reflection, docs/QUALITY.md).
//
// A cone travelling d weighs the blocks of d's signs by d's squared cosines, and sees the light
// leaving towards -d. So a narrow lobe about R goes to the blocks of -R's signs, each with R's
// squared cosine on its axis (P_b, summing to 1); a wide one (t = 1) spreads over the
// hemisphere as a Lambertian surface's light does. Each block's share is divided by what a
// block gathers of a surface's exitance across the hemisphere the cosine weighs, I_b = the
// integral of the squared cosine on its axis times the cosine to the normal over the
// directions it serves: pi/2 for the block facing along the normal, pi/8 across it, 0 behind
// it; the quadratic (pi/8)(1 + c)^2 in the cosine c between the block's outgoing axis and the
// normal takes these three values. Summed over the blocks the reflected exitance comes back
// whole (sum P_b = 1), as a Lambertian surface's radiance M/pi does (sum I_b = pi).
fn lobe_radiance(lobe: Lobe, n: vec3<f32>, block: u32) -> vec3<f32> {
    let axis = block / 2u;
    // The direction a cone of this block sees light leave in: against the block's own.
    let out_sign = select(1.0, -1.0, (block & 1u) == 0u);
    let c = out_sign * n[axis];
    let gathers = 0.39269908 * (1.0 + c) * (1.0 + c);
    let r = lobe.dir[axis];
    let narrow = select(0.0, r * r, r * out_sign > 0.0);
    let wide = gathers * 0.31830989;
    // (Floored: a narrow lobe grazing the surface still leaves by a block across it.)
    return lobe.m * mix(narrow, wide, lobe.t) / max(gathers, 0.1);
}

// --- The lobe chain: two more blocks in every level above the finest keep the lobes'
// moments, averaged like the isotropic chain, and a cone evaluates them towards itself, so a
// narrow lobe keeps its direction at every level instead of spreading over the six blocks.
//
// Block 6: the coverage-weighted exitance and the coverage (a M, a); block 7: the
// luminance-weighted direction, each leaf's as long as its lobe's mean cosine (a |M| rbar d,
// a |M|). Means of these are the merged lobe's: the exitance per covered area M = rgb / a, and
// a von Mises-Fisher lobe whose mean cosine is the summed direction's length over its weight
// (Toksvig's and Banerjee's estimates): lobes that disagree merge into a wider one.

// A leaf's lobe splits by its spread t: the share t leaves as a Lambertian surface's light does
// (folded into the six directions, `lobe_radiance` with t = 1), the share 1 - t keeps its
// direction in the chain as a vMF of concentration 1 / t (its solid angle, 2 pi t, kept; t is
// stored in 63 steps, the narrowest counts as half a step). The chain holds radiance per covered
// area: a surface seen at angle theta covers 1 / cos theta of the area it fills across the
// cone, so the narrow share's exitance is divided by the cosine between its direction and the
// normal (at most tenfold: a lobe grazing its surface).
fn lobe_kappa(t: f32) -> f32 {
    return 1.0 / max(t, 0.5 / 63.0);
}

fn narrow_share(lobe: Lobe, n: vec3<f32>) -> Lobe {
    let c = max(dot(n, lobe.dir), 0.1);
    return Lobe(lobe.m * (1.0 - lobe.t) / c, lobe.dir, lobe.t);
}

fn wide_share(lobe: Lobe) -> Lobe {
    return Lobe(lobe.m * lobe.t, lobe.dir, 1.0);
}

// The lobe chain's two blocks after the six directions' (block index in a level's texture):
// the exitance moments (coverage-weighted exitance, coverage) and the direction moments
// (luminance-weighted mean direction, luminance).
const LOBE_EXITANCE: u32 = 6u;
const LOBE_DIRECTION: u32 = 7u;

// A leaf without a lobe that faces a light (in a shadow, or not a metal): in the chain its
// coverage dilutes the lobes beside it, whose exitance is per covered area. A leaf that faces
// away from every light has no lobe either, but does not dilute: it is the far face of a lit
// slab or wall, hidden behind the lit face from where that face's lobe sends its light (the two
// faces of a floor thinner than two voxels share the chain's first level, and the far face
// halved the metal floor's reflection, docs/QUALITY.md).
const NO_LOBE_FACING: vec4<f32> = vec4<f32>(0.0, 0.0, 0.0, 1.0);

// Whether a leaf's packed lobe (or its absence) counts in the chain's coverage.
fn lobe_covers(packed: vec4<f32>) -> bool {
    return packed.w > 0.0;
}

// The two moment blocks of one leaf of opacity `a` (LOBE_EXITANCE or LOBE_DIRECTION).
fn lobe_moments(lobe: Lobe, a: f32, block: u32) -> vec4<f32> {
    let w = a * dot(lobe.m, vec3<f32>(0.2126, 0.7152, 0.0722));
    if block == LOBE_EXITANCE {
        return vec4<f32>(a * lobe.m, a);
    }
    let k = lobe_kappa(lobe.t);
    // The vMF's mean cosine, coth k - 1/k (1 - 1/k within f32 for k > 9).
    let rbar = select(1.0 / tanh(k) - 1.0 / k, 1.0 - 1.0 / k, k > 9.0);
    return vec4<f32>(w * rbar * lobe.dir, w);
}

// A cone of half-angle tangent `tan_half` as a vMF: its solid angle, 2 pi (1 - cos), is the
// lobe's 2 pi / kappa.
fn cone_kappa(tan_half: f32) -> f32 {
    let c = inverseSqrt(1.0 + tan_half * tan_half);
    return (1.0 + c) / max(tan_half * tan_half * c * c, 1e-8);
}

// The radiance the merged lobe of moments `m` (block 6) and `v` (block 7) sends towards `out`
// as a cone of concentration `cone` sees it: the lobe convolved with the cone (two vMFs'
// concentrations combine as k1 k2 / (k1 + k2)), times the exitance per covered area. A
// lobe's radiance M D(out) meets a Lambertian surface's M / pi where it looks along the normal.
fn lobe_light(m: vec4<f32>, v: vec4<f32>, out: vec3<f32>, cone: f32) -> vec3<f32> {
    if m.a <= 1e-6 || v.w <= 1e-8 {
        return vec3<f32>(0.0);
    }
    let len = length(v.xyz);
    let rbar = min(len / v.w, 0.999);
    let lobe = rbar * (3.0 - rbar * rbar) / (1.0 - rbar * rbar);
    let k = max(lobe * cone / (lobe + cone), 1e-3);
    let axis = v.xyz / max(len, 1e-8);
    let d = k / (6.28318531 * (1.0 - exp(-2.0 * k))) * exp(k * (dot(axis, out) - 1.0));
    return max(m.rgb, vec3<f32>(0.0)) / m.a * d;
}

// What a sample of the lobe chain with moments `m` and `v` sends back along a cone travelling
// `dir`, as the cone being traced (`cone_tan_half`) sees it. The cone counts as half its
// half-angle wide: a sample already merges the lobes of every point its footprint covers,
// whose disagreement widens the merged lobe, and the cone's whole aperture counted again on
// top spread the light a metal floor reflects onto a wall over directions that miss it (a
// third of it lost); narrower still, the reflection breaks into the texels' blocks
// (docs/QUALITY.md, "Specular light in the bounces").
fn chain_lobe_light(m: vec4<f32>, v: vec4<f32>, dir: vec3<f32>) -> vec3<f32> {
    return lobe_light(m, v, -dir, cone_kappa(0.5 * cone_tan_half));
}
