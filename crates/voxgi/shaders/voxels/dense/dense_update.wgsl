// dense_update: the dynamic geometry's fragments merged into the static build, undoing the
// previous update first, so that a volume updated any number of times holds what a build of
// the final state would: the sums are integers, static and dynamic added exactly.
//
// Entry points, in the order the host runs them:
//   begin        the previous update's `touched` becomes the list to restore; dispatch sizes
//   restore      per previously touched slot: drop its dynamic sums; a static slot gets its
//                static average back, a dynamic one is emptied and freed
//   allocate     per dynamic fragment: a new slot for an empty voxel, or the static slot it
//                shares marked as touched
//   accumulate   the dynamic sums
//   prepare      dispatch sizes over the slots and the touched list
//   resolve      per touched slot: static plus dynamic sums -> the finest level

//!include voxels/build_shared.wgsl

fn dynamic_fragments() -> vec2<u32> {
    return vec2<u32>(min(atomicLoad(&counters[5]), arrayLength(&fragments)), stored_fragments());
}

@compute @workgroup_size(1)
fn begin() {
    let previous = min(atomicLoad(&counters[3]), slot_limit());
    atomicStore(&counters[4], previous);
    atomicStore(&counters[3], 0u);
    write_args(6u, previous);
    let range = dynamic_fragments();
    write_args(3u, range.y - min(range.x, range.y));
}

@compute @workgroup_size(64)
fn restore(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = flat(gid, nwg);
    if i >= atomicLoad(&counters[4]) {
        return;
    }
    let s = touched(i);
    // Not the list word: other threads are reading the list.
    for (var k = 0u; k < DYN_LIST; k++) {
        atomicStore(&dyn_accum[s * DYN_STRIDE + k], 0u);
    }
    if slot_static(s, vol.windows) {
        resolve_slot(s, false);
    } else {
        let v = slot_voxel[s];
        clear_voxel(voxel_coord(v, vol.resolution));
        atomicStore(&occupancy[v], 0u);
    }
}

// After `restore`: the slots above the static ones are free again.
@compute @workgroup_size(1)
fn free() {
    for (var w = 0u; w < vol.windows; w++) {
        atomicStore(&counters[window_word(w, W_COUNT)], atomicLoad(&counters[window_word(w, W_STATIC)]));
    }
}

fn push_touched(s: u32) {
    let t = atomicAdd(&counters[3], 1u);
    if t < slot_limit() {
        atomicStore(&dyn_accum[t * DYN_STRIDE + DYN_LIST], s);
    }
}

@compute @workgroup_size(64)
fn allocate(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let range = dynamic_fragments();
    let i = range.x + flat(gid, nwg);
    if i >= range.y {
        return;
    }
    let v = voxel_index(unpack_coord(fragments[i].coord), vol.resolution);
    for (var tries = 0u; tries < 64u; tries++) {
        let r = atomicCompareExchangeWeak(&occupancy[v], 0u, LOCKED);
        if r.exchanged {
            let s = take_slot(v);
            if s < slot_limit() {
                slot_voxel[s] = v;
                atomicStore(&occupancy[v], s + 2u);
                push_touched(s);
            }
            return;
        }
        if r.old_value == LOCKED {
            // Another fragment is allocating this voxel and lists it.
            return;
        }
        if r.old_value != 0u {
            let s = r.old_value - 2u;
            // A static voxel the dynamic geometry shares: listed once.
            if slot_static(s, vol.windows) && atomicExchange(&dyn_accum[s * DYN_STRIDE + DYN_FLAG], 1u) == 0u {
                push_touched(s);
            }
            return;
        }
    }
}

@compute @workgroup_size(64)
fn accumulate(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let range = dynamic_fragments();
    let i = range.x + flat(gid, nwg);
    if i >= range.y {
        return;
    }
    let f = fragments[i];
    let v = voxel_index(unpack_coord(f.coord), vol.resolution);
    let o = atomicLoad(&occupancy[v]);
    if o < 2u || o == LOCKED {
        return;
    }
    add_fragment(o - 2u, f, true);
}

@compute @workgroup_size(1)
fn prepare() {
    count_windows();
    write_args(6u, min(atomicLoad(&counters[3]), slot_limit()));
}

@compute @workgroup_size(64)
fn resolve(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = flat(gid, nwg);
    if i >= min(atomicLoad(&counters[3]), slot_limit()) {
        return;
    }
    resolve_slot(touched(i), true);
}
