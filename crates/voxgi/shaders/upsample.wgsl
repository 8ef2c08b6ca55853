// upsample: the gather's output (full or half resolution, one bundle rotation per pixel of each
// 4x4 block) to full-resolution indirect light. Each pixel averages the 4x4 window of gather
// samples around it, weighted by depth and normal similarity, so it receives all sixteen bundle
// rotations while light does not bleed across silhouettes and creases.

//!include shared/scene.wgsl

@group(0) @binding(0) var<uniform> frame: Frame;
@group(0) @binding(1) var low: texture_2d<f32>;
@group(0) @binding(2) var gb_normal: texture_2d<f32>;
@group(0) @binding(3) var gb_depth: texture_depth_2d;
@group(0) @binding(4) var full: texture_storage_2d<rgba16float, write>;

// The gather's cone half of a sample (the parity of its Bayer rank).
fn cone_half(p: vec2<u32>) -> u32 {
    let m = array<u32, 16>(0u, 8u, 2u, 10u, 12u, 4u, 14u, 6u, 3u, 11u, 1u, 9u, 15u, 7u, 13u, 5u);
    return m[(p.y & 3u) * 4u + (p.x & 3u)] & 1u;
}

fn view_depth(px: vec2<u32>) -> f32 {
    let d = textureLoad(gb_depth, px, 0);
    let uv = (vec2<f32>(px) + 0.5) * frame.inv_size;
    let w = frame.inv_view_proj * vec4<f32>(uv.x * 2.0 - 1.0, 1.0 - uv.y * 2.0, d, 1.0);
    return length(w.xyz / w.w - frame.camera_pos);
}

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let size = vec2<u32>(frame.size);
    if any(gid.xy >= size) {
        return;
    }
    let low_size = textureDimensions(low);
    let scale = max(size.x / low_size.x, 1u);
    if textureLoad(gb_depth, gid.xy, 0) >= 1.0 {
        textureStore(full, gid.xy, vec4<f32>(0.0, 0.0, 0.0, 1.0));
        return;
    }
    let d0 = view_depth(gid.xy);
    let n0 = textureLoad(gb_normal, gid.xy, 0).xyz;
    // The window moves inside the image rather than clamping, so it always holds all sixteen
    // rotations and both halves of the cone set.
    let base = clamp(vec2<i32>(gid.xy / scale) - 1, vec2<i32>(0), max(vec2<i32>(low_size) - 4, vec2<i32>(0)));
    // Even and odd Bayer ranks traced different halves of the cones: average each half on its
    // own, then the two, so rejected neighbours at edges cannot tip the balance.
    var sum = array<vec4<f32>, 2>(vec4<f32>(0.0), vec4<f32>(0.0));
    var wsum = array<f32, 2>(0.0, 0.0);
    for (var i = 0; i < 16; i++) {
        let c = min(base + vec2<i32>(i & 3, i >> 2), vec2<i32>(low_size) - 1);
        let px = min(vec2<u32>(c) * scale, size - 1u);
        if textureLoad(gb_depth, px, 0) >= 1.0 {
            continue;
        }
        let d = view_depth(px);
        let n = textureLoad(gb_normal, px, 0).xyz;
        // Depth within 5 % and normals within ~30 degrees count fully; beyond, weights fall fast.
        let wd = exp(-abs(d - d0) / max(0.05 * d0, 1e-4));
        let wn = pow(max(dot(n, n0), 0.0), 8.0);
        let w = wd * wn + 1e-6;
        let k = cone_half(vec2<u32>(c));
        sum[k] += w * textureLoad(low, c, 0);
        wsum[k] += w;
    }
    var out: vec4<f32>;
    if wsum[0] > 1e-5 && wsum[1] > 1e-5 {
        out = 0.5 * (sum[0] / wsum[0] + sum[1] / wsum[1]);
    } else {
        out = (sum[0] + sum[1]) / max(wsum[0] + wsum[1], 1e-6);
    }
    textureStore(full, gid.xy, out);
}
