// tonemap: exposure, a filmic curve and the sRGB encoding, HDR target -> 8-bit image.

//!include shared/scene.wgsl

@group(0) @binding(0) var<uniform> frame: Frame;
@group(0) @binding(1) var hdr: texture_2d<f32>;
@group(0) @binding(2) var ldr: texture_storage_2d<rgba8unorm, write>;

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

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if f32(id.x) >= frame.size.x || f32(id.y) >= frame.size.y {
        return;
    }
    let c = max(textureLoad(hdr, id.xy, 0).rgb * frame.exposure, vec3<f32>(0.0));
    var t: vec3<f32>;
    switch frame.tonemap {
        case 0u: {
            t = aces(c);
        }
        case 1u: {
            t = pbr_neutral(c);
        }
        default: {
            t = c;
        }
    }
    textureStore(ldr, id.xy, vec4<f32>(srgb_encode(clamp(t, vec3<f32>(0.0), vec3<f32>(1.0))), 1.0));
}
