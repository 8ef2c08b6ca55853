// tonemap: exposure, a tone curve and the output encoding, from the HDR target into the
// caller's target. A fullscreen triangle, so any renderable format works: sRGB formats encode
// in the blending unit, 8-bit linear ones get the sRGB curve here (ENCODE_SRGB), float ones get
// the tone-mapped linear values.

//!include shared/globals.wgsl

@group(2) @binding(0) var hdr: texture_2d<f32>;

// True for an 8-bit target without an sRGB view: the shader applies the sRGB curve itself.
override ENCODE_SRGB: bool = false;

@vertex
fn vs_main(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    // One triangle covering the screen: (-1,-1), (3,-1), (-1,3).
    let uv = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u));
    return vec4<f32>(uv * 2.0 - 1.0, 0.0, 1.0);
}

// Narkowicz's fit of the ACES reference rendering transform.
fn aces(x: vec3<f32>) -> vec3<f32> {
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

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let c = max(textureLoad(hdr, vec2<u32>(pos.xy), 0).rgb * frame.exposure, vec3<f32>(0.0));
    var t: vec3<f32>;
    switch frame.tonemap {
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
    t = clamp(t, vec3<f32>(0.0), vec3<f32>(1.0));
    if ENCODE_SRGB {
        t = srgb_encode(t);
    }
    return vec4<f32>(t, 1.0);
}
