// Writing a leaf's radiance into the dense volume's finest level (as optical depth). A separate
// group, @group(3): a pass that samples the volume cannot also write it.

//!include voxels/leaves.wgsl
//!include shared/half.wgsl

@group(3) @binding(0) var leaf_radiance_out: texture_storage_3d<rgba16float, write>;

// `v`: premultiplied radiance (rgb) and opacity.
fn store_leaf_radiance(i: u32, v: vec4<f32>) {
    textureStore(leaf_radiance_out, leaf_coord(i), to_half(to_depth(v)));
}
