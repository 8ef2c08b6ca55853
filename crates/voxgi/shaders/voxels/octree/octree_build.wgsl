// octree_build: voxel fragments -> the sparse voxel octree, level by level from the root, with
// indirect dispatches and no locks (Crassin and Green, "Octree-Based Sparse Voxelization Using
// the GPU Hardware Rasterizer", OpenGL Insights 2012). Per depth t, from 0 down:
//   flag     each fragment descends to its node at depth t and marks it CONTENT
//   dilate   each CONTENT node marks its seven negative neighbours NEEDED (their bricks hold
//            its voxels as their positive border)
//   mark     remember where this depth's tiles start in their class
//   count    per workgroup of 64 nodes, how many are marked
//   scan     one workgroup: the counts' exclusive prefix sum
//   allocate each marked node takes a tile of eight children (and so a brick), numbered by
//            its rank among the depth's marked nodes
//   finish   the new tiles' range and the dispatch size over their nodes
//   init     the new nodes: no children, their negative neighbours, a cleared brick, and
//            (down to GRID_DEPTH) their entry in the top grid
// then at depth D (the finest voxels): flag, count and scan, one leaf slot per occupied voxel
// (by rank), integer sums of the fragments per slot, and the averages. Ranks instead of an
// atomic counter make the layout itself deterministic, not only the values: the atlases'
// filtering rounds by a texel's position, so the same scene gives the same image every run.
//
// Every pool counts what it was asked for past its capacity; a node whose tile did not fit
// stays a leaf without children (its geometry is missing until the pools grow and the next
// build runs), never an overrun. The steps both this and octree_update run are in
// build_shared.wgsl.

//!include voxels/build_shared.wgsl


@compute @workgroup_size(1)
fn begin() {
    for (var i = 0u; i <= STOOD_IN; i++) {
        atomicStore(&nodes[i], 0u);
    }
    // Depth 0 is the root tile: tile 0, whose node 0 is the root.
    atomicStore(&nodes[RANGES], 0u);
    atomicStore(&nodes[RANGES + 1u], 1u);
    for (var t = 1u; t <= tree.depth; t++) {
        atomicStore(&nodes[RANGES + 2u * t], 0u);
        atomicStore(&nodes[RANGES + 2u * t + 1u], 0u);
    }
    for (var t = 0u; t <= tree.depth; t++) {
        atomicStore(&nodes[DYN_RANGES + 2u * t], 0u);
        atomicStore(&nodes[DYN_RANGES + 2u * t + 1u], 0u);
    }
    atomicStore(&nodes[STATIC_SLOTS], 0u);
    atomicStore(&nodes[FIRST_FRAGMENT], 0u);
    atomicStore(&nodes[UPDATING], 0u);
    for (var i = 0u; i < 8u * NODE_STRIDE; i++) {
        atomicStore(&nodes[NODE_HEADER + i], 0u);
    }
    // The root tile's "parent" sits at the origin, so the root's coordinate is 0.
    tiles[0] = 0u;
    tiles[1] = 0u;
    grid[0] = 0u;
    // The level above the root's brick (one voxel, level D): the first tile of its class,
    // reserved here, is its brick, and node TOP_NODE of the root tile points to it.
    let top_class = brick_class(tree.depth);
    atomicStore(&nodes[1u + top_class], 1u);
    let top = class_base(tree, top_class);
    atomicStore(&nodes[NODE_HEADER + TOP_NODE * NODE_STRIDE], top);
    for (var o = 0u; o < 8u; o++) {
        clear_brick(top, tree.depth, o);
    }
    write_args(0u, stored_fragments());
    write_args(6u, 8u);
}

@compute @workgroup_size(64)
fn flag(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = flat(gid, nwg);
    if i >= stored_fragments() {
        return;
    }
    let node = descend(unpack_coord(fragments[i].coord), level.t);
    if node != NONE {
        atomicMax(&nodes[child_word(tree, node)], CONTENT);
    }
}

@compute @workgroup_size(64)
fn dilate(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let n = node_of_depth(flat(gid, nwg), level.t);
    if n == NONE || child(n) != CONTENT {
        return;
    }
    // The nodes n - (0|1, 0|1, 0|1): each holds a voxel of n in its brick's border. They all
    // exist (their parents were subdivided for the same reason one level up).
    let x = neighbour(n, 0u);
    let y = neighbour(n, 1u);
    let z = neighbour(n, 2u);
    var around = array<u32, 7>(x, y, z, 0u, 0u, 0u, 0u);
    if x != 0u {
        around[3] = neighbour(x, 1u);
        around[4] = neighbour(x, 2u);
    }
    if y != 0u {
        around[5] = neighbour(y, 2u);
    }
    if around[3] != 0u {
        around[6] = neighbour(around[3], 2u);
    }
    for (var k = 0u; k < 7u; k++) {
        if around[k] != 0u {
            atomicMax(&nodes[child_word(tree, around[k])], NEEDED);
        }
    }
}

@compute @workgroup_size(1)
fn finish() {
    let count = record_new_tiles(RANGES);
    write_args(6u + 3u * (level.t + 1u), count * 8u);
}


// The end of a build: its slots and fragments are the static geometry's; updates go after them.
@compute @workgroup_size(1)
fn seal() {
    atomicStore(&nodes[STATIC_SLOTS], min(atomicLoad(&nodes[0]), tree.slots));
    atomicStore(&nodes[FIRST_FRAGMENT], stored_fragments());
}
