// tonemap: exposure, a tone curve and the output encoding, from the HDR target into the
// caller's target. A fullscreen triangle, so any renderable format works: sRGB formats encode
// in the blending unit, 8-bit linear ones get the sRGB curve here (ENCODE_SRGB), float ones get
// the tone-mapped linear values.

//!include shared/globals.wgsl
//!include shared/tone_curves.wgsl
//!include shared/fullscreen.wgsl

@group(2) @binding(0) var hdr: texture_2d<f32>;

// True for an 8-bit target without an sRGB view: the shader applies the sRGB curve itself.
override ENCODE_SRGB: bool = false;

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let c = max(textureLoad(hdr, vec2<u32>(pos.xy), 0).rgb * frame.exposure, vec3<f32>(0.0));
    var t = tone_curve(c, frame.tonemap);
    if ENCODE_SRGB {
        t = srgb_encode(t);
    }
    return vec4<f32>(t, 1.0);
}
