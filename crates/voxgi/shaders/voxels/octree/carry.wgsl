// Where a new leaf's bounced light can start from: the names of voxels/dense/carry.wgsl. The
// octree is built whole: a new leaf is a moved instance's, and gathers at once.

fn leaf_carry_source(i: u32) -> u32 {
    return NO_LEAF;
}

fn leaf_kept_self(i: u32) -> u32 {
    return NO_LEAF;
}
