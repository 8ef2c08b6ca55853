// Writing a leaf's radiance (as optical depth) into the level-0 brick of its parent node, and
// into the positive borders of the bricks of that node's negative neighbours that hold it
// (voxels/octree/tree.wgsl), so the bricks need no separate border pass. @group(3).

//!include voxels/leaves.wgsl
//!include shared/half.wgsl

@group(3) @binding(0) var leaf_atlas_out: texture_storage_3d<rgba16float, write>;
@group(3) @binding(1) var leaf_filter_flags: texture_storage_2d<r32uint, write>;

fn leaf_node_child(n: u32) -> u32 {
    return leaf_nodes[NODE_HEADER + n * NODE_STRIDE];
}

fn leaf_neighbour(n: u32, axis: u32) -> u32 {
    return leaf_nodes[NODE_HEADER + n * NODE_STRIDE + 1u + axis];
}

// `v`: premultiplied radiance (rgb) and opacity. The parent node is flagged for the filter
// (the neighbours' bricks take the value only in their borders, which nothing filters).
fn store_leaf_radiance(i: u32, v: vec4<f32>) {
    let info = leaf_slots[i * SLOT_STRIDE + 1u];
    let m = info & 0x1fffffffu;
    let o = info >> 29u;
    let d = to_half(to_depth(v));
    textureStore(leaf_filter_flags, flag_texel(m), vec4<u32>(1u));
    // Node 0 (the root) has no neighbours, so a missing one stays 0 down the chain.
    let x = leaf_neighbour(m, 0u);
    let y = leaf_neighbour(m, 1u);
    let xy = leaf_neighbour(x, 1u);
    let around = array<u32, 8>(m, x, y, xy, leaf_neighbour(m, 2u), leaf_neighbour(x, 2u), leaf_neighbour(y, 2u), leaf_neighbour(xy, 2u));
    for (var s = 0u; s < 8u; s++) {
        if !border_holds(o, s) || (s != 0u && around[s] == 0u) {
            continue;
        }
        let tile = leaf_node_child(around[s]);
        if tile == 0u {
            continue;
        }
        let p = brick_texel(leaf_tree.leaf_atlas, tile - leaf_tree.base_v, 0u) + border_local(o, s);
        textureStore(leaf_atlas_out, p, d);
    }
}
