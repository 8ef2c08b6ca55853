// The box of finest voxels written since the last filter, in the volume's counters
// (`counters`, array<atomic<u32>>, declared by the includer): the filter redoes only the
// levels' voxels above it. Stored so that all zeros is the empty box:
// counters[CHANGED..CHANGED + 3] hold u32::MAX - the lowest corner,
// counters[CHANGED + 4..CHANGED + 7] the highest corner + 1; both grow by atomicMax.

const CHANGED: u32 = 8u;

fn mark_changed(c: vec3<u32>) {
    for (var k = 0u; k < 3u; k++) {
        // Loads first: once the box holds the voxel, no atomic write contends.
        let lo = 0xffffffffu - c[k];
        if atomicLoad(&counters[CHANGED + k]) < lo {
            atomicMax(&counters[CHANGED + k], lo);
        }
        if atomicLoad(&counters[CHANGED + 4u + k]) < c[k] + 1u {
            atomicMax(&counters[CHANGED + 4u + k], c[k] + 1u);
        }
    }
}
