// reference_display: the path tracer's running mean, exposed and tone-mapped like the tonemap
// pass, into the caller's target — over the columns a scissor leaves, so a split view shows
// cone tracing on one side and the path tracer on the other.

//!include shared/scene.wgsl
//!include shared/tone_curves.wgsl
//!include shared/fullscreen.wgsl

struct Display {
    // Linear exposure scale (2^EV).
    exposure: f32,
    // TONEMAP_*.
    tonemap: u32,
    width: u32,
    _pad: u32,
}

@group(0) @binding(0) var<uniform> display: Display;
@group(0) @binding(1) var<storage, read> accum: array<vec4<f32>>;

// True for an 8-bit target without an sRGB view, as in the tonemap pass.
override ENCODE_SRGB: bool = false;

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let p = accum[u32(pos.y) * display.width + u32(pos.x)];
    let mean = p.rgb / max(p.w, 1.0);
    var t = tone_curve(max(mean * display.exposure, vec3<f32>(0.0)), display.tonemap);
    if ENCODE_SRGB {
        t = srgb_encode(t);
    }
    return vec4<f32>(t, 1.0);
}
