// shadow: renders one shadow view (a layer of the shadow atlas) as occluder distances.

//!include shared/scene.wgsl

@group(0) @binding(0) var<uniform> view: ShadowView;
@group(0) @binding(1) var<storage, read> vertices: array<Vertex>;
@group(0) @binding(2) var<storage, read> draws: array<Draw>;

struct VsOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
}

@vertex
fn vs_main(@builtin(vertex_index) vi: u32, @builtin(instance_index) di: u32) -> VsOut {
    let world = draws[di].model * vec4<f32>(vertices[vi].position, 1.0);
    var out: VsOut;
    out.clip = view.view_proj * world;
    out.world = world.xyz;
    return out;
}

@fragment
fn fs_main(in: VsOut) -> @location(0) f32 {
    if dot(view.plane.xyz, in.world) + view.plane.w < 0.0 {
        discard;
    }
    if view.kind == SHADOW_ORTHO {
        return dot(in.world - view.origin, view.dir);
    }
    return length(in.world - view.origin);
}
