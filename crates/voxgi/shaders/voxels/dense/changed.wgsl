// The voxels the next filter redoes, in the volume's counters (`counters`,
// array<atomic<u32>>, declared by the includer). For each level above the finest: a bit per
// voxel, set once a child of it changed, and the list of the voxels whose bits were set (each
// once), counted in the level's header. The finest level's writers list the level above
// (`mark_changed`); the filter lists each level's parents as it redoes it (filter.wgsl).
// DenseVolume's `filter::counter_bytes` is the twin of this layout. `windows` cubes of `res`
// voxels a side are stacked along z (`Volume::windows`): a level's voxels are all of theirs.

// Voxels the last filter redid (one for all its directions; 0 when it redid everything).
const REDONE: u32 = 6u;
// Per level above the finest (the first at index 0): how many voxels its list holds.
const COUNTS: u32 = 8u;
const MAX_LEVELS: u32 = 10u;
// After the slot pool's words per window (slots.wgsl, eight windows of four words): the
// levels' bits, then their lists.
const BITS: u32 = COUNTS + MAX_LEVELS + 32u;

// Levels above the finest of a volume `res` voxels a side (a power of two).
fn levels_above(res: u32) -> u32 {
    return firstLeadingBit(res);
}

fn level_voxels(res: u32, windows: u32, l: u32) -> u32 {
    let n = res >> l;
    return n * n * n * windows;
}

fn bit_words(res: u32, windows: u32, l: u32) -> u32 {
    return (level_voxels(res, windows, l) + 31u) / 32u;
}

// Where level `l`'s bits begin.
fn bits_of(res: u32, windows: u32, l: u32) -> u32 {
    var b = BITS;
    for (var j = 1u; j < l; j++) {
        b += bit_words(res, windows, j);
    }
    return b;
}

// Where level `l`'s list begins: after every level's bits.
fn list_of(res: u32, windows: u32, l: u32) -> u32 {
    var b = bits_of(res, windows, levels_above(res) + 1u);
    for (var j = 1u; j < l; j++) {
        b += level_voxels(res, windows, j);
    }
    return b;
}

// The voxel of level `l` at `c` has a changed child: listed for the filter, once.
fn mark_level(res: u32, windows: u32, l: u32, c: vec3<u32>) {
    let n = res >> l;
    let i = c.x + n * (c.y + n * c.z);
    let w = bits_of(res, windows, l) + i / 32u;
    let bit = 1u << (i % 32u);
    // Loads first: once the bit is set, no atomic write contends.
    if (atomicLoad(&counters[w]) & bit) != 0u || (atomicOr(&counters[w], bit) & bit) != 0u {
        return;
    }
    let k = atomicAdd(&counters[COUNTS + l - 1u], 1u);
    atomicStore(&counters[list_of(res, windows, l) + k], i);
}

// Finest voxel `c` of a volume `res` a side (in `windows` stacked cubes) was written.
fn mark_changed(c: vec3<u32>, res: u32, windows: u32) {
    mark_level(res, windows, 1u, c >> vec3<u32>(1u));
}
