// octree_filter: the levels above the leaves, one depth per dispatch from the finest up. Each
// thread takes one node c of depth t + 1 whose children have a brick (level k - 1) and writes
// c's value at level k into its parent's brick, and into the positive borders of the bricks
// of the parent's negative neighbours that hold it. The value is the dense volume's filter
// (voxels/dense/filter.wgsl) applied to the eight voxels of c's brick: the mean in isotropic
// mode; per direction, front-to-back pairs along it averaged, otherwise. Level k - 1 is read
// from one atlas and level k written into the other (they alternate by level).
//
// Level 0 stores optical depth (the leaf store's); the levels written here store premultiplied
// opacity (L alpha, alpha), which voxels/octree/sample.wgsl converts to depth after each fetch,
// so that a fetch averages coverage, not depth, across its texels.
//
// Only flagged nodes are redone (voxels/octree/tree.wgsl's FLAG_SHIFT): a node's value
// depends on its children's brick alone (and, for the first level, their leaves' normals,
// which change only with their radiance), so an unflagged node's stored value is what the
// filter would write. A redone node flags its parent; an unchanged value written again
// changes nothing, so flagging more than changed costs time, never exactness.

//!include shared/volume.wgsl
//!include shared/specular_lobe.wgsl
//!include voxels/tree.wgsl

struct Level {
    t: u32,
}

@group(0) @binding(0) var<uniform> tree: Octree;
@group(0) @binding(1) var<storage, read> nodes: array<u32>;
// Per tile, TILE_WORDS u32: its parent node first.
@group(0) @binding(2) var<storage, read> tiles: array<u32>;
// Level k - 1's atlas (read) and level k's (written).
@group(0) @binding(3) var src: texture_3d<f32>;
@group(0) @binding(4) var dst: texture_storage_3d<rgba16float, write>;
@group(0) @binding(5) var<uniform> level: Level;
// Per leaf slot, SLOT_STRIDE u32: word 3 its normal and agreement (for `tree.ndf`).
@group(0) @binding(6) var<storage, read> slots: array<u32>;
@group(0) @binding(7) var flags: texture_storage_2d<r32uint, read_write>;
// [0]: the nodes the filter redid since the host last cleared it.
@group(0) @binding(8) var<storage, read_write> redone: array<atomic<u32>>;
// Per leaf slot: its direct light, and with `tree.lobes` its specular lobe after it (leaves.wgsl's
// `leaf_direct`).
@group(0) @binding(9) var<storage, read> leaf_direct: array<vec4<f32>>;

fn child(n: u32) -> u32 {
    return nodes[NODE_HEADER + n * NODE_STRIDE];
}

fn neighbour(n: u32, axis: u32) -> u32 {
    return nodes[NODE_HEADER + n * NODE_STRIDE + 1u + axis];
}

// Voxel `o` of the level k - 1 brick at `base`, premultiplied: level 0 stores optical depth,
// the levels above premultiplied opacity already.
fn source(base: vec3<u32>, o: vec3<u32>, k: u32) -> vec4<f32> {
    let v = textureLoad(src, base + o, 0);
    return select(v, from_depth(v), k == 1u);
}

// Leaf voxel `o` of the leaf tile `below` (level 0) as direction d counts it: weighed by its
// normals with `tree.ndf`, as the dense volume's filter weighs its finest voxels, and with what
// its specular lobe sends that way (voxels/dense/filter.wgsl's `leaf_child`).
fn leaf_source(base: vec3<u32>, o: vec3<u32>, below: u32, d: u32) -> vec4<f32> {
    let v = source(base, o, 1u);
    // `filtered` also runs (and is discarded) for nodes without a brick: below 0.
    if below == 0u {
        return v;
    }
    let word = nodes[child_word(tree, below * 8u + o.x + 2u * o.y + 4u * o.z)];
    let slot = min(max(word, 1u) - 1u, tree.slots - 1u);
    let normal = unpack4x8snorm(slots[slot * SLOT_STRIDE + 3u]);
    var w = 1.0;
    if tree.ndf != 0u {
        w = select(1.0, ndf_weight(normal, d), word != 0u);
    }
    // Apart, so that a voxel without a lobe filters to the same bits as without lobes.
    if tree.lobes == 0u || word == 0u || v.a <= 0.0 {
        return w * v;
    }
    let packed = leaf_direct[2u * slot + 1u];
    if all(packed.rgb <= vec3<f32>(0.0)) {
        return w * v;
    }
    let n = normal.xyz / max(length(normal.xyz), 1e-4);
    // The lobe's wide share; the rest goes up the lobe blocks (`lobe_filtered`).
    return w * v + vec4<f32>(v.a * lobe_radiance(wide_share(unpack_lobe(packed)), n, d), 0.0);
}

// Lobe block d (6 or 7) at level k of the node whose children's brick is `below`: the mean of
// its eight voxels' moments, the leaves' own at level 1 (shared/specular_lobe.wgsl, "The lobe
// chain"; the dense volume's filter.wgsl `filter_lobes`).
fn lobe_filtered(below: u32, k: u32, d: u32) -> vec4<f32> {
    let block = select(dir_block(tree, d), 0u, k == 1u);
    let base = brick_texel(atlas_shape(tree, k - 1u), brick_index(tree, below, k - 1u), block);
    var sum = vec4<f32>(0.0);
    for (var j = 0u; j < 8u; j++) {
        let o = octant_offset(j);
        if k > 1u {
            sum += textureLoad(src, base + o, 0);
            continue;
        }
        let a = source(base, o, 1u).a;
        let word = nodes[child_word(tree, below * 8u + j)];
        if a <= 0.0 || word == 0u {
            continue;
        }
        let slot = min(word - 1u, tree.slots - 1u);
        let packed = leaf_direct[2u * slot + 1u];
        if any(packed.rgb > vec3<f32>(0.0)) {
            let normal = unpack4x8snorm(slots[slot * SLOT_STRIDE + 3u]).xyz;
            let lobe = narrow_share(unpack_lobe(packed), normal / max(length(normal), 1e-4));
            sum += lobe_moments(lobe, a, d);
        } else if d == LOBE_EXITANCE && lobe_covers(packed) {
            sum.a += a;
        }
    }
    return sum * 0.125;
}

// The redone nodes of this workgroup, added to `redone` once (one global atomic per node
// would cost more than a node's filtering).
var<workgroup> group_redone: atomic<u32>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(local_invocation_index) lid: u32, @builtin(num_workgroups) nwg: vec3<u32>) {
    // Nodes of depth u = t + 1, whose values are level k = D - u.
    let u = level.t + 1u;
    let i = gid.x + gid.y * nwg.x * 64u;
    // The static build's nodes of depth u, then the last update's.
    let s_count = nodes[RANGES + 2u * u + 1u] * 8u;
    let c = select(nodes[DYN_RANGES + 2u * u] * 8u + (i - s_count), nodes[RANGES + 2u * u] * 8u + i, i < s_count);
    let todo = i < s_count + nodes[DYN_RANGES + 2u * u + 1u] * 8u && textureLoad(flags, flag_texel(c)).x != 0u;
    if todo {
        atomicAdd(&group_redone, 1u);
    }
    workgroupBarrier();
    if lid == 0u {
        let n = atomicLoad(&group_redone);
        if n != 0u {
            atomicAdd(&redone[0], n);
        }
    }
    if !todo {
        return;
    }
    textureStore(flags, flag_texel(c), vec4<u32>(0u));
    // No brick below: c and its positive neighbours are empty, and so is its value, which is
    // written all the same (an update may have taken c's children away).
    let below = child(c);
    let tile = c / 8u;
    let o = c % 8u;
    let k = tree.depth - u;
    let m = tiles[tile * TILE_WORDS];
    textureStore(flags, flag_texel(m), vec4<u32>(1u));
    let x = neighbour(m, 0u);
    let y = neighbour(m, 1u);
    let xy = neighbour(x, 1u);
    let around = array<u32, 8>(m, x, y, xy, neighbour(m, 2u), neighbour(x, 2u), neighbour(y, 2u), neighbour(xy, 2u));
    var targets = array<u32, 8>();
    for (var s = 0u; s < 8u; s++) {
        var t = 0u;
        if border_holds(o, s) && (s == 0u || around[s] != 0u) {
            t = child(around[s]);
        }
        targets[s] = t;
    }
    let dirs = select(1u, tree.dirs, tree.anisotropic != 0u);
    let dst_shape = atlas_shape(tree, k);
    for (var d = 0u; d < dirs; d++) {
        let stored = select(vec4<f32>(0.0), filtered(below, k, d), below != 0u);
        for (var s = 0u; s < 8u; s++) {
            if targets[s] != 0u {
                let p = brick_texel(dst_shape, brick_index(tree, targets[s], k), dir_block(tree, d)) + border_local(o, s);
                textureStore(dst, p, stored);
            }
        }
    }
}

// The value at level k, direction block d, of the node whose children's brick is `below`
// (level k - 1): the dense volume's filter over its eight voxels, as stored: premultiplied.
fn filtered(below: u32, k: u32, d: u32) -> vec4<f32> {
    if d >= LOBE_EXITANCE {
        return lobe_filtered(below, k, d);
    }
    // Level 0 is isotropic: every direction filters its one block.
    let block = select(dir_block(tree, d), 0u, k == 1u);
    let base = brick_texel(atlas_shape(tree, k - 1u), brick_index(tree, below, k - 1u), block);
    var value = vec4<f32>(0.0);
    if tree.anisotropic == 0u {
        for (var j = 0u; j < 8u; j++) {
            value += source(base, octant_offset(j), k);
        }
        return value * 0.125;
    }
    let axis = d / 2u;
    let positive = (d & 1u) == 0u;
    for (var j = 0u; j < 4u; j++) {
        var front = vec3<u32>(0u);
        front[(axis + 1u) % 3u] = j & 1u;
        front[(axis + 2u) % 3u] = j >> 1u;
        var back = front;
        front[axis] = select(1u, 0u, positive);
        back[axis] = select(0u, 1u, positive);
        var f: vec4<f32>;
        var b: vec4<f32>;
        if k == 1u {
            f = leaf_source(base, front, below, d);
            b = leaf_source(base, back, below, d);
        } else {
            f = source(base, front, k);
            b = source(base, back, k);
        }
        value += f + (1.0 - f.a) * b;
    }
    return value * 0.25;
}

// Level D, the volume as one voxel, from the root's brick, into the brick TOP_NODE names (its
// texel 0: level D is sampled at exactly that texel's centre).
// Runs after every filter (one thread): the root's flag, set by depth 1, is cleared.
@compute @workgroup_size(1)
fn top() {
    textureStore(flags, flag_texel(0u), vec4<u32>(0u));
    let below = child(0u);
    let top = child(TOP_NODE);
    if below == 0u || top == 0u {
        return;
    }
    let k = tree.depth;
    let dirs = select(1u, tree.dirs, tree.anisotropic != 0u);
    for (var d = 0u; d < dirs; d++) {
        textureStore(dst, brick_texel(atlas_shape(tree, k), brick_index(tree, top, k), dir_block(tree, d)), filtered(below, k, d));
    }
}
