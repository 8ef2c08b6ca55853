// composite: deferred shading. Direct light from every light (with shadows), emission and the
// gathered indirect light, in linear radiance, written to the HDR target.

//!include shared/globals.wgsl
//!include shared/lights.wgsl
//!include shared/upsample.wgsl

// Group 0: the frame's globals (shared/globals.wgsl): the lights, the shadow atlas, and over
// (n.v, roughness) the inverse matrices of the linearly transformed cosines fitted to the GGX
// lobe (m00, m02, m20, m22, with m11 = 1; tools/fit_ltc.py; f32, interpolated here) and the
// lobe's directional albedo (a, b: f0 a + f90 b), both from voxgi::brdf. Group 2, the pass's:
@group(2) @binding(0) var gb_albedo: texture_2d<f32>;
@group(2) @binding(1) var gb_normal: texture_2d<f32>;
@group(2) @binding(2) var gb_emission: texture_2d<f32>;
@group(2) @binding(3) var gb_depth: texture_depth_2d;
@group(2) @binding(4) var hdr: texture_storage_2d<rgba32float, write>;
// At the gather's resolution: rgb indirect radiance, a ambient occlusion (upsample stage one).
@group(2) @binding(5) var indirect: texture_2d<f32>;
// Cone-traced visibility of the first CONE_SHADOW_LIGHTS area lights, as the gather traced it.
@group(2) @binding(6) var visibility: texture_2d<f32>;
// Each gather sample's normal and camera distance.
@group(2) @binding(7) var guide: texture_2d<f32>;
// The G-buffer's motion vectors (the motion view).
@group(2) @binding(8) var gb_motion: texture_2d<f32>;

// False when every light's visibility is cone-traced: the shadow-map code is then compiled
// out. CPU drivers run a branch's code even when no lane takes it, and the shadow-map lookup
// left in an untaken branch nearly doubled this pass on lavapipe.
override SHADOW_MAPS: bool = true;

// False when no surface has a specular lobe: the area lights' specular integral is then
// compiled out (as SHADOW_MAPS, for CPU drivers).
override SPECULAR: bool = true;

fn world_position(px: vec2<u32>, depth: f32) -> vec3<f32> {
    let uv = (vec2<f32>(px) + 0.5) * frame.inv_size;
    let ndc = vec4<f32>(uv.x * 2.0 - 1.0, 1.0 - uv.y * 2.0, depth, 1.0);
    let w = frame.inv_view_proj * ndc;
    return w.xyz / w.w;
}

struct Upsampled {
    indirect: vec4<f32>,
    visibility: vec4<f32>,
}

// Upsample stage two: the 2x2 gather samples around the pixel (sample c was traced at pixel
// c * scale), bilinear weights times edge weights, so light and shadow do not bleed across
// silhouettes and creases. Where no sample shares the pixel's surface, the nearest stands in.
fn upsampled(px: vec2<u32>, n0: vec3<f32>, d0: f32) -> Upsampled {
    let low_size = textureDimensions(indirect);
    // Rounded up, as the gather's size was (see gather.wgsl).
    let scale = max((u32(frame.size.x) + low_size.x - 1u) / low_size.x, 1u);
    let c0 = min(px / scale, low_size - 1u);
    let f = vec2<f32>(px - c0 * scale) / f32(scale);
    var ind = vec4<f32>(0.0);
    var vis = vec4<f32>(0.0);
    var sum = 0.0;
    for (var i = 0u; i < 4u; i++) {
        let o = vec2<u32>(i & 1u, i >> 1u);
        let c = min(c0 + o, low_size - 1u);
        let bilinear = select(1.0 - f, f, o == vec2<u32>(1u));
        let w = bilinear.x * bilinear.y * edge_weight(textureLoad(guide, c, 0), n0, d0);
        ind += w * textureLoad(indirect, c, 0);
        vis += w * textureLoad(visibility, c, 0);
        sum += w;
    }
    if sum <= 1e-7 {
        return Upsampled(textureLoad(indirect, c0, 0), textureLoad(visibility, c0, 0));
    }
    return Upsampled(ind / sum, vis / sum);
}

// The LTC table bilinearly interpolated between texel centres, as the sampler would.
fn ltc_entries(uv: vec2<f32>) -> vec4<f32> {
    let size = vec2<i32>(textureDimensions(ltc_table));
    let x = clamp(uv * vec2<f32>(size) - 0.5, vec2<f32>(0.0), vec2<f32>(size - 1));
    let i = vec2<i32>(floor(x));
    let f = x - vec2<f32>(i);
    let j = min(i + 1, size - 1);
    let top = mix(textureLoad(ltc_table, i, 0), textureLoad(ltc_table, vec2<i32>(j.x, i.y), 0), f.x);
    let bottom = mix(textureLoad(ltc_table, vec2<i32>(i.x, j.y), 0), textureLoad(ltc_table, j, 0), f.x);
    return mix(top, bottom, f.y);
}

// The GGX lobe's reflection of a uniform polygonal light (unit radiance times the light's),
// by linearly transformed cosines (Heitz, Dupuy, Hill and Neubelt 2016): the lobe's shape is
// a cosine distribution mapped by a matrix fitted per (n.v, roughness), so its integral over
// the polygon is the Lambert formula over the polygon mapped back by the inverse matrix, and
// the Fresnel-weighted directional albedo scales it.
fn area_specular(light: Light, s: Surface, p: vec3<f32>, n: vec3<f32>, v: vec3<f32>) -> vec3<f32> {
    let n_dot_v = max(dot(n, v), 1e-4);
    let uv = vec2<f32>(n_dot_v, s.roughness);
    let t = ltc_entries(uv);
    let ab = textureSampleLevel(specular_table, table_sampler, uv, 0.0).rg;
    // The fit's frame: z the normal, x towards the view (any tangent when looking straight on).
    let tv = v - n * dot(n, v);
    let x = select(tangent_frame(n)[0], tv / max(length(tv), 1e-8), dot(tv, tv) > 1e-10);
    let to_frame = transpose(mat3x3<f32>(x, cross(n, x), n));
    let minv = mat3x3<f32>(vec3<f32>(t.x, 0.0, t.z), vec3<f32>(0.0, 1.0, 0.0), vec3<f32>(t.y, 0.0, t.w));
    let integral = polygon_integral(light, p, minv * to_frame) / PI;
    return specular_albedo(f0_of(s), ab) * light.radiance * integral;
}

// Outgoing radiance towards v from one light, unshadowed: the caller multiplies by a
// visibility (`light_visibility`, or a cone-traced one) where this is not zero, so that no
// shadow lookup is paid for pixels a light cannot reach.
fn shade_light(light: Light, s: Surface, p: vec3<f32>, n: vec3<f32>, v: vec3<f32>) -> vec3<f32> {
    if is_area_light(light) {
        // The light's own surface, whose position from the depth buffer may fall a hair on the
        // emitting side, where the emitter would fill its hemisphere, is not lit by itself.
        let e = area_irradiance(light, p, n, 1e-4 * length(frame.camera_pos - p));
        if e <= 0.0 {
            return vec3<f32>(0.0);
        }
        var spec = vec3<f32>(0.0);
        if SPECULAR {
            spec = area_specular(light, s, p, n, v);
        }
        return brdf_diffuse(s) * light.radiance * e + spec;
    }

    let ls = punctual_light(light, p);
    let l = ls.l;
    let e = ls.e;
    let n_dot_l = dot(n, l);
    if n_dot_l <= 0.0 || all(e <= vec3<f32>(0.0)) {
        return vec3<f32>(0.0);
    }
    return (brdf_diffuse(s) + brdf_specular(s, n, v, l)) * e * n_dot_l;
}

// An integer hash of a 2x2 block's coordinates (a multiply-xorshift mix).
fn block_hash(b: vec2<u32>) -> u32 {
    var h = (b.x * 0x8da6b343u) ^ (b.y * 0xd8163841u);
    h = (h ^ (h >> 16u)) * 0x7feb352du;
    return h ^ (h >> 15u);
}

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if f32(id.x) >= frame.size.x || f32(id.y) >= frame.size.y {
        return;
    }
    let px = id.xy;
    let depth = textureLoad(gb_depth, px, 0);
    if depth >= 1.0 {
        var background = frame.background;
        if frame.view_mode == VIEW_MOTION {
            background = vec4<f32>(0.0, 0.0, 0.0, 1.0);
        }
        textureStore(hdr, px, background);
        return;
    }
    let am = textureLoad(gb_albedo, px, 0);
    let nr = textureLoad(gb_normal, px, 0);
    let em = textureLoad(gb_emission, px, 0);
    let p = world_position(px, depth);
    let n = normalize(nr.xyz);
    let v = normalize(frame.camera_pos - p);
    let s = Surface(am.rgb, am.a, nr.w, em.a);

    var direct = vec3<f32>(0.0);
    let up = upsampled(px, n, length(frame.camera_pos - p));
    let vis = up.visibility;
    var area = 0u;
    for (var i = 0u; i < frame.light_count; i++) {
        let light = lights[i];
        let is_area = is_area_light(light);
        let cone = frame.cone_shadows != 0u && is_area && area < CONE_SHADOW_LIGHTS;
        let channel = min(area, 3u);
        area += u32(is_area);
        let c = shade_light(light, s, p, n, v);
        if all(c <= vec3<f32>(0.0)) {
            continue;
        }
        // A cone-traced visibility replaces the shadow map's.
        var w = 1.0;
        if cone {
            w = vis[channel];
        } else if SHADOW_MAPS && light.sample_first != NO_INDEX && frame.history != HISTORY_NONE {
            // Accumulating frames: one of this frame's points on the light, a different one
            // for each pixel of a 2x2 block (the temporal pass's neighbourhood then spans
            // the penumbra) and for each frame, the blocks' order scrambled so that their
            // pixels' sequences (and their leftover errors) do not repeat in a grid.
            let s = (px.x & 1u) + 2u * (px.y & 1u) + frame.light_sample + block_hash(px >> vec2<u32>(1u));
            w = sampled_visibility(light, p, n, s & 3u);
        } else if SHADOW_MAPS {
            w = light_visibility(light, p, n, frame.shadow_softness);
        }
        direct += c * w;
    }
    let ind = up.indirect;
    var out = direct + em.rgb + ind.rgb;
    switch frame.view_mode {
        case VIEW_ALBEDO: {
            out = am.rgb;
        }
        case VIEW_NORMAL: {
            out = n * 0.5 + 0.5;
        }
        case VIEW_DIRECT: {
            out = direct;
        }
        case VIEW_AO: {
            out = vec3<f32>(ind.a);
        }
        case VIEW_INDIRECT: {
            out = ind.rgb;
        }
        case VIEW_MOTION: {
            out = textureLoad(gb_motion, px, 0).xyz;
        }
        default: {}
    }
    textureStore(hdr, px, vec4<f32>(out, 1.0));
}
