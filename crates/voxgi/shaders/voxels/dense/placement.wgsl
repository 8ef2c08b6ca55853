// Where the dense volume's leaves lie (voxels/dense/leaves.wgsl includes it): in its one grid.

fn leaf_center(i: u32) -> vec3<f32> {
    return voxel_center(leaf_coord(i), leaf_grid);
}

fn leaf_size(i: u32) -> f32 {
    return leaf_grid.voxel_size;
}

fn leaf_size_max() -> f32 {
    return leaf_grid.voxel_size;
}

// The volume is always built whole: its leaves are new only where an update made them.
fn leaf_window_rebuilt(w: u32) -> bool {
    return false;
}
