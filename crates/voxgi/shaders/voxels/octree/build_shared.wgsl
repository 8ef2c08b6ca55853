// The octree's build resources and helpers, shared by octree_build (the static geometry, from
// scratch) and octree_update (the dynamic geometry, on top of the static build), and the
// steps both run: mark, count, scan, allocate, init, allocate_slots, accumulate, resolve.

//!include shared/fragment.wgsl
//!include voxels/tree.wgsl

struct Level {
    // The depth this dispatch works on.
    t: u32,
}

@group(0) @binding(0) var<uniform> tree: Octree;
@group(0) @binding(1) var<storage, read> fragments: array<Fragment>;
@group(0) @binding(2) var<storage, read> fragment_count: array<u32>;
// The header (counters, voxels/octree/tree.wgsl), then the nodes.
@group(0) @binding(3) var<storage, read_write> nodes: array<atomic<u32>>;
// Per tile, TILE_WORDS u32: its parent node and the parent's packed coordinate.
@group(0) @binding(4) var<storage, read_write> tiles: array<u32>;
@group(0) @binding(5) var<storage, read_write> slots: array<atomic<u32>>;
@group(0) @binding(6) var even_out: texture_storage_3d<rgba16float, write>;
@group(0) @binding(7) var odd_out: texture_storage_3d<rgba16float, write>;
@group(0) @binding(8) var<uniform> level: Level;
// The build's scratch: first, per workgroup of `count`, its marked nodes, then (after `scan`)
// the marked nodes before it (`block_words()` of them); then per leaf slot from STATIC_SLOTS
// on, ACCUM_STRIDE words: the sums of its fragments, and (in an update) 1 + the static slot
// it stands in for. A build makes one for all its slots and drops it after; a dynamic scene
// keeps one for the slots its updates may add (the last update's are read by the next one's
// clear).
@group(0) @binding(9) var<storage, read_write> scratch: array<atomic<u32>>;
// The top grid (voxels/octree/tree.wgsl): per depth down to GRID_DEPTH, the node at each
// position, 0 where none.
@group(0) @binding(10) var<storage, read_write> grid: array<u32>;
// The filter's flags (voxels/octree/tree.wgsl's FLAG_SHIFT).
@group(0) @binding(11) var filter_flags: texture_storage_2d<r32uint, write>;
// Indirect dispatch sizes: [0..3] over fragments, [3..6] over leaf slots, from [6] per depth
// t over the nodes of depth t. Only the one-thread kernels bind them.
@group(1) @binding(0) var<storage, read_write> args: array<u32>;

const WG: u32 = 64u;

fn flat(gid: vec3<u32>, nwg: vec3<u32>) -> u32 {
    return gid.x + gid.y * nwg.x * WG;
}

fn write_args(offset: u32, count: u32) {
    let groups = (count + WG - 1u) / WG;
    args[offset] = max(min(groups, 65535u), 1u);
    args[offset + 1u] = max((groups + 65534u) / 65535u, 1u);
    args[offset + 2u] = 1u;
}

// Words of the scratch's per-workgroup counts (`OctreeVolume::scratch_bytes` agrees): a depth
// has at most eight nodes per tile of the pool, one count per 64 of them.
fn block_words() -> u32 {
    return tree.tiles / 8u + 2u;
}

// Where slot s's sums begin in the scratch: a build's from slot 0 (STATIC_SLOTS is 0 while it
// runs), an update's from the first slot after the static build's.
fn sums_of(s: u32) -> u32 {
    return block_words() + (s - atomicLoad(&nodes[STATIC_SLOTS])) * ACCUM_STRIDE;
}

// Whether slot s (at least STATIC_SLOTS) has its sums in the scratch: a dynamic scene's scratch
// holds the slots its pools leave for updates, which a static build larger than the one the
// pools were sized for may leave fewer of.
fn sums_fit(s: u32) -> bool {
    return block_words() + (s - atomicLoad(&nodes[STATIC_SLOTS]) + 1u) * ACCUM_STRIDE <= arrayLength(&scratch);
}

// Whether leaf slot s is a static one whose voxel the running update's dynamic geometry shares
// (`flag` hides it: a slot of the update takes the voxel, with the sums of both).
fn shared_static(s: u32) -> bool {
    return s < atomicLoad(&nodes[STATIC_SLOTS]) && atomicLoad(&slots[s * SLOT_STRIDE + 1u]) == HIDDEN;
}

fn stored_fragments() -> u32 {
    return min(fragment_count[0], arrayLength(&fragments));
}

fn child(n: u32) -> u32 {
    return atomicLoad(&nodes[child_word(tree, n)]);
}

fn neighbour(n: u32, axis: u32) -> u32 {
    return atomicLoad(&nodes[NODE_HEADER + n * NODE_STRIDE + 1u + axis]);
}

// The node of depth t (whose children are allocated down to it) that holds finest voxel c, or
// NONE where a pool overflowed above it.
fn descend(c: vec3<u32>, t: u32) -> u32 {
    var node = 0u;
    for (var i = 0u; i < t; i++) {
        let tile = child(node);
        if tile == 0u || tile >= NEEDED {
            return NONE;
        }
        node = tile * 8u + octant_of(c, tree.depth - 1u - i);
    }
    return node;
}

// Nodes of depth t: the static build's tiles, then the last update's.
fn nodes_at(t: u32) -> u32 {
    return (atomicLoad(&nodes[RANGES + 2u * t + 1u]) + atomicLoad(&nodes[DYN_RANGES + 2u * t + 1u])) * 8u;
}

// Node `i` of depth t (threads over the depth's static tiles, then its dynamic ones, eight
// nodes each), or NONE.
fn node_of_depth(i: u32, t: u32) -> u32 {
    let s = atomicLoad(&nodes[RANGES + 2u * t + 1u]) * 8u;
    if i < s {
        return atomicLoad(&nodes[RANGES + 2u * t]) * 8u + i;
    }
    if i - s >= atomicLoad(&nodes[DYN_RANGES + 2u * t + 1u]) * 8u {
        return NONE;
    }
    return atomicLoad(&nodes[DYN_RANGES + 2u * t]) * 8u + (i - s);
}

// Node `i` of the tiles of depth t the running build or update has just made: the static range
// in a build, the dynamic one in an update (header word UPDATING).
fn node_of_new(i: u32, t: u32) -> u32 {
    let r = select(RANGES, DYN_RANGES, atomicLoad(&nodes[UPDATING]) != 0u);
    if i >= atomicLoad(&nodes[r + 2u * t + 1u]) * 8u {
        return NONE;
    }
    return atomicLoad(&nodes[r + 2u * t]) * 8u + i;
}

// The node at coordinate c of depth t, or NONE.
fn node_at(c: vec3<u32>, t: u32) -> u32 {
    var node = 0u;
    for (var i = 0u; i < t; i++) {
        let tile = child(node);
        if tile == 0u || tile >= NEEDED {
            return NONE;
        }
        node = tile * 8u + octant_of(c, t - 1u - i);
    }
    return node;
}

struct Box {
    lo: vec3<u32>,
    size: vec3<u32>,
}

// In an update, the box at depth t of the nodes its fragments can mark: their own and, above
// the leaves, their negative neighbours. Empty when the update has no fragments.
fn update_box(t: u32) -> Box {
    let lo = vec3<u32>(atomicLoad(&nodes[BOX]), atomicLoad(&nodes[BOX + 1u]), atomicLoad(&nodes[BOX + 2u]));
    let hi = vec3<u32>(atomicLoad(&nodes[BOX + 3u]), atomicLoad(&nodes[BOX + 4u]), atomicLoad(&nodes[BOX + 5u]));
    if any(lo > hi) {
        return Box(vec3<u32>(0u), vec3<u32>(0u));
    }
    let shift = vec3<u32>(tree.depth - t);
    let margin = vec3<u32>(select(1u, 0u, t == tree.depth));
    let l = (lo >> shift) - min(lo >> shift, margin);
    return Box(l, (hi >> shift) - l + 1u);
}

// Whether the dispatches over the nodes of depth t run over the positions of the update's box:
// in an update, unless the box holds more positions than the scratch keeps per-workgroup
// counts for (`block_words`, a count per 64 of the pool's nodes: scattered or long dynamic
// geometry), where they run over the depth's nodes as a build's do.
fn over_box(t: u32) -> bool {
    if atomicLoad(&nodes[UPDATING]) == 0u {
        return false;
    }
    let b = update_box(t);
    return (b.size.x * b.size.y * b.size.z + 63u) / 64u <= block_words();
}

// Threads of the dispatches over the nodes of depth t: every node, or in an update a thread per
// position of its box (so the update's cost follows what moved, not the static octree, and its
// ranks follow the positions: the same layout every run).
fn threads_at(t: u32) -> u32 {
    if !over_box(t) {
        return nodes_at(t);
    }
    let b = update_box(t);
    return b.size.x * b.size.y * b.size.z;
}

// The node thread `i` of such a dispatch takes, or NONE.
fn node_for_thread(i: u32, t: u32) -> u32 {
    if !over_box(t) {
        return node_of_depth(i, t);
    }
    let b = update_box(t);
    if i >= b.size.x * b.size.y * b.size.z {
        return NONE;
    }
    let p = b.lo + vec3<u32>(i % b.size.x, (i / b.size.x) % b.size.y, i / (b.size.x * b.size.y));
    return node_at(p, t);
}

// Node n's coordinate at its depth: its tile's parent's, doubled, plus its octant.
fn node_coord(n: u32) -> vec3<u32> {
    return 2u * unpack_coord(tiles[(n / 8u) * TILE_WORDS + 1u]) + octant_offset(n % 8u);
}

fn class_capacity(c: u32) -> u32 {
    return class_end(tree, c) - class_base(tree, c);
}

@compute @workgroup_size(1)
fn mark() {
    let c = brick_class(tree.depth - 1u - level.t);
    atomicStore(&nodes[ALLOC_START], atomicLoad(&nodes[1u + c]));
}

var<workgroup> ranks: array<u32, 64>;

// Inclusive prefix sum of `v` over the workgroup (every thread must call it).
fn workgroup_scan(lid: u32, v: u32) -> u32 {
    ranks[lid] = v;
    workgroupBarrier();
    for (var d = 1u; d < 64u; d *= 2u) {
        var x = 0u;
        if lid >= d {
            x = ranks[lid - d];
        }
        workgroupBarrier();
        ranks[lid] += x;
        workgroupBarrier();
    }
    return ranks[lid];
}

fn block_index(wid: vec3<u32>, nwg: vec3<u32>) -> u32 {
    return wid.x + wid.y * nwg.x;
}

// Whether node n (of the dispatch's depth) takes a tile (depth < D) or a leaf slot (depth D).
fn marked(n: u32) -> bool {
    if n == NONE {
        return false;
    }
    let c = child(n);
    if level.t == tree.depth {
        return c == CONTENT || (c != 0u && c < NEEDED && shared_static(c - 1u));
    }
    return c >= NEEDED;
}

@compute @workgroup_size(64)
fn count(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(local_invocation_index) lid: u32, @builtin(workgroup_id) wid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let n = node_for_thread(flat(gid, nwg), level.t);
    let total = workgroup_scan(lid, u32(marked(n)));
    if lid == 63u {
        atomicStore(&scratch[block_index(wid, nwg)], total);
    }
}

// One workgroup: the exclusive prefix sum of the counts of the depth's blocks, in chunks of 64.
var<workgroup> scan_blocks: u32;

@compute @workgroup_size(64)
fn scan(@builtin(local_invocation_index) lid: u32) {
    if lid == 0u {
        scan_blocks = (threads_at(level.t) + 63u) / 64u;
    }
    let blocks = workgroupUniformLoad(&scan_blocks);
    var offset = 0u;
    for (var base = 0u; base < blocks; base += 64u) {
        let i = base + lid;
        var v = 0u;
        if i < blocks {
            v = atomicLoad(&scratch[i]);
        }
        let inclusive = workgroup_scan(lid, v);
        if i < blocks {
            atomicStore(&scratch[i], offset + inclusive - v);
        }
        offset += ranks[63];
        workgroupBarrier();
    }
}

// The rank of node n among the marked nodes of its depth (every thread must call it).
fn rank(n: u32, lid: u32, wid: vec3<u32>, nwg: vec3<u32>) -> u32 {
    let m = u32(marked(n));
    return atomicLoad(&scratch[block_index(wid, nwg)]) + workgroup_scan(lid, m) - m;
}

@compute @workgroup_size(64)
fn allocate(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(local_invocation_index) lid: u32, @builtin(workgroup_id) wid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let n = node_for_thread(flat(gid, nwg), level.t);
    let r = rank(n, lid, wid, nwg);
    if !marked(n) {
        return;
    }
    let c = brick_class(tree.depth - 1u - level.t);
    // Counted past the capacity, so the host sees how many tiles the class needs.
    atomicMax(&nodes[1u + c], atomicLoad(&nodes[ALLOC_START]) + r + 1u);
    let k = atomicLoad(&nodes[ALLOC_START]) + r;
    if k >= class_capacity(c) {
        atomicStore(&nodes[child_word(tree, n)], 0u);
        return;
    }
    let tile = class_base(tree, c) + k;
    atomicStore(&nodes[child_word(tree, n)], tile);
    tiles[tile * TILE_WORDS] = n;
    tiles[tile * TILE_WORDS + 1u] = pack_coord(node_coord(n));
}

// Clears the texels of brick `tile` (holding `lvl`) that octant thread `o` owns: every eighth.
fn clear_brick(tile: u32, lvl: u32, o: u32) {
    let dirs = select(1u, tree.dirs, lvl > 0u);
    let shape = atlas_shape(tree, lvl);
    let b = brick_index(tree, tile, lvl);
    for (var d = 0u; d < dirs; d++) {
        let base = brick_texel(shape, b, d);
        for (var k = o; k < 27u; k += 8u) {
            let p = base + vec3<u32>(k % 3u, (k / 3u) % 3u, k / 9u);
            if (lvl & 1u) == 0u {
                textureStore(even_out, p, vec4<f32>(0.0));
            } else {
                textureStore(odd_out, p, vec4<f32>(0.0));
            }
        }
    }
}

// Node n's value is out of date: the next filter redoes it and the levels above.
fn flag_node(n: u32) {
    textureStore(filter_flags, flag_texel(n), vec4<u32>(1u));
}

// The nodes of depth level.t, just allocated. Each is flagged for the filter, and so is its
// parent (whose brick this is). An update's new brick also takes in its positive border the
// values of nodes that were there before it (static ones, which nothing else flags): those
// are flagged too, so that the filter pushes them into it.
@compute @workgroup_size(64)
fn init(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let u = level.t;
    let n = node_of_new(flat(gid, nwg), u);
    if n == NONE {
        return;
    }
    let tile = n / 8u;
    let o = n % 8u;
    atomicStore(&nodes[child_word(tree, n)], 0u);
    let parent = tiles[tile * TILE_WORDS];
    flag_node(parent);
    if u < tree.depth {
        flag_node(n);
        if atomicLoad(&nodes[UPDATING]) != 0u {
            flag_border_sources(n, u);
        }
    }
    if u <= grid_depth(tree) {
        grid[grid_index(node_coord(n), u)] = n;
    }
    // Leaf voxels keep no neighbours.
    for (var a = 0u; a < 3u * u32(u < tree.depth); a++) {
        var nb = 0u;
        if ((o >> a) & 1u) == 1u {
            nb = tile * 8u + (o ^ (1u << a));
        } else {
            let pn = neighbour(parent, a);
            if pn != 0u {
                let pt = child(pn);
                if pt != 0u {
                    nb = pt * 8u + (o | (1u << a));
                }
            }
        }
        atomicStore(&nodes[NODE_HEADER + n * NODE_STRIDE + 1u + a], nb);
    }
    clear_brick(tile, tree.depth - u, o);
}

// The nodes of depth u whose values lie in the positive border of new node n's tile: n's
// neighbours along the axes of each nonempty s where n lies on its tile's positive face.
fn flag_border_sources(n: u32, u: u32) {
    let o = n % 8u;
    let c = node_coord(n);
    let side = 1u << u;
    for (var s = 1u; s < 8u; s++) {
        if (o & s) != s {
            continue;
        }
        let p = c + octant_offset(s);
        if any(p >= vec3<u32>(side)) {
            continue;
        }
        let m = node_at(p, u);
        if m != NONE {
            flag_node(m);
        }
    }
}

// Depth D: one leaf slot per newly occupied finest voxel, by rank.
@compute @workgroup_size(64)
fn allocate_slots(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(local_invocation_index) lid: u32, @builtin(workgroup_id) wid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let n = node_for_thread(flat(gid, nwg), tree.depth);
    // An update's slots follow the static build's (STATIC_SLOTS is 0 during a build).
    let s = atomicLoad(&nodes[STATIC_SLOTS]) + rank(n, lid, wid, nwg);
    if !marked(n) {
        return;
    }
    atomicMax(&nodes[0], s + 1u);
    let info = tiles[(n / 8u) * TILE_WORDS] | ((n % 8u) << 29u);
    // A voxel a static leaf holds (shared with the update's geometry), or 0.
    let held = atomicLoad(&nodes[child_word(tree, n)]);
    let stands_in = select(0u, held, held != CONTENT);
    if s >= tree.slots || !sums_fit(s) {
        // No room: a shared voxel keeps its static leaf (shown again), a new one stays empty.
        atomicStore(&nodes[child_word(tree, n)], stands_in);
        if stands_in != 0u {
            atomicStore(&slots[(stands_in - 1u) * SLOT_STRIDE + 1u], info);
        }
        // Within the pool but past the scratch: the slot stays unlit and the next clear skips it.
        if s < tree.slots {
            atomicStore(&slots[s * SLOT_STRIDE + 1u], HIDDEN);
        }
        return;
    }
    atomicStore(&nodes[child_word(tree, n)], s + 1u);
    atomicStore(&slots[s * SLOT_STRIDE], pack_coord(node_coord(n)));
    atomicStore(&slots[s * SLOT_STRIDE + 1u], info);
    for (var k = 0u; k < FRAGMENT_SUMS + 1u; k++) {
        atomicStore(&scratch[sums_of(s) + k], 0u);
    }
    atomicStore(&scratch[sums_of(s) + STANDS_IN], stands_in);
    if stands_in != 0u {
        atomicAdd(&nodes[STOOD_IN], 1u);
    }
}

@compute @workgroup_size(64)
fn accumulate(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    // A build's fragments from 0, an update's from the static ones on (FIRST_FRAGMENT).
    let i = atomicLoad(&nodes[FIRST_FRAGMENT]) + flat(gid, nwg);
    if i >= stored_fragments() {
        return;
    }
    let f = fragments[i];
    let node = descend(unpack_coord(f.coord), tree.depth);
    if node == NONE {
        return;
    }
    add_fragment(f, child(node));
}

// Adds fragment f into the sums of the leaf whose child word is v, if it has sums: every slot
// in a build, the update's own slots in an update (a static leaf's attributes are its build's).
fn add_fragment(f: Fragment, v: u32) {
    if v == 0u || v >= NEEDED || v - 1u < atomicLoad(&nodes[STATIC_SLOTS]) {
        return;
    }
    let base = sums_of(v - 1u);
    let sums = fragment_sums(f);
    for (var k = 0u; k < FRAGMENT_SUMS; k++) {
        atomicAdd(&scratch[base + k], sums[k]);
    }
    atomicMax(&scratch[base + FRAGMENT_SUMS], fragment_coverage(f));
}

@compute @workgroup_size(1)
fn prepare_slots() {
    write_args(3u, min(atomicLoad(&nodes[0]), tree.slots));
}

@compute @workgroup_size(64)
fn resolve(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    // A build resolves every slot; an update its own slots, by the voxels of its box.
    var s = flat(gid, nwg);
    if atomicLoad(&nodes[UPDATING]) != 0u {
        let n = node_for_thread(s, tree.depth);
        let v = select(0u, child(n), n != NONE);
        let own = v != 0u && v < NEEDED && v - 1u >= atomicLoad(&nodes[STATIC_SLOTS]);
        s = select(NONE, v - 1u, own);
    }
    if s >= min(atomicLoad(&nodes[0]), tree.slots) {
        return;
    }
    let base = s * SLOT_STRIDE;
    let sums = sums_of(s);
    var sum = array<u32, FRAGMENT_SUMS>();
    for (var k = 0u; k < FRAGMENT_SUMS; k++) {
        sum[k] = atomicLoad(&scratch[sums + k]);
    }
    let a = resolve_sums(sum, atomicLoad(&scratch[sums + FRAGMENT_SUMS]));
    atomicStore(&slots[base + 2u], pack4x8unorm(a.albedo));
    atomicStore(&slots[base + 3u], pack4x8snorm(a.normal));
    atomicStore(&slots[base + 4u], pack2x16float(a.emission.rg));
    atomicStore(&slots[base + 5u], pack2x16float(vec2<f32>(a.emission.b, a.surface)));
}

// Writes `v` (as stored: optical depth at level 0, premultiplied opacity above; the clears'
// zero is empty in both) as the value of octant `o` of node m's brick, holding level `lvl`,
// direction block `block`: into m's brick and the positive borders of the bricks of m's
// negative neighbours that hold it (as the filter and the leaf store do).
fn store_value(m: u32, o: u32, lvl: u32, block: u32, v: vec4<f32>) {
    let x = neighbour(m, 0u);
    let y = neighbour(m, 1u);
    let xy = neighbour(x, 1u);
    let around = array<u32, 8>(m, x, y, xy, neighbour(m, 2u), neighbour(x, 2u), neighbour(y, 2u), neighbour(xy, 2u));
    let shape = atlas_shape(tree, lvl);
    for (var s = 0u; s < 8u; s++) {
        if !border_holds(o, s) || (s != 0u && around[s] == 0u) {
            continue;
        }
        let tile = child(around[s]);
        if tile == 0u || tile >= NEEDED {
            continue;
        }
        let p = brick_texel(shape, brick_index(tree, tile, lvl), block) + border_local(o, s);
        if (lvl & 1u) == 0u {
            textureStore(even_out, p, v);
        } else {
            textureStore(odd_out, p, v);
        }
    }
}

// After allocate at depth level.t: the new tiles (of depth t + 1) as the range at `ranges`
// (RANGES in a build, DYN_RANGES in an update); returns how many.
fn record_new_tiles(ranges: u32) -> u32 {
    let c = brick_class(tree.depth - 1u - level.t);
    let start = atomicLoad(&nodes[ALLOC_START]);
    let end = min(atomicLoad(&nodes[1u + c]), class_capacity(c));
    let count = select(0u, end - start, end > start);
    let u = level.t + 1u;
    atomicStore(&nodes[ranges + 2u * u], class_base(tree, c) + start);
    atomicStore(&nodes[ranges + 2u * u + 1u], count);
    return count;
}
