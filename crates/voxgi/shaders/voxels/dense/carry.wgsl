// Where a new leaf's bounced light can start from (the bounce's `mark`, with bounce slices):
//
//   fn leaf_carry_source(i) -> u32     a leaf that is not new and whose kept irradiance stands
//                                      in for new leaf i's until i gathers in its turn, or
//                                      NO_LEAF (leaves.wgsl; i gathers at once)
//
// With the structure's irradiance lookup group at @group(3) (`irradiance_layout`) if it reads
// one. The dense volume is built whole: a new leaf is a moved instance's, and gathers at once.

fn leaf_carry_source(i: u32) -> u32 {
    return NO_LEAF;
}
