// What a leaf reflects specularly of the lights: its lobe (`specular_bounces`). inject writes it
// beside the leaf's direct light (leaf_direct[2i + 1]); the first directional mip level folds it into the six
// directions (voxels/<kind>/ filters), so a cone that looks at a lit metal from where its
// reflection goes sees the light it reflects. The finest level stays isotropic: cones that read
// it (the nearest samples of narrow cones) see no lobe.
//
// A lobe is one vec4: the specular radiant exitance M (rgb, W/m^2: the lights' irradiance
// times the lobe's directional albedo), and in w an integer below 2^24 (exact in f32): the lobe's mean direction
// octahedrally in nine bits a coordinate, and in six bits how widely it spreads (`t`, 0: a
// mirror's beam, 1: as wide as a Lambertian surface's light).

//!include shared/fragment.wgsl

struct Lobe {
    // Specular radiant exitance.
    m: vec3<f32>,
    // Mean reflected direction (unit).
    dir: vec3<f32>,
    // Spread: 0 narrow ... 1 cosine-wide.
    t: f32,
}

fn pack_lobe(m: vec3<f32>, dir: vec3<f32>, t: f32) -> vec4<f32> {
    let e = vec2<u32>(round((oct_encode(dir) * 0.5 + 0.5) * 511.0));
    let q = u32(round(clamp(t, 0.0, 1.0) * 63.0));
    return vec4<f32>(m, f32(e.x | (e.y << 9u) | (q << 18u)));
}

fn unpack_lobe(v: vec4<f32>) -> Lobe {
    let w = u32(v.w);
    let e = vec2<f32>(vec2<u32>(w & 511u, (w >> 9u) & 511u)) / 511.0 * 2.0 - 1.0;
    return Lobe(v.rgb, oct_decode(e), f32(w >> 18u) / 63.0);
}

// The radiance a cone travelling along direction block `block` (+X, -X, +Y, -Y, +Z, -Z: the
// chains' order) reads of a leaf with lobe `lobe` and normal `n`, opacity aside.
//
// A cone travelling d weighs the blocks of d's signs by d's squared cosines, and sees the light
// leaving towards -d. So a narrow lobe about R goes to the blocks of -R's signs, each with R's
// squared cosine on its axis (P_b, summing to 1); a wide one (t = 1) spreads over the
// hemisphere as a Lambertian surface's light does. Each block's share is divided by what a
// block gathers of a surface's exitance across the hemisphere the cosine weighs, I_b = the
// integral of the squared cosine on its axis times the cosine to the normal over the
// directions it serves: pi/2 for the block facing along the normal, pi/8 across it, 0 behind
// it; the quadratic (pi/8)(1 + c)^2 in the cosine c between the block's outgoing axis and the
// normal takes these three values. Summed over the blocks the reflected exitance comes back
// whole (sum P_b = 1), as a Lambertian surface's radiance M/pi does (sum I_b = pi).
fn lobe_radiance(lobe: Lobe, n: vec3<f32>, block: u32) -> vec3<f32> {
    let axis = block / 2u;
    // The direction a cone of this block sees light leave in: against the block's own.
    let out_sign = select(1.0, -1.0, (block & 1u) == 0u);
    let c = out_sign * n[axis];
    let gathers = 0.39269908 * (1.0 + c) * (1.0 + c);
    let r = lobe.dir[axis];
    let narrow = select(0.0, r * r, r * out_sign > 0.0);
    let wide = gathers * 0.31830989;
    // (Floored: a narrow lobe grazing the surface still leaves by a block across it.)
    return lobe.m * mix(narrow, wide, lobe.t) / max(gathers, 0.1);
}
