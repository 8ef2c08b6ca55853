// Radiance kept in half floats (voxels, the indirect light, the fast shading's records) is
// clamped to the largest finite half first: a light too bright for them then saturates
// instead of becoming infinity, which turned into NaN downstream (black and cyan patches).
const HALF_MAX: f32 = 65504.0;

fn to_half(v: vec4<f32>) -> vec4<f32> {
    return min(v, vec4<f32>(HALF_MAX));
}
