// What the structures' voxel debug views share: the ray's span through the volume, and the
// voxel-nodes view's colours.

// Ray / box [lo, hi] entry and exit distances (t_enter > t_exit: miss).
fn ray_box(o: vec3<f32>, inv_d: vec3<f32>, lo: vec3<f32>, hi: vec3<f32>) -> vec2<f32> {
    let t0 = (lo - o) * inv_d;
    let t1 = (hi - o) * inv_d;
    let tmin = min(t0, t1);
    let tmax = max(t0, t1);
    return vec2<f32>(max(max(tmin.x, tmin.y), max(tmin.z, 0.0)), min(tmax.x, min(tmax.y, tmax.z)));
}

// A colour per level, so the levels of the voxel-nodes view tell apart.
fn level_colour(lvl: u32) -> vec3<f32> {
    let h = f32(lvl) * 0.618034;
    let k = fract(vec3<f32>(h, h + 0.333333, h + 0.666667)) * 6.283185;
    return 0.55 + 0.4 * cos(k);
}

// The voxel-nodes view's colour of a cell of level `lvl` hit at `p` (cell units) through its
// face across `axis`: shaded by the face, darkened near the cell's edges.
fn node_colour(lvl: u32, p: vec3<f32>, axis: u32) -> vec3<f32> {
    let f = fract(p);
    let e = min(f, 1.0 - f);
    var m = vec2<f32>(e.y, e.z);
    if axis == 1u {
        m = vec2<f32>(e.x, e.z);
    } else if axis == 2u {
        m = vec2<f32>(e.x, e.y);
    }
    let shade = array<f32, 3>(0.8, 1.0, 0.6)[axis];
    return level_colour(lvl) * shade * select(1.0, 0.35, min(m.x, m.y) < 0.06);
}
