// dense_build: voxel fragments -> the dense volume's finest level. Integer atomics average the
// fragments of each voxel, so the result does not depend on thread order (deterministic).
//
// Entry points, in the order the host runs them (after dense_update's restore has taken the
// last update out, and with the windows to rebuild in counters[REBUILD]: all of them, or the
// levels a clipmap moves this frame; every other window keeps its slots and sums):
//   begin           remember each rebuilt window's slot count, reset it; the clear's dispatch
//   clear_previous  zero the voxels the rebuilt windows filled (cheaper than clearing N^3)
//   keep            a moved window's voxels that lay in it before: their slots again, with
//                   their static sums (the fragments are only the other voxels') and their
//                   direct light
//   prepare_fragments / prepare_slots  indirect dispatch sizes from the counters
//   allocate        one slot per occupied voxel, in its window's part of the pool
//   accumulate      integer sums per slot
//   resolve         averages -> albedo/opacity, normal, emission textures
//
// The slots it allocates are the static ones (each window's W_STATIC); dense_update merges the
// dynamic geometry's fragments on top.

//!include voxels/build_shared.wgsl

@compute @workgroup_size(1)
fn begin() {
    var end = 0u;
    let c = window_slots(vol.windows);
    for (var w = 0u; w < vol.windows; w++) {
        if !rebuilding(w) {
            continue;
        }
        let n = atomicLoad(&counters[window_word(w, W_COUNT)]);
        atomicStore(&counters[window_word(w, W_PREVIOUS)], n);
        atomicStore(&counters[window_word(w, W_COUNT)], 0u);
        atomicStore(&counters[window_word(w, W_STATIC)], 0u);
        if n > 0u {
            end = w * c + min(n, c);
        }
    }
    atomicStore(&counters[3], 0u);
    atomicStore(&counters[4], 0u);
    atomicStore(&counters[5], 0u);
    write_args(0u, end);
}

@compute @workgroup_size(1)
fn prepare_fragments() {
    // Every slot a rebuilt window holds so far is one `keep` took (the first of its part).
    let c = window_slots(vol.windows);
    for (var w = 0u; w < vol.windows; w++) {
        if rebuilding(w) {
            atomicStore(&counters[window_word(w, W_KEPT)], min(atomicLoad(&counters[window_word(w, W_COUNT)]), c));
        }
    }
    // The build's fragments are the static geometry's: updates take those past them.
    atomicStore(&counters[5], atomicLoad(&counters[FRAGMENTS]));
    write_args(3u, stored_fragments());
}

@compute @workgroup_size(1)
fn prepare_slots() {
    // Every slot so far is the static geometry's. Kept as counted (past the capacity), so an
    // overflow still shows after an update frees the dynamic slots.
    for (var w = 0u; w < vol.windows; w++) {
        if rebuilding(w) {
            atomicStore(&counters[window_word(w, W_STATIC)], atomicLoad(&counters[window_word(w, W_COUNT)]));
        }
    }
    count_windows();
}

// Slot `s` lies in a rebuilt window, below `word`'s count of it: the window's slot and whether.
fn rebuilt_slot(s: u32, word: u32) -> bool {
    let c = window_slots(vol.windows);
    let w = s / c;
    return w < vol.windows && rebuilding(w)
        && s - w * c < min(atomicLoad(&counters[window_word(w, word)]), c);
}

@compute @workgroup_size(64)
fn clear_previous(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let s = flat(gid, nwg);
    if !rebuilt_slot(s, W_PREVIOUS) {
        return;
    }
    clear_voxel(voxel_coord(slot_voxel[s], vol.resolution));
}

@compute @workgroup_size(64)
fn keep(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    if kept[0] == 0u {
        return;
    }
    let w = kept[0] - 1u;
    let r = vol.resolution;
    let part = window_slots(vol.windows);
    // A thread per static slot the window had (the last update's were freed before the build;
    // `begin` kept their count): the threads take slots about in the old slots' order, so the
    // leaves keep about the order their fragments gave them, which the lighting passes'
    // workgroups gather in (in voxel order the town's bounce ran slower).
    let t = flat(gid, nwg);
    if t >= min(atomicLoad(&counters[window_word(w, W_PREVIOUS)]), part) {
        return;
    }
    let old = voxel_coord(kept[KEPT_OCCUPANCY + r * r * r + t] - w * r * r * r, r);
    let c = vec3<i32>(old) - kept_by();
    if any(c < vec3<i32>(0)) || any(c >= vec3<i32>(i32(r))) {
        return;
    }
    let v = voxel_index(vec3<u32>(c) + vec3<u32>(0u, 0u, w * r), r);
    // Voxels beyond the capacity stay locked, as `allocate` leaves them.
    atomicStore(&occupancy[v], LOCKED);
    let s = take_slot(v);
    if s >= slot_limit() {
        return;
    }
    slot_voxel[s] = v;
    atomicStore(&occupancy[v], s + 2u);
    let sums = KEPT_OCCUPANCY + r * r * r + part + t * ACCUM_STRIDE;
    for (var k = 0u; k < ACCUM_STRIDE; k++) {
        atomicStore(&accum[s * ACCUM_STRIDE + k], kept[sums + k]);
    }
    // Its direct light (and lobe: `kept[4]` words a slot), unless the lights or what moved
    // change them (inject decides).
    let words = kept[4];
    let direct = KEPT_OCCUPANCY + r * r * r + part * (1u + ACCUM_STRIDE);
    let handed = direct + words * part + words * (s - w * part);
    for (var k = 0u; k < words; k++) {
        kept[handed + k] = kept[direct + words * t + k];
    }
}

@compute @workgroup_size(64)
fn allocate(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = flat(gid, nwg);
    if i >= stored_fragments() {
        return;
    }
    let v = voxel_index(unpack_coord(fragments[i].coord), vol.resolution);
    // A kept voxel has its sums (a fragment there would count twice).
    if !rebuilding(window_of_voxel(v)) || kept_voxel(v) {
        return;
    }
    // The first fragment of a voxel takes it; the weak exchange may fail spuriously, so retry
    // while the voxel is still unclaimed.
    for (var tries = 0u; tries < 64u; tries++) {
        let r = atomicCompareExchangeWeak(&occupancy[v], 0u, LOCKED);
        if r.exchanged {
            // Counted even past the capacity, so the host can see how many slots it needs;
            // voxels beyond it stay unallocated (LOCKED) and are skipped.
            let s = take_slot(v);
            if s < slot_limit() {
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
    if o < 2u || o == LOCKED || !rebuilding(window_of_voxel(v)) || kept_voxel(v) {
        return;
    }
    add_fragment(o - 2u, f, false);
}

@compute @workgroup_size(64)
fn resolve(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    // prepare_slots' dispatch: a thread per filled slot of every window.
    let s = filled_slot(flat(gid, nwg), vol.windows);
    if s == 0xffffffffu || !rebuilt_slot(s, W_COUNT) {
        return;
    }
    resolve_slot(s, false);
}
