//!include shared/brdf.wgsl

//!include voxels/sample.wgsl

// Cone tracing, written once against the voxel contract (voxels/<kind>/sample.wgsl):
// WIDE_SAMPLE, voxels_voxel_size, voxels_voxel_size_at, voxels_contains, sample_depth,
// sample_depth_wide and sample_voxels, and nothing else of the structure. The including shader
// declares `cones`.
//
// Every trace takes `vs`, the voxel edge it starts at (the first sample's size, the origin's
// offset, the self-clearance's unit): the finest voxels the structure holds where the cone
// starts (`voxels_voxel_size_at`, for a pixel), or the leaf's own (for a bounce from it). A
// structure with one finest size (dense, octree) gives the same everywhere; clipmap levels
// are coarser away from the camera, and a cone from a coarse leaf must clear its own voxel.

// The filter size of a cone sample at distance t from a surface (normal n). A surface can
// neither occlude nor light itself, so a sample must not read the voxels of its cone's own
// surface: those reach up to a voxel above the surface's plane (conservative voxelization
// marks both sides of a plane on a voxel boundary). A sample of diameter ds reads texels up to
// 2 ds wide (the level nearest its size, trilinear), and such a texel touches everything within 1.5 of
// its widths below the sample: so ds <= (h - 1 voxel) / 3 at height h above the plane. Only
// the cone's own surface is cleared this way; occluders in front are still seen (at a finer
// level than the cone's width would pick).
const SELF_CLEARANCE: f32 = 3.0;

fn cone_sample_size(origin: vec3<f32>, n: vec3<f32>, p: vec3<f32>, d: f32, vs: f32) -> f32 {
    let h = dot(p - origin, n) + vs * cones.origin_offset;
    return clamp((h - vs) / SELF_CLEARANCE, vs, d);
}

fn outside_volume(p: vec3<f32>) -> bool {
    return !voxels_contains(p);
}

// A narrowed sample covers less: step no further than its filter reaches, so thin walls are
// not stepped over.
fn cone_step(d: f32, ds: f32, vs: f32) -> f32 {
    return max(min(d * cones.step_factor, ds), vs * 0.25);
}

// Opacity a of a sample of size ds, corrected for a step of length `step`.
fn step_opacity(a: f32, step: f32, ds: f32) -> f32 {
    return 1.0 - pow(1.0 - a, step / ds);
}

// Which part of its footprint a cone traces: one of the four quarters (0..3), or the whole.
const WHOLE_FOOTPRINT: u32 = 4u;
// A quarter's samples, as a fraction of the footprint's diameter: a disc of diameter 0.35
// about a quarter's centre (a quarter diameter off the axis on both cross axes) covers the
// quarter about as a whole-footprint sample covers the footprint.
const QUARTER_WIDTH: f32 = 0.35;

// Front-to-back accumulation of one cone. Returns premultiplied radiance (rgb) and opacity (a).
// Each step is `step_factor` cone diameters long; a sample's opacity is corrected for the step
// length d' against the voxel size d of its level: alpha' = 1 - (1 - alpha)^(d'/d), which in
// optical depth is 1 - e^(-sigma d'/d).
//
// Compositing takes each sample's opacity as independent of the last, which holds for a
// sample filled evenly (a medium), not for one a surface covers in part: the rays that a
// block's back face stops behind the front face that covered the same part of an earlier
// sample are stopped twice, and a cone beside an edge loses far more light than the rays
// within it (measured cone by cone against the path tracer: docs/QUALITY.md). A narrower
// sample is more nearly all or nothing, so `part` < WHOLE_FOOTPRINT traces one quarter of
// the footprint with samples QUARTER_WIDTH wide and as long: its transmittance follows the
// rays of that quarter, and the mean of the four quarters (over the pixels of a block, the
// voxels about a leaf, the frames) is the footprint's. Narrowing every sample instead lets
// light through a one-voxel wall; the quarters' samples still overlap along the cone, so they
// do not. A quarter stops where its own samples leave the volume, not its axis: a quarter
// still inside a wall on the bounds that the axis has crossed has yet to meet the wall.
fn trace_cone(origin: vec3<f32>, n: vec3<f32>, dir: vec3<f32>, tan_half: f32, max_dist: f32, vs: f32, part: u32) -> vec4<f32> {
    var acc = vec4<f32>(0.0);
    var t = vs;
    cone_tan_half = tan_half;
    var off = vec3<f32>(0.0);
    var width = 1.0;
    if part < WHOLE_FOOTPRINT {
        let up = select(vec3<f32>(0.0, 1.0, 0.0), vec3<f32>(1.0, 0.0, 0.0), abs(dir.y) > 0.9);
        let u = normalize(cross(dir, up));
        let v = cross(dir, u);
        off = (u * (f32(part & 1u) - 0.5) + v * (f32(part >> 1u) - 0.5)) * 0.5;
        width = QUARTER_WIDTH;
        // Its samples are a quarter cone's: the lobes' light is seen through that narrower
        // aperture (shared/specular_lobe.wgsl, `chain_lobe_light`).
        cone_tan_half = tan_half * QUARTER_WIDTH;
    }
    // Two loops: samples widen monotonically along a cone that leaves its surface, and once
    // they are WIDE_SAMPLE voxels across they no longer read the finest level (a quarter of the
    // fetches per step).
    for (var i = 0u; i < 1024u; i++) {
        let d = max(vs, 2.0 * tan_half * t);
        let ds = cone_sample_size(origin, n, origin + dir * t, d, vs);
        let p = origin + dir * t + off * ds;
        let w = max(ds * width, vs);
        if t >= max_dist || acc.a >= 0.995 || outside_volume(p) || w >= WIDE_SAMPLE * vs {
            break;
        }
        let step = cone_step(d, w, vs);
        acc = composite_sample(acc, sample_depth(p, w, dir), step / w);
        t += step;
    }
    for (var i = 0u; i < 1024u; i++) {
        let d = max(vs, 2.0 * tan_half * t);
        let ds = cone_sample_size(origin, n, origin + dir * t, d, vs);
        let p = origin + dir * t + off * ds;
        // The volume is convex: a cone that has left it meets nothing more.
        if t >= max_dist || acc.a >= 0.995 || outside_volume(p) {
            break;
        }
        let w = max(ds * width, vs);
        let step = cone_step(d, w, vs);
        acc = composite_sample(acc, sample_depth_wide(p, w, dir), step / w);
        t += step;
    }
    return acc;
}

// The quarter (trace_cone's `part`) that cone i traces at a point of interleaving rank
// `rank` (0..15), turned by `shift` (frames): every cone meets each quarter equally often
// over the sixteen ranks and within each half of them (the two parities trace the two halves
// of the ring, shared/interleave.wgsl), and not always at the same place in its cell (ranks
// 2m and 2m + 1 place it at azimuth m and zenith m's 3-bit reversal, the gather's Hammersley
// set): bit 0 follows the azimuth's middle bit, bit 1 whether azimuth and zenith lie in the
// same half of the cell.
fn cone_quarter(rank: u32, i: u32, shift: u32) -> u32 {
    let m = rank >> 1u;
    let q = ((m >> 1u) & 1u) | ((((m & 1u) ^ (m >> 2u)) & 1u) << 1u);
    return (q + i + shift) & 3u;
}

// Front-to-back compositing of a sample of optical depth (L sigma, sigma) per sample diameter
// over `k` diameters: opacity 1 - e^(-sigma k), premultiplied radiance L times that.
fn composite_sample(acc: vec4<f32>, s: vec4<f32>, k: f32) -> vec4<f32> {
    // At most the depth of opacity 0.9999, as the opacity form clamped.
    let sigma = clamp(s.a, 0.0, 9.2);
    let a = 1.0 - exp(-sigma * k);
    return acc + (1.0 - acc.a) * vec4<f32>(s.rgb * (a / max(sigma, 1e-6)), a);
}

// Ambient occlusion along one cone: opacity weighted by 1/(1 + lambda r), up to ao_radius.
fn trace_ao(origin: vec3<f32>, n: vec3<f32>, dir: vec3<f32>, tan_half: f32, vs: f32) -> f32 {
    var occ = 0.0;
    var t = vs;
    for (var i = 0u; i < 256u; i++) {
        let p = origin + dir * t;
        if t >= cones.ao_radius || occ >= 0.995 || outside_volume(p) {
            break;
        }
        let d = max(vs, 2.0 * tan_half * t);
        let ds = cone_sample_size(origin, n, p, d, vs);
        let s = sample_voxels(p, ds, dir);
        let step = cone_step(d, ds, vs);
        let ca = step_opacity(clamp(s.a, 0.0, 0.9999), step, ds);
        occ += (1.0 - occ) * ca / (1.0 + cones.ao_lambda * t);
        t += step;
    }
    return occ;
}

struct Gathered {
    // Irradiance from the cones, W/m^2.
    irradiance: vec3<f32>,
    // Cosine-weighted visibility in [0, 1].
    ao: f32,
}

// The diffuse bundle partitions the hemisphere into cells: the normal's cone a cap, each cone
// of the ring a sector of the band below it, each weighted by its cell's share of the
// cosine-weighted hemisphere (`cones.dirs[i].w`; the cap's share is sin² of its rim's zenith
// angle, so the cap ends where sin² reaches the normal cone's weight).
//
// Near their surface the cones are far narrower than their aperture (cone_sample_size keeps a
// sample's filter off the cone's own surface), so a cone measures the light about its axis,
// not the mean over its cell: traced along fixed axes (the ring at 60 degrees) with the
// cells' weights, the sum was 20-25 % off the path tracer's irradiance wherever the light
// differs across a cell (beside the Cornell box's open front: `voxgi probe`). So each cone's
// axis is drawn from its cell, cosine-weighted, by `turn` in [0, 1)^2: x turns the sectors
// about the normal (a fraction of the ring's period; the cap's azimuth goes once round), y
// places the zenith within the cell (uniform in sin², the cosine-weighted measure). Pixels of
// a 4x4 block and frames draw different turns, so their mean is each cell's cosine-weighted
// mean, as the weights assume.
//
// Directions within 12 degrees of the horizon are traced at 78 degrees: a cone that grazes
// its own plane steps a voxel at a time (4.3 % of the cosine-weighted hemisphere lies there).
const GRAZING_SIN2: f32 = 0.9568;
// The cosine of that zenith angle, sqrt(1 - GRAZING_SIN2).
const GRAZING_COS: f32 = 0.2079;

// Cone i of the diffuse bundle at `turn` (`frame`: tangent space to world): its direction
// (xyz) and its weight (w).
fn diffuse_cone(frame: mat3x3<f32>, turn: vec2<f32>, i: u32) -> vec4<f32> {
    let cap = cones.dirs[0].w;
    let ring = max(cones.count, 2u) - 1u;
    var u = turn.y * cap;
    var phi = turn.x * 2.0 * PI;
    if i > 0u {
        u = cap + turn.y * (1.0 - cap);
        phi = atan2(cones.dirs[i].y, cones.dirs[i].x) + turn.x * 2.0 * PI / f32(ring);
    }
    u = min(u, GRAZING_SIN2);
    let s = sqrt(u);
    let d = frame * vec3<f32>(s * cos(phi), s * sin(phi), sqrt(1.0 - u));
    return vec4<f32>(normalize(d), cones.dirs[i].w);
}

const ALL_CONES: u32 = 2u;

// Irradiance at a surface point from the diffuse cones, the bundle drawn at `turn`
// (diffuse_cone).
// `half` = ALL_CONES traces every cone. `half` = 0 or 1 traces the normal's cone and every
// other cone of the ring at twice its weight: pixels of even and odd Bayer rank trace the two
// halves, and the reconstruction's 4x4 average sees every cone at eight turns spread over its
// cell (the gather gives each parity a Hammersley set of its own), so the estimate keeps its
// mean at about 60 % of the cost.
//
// With `cones.quarters` each cone traces one quarter of its footprint (trace_cone),
// cone_quarter(rank, i, shift); without, the whole.
fn gather_diffuse(p: vec3<f32>, n: vec3<f32>, turn: vec2<f32>, with_ao: bool, half: u32, vs: f32, rank: u32, shift: u32) -> Gathered {
    let frame = tangent_frame(n);
    let origin = p + n * vs * cones.origin_offset;
    var e = vec3<f32>(0.0);
    var occ = 0.0;
    // Neighbouring pixels trace different cones but the same number of them, so SIMD lanes
    // stay in step: the normal's cone, then every cone of the ring or every other one.
    let ring = cones.count - 1u;
    var n_cones = cones.count;
    if half != ALL_CONES {
        n_cones = 1u + (ring + 1u) / 2u;
    }
    for (var k = 0u; k < n_cones; k++) {
        var i = k;
        var w_scale = 1.0;
        if half != ALL_CONES && k > 0u {
            i = 2u * k - 1u + half;
            w_scale = 2.0;
        }
        if i >= cones.count {
            continue;
        }
        let c = diffuse_cone(frame, turn, i);
        let w = c.w * w_scale;
        let d = c.xyz;
        if cones.indirect != 0u {
            let part = select(WHOLE_FOOTPRINT, cone_quarter(rank, i, shift), cones.quarters != 0u);
            let r = trace_cone(origin, n, d, cones.diffuse_tan, cones.max_distance, vs, part);
            // Weights are fractions of the cosine-weighted hemisphere, whose integral is pi.
            e += PI * w * r.rgb;
        }
        if with_ao {
            occ += w * trace_ao(origin, n, d, cones.diffuse_tan, vs);
        }
    }
    return Gathered(e, 1.0 - occ);
}
