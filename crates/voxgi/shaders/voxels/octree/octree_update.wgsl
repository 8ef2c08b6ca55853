// octree_update: the dynamic geometry's fragments (those after the static build's) merged into
// the static octree, so that it equals a build of static and dynamic fragments together (the
// seeds' scheme: dynamic nodes, bricks and leaves go after the static ones in every pool, and
// an update starts by dropping the last one's). In the order the host runs them:
//   begin_clear, clear_leaves, clear_nodes
//            zero the texels the last update's leaves and nodes wrote into the static bricks
//            (their own bricks go with them); the leaves' voxels get their static child words
//            back (none, or the static leaf a slot stood in for, shown again)
//   restore  per depth, what the last update wrote into static records: the child pointer of
//            a static node it gave a tile, the -axis neighbour of a static node beside one of
//            its nodes, its nodes' top-grid entries (the host then copies the static build's
//            header of counters back). No copy of the static nodes or leaves is kept: an update
//            writes into them only these words, whose static values are known (0, or the slot)
//   begin_update, bounds
//            the ranges and dispatch sizes of this update, and the box of its fragments
// then per depth t as octree_build, but from the dynamic fragments only:
//   flag     each fragment's node and its seven negative neighbours, where they have no
//            children yet, are marked (a static node that has children keeps them)
//   mark, prepare_depth, count, scan, allocate, finish_update, init
//            the marked nodes, static or dynamic, take tiles after the static ones, ranked by
//            their position in the box (the marks lie in it), so the cost follows what moved
//   repair   a static node whose negative neighbour is one of the new nodes points to it
// and at depth D: the new voxels take slots after the static ones, and so do the voxels a
// static leaf holds that the dynamic fragments reach (the static leaf is hidden, not changed);
// the dynamic fragments' sums are added, then the static fragments' in those shared voxels
// (accumulate_static: the integer sums do not depend on the order, so the shared leaf is a
// build's to the bit), and the update's leaves are resolved.

//!include voxels/build_shared.wgsl

const ARGS_NEW: u32 = 39u;
const ARGS_CLEAR: u32 = 72u;
const ARGS_STATIC: u32 = 75u;

@compute @workgroup_size(1)
fn begin_clear() {
    let slots_now = min(atomicLoad(&nodes[0]), tree.slots);
    let static_slots = atomicLoad(&nodes[STATIC_SLOTS]);
    write_args(ARGS_CLEAR, select(0u, slots_now - static_slots, slots_now > static_slots));
    for (var t = 1u; t <= tree.depth; t++) {
        write_args(ARGS_NEW + 3u * t, atomicLoad(&nodes[DYN_RANGES + 2u * t + 1u]) * 8u);
    }
}

// The last update's leaves: each zeroes its texel in its parent's level-0 brick and in the
// borders of the neighbours' bricks (the parent may be static), and flags the parent.
@compute @workgroup_size(64)
fn clear_leaves(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let s = atomicLoad(&nodes[STATIC_SLOTS]) + flat(gid, nwg);
    if s >= min(atomicLoad(&nodes[0]), tree.slots) {
        return;
    }
    let info = atomicLoad(&slots[s * SLOT_STRIDE + 1u]);
    // A slot counted past the room for its sums was never given its voxel.
    if !sums_fit(s) || info == HIDDEN {
        return;
    }
    let parent = info & 0x1fffffffu;
    store_value(parent, info >> 29u, 0u, 0u, vec4<f32>(0.0));
    flag_node(parent);
    // The voxel's static child word: none, or the static leaf this slot stood in for (its
    // parent is the same node). The node may lie in a tile of the last update: no matter.
    let tile = child(parent);
    let stands_in = atomicLoad(&scratch[sums_of(s) + STANDS_IN]);
    if tile != 0u && tile < NEEDED {
        atomicStore(&nodes[child_word(tree, tile * 8u + (info >> 29u))], stands_in);
    }
    if stands_in != 0u {
        atomicStore(&slots[(stands_in - 1u) * SLOT_STRIDE + 1u], info);
    }
}

// The last update's nodes of depth level.t: each zeroes its value, every direction, in its
// parent's brick and the borders it pushed into the neighbours' (static ones among them), and
// flags the parent. At the leaves' depth only the flag: clear_leaves zeroed what the leaves
// wrote, and a tile whose voxels hold no leaf (made for a neighbour's sake) still leaves its
// parent childless.
@compute @workgroup_size(64)
fn clear_nodes(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let u = level.t;
    let c = last_update_node(flat(gid, nwg), u);
    if c == NONE {
        return;
    }
    let m = tiles[(c / 8u) * TILE_WORDS];
    let k = tree.depth - u;
    for (var d = 0u; d < tree.dirs * u32(k > 0u); d++) {
        store_value(m, c % 8u, k, d, vec4<f32>(0.0));
    }
    // m may be a static node that keeps no children now: its value is to be redone.
    flag_node(m);
}

// The last update's nodes of depth level.t (after clear_nodes of every depth, which reach the
// bricks through the child pointers this resets): each one's parent had no children in the
// static build (else it would not have taken a new tile); a static node on its positive side
// had no -axis neighbour there (the position was empty); the top grid had no node there.
@compute @workgroup_size(64)
fn restore(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let u = level.t;
    let n = last_update_node(flat(gid, nwg), u);
    if n == NONE {
        return;
    }
    atomicStore(&nodes[child_word(tree, tiles[(n / 8u) * TILE_WORDS])], 0u);
    let c = node_coord(n);
    if u <= grid_depth(tree) {
        grid[grid_index(c, u)] = 0u;
    }
    // `repair`'s writes (above the leaves, which keep no neighbours).
    if u >= tree.depth {
        return;
    }
    for (var a = 0u; a < 3u; a++) {
        // A static one is reached through static nodes only, whose child pointers stay.
        let m = beside_new(n, c, u, a);
        if m != NONE && atomicLoad(&nodes[NODE_HEADER + m * NODE_STRIDE + 1u + a]) == n {
            atomicStore(&nodes[NODE_HEADER + m * NODE_STRIDE + 1u + a], 0u);
        }
    }
}

// Node `i` of the last update's tiles of depth u (which the next update's clear reads before
// the header comes back), or NONE.
fn last_update_node(i: u32, u: u32) -> u32 {
    if i >= atomicLoad(&nodes[DYN_RANGES + 2u * u + 1u]) * 8u {
        return NONE;
    }
    return atomicLoad(&nodes[DYN_RANGES + 2u * u]) * 8u + i;
}

// The node on new node n's positive side along axis a (n at coordinate c of depth u), or NONE:
// where n comes first in its tile along the axis, the next node is its sibling (new too).
fn beside_new(n: u32, c: vec3<u32>, u: u32, a: u32) -> u32 {
    if (((n % 8u) >> a) & 1u) == 0u || c[a] + 1u >= (1u << u) {
        return NONE;
    }
    var p = c;
    p[a] += 1u;
    return node_at(p, u);
}

@compute @workgroup_size(1)
fn begin_update() {
    for (var t = 0u; t <= tree.depth; t++) {
        atomicStore(&nodes[DYN_RANGES + 2u * t], 0u);
        atomicStore(&nodes[DYN_RANGES + 2u * t + 1u], 0u);
    }
    atomicStore(&nodes[UPDATING], 1u);
    for (var a = 0u; a < 3u; a++) {
        atomicStore(&nodes[BOX + a], 0xffffffffu);
        atomicStore(&nodes[BOX + 3u + a], 0u);
    }
    let first = atomicLoad(&nodes[FIRST_FRAGMENT]);
    let frags = stored_fragments();
    write_args(0u, select(0u, frags - first, frags > first));
}

// The box of the update's fragments.
@compute @workgroup_size(64)
fn bounds(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = atomicLoad(&nodes[FIRST_FRAGMENT]) + flat(gid, nwg);
    if i >= stored_fragments() {
        return;
    }
    let c = unpack_coord(fragments[i].coord);
    for (var a = 0u; a < 3u; a++) {
        atomicMin(&nodes[BOX + a], c[a]);
        atomicMax(&nodes[BOX + 3u + a], c[a]);
    }
}

// The dispatch size over the positions of depth level.t's box.
@compute @workgroup_size(1)
fn prepare_depth() {
    write_args(6u + 3u * level.t, threads_at(level.t));
}

// Marks node n for children where it has none (a node with children, or marked already,
// stays as it is). The weak exchange may fail spuriously: retry while the node is unmarked.
fn mark_node(n: u32, value: u32) {
    for (var r = 0u; r < 64u; r++) {
        let x = atomicCompareExchangeWeak(&nodes[child_word(tree, n)], 0u, value);
        if x.exchanged || x.old_value != 0u {
            return;
        }
    }
}

@compute @workgroup_size(64)
fn flag(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = atomicLoad(&nodes[FIRST_FRAGMENT]) + flat(gid, nwg);
    if i >= stored_fragments() {
        return;
    }
    let t = level.t;
    let n = descend(unpack_coord(fragments[i].coord), t);
    if n == NONE {
        return;
    }
    if t == tree.depth {
        // A voxel a static leaf holds is hidden for one of the update's slots to take it.
        let v = child(n);
        if v != 0u && v < NEEDED && v - 1u < atomicLoad(&nodes[STATIC_SLOTS]) {
            atomicStore(&slots[(v - 1u) * SLOT_STRIDE + 1u], HIDDEN);
        } else {
            mark_node(n, CONTENT);
        }
        return;
    }
    // The node and its seven negative neighbours (their bricks hold its voxels as a border),
    // as octree_build's flag and dilate do.
    let x = neighbour(n, 0u);
    let y = neighbour(n, 1u);
    let z = neighbour(n, 2u);
    var around = array<u32, 8>(n, x, y, z, 0u, 0u, 0u, 0u);
    if x != 0u {
        around[4] = neighbour(x, 1u);
        around[5] = neighbour(x, 2u);
    }
    if y != 0u {
        around[6] = neighbour(y, 2u);
    }
    if around[4] != 0u {
        around[7] = neighbour(around[4], 2u);
    }
    for (var k = 0u; k < 8u; k++) {
        if k == 0u || around[k] != 0u {
            mark_node(around[k], NEEDED);
        }
    }
}

// The dispatch over the static fragments, when the update shares any voxel with a static leaf.
@compute @workgroup_size(1)
fn prepare_static() {
    let any_shared = atomicLoad(&nodes[STOOD_IN]) > 0u;
    write_args(ARGS_STATIC, select(0u, min(atomicLoad(&nodes[FIRST_FRAGMENT]), stored_fragments()), any_shared));
}

// The static fragments in the voxels the update shares with static leaves (a slot of the
// update stands in for each): their sums join the dynamic ones (add_fragment leaves the
// static leaves' alone). A thread per static fragment: those outside the update's box return
// after reading their coordinate, but the pass still grows with the static fragments, not
// with what moved (on lavapipe it is most of the update's cost at Sponza 256³).
@compute @workgroup_size(64)
fn accumulate_static(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = flat(gid, nwg);
    // Without a shared voxel the dispatch is one workgroup (write_args' least), whose
    // fragments add to nothing: add_fragment finds only static leaves.
    if i >= min(atomicLoad(&nodes[FIRST_FRAGMENT]), stored_fragments()) {
        return;
    }
    let c = unpack_coord(fragments[i].coord);
    let b = update_box(tree.depth);
    if any(c < b.lo) || any(c >= b.lo + b.size) {
        return;
    }
    let node = descend(c, tree.depth);
    if node != NONE {
        add_fragment(fragments[i], child(node));
    }
}

@compute @workgroup_size(1)
fn finish_update() {
    let count = record_new_tiles(DYN_RANGES);
    let u = level.t + 1u;
    write_args(ARGS_NEW + 3u * u, count * 8u);
}

// The new nodes of depth level.t: a static node on their positive side along an axis points
// back at them (its -axis neighbour was none, or another update's).
@compute @workgroup_size(64)
fn repair(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let u = level.t;
    let n = node_of_new(flat(gid, nwg), u);
    if n == NONE {
        return;
    }
    let c = node_coord(n);
    let dyn_start = atomicLoad(&nodes[DYN_RANGES + 2u * u]);
    let dyn_end = dyn_start + atomicLoad(&nodes[DYN_RANGES + 2u * u + 1u]);
    for (var a = 0u; a < 3u; a++) {
        let m = beside_new(n, c, u, a);
        if m != NONE && (m / 8u < dyn_start || m / 8u >= dyn_end) {
            atomicStore(&nodes[NODE_HEADER + m * NODE_STRIDE + 1u + a], n);
        }
    }
}

// The end of an update: the dispatch sizes over every node of each depth, static and dynamic,
// for the filter (the update's own were over its box).
@compute @workgroup_size(1)
fn end_update() {
    for (var t = 0u; t <= tree.depth; t++) {
        write_args(6u + 3u * t, nodes_at(t));
    }
}
