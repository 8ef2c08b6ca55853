//!include shared/brdf.wgsl

//!include voxels/sample.wgsl

// Cone tracing, written once against the voxel contract (voxels/<kind>/sample.wgsl):
// WIDE_SAMPLE, voxels_voxel_size, voxels_contains, sample_depth, sample_depth_wide and
// sample_voxels, and nothing else of the structure. The including shader declares `cones`.

// The filter size of a cone sample at distance t from a surface (normal n). A surface can
// neither occlude nor light itself, so a sample must not read the voxels of its cone's own
// surface: those reach up to a voxel above the surface's plane (conservative voxelization
// marks both sides of a plane on a voxel boundary). A sample of diameter ds reads texels up to
// 2 ds wide (trilinear between two levels), and such a texel touches everything within 1.5 of
// its widths below the sample: so ds <= (h - 1 voxel) / 3 at height h above the plane. Only
// the cone's own surface is cleared this way; occluders in front are still seen (at a finer
// level than the cone's width would pick).
const SELF_CLEARANCE: f32 = 3.0;

fn cone_sample_size(origin: vec3<f32>, n: vec3<f32>, p: vec3<f32>, d: f32) -> f32 {
    let h = dot(p - origin, n) + voxels_voxel_size() * cones.origin_offset;
    return clamp((h - voxels_voxel_size()) / SELF_CLEARANCE, voxels_voxel_size(), d);
}

fn outside_volume(p: vec3<f32>) -> bool {
    return !voxels_contains(p);
}

// A narrowed sample covers less: step no further than its filter reaches, so thin walls are
// not stepped over.
fn cone_step(d: f32, ds: f32) -> f32 {
    return max(min(d * cones.step_factor, ds), voxels_voxel_size() * 0.25);
}

// Opacity a of a sample of size ds, corrected for a step of length `step`.
fn step_opacity(a: f32, step: f32, ds: f32) -> f32 {
    return 1.0 - pow(1.0 - a, step / ds);
}

// Front-to-back accumulation of one cone. Returns premultiplied radiance (rgb) and opacity (a).
// Each step is `step_factor` cone diameters long; a sample's opacity is corrected for the step
// length d' against the voxel size d of its level: alpha' = 1 - (1 - alpha)^(d'/d), which in
// optical depth is 1 - e^(-sigma d'/d).
fn trace_cone(origin: vec3<f32>, n: vec3<f32>, dir: vec3<f32>, tan_half: f32, max_dist: f32) -> vec4<f32> {
    var acc = vec4<f32>(0.0);
    var t = voxels_voxel_size();
    // Two loops: samples widen monotonically along a cone that leaves its surface, and once
    // they are WIDE_SAMPLE voxels across they no longer read the finest level (a quarter of the
    // fetches per step; 8 % of the gather on lavapipe).
    for (var i = 0u; i < 512u; i++) {
        let p = origin + dir * t;
        let d = max(voxels_voxel_size(), 2.0 * tan_half * t);
        let ds = cone_sample_size(origin, n, p, d);
        if t >= max_dist || acc.a >= 0.995 || outside_volume(p) || ds >= WIDE_SAMPLE * voxels_voxel_size() {
            break;
        }
        let step = cone_step(d, ds);
        acc = composite_sample(acc, sample_depth(p, ds, dir), step / ds);
        t += step;
    }
    for (var i = 0u; i < 512u; i++) {
        let p = origin + dir * t;
        // The volume is convex: a cone that has left it meets nothing more.
        if t >= max_dist || acc.a >= 0.995 || outside_volume(p) {
            break;
        }
        let d = max(voxels_voxel_size(), 2.0 * tan_half * t);
        let ds = cone_sample_size(origin, n, p, d);
        let step = cone_step(d, ds);
        acc = composite_sample(acc, sample_depth_wide(p, ds, dir), step / ds);
        t += step;
    }
    return acc;
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
fn trace_ao(origin: vec3<f32>, n: vec3<f32>, dir: vec3<f32>, tan_half: f32) -> f32 {
    var occ = 0.0;
    var t = voxels_voxel_size();
    for (var i = 0u; i < 256u; i++) {
        let p = origin + dir * t;
        if t >= cones.ao_radius || occ >= 0.995 || outside_volume(p) {
            break;
        }
        let d = max(voxels_voxel_size(), 2.0 * tan_half * t);
        let ds = cone_sample_size(origin, n, p, d);
        let s = sample_voxels(p, ds, dir);
        let step = cone_step(d, ds);
        let ca = step_opacity(clamp(s.a, 0.0, 0.9999), step, ds);
        occ += (1.0 - occ) * ca / (1.0 + cones.ao_lambda * t);
        t += step;
    }
    return occ;
}

fn rotate_z(v: vec3<f32>, angle: f32) -> vec3<f32> {
    let c = cos(angle);
    let s = sin(angle);
    return vec3<f32>(c * v.x - s * v.y, s * v.x + c * v.y, v.z);
}

struct Gathered {
    // Irradiance from the cones, W/m^2.
    irradiance: vec3<f32>,
    // Cosine-weighted visibility in [0, 1].
    ao: f32,
}

const ALL_CONES: u32 = 2u;

// Irradiance at a surface point from the diffuse cones, the bundle rotated by `angle` about n.
// `half` = ALL_CONES traces every cone. `half` = 0 or 1 traces the normal's cone and every
// other cone of the ring at twice its weight: pixels of even and odd Bayer rank trace the two
// halves, and the reconstruction's 4x4 average sees every cone in eight rotations spread over
// the period, so the estimate is unbiased at about 60 % of the cost.
fn gather_diffuse(p: vec3<f32>, n: vec3<f32>, angle: f32, with_ao: bool, half: u32) -> Gathered {
    let frame = tangent_frame(n);
    let origin = p + n * voxels_voxel_size() * cones.origin_offset;
    var e = vec3<f32>(0.0);
    var occ = 0.0;
    // Neighbouring pixels trace different cones but the same number of them, so SIMD lanes
    // stay in step: the normal's cone, then every cone of the ring or every other one.
    let ring = cones.count - 1u;
    var n_cones = cones.count;
    if half != ALL_CONES {
        n_cones = 1u + (ring + 1u) / 2u;
    }
    // The normal's cone is tilted by two thirds of its aperture (about the cosine-weighted mean
    // angle of its cell) towards an azimuth that goes once round as the ring's angle covers
    // its period: the sixteen pixels of a 4x4 block spread it over its cell. Untilted, every
    // pixel of a plane traced the same direction, and a sample narrowed near its own surface
    // imaged what lies straight ahead like a pinhole (a sharp bright patch on the Cornell
    // box's ceiling above the tall block).
    let az = angle * f32(max(ring, 1u));
    let tilt = (2.0 / 3.0) * atan(cones.diffuse_tan);
    let tilted = vec3<f32>(sin(tilt) * cos(az), sin(tilt) * sin(az), cos(tilt));
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
        let w = cones.dirs[i].w * w_scale;
        let d = normalize(frame * select(rotate_z(cones.dirs[i].xyz, angle), tilted, i == 0u));
        if cones.indirect != 0u {
            let r = trace_cone(origin, n, d, cones.diffuse_tan, cones.max_distance);
            // Weights are fractions of the cosine-weighted hemisphere, whose integral is pi.
            e += PI * w * r.rgb;
        }
        if with_ao {
            occ += w * trace_ao(origin, n, d, cones.diffuse_tan);
        }
    }
    return Gathered(e, 1.0 - occ);
}
