// The vertex stage of the passes that draw into the caller's target (tonemap,
// reference_display): one triangle covering the screen, (-1,-1), (3,-1), (-1,3).

@vertex
fn vs_main(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    let uv = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u));
    return vec4<f32>(uv * 2.0 - 1.0, 0.0, 1.0);
}
