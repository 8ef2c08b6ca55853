// bounce_store: writes the bounced radiance of every occupied voxel into the finest level.

//!include shared/volume.wgsl

@group(0) @binding(0) var<uniform> vol: Volume;
@group(0) @binding(1) var<storage, read> slot_voxel: array<u32>;
@group(0) @binding(2) var<storage, read> counters: array<u32>;
@group(0) @binding(3) var<storage, read> slot_next: array<vec4<f32>>;
@group(0) @binding(4) var radiance_out: texture_storage_3d<rgba16float, write>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let s = gid.x + gid.y * nwg.x * 64u;
    if s >= min(counters[0], arrayLength(&slot_voxel)) {
        return;
    }
    textureStore(radiance_out, voxel_coord(slot_voxel[s], vol.resolution), to_depth(slot_next[s]));
}
