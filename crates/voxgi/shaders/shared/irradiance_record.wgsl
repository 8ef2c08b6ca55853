// A leaf's irradiance record for the fast shading (`IndirectShading::Leaves`): what the last
// bounce kept of its diffuse gather, as four u32: irradiance rgb and occlusion as four f16,
// the leaf's normal and how well its fragments' normals agree as snorm8, and 1 (a record
// exists; an empty one is all zero).

//!include shared/half.wgsl

fn pack_irradiance(e: vec3<f32>, ao: f32, normal: vec4<f32>) -> vec4<u32> {
    let h = to_half(vec4<f32>(e, ao));
    return vec4<u32>(pack2x16float(h.rg), pack2x16float(h.ba), pack4x8snorm(normal), 1u);
}

// Irradiance (rgb) and ambient occlusion (a).
fn record_light(r: vec4<u32>) -> vec4<f32> {
    return vec4<f32>(unpack2x16float(r.x), unpack2x16float(r.y));
}

fn record_normal(r: vec4<u32>) -> vec4<f32> {
    return unpack4x8snorm(r.z);
}

// Leaf c's rank in the 4x4 windows of leaf_turn (and its cones' quarters, cone_quarter).
fn leaf_rank(c: vec3<u32>) -> u32 {
    return 4u * ((c.x + c.y) & 3u) + ((c.y + c.z) & 3u);
}

// The turn of leaf c's cone bundle (shared/cone.wgsl, diffuse_cone): one of the sixteen
// points of a Hammersley set, each once in every 4x4 window of any axis-aligned plane
// ((x + y, y + z) mod 4 is one-to-one on each), the layout shared/leaf_irradiance.wgsl's
// window averages.
fn leaf_turn(c: vec3<u32>) -> vec2<f32> {
    let rank = leaf_rank(c);
    return (vec2<f32>(f32(rank), f32(reverseBits(rank) >> 28u)) + 0.5) / 16.0;
}
