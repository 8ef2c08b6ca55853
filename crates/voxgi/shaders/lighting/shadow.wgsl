// shadow: renders one shadow view (a layer of the shadow atlas) as occluder distances, from the
// mesh instances and from point-cloud surfels, and beside each distance the specular material of
// the surface seen there (`material_code`): inject reads it to put what a lit metal reflects
// into its leaf. An atlas of one channel (a scene without metals) keeps the distance only.

//!include shared/scene.wgsl
//!include shared/surfel.wgsl

@group(0) @binding(0) var<uniform> view: ShadowView;
@group(0) @binding(1) var<storage, read> vertices: array<Vertex>;
@group(0) @binding(2) var<storage, read> draws: array<Draw>;
@group(0) @binding(3) var<storage, read> points: array<Point>;
// Per point: how far its neighbours stray from its tangent plane (metres).
@group(0) @binding(4) var<storage, read> point_spread: array<f32>;
@group(0) @binding(5) var<storage, read> materials: array<Material>;

struct VsOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) @interpolate(flat) material: u32,
}

// A metal's F0 and roughness as one integer below 2^24 + 1 (exact in f32): 0 for a surface
// without a metallic part, whose specular light the voxels leave out (a dielectric's 4 %),
// else 1 + six bits each of F0's rgb and of the roughness. Decoded by lights.wgsl's
// `shadow_material`.
fn material_code(m: Material) -> f32 {
    if m.metallic <= 0.0 {
        return 0.0;
    }
    let f0 = mix(vec3<f32>(0.04 * m.specular), m.base_color.rgb, m.metallic);
    let q = vec4<u32>(round(clamp(vec4<f32>(f0, m.roughness), vec4<f32>(0.0), vec4<f32>(1.0)) * 63.0));
    return f32(1u + (q.x | (q.y << 6u) | (q.z << 12u) | (q.w << 18u)));
}

@vertex
fn vs_main(@builtin(vertex_index) vi: u32, @builtin(instance_index) di: u32) -> VsOut {
    let world = draws[di].model * vec4<f32>(vertices[vi].position, 1.0);
    var out: VsOut;
    out.clip = view.view_proj * world;
    out.world = world.xyz;
    out.material = draws[di].material;
    return out;
}

// How far surfels are pushed away from the light in shadow maps: this many disc radii plus this
// many times the point's surface spread (measured along the light). Tuned on the Kinect office
// scan, whose depth comes in ~5 cm steps at 4 m: 4 radii without the spread left blotches of
// self-shadow all over its walls; 8 radii plus the spread leaves a few. Clean surfaces have no
// spread, and their contact shadows start 8 radii from the occluder.
const SURFEL_SHADOW_OFFSET: f32 = 8.0;
const SURFEL_SPREAD_OFFSET: f32 = 1.0;

struct PointOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) disc: vec2<f32>,
}

// Surfels: point `vertex_index / 6`, corner `vertex_index % 6`, the same discs as the gbuffer's.
@vertex
fn vs_points(@builtin(vertex_index) vi: u32) -> PointOut {
    let p = points[vi / 6u];
    var n = point_normal(p);
    if dot(n, n) == 0.0 {
        // No normal: face the light, as the gbuffer's disc faces the camera.
        if view.kind == SHADOW_ORTHO {
            n = -view.dir;
        } else {
            n = normalize(view.origin - p.position);
        }
    }
    let corner = surfel_corner(vi);
    // Away from the light: by some radii, which covers the tilt of neighbouring discs, plus the
    // point's surface spread projected onto the light direction, so that scanned points that
    // scatter about their surface (by more than the composite's receiver-plane bias allows for)
    // do not shadow their neighbours.
    var away = view.dir;
    if view.kind != SHADOW_ORTHO {
        away = normalize(p.position - view.origin);
    }
    let spread = point_spread[vi / 6u] / max(abs(dot(n, away)), 0.25);
    let offset = SURFEL_SHADOW_OFFSET * p.radius + SURFEL_SPREAD_OFFSET * spread;
    let world = surfel_world(p, n, corner) + away * offset;
    var out: PointOut;
    out.clip = view.view_proj * vec4<f32>(world, 1.0);
    out.world = world;
    out.disc = corner;
    return out;
}

// Points carry no metal: a distance without a material.
@fragment
fn fs_points(in: PointOut) -> @location(0) vec2<f32> {
    if dot(in.disc, in.disc) > 1.0 {
        discard;
    }
    return vec2<f32>(occluder_distance(in.world), 0.0);
}

// The occluder distance this view stores for a surface point.
fn occluder_distance(world: vec3<f32>) -> f32 {
    if dot(view.plane.xyz, world) + view.plane.w < 0.0 {
        discard;
    }
    if view.kind == SHADOW_ORTHO {
        return dot(world - view.origin, view.dir);
    }
    return length(world - view.origin);
}

@fragment
fn fs_main(in: VsOut) -> @location(0) vec2<f32> {
    return vec2<f32>(occluder_distance(in.world), material_code(materials[in.material]));
}

// With static maps (`StaticMaps`, a scene with dynamic geometry and four times as many static
// occluders): each view's static geometry alone, drawn first; the
// dynamic geometry is then drawn over a copy of it, keeping a fragment only where it lies
// nearer than the static occluder (the depth buffer orders the dynamic fragments among
// themselves), as one pass over both would.
@group(1) @binding(0) var static_maps: texture_2d_array<f32>;

fn over_static(clip: vec4<f32>, d: f32, material: f32) -> vec2<f32> {
    let s = textureLoad(static_maps, vec2<i32>(clip.xy), i32(view.layer), 0).r;
    if d >= s {
        discard;
    }
    return vec2<f32>(d, material);
}

@fragment
fn fs_main_over(in: VsOut) -> @location(0) vec2<f32> {
    return over_static(in.clip, occluder_distance(in.world), material_code(materials[in.material]));
}

@fragment
fn fs_points_over(in: PointOut) -> @location(0) vec2<f32> {
    if dot(in.disc, in.disc) > 1.0 {
        discard;
    }
    return over_static(in.clip, occluder_distance(in.world), 0.0);
}

// Resetting a rectangle of a view before re-rendering only that part (the scissor limits the
// triangle to it): "nothing seen", at the far plane, like the pass's clear.
@vertex
fn vs_clear(@builtin(vertex_index) vi: u32) -> @builtin(position) vec4<f32> {
    let uv = vec2<f32>(f32((vi << 1u) & 2u), f32(vi & 2u));
    return vec4<f32>(uv * 2.0 - 1.0, 1.0, 1.0);
}

@fragment
fn fs_clear() -> @location(0) vec2<f32> {
    return vec2<f32>(3.0e38, 0.0);
}
