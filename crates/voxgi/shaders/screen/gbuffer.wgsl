// gbuffer: rasterizes every mesh instance into albedo/metallic, normal/roughness, emission,
// motion and depth, then every point-cloud sample as a surfel (an oriented disc, see
// shared/surfel.wgsl). Motion: how far the surface under a pixel moved on screen since the
// last frame (pixels, without the jitter), and its distance from the last frame's camera
// (the temporal pass's disocclusion test).

//!include shared/scene.wgsl
//!include shared/surfel.wgsl

@group(0) @binding(0) var<uniform> frame: Frame;
@group(0) @binding(1) var<storage, read> vertices: array<Vertex>;
@group(0) @binding(2) var<storage, read> draws: array<Draw>;
@group(0) @binding(3) var<storage, read> materials: array<Material>;
@group(0) @binding(4) var textures: texture_2d_array<f32>;
@group(0) @binding(5) var texture_sampler: sampler;
@group(0) @binding(6) var<storage, read> points: array<Point>;
// Per point: how far its neighbours stray from its tangent plane, metres (scan noise).
@group(0) @binding(7) var<storage, read> point_spread: array<f32>;
// Per draw, its model matrix in the previous frame.
@group(0) @binding(8) var<storage, read> prev_models: array<mat4x4<f32>>;
// Per point of a scene with dynamic clouds: where it was at the last frame, less where it is
// (xyz; zero where it did not move). One element, never read, in a scene without.
@group(0) @binding(9) var<storage, read> point_motion: array<vec4<f32>>;

struct VsOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) normal: vec3<f32>,
    @location(1) uv: vec2<f32>,
    @location(2) @interpolate(flat) draw: u32,
    // Clip positions without the jitter, now and in the last frame; world position then.
    @location(3) now: vec4<f32>,
    @location(4) then: vec4<f32>,
    @location(5) then_world: vec3<f32>,
}

@vertex
fn vs_main(@builtin(vertex_index) vi: u32, @builtin(instance_index) di: u32) -> VsOut {
    let v = vertices[vi];
    let d = draws[di];
    var out: VsOut;
    let world = d.model * vec4<f32>(v.position, 1.0);
    let then_world = prev_models[di] * vec4<f32>(v.position, 1.0);
    out.clip = frame.view_proj * world;
    out.now = frame.view_proj_unjittered * world;
    out.then = frame.prev_view_proj * then_world;
    out.then_world = then_world.xyz;
    out.normal = (d.normal_matrix * vec4<f32>(v.normal, 0.0)).xyz;
    out.uv = vec2<f32>(v.u, v.v);
    out.draw = di;
    return out;
}

struct GBuffer {
    @location(0) albedo_metallic: vec4<f32>,
    @location(1) normal_roughness: vec4<f32>,
    @location(2) emission: vec4<f32>,
    @location(3) motion: vec4<f32>,
}

// Screen motion in pixels from the last frame to this one, the surface's distance from the
// last frame's camera, and 1 (background stays cleared to 0).
fn motion(now: vec4<f32>, then: vec4<f32>, then_world: vec3<f32>) -> vec4<f32> {
    let ndc = now.xy / now.w - then.xy / then.w;
    let px = ndc * vec2<f32>(0.5, -0.5) * frame.size;
    return vec4<f32>(px, length(then_world - frame.prev_camera_pos), 1.0);
}

@fragment
fn fs_main(in: VsOut, @builtin(front_facing) front: bool) -> GBuffer {
    let m = materials[draws[in.draw].material];
    // Sample unconditionally (derivatives need uniform control flow), then select.
    let base_t = textureSample(textures, texture_sampler, in.uv, max(m.base_texture, 0));
    let emit_t = textureSample(textures, texture_sampler, in.uv, max(m.emissive_texture, 0));
    var base = m.base_color;
    if m.base_texture >= 0 {
        base *= base_t;
    }
    if base.a < m.alpha_cutoff {
        discard;
    }
    var emission = m.emissive;
    if m.emissive_texture >= 0 {
        emission *= emit_t.rgb;
    }
    // Back faces show their reverse side: flip the normal so it faces the viewer. An area
    // light's surface emits on the light's side only, as the light itself does.
    var n = normalize(in.normal);
    if !front {
        n = -n;
        if draws[in.draw].light != NO_INDEX {
            emission = vec3<f32>(0.0);
        }
    }
    var out: GBuffer;
    out.albedo_metallic = vec4<f32>(base.rgb, m.metallic);
    out.normal_roughness = vec4<f32>(n, m.roughness);
    out.emission = vec4<f32>(emission, m.specular);
    out.motion = motion(in.now, in.then, in.then_world);
    return out;
}

// Surfels: point `vertex_index / 6`, corner `vertex_index % 6`.
struct PointOut {
    @builtin(position) clip: vec4<f32>,
    // Position in the disc, in radii: outside the unit circle is discarded.
    @location(0) disc: vec2<f32>,
    @location(1) @interpolate(flat) normal: vec3<f32>,
    @location(2) @interpolate(flat) albedo: vec3<f32>,
    @location(3) @interpolate(flat) emission: vec3<f32>,
    @location(4) now: vec4<f32>,
    @location(5) then: vec4<f32>,
    @location(6) world: vec3<f32>,
}

@vertex
fn vs_points(@builtin(vertex_index) vi: u32) -> PointOut {
    let p = points[vi / 6u];
    let to_camera = frame.camera_pos - p.position;
    var n = point_normal(p);
    var emission = point_emission(p);
    if dot(n, n) == 0.0 {
        // No normal: face the camera.
        n = normalize(to_camera);
    } else if dot(n, to_camera) < 0.0 {
        // The side the camera sees; an area light's surface does not emit on its back.
        n = -n;
        if vi / 6u >= frame.geometry_points {
            emission = vec3<f32>(0.0);
        }
    }
    let corner = surfel_corner(vi);
    // A surfel is drawn at the front of its neighbourhood's spread, along its own normal: the
    // voxels hold the neighbourhood's surface, so cones and shadow lookups leaving a noisy
    // scan's surfel that lay behind it started inside it (blotches of occlusion all over the
    // office scan's walls). Along the normal as the file or the estimate has it, not as turned
    // to the camera: the back faces of thin things move back, behind their front faces. At
    // most a radius: on a finely curved clean surface (the dragon's scales) the spread measures
    // curvature, not noise, and a full push swelled the model and opened gaps between discs.
    // Flat clean surfaces have no spread and stay where they are.
    var q = p;
    q.position += point_normal(p) * min(point_spread[vi / 6u], p.radius);
    var out: PointOut;
    let world = vec4<f32>(surfel_world(q, n, corner), 1.0);
    // A moving cloud's surfel was where its point was at the last frame (the disc's turn is
    // left out of the motion vector).
    var moved = vec3<f32>(0.0);
    if arrayLength(&point_motion) > vi / 6u {
        moved = point_motion[vi / 6u].xyz;
    }
    out.clip = frame.view_proj * world;
    out.now = frame.view_proj_unjittered * world;
    out.then = frame.prev_view_proj * vec4<f32>(world.xyz + moved, 1.0);
    out.world = world.xyz;
    out.disc = corner;
    out.normal = n;
    out.albedo = point_albedo(p);
    out.emission = emission;
    return out;
}

@fragment
fn fs_points(in: PointOut) -> GBuffer {
    if dot(in.disc, in.disc) > 1.0 {
        discard;
    }
    var out: GBuffer;
    out.albedo_metallic = vec4<f32>(in.albedo, 0.0);
    out.normal_roughness = vec4<f32>(in.normal, 1.0);
    // Specular 0.5: scans are mostly matte; half the dielectric default keeps a faint sheen.
    out.emission = vec4<f32>(in.emission, 0.5);
    out.motion = motion(in.now, in.then, in.world);
    return out;
}
