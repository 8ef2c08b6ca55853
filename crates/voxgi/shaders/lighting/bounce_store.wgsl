// bounce_store: writes the bounced radiance of every leaf into the structure.

//!include shared/volume.wgsl
//!include voxels/leaf_store.wgsl

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let s = leaf_slot(dispatch_index(gid, nwg));
    if s == NO_LEAF {
        return;
    }
    store_leaf_radiance(s, leaf_next[s]);
}
