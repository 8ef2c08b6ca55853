// upsample: half-resolution indirect light to full resolution. Each pixel blends its four
// nearest low-resolution samples with bilinear weights times depth and normal similarity, so
// light does not bleed across silhouettes and creases.

//!include shared/scene.wgsl

@group(0) @binding(0) var<uniform> frame: Frame;
@group(0) @binding(1) var low: texture_2d<f32>;
@group(0) @binding(2) var gb_normal: texture_2d<f32>;
@group(0) @binding(3) var gb_depth: texture_depth_2d;
@group(0) @binding(4) var full: texture_storage_2d<rgba16float, write>;

fn linear_depth(px: vec2<u32>) -> f32 {
    let d = textureLoad(gb_depth, px, 0);
    let w = frame.inv_view_proj * vec4<f32>(0.0, 0.0, d, 1.0);
    let near = frame.inv_view_proj * vec4<f32>(0.0, 0.0, 0.0, 1.0);
    return length(w.xyz / w.w - near.xyz / near.w);
}

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let size = vec2<u32>(frame.size);
    if any(gid.xy >= size) {
        return;
    }
    let low_size = textureDimensions(low);
    let d0 = linear_depth(gid.xy);
    let n0 = textureLoad(gb_normal, gid.xy, 0).xyz;
    // Position in the low-resolution grid, whose sample i sits at full-res pixel 2i.
    let q = vec2<f32>(gid.xy) * 0.5;
    let base = vec2<i32>(floor(q));
    let f = q - vec2<f32>(base);
    var sum = vec4<f32>(0.0);
    var wsum = 0.0;
    for (var i = 0; i < 4; i++) {
        let o = vec2<i32>(i & 1, i >> 1);
        let c = clamp(base + o, vec2<i32>(0), vec2<i32>(low_size) - 1);
        let bil = select(1.0 - f.x, f.x, o.x == 1) * select(1.0 - f.y, f.y, o.y == 1);
        let full_px = min(vec2<u32>(c) * 2u, size - 1u);
        let d = linear_depth(full_px);
        let n = textureLoad(gb_normal, full_px, 0).xyz;
        let wd = exp(-abs(d - d0) / max(0.02 * d0, 1e-4));
        let wn = pow(max(dot(n, n0), 0.0), 8.0);
        let w = max(bil, 1e-3) * wd * wn + 1e-6;
        sum += w * textureLoad(low, c, 0);
        wsum += w;
    }
    textureStore(full, gid.xy, sum / wsum);
}
