// upsample, stage one of two: at the gather's resolution, each sample averages the 5x5 window
// of gather samples centred on it with a tent's weights (its rim half, its corners a quarter),
// weighted by depth and normal similarity. The tent is the mean of the four 4x4 windows
// around the sample, each of which holds all sixteen turns of the cone bundle once, so every
// turn weighs the same while light does not bleed across silhouettes and creases; a single
// 4x4 window is half a sample off-centre and shifts the light towards it. The composite
// upsamples the result to full resolution (shared/upsample.wgsl).

//!include shared/globals.wgsl
//!include shared/half.wgsl
//!include shared/interleave.wgsl
//!include shared/upsample.wgsl

@group(2) @binding(0) var low: texture_2d<f32>;
// Each gather sample's normal (rgb) and distance to the camera (a, 0 for background).
@group(2) @binding(1) var guide: texture_2d<f32>;
@group(2) @binding(2) var filtered: texture_storage_2d<rgba16float, write>;

// No branch or indexed local array in the loop: CPU drivers run both sides of lane-divergent
// branches and spill indexed arrays to memory.
@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let low_size = textureDimensions(low);
    if any(gid.xy >= low_size) {
        return;
    }
    let g0 = textureLoad(guide, gid.xy, 0);
    if g0.a <= 0.0 {
        textureStore(filtered, gid.xy, vec4<f32>(0.0, 0.0, 0.0, 1.0));
        return;
    }
    // The window moves inside the image rather than clamping, so it always holds all sixteen
    // turns and both halves of the cone set.
    let base = clamp(vec2<i32>(gid.xy) - 2, vec2<i32>(0), max(vec2<i32>(low_size) - 5, vec2<i32>(0)));
    // Even and odd Bayer ranks traced different halves of the cones: average each half on its
    // own, then the two, so rejected neighbours at edges cannot tip the balance.
    var sum0 = vec4<f32>(0.0);
    var sum1 = vec4<f32>(0.0);
    var w0 = 0.0;
    var w1 = 0.0;
    for (var i = 0; i < 25; i++) {
        let o = vec2<i32>(i % 5, i / 5);
        let c = min(base + o, vec2<i32>(low_size) - 1);
        let rim = select(vec2<f32>(1.0), vec2<f32>(0.5), (o == vec2<i32>(0)) | (o == vec2<i32>(4)));
        let w = rim.x * rim.y * edge_weight(textureLoad(guide, c, 0), g0.xyz, g0.a);
        let k = f32(cone_half(vec2<u32>(c), frame.light_sample));
        let value = textureLoad(low, c, 0);
        sum0 += (w * (1.0 - k)) * value;
        sum1 += (w * k) * value;
        w0 += w * (1.0 - k);
        w1 += w * k;
    }
    var out: vec4<f32>;
    if w0 > 1e-5 && w1 > 1e-5 {
        out = 0.5 * (sum0 / w0 + sum1 / w1);
    } else {
        out = (sum0 + sum1) / max(w0 + w1, 1e-6);
    }
    textureStore(filtered, gid.xy, to_half(out));
}
