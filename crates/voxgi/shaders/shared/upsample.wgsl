// Edge-aware weights shared by the two stages of the gather's reconstruction (upsample.wgsl at
// the gather's resolution, composite.wgsl to full resolution).

// The weight of a gather sample (guide g: normal, camera distance, 0 for background) for a
// pixel of normal n0 at camera distance d0. Depth within 5 % and normals within ~30 degrees
// count fully; beyond, weights fall fast. Background samples count nothing.
fn edge_weight(g: vec4<f32>, n0: vec3<f32>, d0: f32) -> f32 {
    let wd = exp(-abs(g.a - d0) / max(0.05 * d0, 1e-4));
    let c1 = max(dot(g.xyz, n0), 0.0);
    let c2 = c1 * c1;
    let c4 = c2 * c2;
    return select(wd * c4 * c4 + 1e-6, 0.0, g.a <= 0.0);
}
