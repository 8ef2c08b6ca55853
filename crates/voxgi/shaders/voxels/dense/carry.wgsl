// Where a new leaf's bounced light can start from (the bounce's `mark`, with bounce slices):
//
//   fn leaf_carry_source(i) -> u32     a leaf that is not new and whose kept irradiance stands
//                                      in for new leaf i's until i gathers in its turn, or
//                                      NO_LEAF (leaves.wgsl; i gathers at once)
//   fn leaf_kept_self(i) -> u32        the slot whose leaf held new leaf i's voxel before the
//                                      last build of part of the structure (its kept light is
//                                      i's, read by the bounce's `stash` before any is
//                                      written), or NO_LEAF
//
// With the structure's carry group at @group(3) (`KindInfo::carry_layout`) if it reads
// one. The dense volume is built whole: a new leaf is a moved instance's, and gathers at once.

fn leaf_carry_source(i: u32) -> u32 {
    return NO_LEAF;
}

fn leaf_kept_self(i: u32) -> u32 {
    return NO_LEAF;
}
