// gather: per pixel (or per 2x2 block at half resolution), indirect light from the voxels:
// diffuse cones (irradiance and ambient occlusion), or with LEAVES the irradiance and occlusion
// the last bounce kept in the leaves around the pixel (shared/leaf_irradiance.wgsl), and one
// glossy cone along the specular lobe's dominant direction whose aperture follows the
// roughness; with cone shadows, the visibility of the first area lights by one cone each.

//!include shared/globals.wgsl
//!include shared/half.wgsl
//!include shared/brdf.wgsl
//!include shared/cone.wgsl
//!include shared/interleave.wgsl
//!include shared/leaf_irradiance.wgsl

// Group 0: the frame's globals (shared/globals.wgsl).
// Group 1: the voxel structure (voxels/<kind>/sample.wgsl); group 3 its irradiance lookup
// (voxels/<kind>/irradiance.wgsl). Group 2, the pass's own:
@group(2) @binding(0) var gb_albedo: texture_2d<f32>;
@group(2) @binding(1) var gb_normal: texture_2d<f32>;
@group(2) @binding(2) var gb_emission: texture_2d<f32>;
@group(2) @binding(3) var gb_depth: texture_depth_2d;
// rgb: indirect radiance towards the camera, a: ambient occlusion.
@group(2) @binding(4) var indirect_out: texture_storage_2d<rgba16float, write>;
// Visibility of the first CONE_SHADOW_LIGHTS area lights, one per channel.
@group(2) @binding(5) var visibility_out: texture_storage_2d<rgba8unorm, write>;
// Normal and distance to the camera (0: background), for the upsample's edge weights: one
// fetch there instead of the g-buffer's depth and normal and an unprojection per tap.
@group(2) @binding(6) var guide_out: texture_storage_2d<rgba16float, write>;

// Visibility of an area light by one cone from p to its centre, as wide as the light looks
// from p: 1 - the opacity the cone gathers before reaching the light.
fn cone_visibility(light: Light, p: vec3<f32>, n: vec3<f32>) -> f32 {
    let to = light.position - p;
    let dist = length(to);
    let dir = to / dist;
    let tan_half = clamp(light.size / dist, 0.01, 1.0);
    let vs = voxels_voxel_size_at(p);
    let origin = p + n * vs * cones.origin_offset;
    // Stop before the samples' filters reach the emitter's plane: the light hangs on (or in)
    // other geometry, which must not count as its occluder. A sample of diameter d filters
    // trilinearly over the next coarser level too, so its support reaches 2d: stop where the
    // plane is 2d away, (dist - t) cos = 4 tan t.
    let cos_plane = max(abs(dot(dir, light.direction)), 0.1);
    let stop = dist * cos_plane / (cos_plane + 4.0 * tan_half) - vs;
    return 1.0 - trace_cone(origin, n, dir, tan_half, max(stop, 0.0), vs, WHOLE_FOOTPRINT).a;
}

fn area_visibility(p: vec3<f32>, n: vec3<f32>) -> vec4<f32> {
    var vis = vec4<f32>(1.0);
    var area = 0u;
    for (var i = 0u; i < frame.light_count && area < CONE_SHADOW_LIGHTS; i++) {
        let light = lights[i];
        if is_area_light(light) {
            vis[area] = cone_visibility(light, p, n);
            area += 1u;
        }
    }
    return vis;
}

fn world_position(px: vec2<u32>, depth: f32) -> vec3<f32> {
    let uv = (vec2<f32>(px) + 0.5) * frame.inv_size;
    let ndc = vec4<f32>(uv.x * 2.0 - 1.0, 1.0 - uv.y * 2.0, depth, 1.0);
    let w = frame.inv_view_proj * ndc;
    return w.xyz / w.w;
}

// Interleaved sampling: each pixel of a 4x4 block draws its cones at a different turn (one
// point of a Hammersley set, shared/cone.wgsl), and the upsample pass averages every 4x4
// window, so each pixel gets the light of sixteen turns of the bundle.

// False when no surface in the scene has a specular lobe: the glossy cone's code is then
// compiled out (CPU drivers run an untaken branch's code; it cost 6 % of this pass).
override GLOSSY: bool = true;
// The fast shading: diffuse light and occlusion from the leaves' records, no diffuse cones.
override LEAVES: bool = false;

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let out_size = textureDimensions(indirect_out);
    if any(gid.xy >= out_size) {
        return;
    }
    // 1, or 2 at half resolution: rounded up, as the target's size was (an odd width's
    // 355 / 178 truncated to 1 traced the left half of the image only).
    let scale = (u32(frame.size.x) + out_size.x - 1u) / out_size.x;
    let px = min(gid.xy * scale, vec2<u32>(frame.size) - 1u);
    let depth = textureLoad(gb_depth, px, 0);
    if depth >= 1.0 {
        textureStore(indirect_out, gid.xy, vec4<f32>(0.0, 0.0, 0.0, 1.0));
        textureStore(visibility_out, gid.xy, vec4<f32>(1.0));
        textureStore(guide_out, gid.xy, vec4<f32>(0.0));
        return;
    }
    let am = textureLoad(gb_albedo, px, 0);
    let nr = textureLoad(gb_normal, px, 0);
    let em = textureLoad(gb_emission, px, 0);
    let s = Surface(am.rgb, am.a, nr.w, em.a);
    let p = world_position(px, depth);
    let n = normalize(nr.xyz);
    let v = normalize(frame.camera_pos - p);
    textureStore(guide_out, gid.xy, vec4<f32>(nr.xyz, length(frame.camera_pos - p)));
    // The sixteen pixels of a 4x4 block draw the cones' axes from their cells at sixteen
    // turns, which the upsample's 4x4 average takes the mean of. Even and odd Bayer ranks
    // trace the two halves of the ring, so each parity's eight turns are a Hammersley set of
    // their own (the rank's half and its 3-bit reversal; the two sets interleave): every cone
    // of the ring meets eight azimuths and eight zeniths spread over its whole cell. With
    // temporal accumulation each frame turns the whole set by its own fraction of a cell
    // (frame.cone_turn, 0 in frame 0), wrapping round, and the block's pattern moves
    // (pixel_rank), so every pixel converges to its own cones' integral over their cells.
    // Turned by less than a sixteenth, the turns stayed in sixteen small patches of each cell
    // frame after frame, and the converged gather read 0.90 to 1.09 of that integral on the
    // open Cornell box's ceiling (tests/gpu/probe.rs).
    // Cones start at the finest voxels held about the point.
    let vs = voxels_voxel_size_at(p);
    let rank = pixel_rank(gid.xy, frame.light_sample);
    let zenith = 2u * (reverseBits(rank >> 1u) >> 29u) + (rank & 1u);
    let turn = fract((vec2<f32>(f32(rank), f32(zenith)) + 0.5) / 16.0 + frame.cone_turn);
    var g: Gathered;
    if LEAVES {
        g = leaf_gather(p, n);
    } else {
        // The cones' quarters turn once every sixteen frames, when every pixel has taken
        // every rank (pixel_rank): each rank meets every quarter of each cone over 64 frames.
        let view_ao = frame.view_mode == VIEW_AO;
        g = gather_diffuse(p, n, turn, view_ao, rank & 1u, vs, rank, frame.light_sample >> 4u);
    }
    var indirect = brdf_diffuse(s) * g.irradiance;
    let f0 = f0_of(s);
    if GLOSSY && cones.indirect != 0u && max(f0.r, max(f0.g, f0.b)) > 0.0 {
        let a = ggx_alpha(s.roughness);
        // A direction drawn from the lobe: a visible normal of the GGX distribution at the
        // pixel's point of the block's Hammersley set, shifted each frame,
        // the view reflected about it, so the block's and the frames' mean is the lobe's mean.
        // One cone along the lobe's dominant direction was not (its footprint mean reached
        // 0.65 of the path tracer's reflection at roughness 0.3). A direction reflected below
        // the surface is folded back above it: the lobe's albedo already counts the light
        // that geometry loses there.
        let frame_n = tangent_frame(n);
        let vt = transpose(frame_n) * v;
        // The glossy cone is one, not two halves: the block's sixteen points as one
        // Hammersley set (the rank and its 4-bit reversal).
        let lobe_turn = fract(
            (vec2<f32>(f32(rank), f32(reverseBits(rank) >> 28u)) + 0.5) / 16.0 + frame.cone_turn,
        );
        let h = frame_n * sample_vndf(vec3<f32>(vt.xy, max(vt.z, 1e-4)), a, lobe_turn);
        let r = reflect(-v, h);
        // Folded above the surface and no nearer its plane than 78 degrees, as the diffuse
        // cones (shared/cone.wgsl): a cone grazing its own plane marches a voxel at a time (on
        // Sponza's rough stone the unclamped lobe cost the gather 25-40 % more on lavapipe,
        // clamped 16 %).
        let folded = r - 2.0 * min(dot(r, n), 0.0) * n;
        let dir = normalize(folded + n * max(GRAZING_COS - dot(folded, n), 0.0));
        // Cones as wide as the distribution (a), no narrower than a voxel allows anyway: the
        // sixteen overlap, which blurs the reflection a little but not its mean, and they
        // march fewer steps than cones of a sixteenth of the lobe each (half as wide read the
        // same means within 3 %, at 10-15 % more of the gather on Sponza).
        let tan_half = clamp(a, 0.01, 1.0);
        let origin = p + n * vs * cones.origin_offset;
        let spec = trace_cone(origin, n, dir, tan_half, cones.max_distance, vs, WHOLE_FOOTPRINT).rgb;
        // Weighted by the lobe's directional albedo, a table of the very BRDF the path tracer
        // integrates (Karis's analytic fit, used before, is 10-18 % low at roughness 0.2-0.5).
        let uv = vec2<f32>(max(dot(n, v), 1e-4), s.roughness);
        let ab = textureSampleLevel(specular_table, table_sampler, uv, 0.0).rg;
        indirect += spec * specular_albedo(f0, ab);
    }
    textureStore(indirect_out, gid.xy, to_half(vec4<f32>(indirect, g.ao)));
    var vis = vec4<f32>(1.0);
    if frame.cone_shadows != 0u {
        vis = area_visibility(p, n);
    }
    textureStore(visibility_out, gid.xy, vis);
}
