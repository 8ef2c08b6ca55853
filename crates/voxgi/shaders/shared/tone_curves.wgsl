// The tone curves and the sRGB encoding, shared by the tonemap pass and the path tracer's
// display so that both images of a split view are mapped alike. Mirrors output.rs's CPU
// versions.

// Narkowicz's fit of the ACES reference rendering transform. Its quadratics overflow f32 past
// about 1e19 (infinity over infinity: NaN, a black or coloured pixel); it is 1 long before 1e4.
fn aces(x_in: vec3<f32>) -> vec3<f32> {
    let x = min(x_in, vec3<f32>(1e4));
    return clamp((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14), vec3<f32>(0.0), vec3<f32>(1.0));
}

// Khronos PBR Neutral: keeps base colours exact up to 0.76 and compresses highlights.
fn pbr_neutral(c_in: vec3<f32>) -> vec3<f32> {
    let start = 0.8 - 0.04;
    let desaturation = 0.15;
    let x = min(c_in.r, min(c_in.g, c_in.b));
    let offset = select(0.04, x - 6.25 * x * x, x < 0.08);
    var c = c_in - offset;
    let peak = max(c.r, max(c.g, c.b));
    if peak < start {
        return c;
    }
    let d = 1.0 - start;
    let new_peak = 1.0 - d * d / (peak + d - start);
    c *= new_peak / peak;
    let g = 1.0 - 1.0 / (desaturation * (peak - new_peak) + 1.0);
    return mix(c, vec3<f32>(new_peak), g);
}

fn srgb_encode(c: vec3<f32>) -> vec3<f32> {
    let lo = c * 12.92;
    let hi = 1.055 * pow(c, vec3<f32>(1.0 / 2.4)) - 0.055;
    return select(hi, lo, c <= vec3<f32>(0.0031308));
}

// `c` (exposed, non-negative) through curve `id` (TONEMAP_* in shared/scene.wgsl), clamped to
// [0, 1].
fn tone_curve(c: vec3<f32>, id: u32) -> vec3<f32> {
    var t: vec3<f32>;
    switch id {
        case TONEMAP_ACES: {
            t = aces(c);
        }
        case TONEMAP_NEUTRAL: {
            t = pbr_neutral(c);
        }
        default: {
            t = c;
        }
    }
    return clamp(t, vec3<f32>(0.0), vec3<f32>(1.0));
}
