// Where the clipmap's leaves lie (voxels/dense/leaves.wgsl includes it): leaf coordinates run
// through the stacked windows, level k's at z in [k, k + 1) * resolution, and a leaf has its
// level's voxel edge. `leaf_clip` is @group(2) binding 8 (`Clipmap::leaves_layout`).

//!include voxels/levels.wgsl

@group(2) @binding(8) var<uniform> leaf_clip: ClipLevels;

fn leaf_level(i: u32) -> u32 {
    return min(leaf_coord(i).z / leaf_clip.resolution, leaf_clip.count - 1u);
}

fn leaf_center(i: u32) -> vec3<f32> {
    let c = leaf_coord(i);
    let k = leaf_level(i);
    let local = vec3<u32>(c.xy, c.z - k * leaf_clip.resolution);
    let l = leaf_clip.levels[k];
    return l.xyz + (vec3<f32>(local) + 0.5) * l.w;
}

fn leaf_size(i: u32) -> f32 {
    return leaf_clip.levels[leaf_level(i)].w;
}

fn leaf_size_max() -> f32 {
    return leaf_clip.levels[leaf_clip.count - 1u].w;
}

// Window `w` (level w) was rebuilt alone by the last build: every leaf of it is new.
fn leaf_window_rebuilt(w: u32) -> bool {
    return (leaf_clip.rebuilt & (1u << w)) != 0u;
}
