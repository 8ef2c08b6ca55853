// gbuffer: rasterizes every mesh instance into albedo/metallic, normal/roughness, emission and
// depth.

//!include shared/scene.wgsl

@group(0) @binding(0) var<uniform> frame: Frame;
@group(0) @binding(1) var<storage, read> vertices: array<Vertex>;
@group(0) @binding(2) var<storage, read> draws: array<Draw>;
@group(0) @binding(3) var<storage, read> materials: array<Material>;
@group(0) @binding(4) var textures: texture_2d_array<f32>;
@group(0) @binding(5) var texture_sampler: sampler;

struct VsOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) normal: vec3<f32>,
    @location(1) uv: vec2<f32>,
    @location(2) @interpolate(flat) draw: u32,
}

@vertex
fn vs_main(@builtin(vertex_index) vi: u32, @builtin(instance_index) di: u32) -> VsOut {
    let v = vertices[vi];
    let d = draws[di];
    var out: VsOut;
    out.clip = frame.view_proj * (d.model * vec4<f32>(v.position, 1.0));
    out.normal = (d.normal_matrix * vec4<f32>(v.normal, 0.0)).xyz;
    out.uv = vec2<f32>(v.u, v.v);
    out.draw = di;
    return out;
}

struct GBuffer {
    @location(0) albedo_metallic: vec4<f32>,
    @location(1) normal_roughness: vec4<f32>,
    @location(2) emission: vec4<f32>,
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
    // Back faces show their reverse side: flip the normal so it faces the viewer.
    var n = normalize(in.normal);
    if !front {
        n = -n;
    }
    var out: GBuffer;
    out.albedo_metallic = vec4<f32>(base.rgb, m.metallic);
    out.normal_roughness = vec4<f32>(n, m.roughness);
    out.emission = vec4<f32>(emission, m.specular);
    return out;
}
