// The ground grid over the cone-traced view: the plane y = height under the scene, lines every
// `spacing` metres and every tenth line stronger, the X axis red and the Z axis blue as
// Blender draws them, hidden where the renderer's depth says the scene is nearer. A full-screen
// triangle: each pixel's ray meets the plane, or draws nothing.

struct Grid {
    view_proj: mat4x4<f32>,
    inv_view_proj: mat4x4<f32>,
    // x: the plane's height, y: minor spacing, z: distance at which the grid has faded out.
    plane: vec4<f32>,
    // xy: the target's size in pixels; zw: the depth's size over it (a moving view is drawn
    // smaller).
    size: vec4<f32>,
};

@group(0) @binding(0) var<uniform> g: Grid;
@group(0) @binding(1) var depth: texture_depth_2d;

@vertex
fn vs_main(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    let uv = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u));
    return vec4<f32>(uv * 2.0 - 1.0, 0.0, 1.0);
}

fn unproject(ndc: vec2<f32>, z: f32) -> vec3<f32> {
    let p = g.inv_view_proj * vec4<f32>(ndc, z, 1.0);
    return p.xyz / p.w;
}

// Coverage of lines every `spacing` along x and z at `xz`, antialiased over a pixel.
fn lines(xz: vec2<f32>, spacing: f32) -> f32 {
    let c = xz / spacing;
    let w = max(fwidth(c), vec2<f32>(1e-6));
    let d = abs(fract(c - 0.5) - 0.5) / w;
    return 1.0 - min(min(d.x, d.y), 1.0);
}

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let ndc = vec2<f32>(pos.x / g.size.x * 2.0 - 1.0, 1.0 - pos.y / g.size.y * 2.0);
    let near = unproject(ndc, 0.0);
    let far = unproject(ndc, 1.0);
    let dir = far - near;
    let height = g.plane.x;
    let spacing = g.plane.y;
    // Where the ray meets the plane, as a fraction of the way from the near to the far plane.
    let t = select(-1.0, (height - near.y) / dir.y, abs(dir.y) > 1e-12);
    let p = near + dir * max(t, 0.0);
    let xz = p.xz;
    // Derivatives before anything that depends on the pixel decides: uniform control flow.
    let minor = lines(xz, spacing);
    let major = lines(xz, spacing * 10.0);
    let w = max(fwidth(xz), vec2<f32>(1e-9));
    let x_axis = 1.0 - min(abs(xz.y) / w.y, 1.0);
    let z_axis = 1.0 - min(abs(xz.x) / w.x, 1.0);
    // Lines closer together than a few pixels fade out rather than shimmer.
    let density = max(w.x, w.y) / spacing;
    let dense = 1.0 - smoothstep(0.15, 0.5, density);

    let scene_z = textureLoad(depth, vec2<i32>(pos.xy * g.size.zw), 0);
    let scene = unproject(ndc, scene_z);
    let hit = length(p - near);
    // In front of what the renderer drew (or on it: the floor the grid lies on), within a
    // sliver for the depth buffer's precision; nothing drawn (depth 1) hides nothing.
    let visible = scene_z >= 1.0 || hit <= length(scene - near) * 1.002 + spacing * 0.01;
    let fade = 1.0 - smoothstep(0.3 * g.plane.z, g.plane.z, hit);

    var colour = vec3<f32>(0.75);
    var alpha = max(minor * 0.22 * dense, major * 0.45);
    if x_axis > 0.0 {
        colour = mix(colour, vec3<f32>(0.9, 0.3, 0.3), x_axis);
        alpha = max(alpha, x_axis * 0.8);
    }
    if z_axis > 0.0 {
        colour = mix(colour, vec3<f32>(0.3, 0.5, 0.95), z_axis);
        alpha = max(alpha, z_axis * 0.8);
    }
    alpha *= fade;
    if t <= 0.0 || t >= 1.0 || !visible || alpha <= 0.002 {
        discard;
    }
    return vec4<f32>(colour * alpha, alpha);
}
