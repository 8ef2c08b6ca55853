// Surfels: each point of a cloud is drawn as a disc in its tangent plane, as a quad of two
// triangles (6 vertices per point, no index buffer) whose fragments outside the unit disc are
// discarded. Shared by the gbuffer and shadow passes so both see the same discs.

//!include shared/scene.wgsl

// Decodes an octahedral normal; returns zero for POINT_NO_NORMAL.
fn point_normal(p: Point) -> vec3<f32> {
    if p.normal == POINT_NO_NORMAL {
        return vec3<f32>(0.0);
    }
    let e = unpack2x16snorm(p.normal);
    var n = vec3<f32>(e.x, e.y, 1.0 - abs(e.x) - abs(e.y));
    let t = max(-n.z, 0.0);
    n.x += select(t, -t, n.x >= 0.0);
    n.y += select(t, -t, n.y >= 0.0);
    return normalize(n);
}

fn point_albedo(p: Point) -> vec3<f32> {
    let rg = unpack2x16float(p.albedo_rg);
    let be = unpack2x16float(p.albedo_b_emission_r);
    return vec3<f32>(rg, be.x);
}

fn point_emission(p: Point) -> vec3<f32> {
    let be = unpack2x16float(p.albedo_b_emission_r);
    let gb = unpack2x16float(p.emission_gb);
    return vec3<f32>(be.y, gb);
}

// Corner `vi % 6` of a point's quad in disc units (-1..1).
fn surfel_corner(vi: u32) -> vec2<f32> {
    var corners = array<vec2<f32>, 6>(
        vec2<f32>(-1.0, -1.0),
        vec2<f32>(1.0, -1.0),
        vec2<f32>(1.0, 1.0),
        vec2<f32>(-1.0, -1.0),
        vec2<f32>(1.0, 1.0),
        vec2<f32>(-1.0, 1.0),
    );
    return corners[vi % 6u];
}

// An orthonormal tangent pair for unit n (Duff et al. 2017, branchless).
fn surfel_tangents(n: vec3<f32>) -> array<vec3<f32>, 2> {
    let s = select(-1.0, 1.0, n.z >= 0.0);
    let a = -1.0 / (s + n.z);
    let b = n.x * n.y * a;
    return array<vec3<f32>, 2>(
        vec3<f32>(1.0 + s * n.x * n.x * a, s * b, -s * n.x),
        vec3<f32>(b, s + n.y * n.y * a, -n.y),
    );
}

// The world position of corner `corner` of the disc of point `p` with unit normal `n`.
fn surfel_world(p: Point, n: vec3<f32>, corner: vec2<f32>) -> vec3<f32> {
    let t = surfel_tangents(n);
    return p.position + (t[0] * corner.x + t[1] * corner.y) * p.radius;
}
