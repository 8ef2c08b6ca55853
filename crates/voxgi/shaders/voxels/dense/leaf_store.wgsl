// Writing a leaf's radiance into the dense volume's finest level (as optical depth). A separate
// group, @group(3): a pass that samples the volume cannot also write it.

//!include voxels/leaves.wgsl
//!include shared/half.wgsl

//!include voxels/changed.wgsl

@group(3) @binding(0) var leaf_radiance_out: texture_storage_3d<rgba16float, write>;

// `v`: premultiplied radiance (rgb) and opacity. The voxel's parent is listed for the next
// filter.
fn store_leaf_radiance(i: u32, v: vec4<f32>) {
    let c = leaf_coord(i);
    textureStore(leaf_radiance_out, c, to_half(to_depth(v)));
    mark_changed(c, leaf_grid.resolution, leaf_grid.windows);
}
