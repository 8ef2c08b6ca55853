// tonemap: exposure, a tone curve and the output encoding, from the HDR target into the
// caller's target. A fullscreen triangle, so any renderable format works: sRGB formats encode
// in the blending unit, 8-bit linear ones get the sRGB curve here (ENCODE_SRGB), float ones get
// the tone-mapped linear values.

//!include shared/globals.wgsl
//!include shared/tone_curves.wgsl

@group(2) @binding(0) var hdr: texture_2d<f32>;

// True for an 8-bit target without an sRGB view: the shader applies the sRGB curve itself.
override ENCODE_SRGB: bool = false;

@vertex
fn vs_main(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    // One triangle covering the screen: (-1,-1), (3,-1), (-1,3).
    let uv = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u));
    return vec4<f32>(uv * 2.0 - 1.0, 0.0, 1.0);
}

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let c = max(textureLoad(hdr, vec2<u32>(pos.xy), 0).rgb * frame.exposure, vec3<f32>(0.0));
    var t = tone_curve(c, frame.tonemap);
    if ENCODE_SRGB {
        t = srgb_encode(t);
    }
    return vec4<f32>(t, 1.0);
}
