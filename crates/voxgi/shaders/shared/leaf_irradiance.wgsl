// The fast shading's diffuse term (`IndirectShading::Leaves`; Salm's thesis, §4.6): instead of
// tracing cones from a pixel, filter the irradiance and occlusion the last bounce kept at the
// centres of the leaves around it, each weighted further by how well its normal faces the
// pixel's (squared cosine; a two-sided leaf, whose record averages both sides, by 1/4). Empty
// voxels weigh nothing.
//
// The filter is interleaved sampling's, in voxels: the last bounce draws each leaf's cone
// bundle at one of sixteen turns (`leaf_turn`), laid out so that every 4x4 window of any
// axis-aligned plane of leaves holds each turn once, and a pixel averages a 4-leaf-wide
// window across the two axes its normal lies least along (the mean of four linear
// interpolants, so the weights move continuously with the pixel: five leaves, the outer two
// sharing one quarter) and interpolates linearly along the third. Each turn then weighs the
// same, as each of the sixteen turns does in the gather's 4x4 reconstruction. A trilinear
// or tricubic fetch weighted the few leaves nearest the pixel most, and their turns'
// differences showed as a voxel-sized pattern.
//
// The normal weight keeps the far side of a thin wall and the other face of a corner out;
// what it cannot keep out is a leaf that holds two surfaces facing the same way, and the light
// it gathered above both: the edge leaking of the thesis' §6 (docs/QUALITY.md).

//!include shared/irradiance_record.wgsl
//!include voxels/irradiance.wgsl

// Below this agreement a leaf's record is the mean of both sides (lighting/bounce.wgsl).
const TWO_SIDED: f32 = 0.3;

// The unit vector of axis a.
fn axis_unit(a: u32) -> vec3<i32> {
    return vec3<i32>(vec3<u32>(0u, 1u, 2u) == vec3<u32>(a));
}

// Weight of tap i (0..5) of the 4-wide window whose first point lies f past its first leaf.
fn window_weight(i: u32, f: f32) -> f32 {
    return select(select(1.0, f, i == 4u), 1.0 - f, i == 0u) * 0.25;
}

fn leaf_gather(p: vec3<f32>, n: vec3<f32>) -> Gathered {
    let an = abs(n);
    let axis = select(select(2u, 1u, an.y >= an.z), 0u, an.x >= an.y && an.x >= an.z);
    let t1 = (axis + 1u) % 3u;
    let t2 = (axis + 2u) % 3u;
    // Leaf centres lie at integers of u.
    let u = irradiance_grid(p) - 0.5;
    // Across: the window's first point, 1.5 leaves before the pixel. Along the normal: linear.
    let v = select(u - 1.5, u, vec3<u32>(0u, 1u, 2u) == vec3<u32>(axis));
    let start = floor(v);
    let f = v - start;
    var sum = vec4<f32>(0.0);
    var weight = 0.0;
    // Without the normals' weights: the fallback where no leaf around faces the pixel (a
    // surface thinner than its leaves' records can tell apart).
    var plain = vec4<f32>(0.0);
    var plain_weight = 0.0;
    for (var k = 0u; k < 50u; k++) {
        let i = k % 5u;
        let j = (k / 5u) % 5u;
        let m = k / 25u;
        let c = vec3<i32>(start) + axis_unit(t1) * i32(i) + axis_unit(t2) * i32(j) + axis_unit(axis) * i32(m);
        let r = leaf_irradiance_at(c);
        let wm = select(f[axis], 1.0 - f[axis], m == 0u);
        let w = window_weight(i, f[t1]) * window_weight(j, f[t2]) * wm * f32(r.w);
        let nl = record_normal(r);
        let facing = max(dot(n, nl.xyz / max(length(nl.xyz), 1e-4)), 0.0);
        let wn = w * select(0.25, facing * facing, nl.w > TWO_SIDED);
        let l = record_light(r);
        sum += wn * l;
        weight += wn;
        plain += w * l;
        plain_weight += w;
    }
    var l = vec4<f32>(0.0, 0.0, 0.0, 1.0);
    if weight > 1e-4 {
        l = sum / weight;
    } else if plain_weight > 0.0 {
        l = plain / plain_weight;
    }
    return Gathered(l.rgb, l.a);
}
