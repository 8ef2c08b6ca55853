// moments: the VSM/ESM shadow filter's prefilter (Salm, §4.2: "pre-filtered with a 5x5 taps
// disk shaped kernel"). For every texel of a rectangle of one shadow map: the mean over the
// 21 texels of the 5x5 disc around it of the occluder distance normalised by the view's far
// plane, of its square (the variance map), and of exp(ESM_C (d - 1)) (the exponential map,
// kept at or below 1). shared/lights.wgsl's `moments_visibility` reads them.

@group(0) @binding(0) var distances: texture_2d_array<f32>;
@group(0) @binding(1) var moments_out: texture_storage_2d_array<rgba32float, write>;
@group(0) @binding(2) var<uniform> rect: MomentRect;

struct MomentRect {
    // Texels from min (inclusive) to max (exclusive), already grown by the disc's radius.
    min: vec2<u32>,
    max: vec2<u32>,
    layer: u32,
    // The view's far plane: distances are stored over it, in [0, 1].
    far: f32,
    _pad: vec2<u32>,
}

// Must match shared/lights.wgsl's.
const ESM_C: f32 = 80.0;

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let t = rect.min + gid.xy;
    if any(t >= rect.max) {
        return;
    }
    let r = i32(textureDimensions(distances).x);
    var sum = vec3<f32>(0.0);
    var n = 0.0;
    for (var y = -2; y <= 2; y++) {
        for (var x = -2; x <= 2; x++) {
            // The disc: the 5x5 square without its corners.
            if x * x + y * y > 5 {
                continue;
            }
            let c = clamp(vec2<i32>(t) + vec2<i32>(x, y), vec2<i32>(0), vec2<i32>(r - 1));
            // "Nothing seen" (3e38) is the far plane.
            let d = clamp(textureLoad(distances, c, i32(rect.layer), 0).r / rect.far, 0.0, 1.0);
            sum += vec3<f32>(d, d * d, exp(ESM_C * (d - 1.0)));
            n += 1.0;
        }
    }
    textureStore(moments_out, t, rect.layer, vec4<f32>(sum / n, 0.0));
}
