// The octree's irradiance lookup for the fast shading (the names are those of the dense
// volume's irradiance.wgsl, which lists them): a descent to the voxel's parent, whose tile
// holds the leaf voxels; a leaf's child word is 1 + its slot (voxels/octree/tree.wgsl). At
// @group(3), after sample.wgsl's @group(1); `OctreeVolume::irradiance_layout` is the twin.

//!include voxels/sample.wgsl

// Per slot: irradiance (rgb, f16), occlusion (f16), normal and agreement (snorm8), written by
// the last bounce.
@group(3) @binding(0) var<storage, read> irradiance_leaves: array<vec4<u32>>;

fn irradiance_grid(p: vec3<f32>) -> vec3<f32> {
    return (p - tree.origin) / tree.voxel_size;
}

fn leaf_irradiance_at(c: vec3<i32>) -> vec4<u32> {
    let r = i32(tree.resolution);
    let inside = all(c >= vec3<i32>(0)) && all(c < vec3<i32>(r));
    let u = vec3<u32>(clamp(c, vec3<i32>(0), vec3<i32>(r - 1)));
    // The parent at depth D - 1, from the top grid down.
    let d = tree.depth - 1u;
    let s = min(d, grid_depth(tree));
    let pc = u >> vec3<u32>(1u);
    var node = grid_node(pc >> vec3<u32>(d - s), s);
    for (var i = 0u; i < d - s; i++) {
        node = descend_step(node, octant_of(pc, d - s - 1u - i));
    }
    let tile = tree_child(node);
    let word = tree_nodes[child_word(tree, tile * 8u + octant_of(u, 0u))];
    let slot = word - 1u;
    let n = arrayLength(&irradiance_leaves);
    let found = inside && tile != 0u && word != 0u && slot < n;
    return select(vec4<u32>(0u), irradiance_leaves[min(slot, n - 1u)], found);
}
