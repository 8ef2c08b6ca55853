// Where a new leaf's bounced light can start from (the names of voxels/dense/carry.wgsl): a
// leaf of a level the last voxel work rebuilt alone starts from the leaf of the next coarser
// level around its centre, which saw the same surroundings with a wider voxel, until it gathers
// in its turn; so a window that moves need not gather all its leaves at once. At @group(3): the
// volume's occupancy, the binding 0 of `irradiance_layout`.

// Per voxel of the stacked windows (x fastest): 0 empty, 2 + slot once allocated.
@group(3) @binding(0) var<storage, read> carry_occupancy: array<u32>;

fn leaf_carry_source(i: u32) -> u32 {
    let k = leaf_level(i);
    if !leaf_window_rebuilt(k) || k + 1u >= leaf_clip.count {
        return NO_LEAF;
    }
    let l = leaf_clip.levels[k + 1u];
    let r = leaf_clip.resolution;
    let q = (leaf_center(i) - l.xyz) / l.w;
    if any(q < vec3<f32>(0.0)) || any(q >= vec3<f32>(f32(r))) {
        return NO_LEAF;
    }
    let c = min(vec3<u32>(q), vec3<u32>(r - 1u)) + vec3<u32>(0u, 0u, (k + 1u) * r);
    let occ = carry_occupancy[voxel_index(c, r)];
    // Empty, or locked past the capacity.
    if occ < 2u || occ == 0xffffffffu {
        return NO_LEAF;
    }
    let t = occ - 2u;
    // A leaf new itself (its level rebuilt too, or a moved instance's) has nothing kept.
    if !leaf_exists(t) || leaf_is_new(t) {
        return NO_LEAF;
    }
    return t;
}
