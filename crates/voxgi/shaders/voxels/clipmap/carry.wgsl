// Where a new leaf's bounced light can start from (the names of voxels/dense/carry.wgsl): a
// leaf of a level the last voxel work rebuilt alone starts from the leaf of the next coarser
// level around its centre, which saw the same surroundings with a wider voxel, until it gathers
// in its turn; so a window that moves need not gather all its leaves at once. Where the moved
// window overlaps its old place, a leaf keeps the light of the leaf that held its voxel there
// (the same voxel of the same lattice: `leaf_kept_self`), so only the slab newly inside starts
// from the coarser light. At @group(3) (`Clipmap::carry_layout`): the volume's occupancy
// (binding 0) and, for the level `leaf_clip.kept`, its window's occupancy before the build
// (binding 2).

// Per voxel of the stacked windows (x fastest): 0 empty, 2 + slot once allocated.
@group(3) @binding(0) var<storage, read> carry_occupancy: array<u32>;
// Window `leaf_clip.kept`'s occupancy before its last build (x fastest), at its old place.
@group(3) @binding(2) var<storage, read> kept_occupancy: array<u32>;

fn leaf_kept_self(i: u32) -> u32 {
    let k = leaf_level(i);
    if k != leaf_clip.kept {
        return NO_LEAF;
    }
    let r = i32(leaf_clip.resolution);
    let c = leaf_coord(i);
    let old = vec3<i32>(i32(c.x), i32(c.y), i32(c.z) - i32(k) * r) + leaf_clip.kept_by.xyz;
    if any(old < vec3<i32>(0)) || any(old >= vec3<i32>(r)) {
        return NO_LEAF;
    }
    let occ = kept_occupancy[voxel_index(vec3<u32>(old), u32(r))];
    // Empty, or locked past the capacity.
    if occ < 2u || occ == 0xffffffffu {
        return NO_LEAF;
    }
    return occ - 2u;
}

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
