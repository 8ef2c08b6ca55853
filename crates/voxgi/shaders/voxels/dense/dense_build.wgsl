// dense_build: voxel fragments -> the dense volume's finest level. Integer atomics average the
// fragments of each voxel, so the result does not depend on thread order (deterministic).
//
// Entry points, in the order the host runs them:
//   begin           remember the previous slot count, reset the counters
//   clear_previous  zero the voxels the previous build filled (cheaper than clearing N^3)
//   prepare_fragments / prepare_slots  indirect dispatch sizes from the counters
//   allocate        one slot per occupied voxel
//   accumulate      integer sums per slot
//   resolve         averages -> albedo/opacity, normal, emission textures
//
// The slots it allocates are the static ones (`counters[2]`); dense_update merges the dynamic
// geometry's fragments on top.

//!include voxels/build_shared.wgsl

@compute @workgroup_size(1)
fn begin() {
    atomicStore(&counters[1], atomicLoad(&counters[0]));
    atomicStore(&counters[0], 0u);
    atomicStore(&counters[2], 0u);
    atomicStore(&counters[3], 0u);
    atomicStore(&counters[4], 0u);
    atomicStore(&counters[5], 0u);
}

@compute @workgroup_size(1)
fn prepare_fragments() {
    // The build's fragments are the static geometry's: updates take those past them.
    atomicStore(&counters[5], fragment_count[0]);
    write_args(3u, stored_fragments());
}

@compute @workgroup_size(1)
fn prepare_slots() {
    // Every slot so far is the static geometry's. Kept as counted (past the capacity), so an
    // overflow still shows in counters[0] after an update frees the dynamic slots.
    let slots = atomicLoad(&counters[0]);
    atomicStore(&counters[2], slots);
    write_args(0u, min(slots, slot_limit()));
}

@compute @workgroup_size(64)
fn clear_previous(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let s = flat(gid, nwg);
    if s >= min(atomicLoad(&counters[1]), arrayLength(&slot_voxel)) {
        return;
    }
    clear_voxel(voxel_coord(slot_voxel[s], vol.resolution));
}

@compute @workgroup_size(64)
fn allocate(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = flat(gid, nwg);
    if i >= stored_fragments() {
        return;
    }
    let v = voxel_index(unpack_coord(fragments[i].coord), vol.resolution);
    // The first fragment of a voxel takes it; the weak exchange may fail spuriously, so retry
    // while the voxel is still unclaimed.
    for (var tries = 0u; tries < 64u; tries++) {
        let r = atomicCompareExchangeWeak(&occupancy[v], 0u, LOCKED);
        if r.exchanged {
            // Counted even past the capacity, so the host can see how many slots it needs;
            // voxels beyond it stay unallocated (LOCKED) and are skipped.
            let s = atomicAdd(&counters[0], 1u);
            if s < arrayLength(&slot_voxel) {
                slot_voxel[s] = v;
                atomicStore(&occupancy[v], s + 2u);
            }
            return;
        }
        if r.old_value != 0u {
            return;
        }
    }
}

@compute @workgroup_size(64)
fn accumulate(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = flat(gid, nwg);
    if i >= stored_fragments() {
        return;
    }
    let f = fragments[i];
    let v = voxel_index(unpack_coord(f.coord), vol.resolution);
    let o = atomicLoad(&occupancy[v]);
    if o < 2u || o == LOCKED {
        return;
    }
    add_fragment(o - 2u, f, false);
}

@compute @workgroup_size(64)
fn resolve(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let s = flat(gid, nwg);
    if s >= min(atomicLoad(&counters[0]), arrayLength(&slot_voxel)) {
        return;
    }
    resolve_slot(s, false);
}
