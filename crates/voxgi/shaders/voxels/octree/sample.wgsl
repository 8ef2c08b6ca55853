// The sparse voxel octree's side of the voxel contract (the dense volume's sample.wgsl lists
// it; the test `every_structure_defines_the_voxel_contract` checks the signatures).
//
// A sample at level-of-detail lod reads the level nearest to it, round(lod): one descent from
// the top grid to the node whose brick holds that level's voxel under the sample, then
// trilinear fetches inside that brick (voxels/octree/tree.wgsl has the layout). The descents to
// both levels around lod run in one loop without branches; a missing child parks a descent on
// node 1 (an unused node of the root tile whose child pointer stays 0), which reads as empty.
//
// Level 0 stores optical depth (L sigma, sigma); the levels above store premultiplied opacity
// (L alpha, alpha), converted to depth after each fetch. Along a direction block's axis two
// fetches, one per texel layer, are blended as depth; across it the trilinear filter averages
// opacity: partial coverage across the cone counts as partly covered, where depth averaged
// there saturates (an opaque texel beside an empty one would read nearly opaque halfway).
// Blending two levels would average depth again: the nearer level is read instead.
//
// Everything here reads @group(1) only; `OctreeVolume::sampling_layout` is its twin.

//!include shared/volume.wgsl
//!include shared/specular_lobe.wgsl
//!include voxels/tree.wgsl

@group(1) @binding(0) var<uniform> tree: Octree;
@group(1) @binding(1) var<storage, read> tree_nodes: array<u32>;
@group(1) @binding(2) var even_atlas: texture_3d<f32>;
@group(1) @binding(3) var odd_atlas: texture_3d<f32>;
@group(1) @binding(4) var voxel_sampler: sampler;
// The top grid (voxels/octree/tree.wgsl): where descents start.
@group(1) @binding(5) var<storage, read> tree_grid: array<u32>;

const WIDE_SAMPLE: f32 = 2.0;

// True when the pipeline serves an isotropic octree: one block read per sample instead of three.
override ISOTROPIC_ONLY: bool = false;
// Directional blocks a sample reads: 3, every axis by its weight, or 2, the two of largest
// weight (as the dense volume's).
override SAMPLE_AXES: u32 = 3u;
// True when the pipeline serves an octree with specular lobes: its levels above the leaves
// hold the lobes' moments in two more blocks, which samples add (as the dense volume's
// `LOBE_CHAIN`; a constant so that other pipelines carry no branch).
override LOBE_CHAIN: bool = false;

fn voxels_voxel_size() -> f32 {
    return tree.voxel_size;
}

fn voxels_voxel_size_at(p: vec3<f32>) -> f32 {
    return tree.voxel_size;
}

fn voxels_contains(p: vec3<f32>) -> bool {
    return inside_tree(tree_uvw(p));
}

fn sample_voxels(pos: vec3<f32>, diameter: f32, dir: vec3<f32>) -> vec4<f32> {
    return from_depth(sample_depth(pos, diameter, dir));
}

fn sample_depth(pos: vec3<f32>, diameter: f32, dir: vec3<f32>) -> vec4<f32> {
    let uvw = tree_uvw(pos);
    let lod = clamp(log2(max(diameter / tree.voxel_size, 1.0)), 0.0, f32(tree.depth));
    let s = sample_levels(uvw, lod, dir) * border_weight(uvw, lod, f32(tree.resolution));
    return select(vec4<f32>(0.0), s, inside_tree(uvw));
}

fn sample_depth_wide(pos: vec3<f32>, diameter: f32, dir: vec3<f32>) -> vec4<f32> {
    let uvw = tree_uvw(pos);
    let lod = clamp(log2(diameter / tree.voxel_size), 1.0, f32(tree.depth));
    let s = sample_levels(uvw, lod, dir) * border_weight(uvw, lod, f32(tree.resolution));
    return select(vec4<f32>(0.0), s, inside_tree(uvw));
}

fn tree_uvw(pos: vec3<f32>) -> vec3<f32> {
    return (pos - tree.origin) / (tree.voxel_size * f32(tree.resolution));
}

fn inside_tree(uvw: vec3<f32>) -> bool {
    return all(uvw >= vec3<f32>(0.0)) && all(uvw <= vec3<f32>(1.0));
}

fn tree_child(n: u32) -> u32 {
    return tree_nodes[NODE_HEADER + n * NODE_STRIDE];
}

// The top grid's node at coordinate c of depth t; node 1 (empty) where there is none (depth 0
// is the root, node 0).
fn grid_node(c: vec3<u32>, t: u32) -> u32 {
    let n = tree_grid[grid_index(c, t)];
    return select(n, 1u, n == 0u && t > 0u);
}

// One step of a descent: the child of `node` in octant `o`, or node 1 (empty) when it has none.
fn descend_step(node: u32, o: u32) -> u32 {
    let tile = tree_child(node);
    return select(tile * 8u + o, 1u, tile == 0u);
}

// Optical depth of the direction block whose first texel is `corner`, at brick-local texel
// position `local` (in [0.5, 2.5): sample_levels' la and lb), read along `axis`: trilinear
// fetches at the centres of the two layers of texels around `local` along the axis, each made
// depth (`opacity`: the texels store premultiplied opacity) and blended by `local`'s place
// between them. Both layers lie inside the brick (0.5 ..= 2.5). Stored depth blends to what
// one fetch at `local` reads.
fn fetch_along(atlas: texture_3d<f32>, corner: vec3<f32>, local: vec3<f32>, axis: u32, inv: vec3<f32>, opacity: bool) -> vec4<f32> {
    let p = local[axis] - 0.5;
    let l0 = floor(p);
    let on = vec3<u32>(axis) == vec3<u32>(0u, 1u, 2u);
    let s0 = textureSampleLevel(atlas, voxel_sampler, (corner + select(local, vec3<f32>(l0 + 0.5), on)) * inv, 0.0);
    let s1 = textureSampleLevel(atlas, voxel_sampler, (corner + select(local, vec3<f32>(l0 + 1.5), on)) * inv, 0.0);
    return mix(select(s0, to_depth(s0), opacity), select(s1, to_depth(s1), opacity), p - l0);
}

// Level `lvl` of the brick of `tile` in `atlas` (the level's; `shape`, its region), at
// brick-local texel position `local`, along `dir`, as optical depth: three blocks weighted by
// the squared direction cosines, each read along its own axis (two with SAMPLE_AXES = 2, one
// with ISOTROPIC_ONLY). Level 0 and an isotropic octree have one block: its three reads weigh
// one along the main axis and none along the others (cheaper on CPU drivers than a branch).
fn fetch_level(atlas: texture_3d<f32>, shape: AtlasShape, tile: u32, lvl: u32, local: vec3<f32>, dir: vec3<f32>) -> vec4<f32> {
    // A tile of 0 (no brick) reads some texel and is masked below.
    let b = brick_index(tree, max(tile, class_base(tree, brick_class(lvl))), lvl);
    let corner = vec3<f32>(brick_texel(shape, b, 0u));
    let inv = shape.inv_size.xyz;
    let opacity = lvl > 0u;
    var v: vec4<f32>;
    if ISOTROPIC_ONLY {
        v = fetch_along(atlas, corner, local, main_axis(dir), inv, opacity);
    } else {
        // An isotropic octree's one block serves every axis, as level 0's does: read along the
        // nearest (`axis_weights`).
        let directional = tree.dirs > 1u && lvl > 0u;
        let block = select(0.0, f32(shape.block), directional);
        let bx = select(1.0, 0.0, dir.x >= 0.0);
        let by = select(3.0, 2.0, dir.y >= 0.0);
        let bz = select(5.0, 4.0, dir.z >= 0.0);
        let w = axis_weights(dir, directional);
        let cx = corner + vec3<f32>(0.0, 0.0, bx * block);
        let cy = corner + vec3<f32>(0.0, 0.0, by * block);
        let cz = corner + vec3<f32>(0.0, 0.0, bz * block);
        if SAMPLE_AXES == 2u {
            // The two axes of largest weight, renormalised (as the dense volume's).
            let drop_x = w.x <= w.y && w.x <= w.z;
            let drop_y = !drop_x && w.y <= w.z;
            let c0 = select(cx, cy, drop_x);
            let a0 = select(0u, 1u, drop_x);
            let w0 = select(w.x, w.y, drop_x);
            let c1 = select(select(cy, cz, drop_y), cz, drop_x);
            let a1 = select(select(1u, 2u, drop_y), 2u, drop_x);
            let w1 = select(select(w.y, w.z, drop_y), w.z, drop_x);
            let s0 = fetch_along(atlas, c0, local, a0, inv, opacity);
            let s1 = fetch_along(atlas, c1, local, a1, inv, opacity);
            v = (w0 * s0 + w1 * s1) / max(w0 + w1, 1e-6);
        } else {
            let x = fetch_along(atlas, cx, local, 0u, inv, opacity);
            let y = fetch_along(atlas, cy, local, 1u, inv, opacity);
            let z = fetch_along(atlas, cz, local, 2u, inv, opacity);
            v = w.x * x + w.y * y + w.z * z;
        }
        if LOBE_CHAIN && lvl > 0u {
            v = vec4<f32>(v.rgb + brick_lobe_light(atlas, corner + local, block, inv, dir) * v.a, v.a);
        }
    }
    return select(vec4<f32>(0.0), v, tile != 0u);
}

// The light the lobes of a brick's texel at `origin` (its level's blocks `block` texels apart
// in z) send back along `dir` (shared/specular_lobe.wgsl). Level 0 has none: its one block is
// the leaves' light.
fn brick_lobe_light(atlas: texture_3d<f32>, origin: vec3<f32>, block: f32, inv: vec3<f32>, dir: vec3<f32>) -> vec3<f32> {
    let m = textureSampleLevel(atlas, voxel_sampler, (origin + vec3<f32>(0.0, 0.0, f32(LOBE_EXITANCE) * block)) * inv, 0.0);
    let l = textureSampleLevel(atlas, voxel_sampler, (origin + vec3<f32>(0.0, 0.0, f32(LOBE_DIRECTION) * block)) * inv, 0.0);
    return chain_lobe_light(m, l, dir);
}

// The even atlas's region for level `lvl` (even): the leaf region for 0, else the even one.
fn even_region(lvl: u32) -> AtlasShape {
    let leaf = lvl == 0u;
    let l = tree.leaf_atlas;
    let e = tree.even_atlas;
    return AtlasShape(select(e.shift, l.shift, leaf), select(e.block, l.block, leaf), select(e.z0, l.z0, leaf), e.inv_size);
}

// Optical depth at lod, read from the nearer of the levels floor(lod) and floor(lod) + 1.
fn sample_levels(uvw: vec3<f32>, lod: f32, dir: vec3<f32>) -> vec4<f32> {
    let lo = min(u32(lod), tree.depth - 1u);
    let f = lod - f32(lo);
    let ra = f32(tree.resolution >> lo);
    let rb = 0.5 * ra;
    // Voxel coordinates at the two levels, clamped as a clamp-to-edge sampler would.
    let qa = clamp(uvw * ra - 0.5, vec3<f32>(0.0), vec3<f32>(ra - 1.0));
    let qb = clamp(uvw * rb - 0.5, vec3<f32>(0.0), vec3<f32>(rb - 1.0));
    let na = vec3<u32>(qa) >> vec3<u32>(1u);
    let nb = vec3<u32>(qb) >> vec3<u32>(1u);
    // The node holding level lo's voxels is at depth da; level lo + 1's at depth da - 1 (above
    // the root: TOP_NODE, whose brick is level D). Both start from the top grid, at depth at
    // most g, and descend the rest of the way together (b needs one step less, or none).
    let da = tree.depth - 1u - lo;
    let db = max(da, 1u) - 1u;
    let g = grid_depth(tree);
    let sa = min(da, g);
    let sb = min(db, g);
    var a = grid_node(na >> vec3<u32>(da - sa), sa);
    var b = select(grid_node(nb >> vec3<u32>(db - sb), sb), TOP_NODE, da == 0u);
    let steps_b = db - sb;
    for (var i = 0u; i < da - sa; i++) {
        a = descend_step(a, octant_of(na, da - sa - 1u - i));
        b = select(b, descend_step(b, octant_of(nb, (steps_b - 1u - i) & 31u)), i < steps_b);
    }
    // Brick-local positions: q less twice its node's coordinate is in [0, 2), so these lie in
    // [0.5, 2.5), inside the 3-texel brick.
    let la = qa - 2.0 * vec3<f32>(na) + 0.5;
    let lb = qb - 2.0 * vec3<f32>(nb) + 0.5;
    let ta = tree_child(a);
    let tb = tree_child(b);
    let upper = f >= 0.5;
    let lvl = select(lo, lo + 1u, upper);
    let tile = select(ta, tb, upper);
    let local = select(la, lb, upper);
    // A texture is no value to select, so both atlases are read, the other level's masked
    // (tile 0), and the chosen one kept: on CPU drivers a branch between the two, which lanes
    // disagree on wherever neighbouring samples lie either side of a half level, costs more.
    let lo_even = (lo & 1u) == 0u;
    let le = select(lo + 1u, lo, lo_even);
    let lodd = select(lo, lo + 1u, lo_even);
    let se = fetch_level(even_atlas, even_region(le), select(0u, tile, le == lvl), le, local, dir);
    let so = fetch_level(odd_atlas, tree.odd_atlas, select(0u, tile, lodd == lvl), lodd, local, dir);
    let s = select(so, se, le == lvl);
    if LOBE_CHAIN && lvl == 0u && tree.dirs > 1u {
        // Samples that read level 0 see the lobes of level 1 wherever they see a surface, as
        // the dense volume's (voxels/dense/windows.wgsl, `window_depth`).
        let b = brick_index(tree, max(tb, class_base(tree, brick_class(1u))), 1u);
        let origin = vec3<f32>(brick_texel(tree.odd_atlas, b, 0u)) + lb;
        let light = brick_lobe_light(odd_atlas, origin, f32(tree.odd_atlas.block), tree.odd_atlas.inv_size.xyz, dir);
        return vec4<f32>(s.rgb + select(vec3<f32>(0.0), light, tb != 0u) * s.a, s.a);
    }
    return s;
}
