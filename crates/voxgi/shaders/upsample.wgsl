// upsample: the gather's output (full or half resolution, one bundle rotation per pixel of each
// 4x4 block) to full-resolution indirect light. Each pixel averages the 4x4 window of gather
// samples around it, weighted by depth and normal similarity, so it receives all sixteen bundle
// rotations while light does not bleed across silhouettes and creases.

//!include shared/scene.wgsl
//!include shared/interleave.wgsl

@group(0) @binding(0) var<uniform> frame: Frame;
@group(0) @binding(1) var low: texture_2d<f32>;
@group(0) @binding(2) var gb_normal: texture_2d<f32>;
@group(0) @binding(3) var gb_depth: texture_depth_2d;
@group(0) @binding(4) var full: texture_storage_2d<rgba16float, write>;
// Area-light visibility as the gather traced it, and at full resolution.
@group(0) @binding(5) var vis_low: texture_2d<f32>;
@group(0) @binding(6) var vis_full: texture_storage_2d<rgba8unorm, write>;
// Each gather sample's normal (rgb) and distance to the camera (a, 0 for background).
@group(0) @binding(7) var guide: texture_2d<f32>;

fn view_depth(px: vec2<u32>, d: f32) -> f32 {
    let uv = (vec2<f32>(px) + 0.5) * frame.inv_size;
    let w = frame.inv_view_proj * vec4<f32>(uv.x * 2.0 - 1.0, 1.0 - uv.y * 2.0, d, 1.0);
    return length(w.xyz / w.w - frame.camera_pos);
}

// No branch or indexed local array in the loop: CPU drivers run both sides of lane-divergent
// branches and spill indexed arrays to memory.
@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let size = vec2<u32>(frame.size);
    if any(gid.xy >= size) {
        return;
    }
    let low_size = textureDimensions(low);
    let scale = max(size.x / low_size.x, 1u);
    let depth0 = textureLoad(gb_depth, gid.xy, 0);
    if depth0 >= 1.0 {
        textureStore(full, gid.xy, vec4<f32>(0.0, 0.0, 0.0, 1.0));
        textureStore(vis_full, gid.xy, vec4<f32>(1.0));
        return;
    }
    let d0 = view_depth(gid.xy, depth0);
    let n0 = textureLoad(gb_normal, gid.xy, 0).xyz;
    // The window moves inside the image rather than clamping, so it always holds all sixteen
    // rotations and both halves of the cone set.
    let base = clamp(vec2<i32>(gid.xy / scale) - 1, vec2<i32>(0), max(vec2<i32>(low_size) - 4, vec2<i32>(0)));
    // Even and odd Bayer ranks traced different halves of the cones: average each half on its
    // own, then the two, so rejected neighbours at edges cannot tip the balance.
    var sum0 = vec4<f32>(0.0);
    var sum1 = vec4<f32>(0.0);
    var w0 = 0.0;
    var w1 = 0.0;
    // Visibility is not interleaved: a bilinear tent over the nearest samples, edge-aware too.
    var vis = vec4<f32>(0.0);
    var wv = 0.0;
    for (var i = 0; i < 16; i++) {
        let c = min(base + vec2<i32>(i & 3, i >> 2), vec2<i32>(low_size) - 1);
        let px = min(vec2<u32>(c) * scale, size - 1u);
        let g = textureLoad(guide, c, 0);
        let d = g.a;
        let n = g.xyz;
        // Depth within 5 % and normals within ~30 degrees count fully; beyond, weights fall
        // fast. Background samples count nothing.
        let wd = exp(-abs(d - d0) / max(0.05 * d0, 1e-4));
        let c1 = max(dot(n, n0), 0.0);
        let c2 = c1 * c1;
        let c4 = c2 * c2;
        let wn = c4 * c4;
        let w = select(wd * wn + 1e-6, 0.0, d <= 0.0);
        let k = f32(cone_half(vec2<u32>(c)));
        let value = textureLoad(low, c, 0);
        sum0 += (w * (1.0 - k)) * value;
        sum1 += (w * k) * value;
        w0 += w * (1.0 - k);
        w1 += w * k;
        let off = abs(vec2<f32>(px) - vec2<f32>(gid.xy)) / f32(scale);
        let tent = max(1.0 - off.x, 0.0) * max(1.0 - off.y, 0.0);
        vis += (w * tent) * textureLoad(vis_low, c, 0);
        wv += w * tent;
    }
    var out: vec4<f32>;
    if w0 > 1e-5 && w1 > 1e-5 {
        out = 0.5 * (sum0 / w0 + sum1 / w1);
    } else {
        out = (sum0 + sum1) / max(w0 + w1, 1e-6);
    }
    textureStore(full, gid.xy, out);
    // Where no neighbour shares the pixel's surface, the nearest sample stands in.
    let nearest = textureLoad(vis_low, min(gid.xy / scale, low_size - 1u), 0);
    textureStore(vis_full, gid.xy, select(nearest, vis / wv, wv > 1e-5));
}
