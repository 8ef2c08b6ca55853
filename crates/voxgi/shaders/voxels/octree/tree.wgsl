// The sparse voxel octree's layout, shared by its build, filter, sampling, leaves and debug
// view (twin: `GpuOctree` in src/voxel/octree/mod.rs; docs/ARCHITECTURE.md has the picture).
//
// Nodes come in tiles of 2x2x2. Tile 0 holds the root (node 0; nodes 1..7 are unused), so a
// child pointer of 0 means "none". A node's record is four u32: its child pointer (the tile
// of its eight children, which also names its brick), and its neighbours along -x, -y and -z
// at the same depth (0: none). Only the negative neighbours are kept: the build and the
// filter push each value into the bricks that hold it as a border, and those lie on the
// negative side.
//
// A node at depth t < D (D = log2 of the finest resolution) that has children has a brick:
// the values of its eight children (the voxels of level k = D - 1 - t, voxel-centred, 2x2x2)
// with a border of one voxel on the positive side copied from the neighbouring bricks, stored
// as 3x3x3 texels. A trilinear fetch anywhere in [0.5, 2.5] texels then blends exactly the
// eight voxels a dense volume's trilinear fetch would, so the octree samples the same function
// as the dense volume. A sample at level-k voxel coordinate q reads the brick of the node that
// holds voxel floor(q): for that brick to exist wherever one of the eight voxels is occupied,
// a node is subdivided when it or one of its seven positive neighbours holds geometry (the
// build's `dilate`).
//
// Nodes at depth D are the finest voxels themselves: their child pointer is 1 + their leaf
// slot, and they keep nothing else (one u32 each, after the other nodes' records: see
// `child_word`). Tiles are numbered per class (E, then O, then V, after the root tile), and a
// brick's place in its atlas is its tile's index in the class:
//   class V: tiles at depth D (leaf voxels); their parents' bricks hold level 0 (isotropic):
//            the leaf region of the even atlas;
//   class E: tiles whose parents' bricks hold an even level k > 0: the even region of the even
//            atlas;
//   class O: odd levels: the odd atlas.
// A region holds its bricks in rows and layers of powers of two (addressing by shifts: CPU
// drivers have no vector integer division), and its direction blocks one after another along
// z. Levels alternate between the even and the odd atlas, so filtering level k + 1 from level
// k reads one texture and writes the other.

// Where a region of an atlas keeps its bricks: log2 of the bricks per row and per layer, the
// texels of one direction block along z, the region's first texel along z, and 1 / the atlas
// size in texels.
struct AtlasShape {
    shift: vec2<u32>,
    block: u32,
    z0: u32,
    inv_size: vec4<f32>,
}

struct Octree {
    // World position of the volume's minimum corner.
    origin: vec3<f32>,
    // Finest voxels per side (2^depth).
    resolution: u32,
    // World size of a finest voxel.
    voxel_size: f32,
    // log2(resolution): depth of the leaf voxels below the root.
    depth: u32,
    // 1: six directional values per voxel above the finest level, 0: one.
    anisotropic: u32,
    // Direction blocks of the atlases above level 0: 6 or 1.
    dirs: u32,
    // First tile of classes V, E and O (in the pool's order E, O, V), and the end of the pool.
    base_v: u32,
    base_e: u32,
    base_o: u32,
    tiles: u32,
    // Leaf slots the pool holds.
    slots: u32,
    // 1: the first directional level weighs the leaves by their normals (`ndf_weight`).
    ndf: u32,
    // 1: `leaf_direct` keeps a specular lobe after each leaf's direct light (`Filtering::lobes`).
    lobes: u32,
    _pad: u32,
    leaf_atlas: AtlasShape,
    even_atlas: AtlasShape,
    odd_atlas: AtlasShape,
}

// The node buffer starts with a header of counters, so that every pass reaching the nodes
// reaches them too (one storage binding fewer: inject's stage holds the minimum eight): [0]
// leaf slots, [1..4] tiles of classes V, E and O (all counted past the capacity: the host
// reads these back to grow the pools), [STOOD_IN] the static leaves the last update's slots
// stand in for (hidden: the host counts the occupied voxels without them), [STATIC_SLOTS] the
// static build's slots (read back too: updates keep sums only for the slots after them),
// [FIRST_FRAGMENT] the first fragment the running build or update reads, [UPDATING] 1 during
// an update; from [RANGES], per depth t, the first tile and the number of tiles of the static
// build, from [DYN_RANGES] those of the last update (after the static ones in each class);
// from [BOX] the box of the update's fragments; [ALLOC_START] where the tiles of the depth
// being allocated start in their class.
const NODE_HEADER: u32 = 64u;
const STOOD_IN: u32 = 4u;
const STATIC_SLOTS: u32 = 5u;
const FIRST_FRAGMENT: u32 = 6u;
const UPDATING: u32 = 7u;
const RANGES: u32 = 8u;
const DYN_RANGES: u32 = 32u;
// [BOX..BOX + 3] and [BOX + 3..BOX + 6]: the smallest and largest finest-voxel coordinates of
// an update's fragments (octree_update.wgsl's `bounds`).
const BOX: u32 = 54u;
const ALLOC_START: u32 = 60u;
const NODE_STRIDE: u32 = 4u;
// Node 2 of the root tile stands above the root: its child pointer names the brick of level D,
// the whole volume as one voxel (the dense volume's top mip), filtered from the root's brick.
// (Node 1 stays empty: descents that lose their way park there.)
const TOP_NODE: u32 = 2u;
// u32 per tile in the tile buffer: the parent node, and the parent's packed coordinate.
const TILE_WORDS: u32 = 2u;

// The filter's flags (an r32uint 2D storage texture, 1 << FLAG_SHIFT texels a row, one per
// node above the leaves): 1 where a node's value is out of date, so the filter redoes only
// those nodes and the levels above them. Whatever writes a brick's texels flags the brick's
// node (the parent of the tile the brick belongs to): the leaf store, an update's clears; an
// update's new nodes flag themselves, their parents and the nodes whose values lie in their
// bricks' borders.
const FLAG_SHIFT: u32 = 12u;

fn flag_texel(n: u32) -> vec2<u32> {
    return vec2<u32>(n & ((1u << FLAG_SHIFT) - 1u), n >> FLAG_SHIFT);
}

// The top grid: for each depth t up to grid_depth (at most GRID_DEPTH), the node at every
// position of that depth (2^t per side, x fastest), 0 where there is none; depths one after
// the other. Sampling starts its descents there instead of at the root, so a descent takes at
// most depth - 1 - GRID_DEPTH steps (none up to 128³).
const GRID_DEPTH: u32 = 6u;

fn grid_depth(t: Octree) -> u32 {
    return min(t.depth - 1u, GRID_DEPTH);
}

fn grid_index(c: vec3<u32>, t: u32) -> u32 {
    // Entries of the depths above t: (8^t - 1) / 7.
    let above = ((1u << (3u * t)) - 1u) / 7u;
    let side = 1u << t;
    return above + c.x + side * (c.y + side * c.z);
}
// A node's child field while the build flags it: geometry lies in it (CONTENT) or in one of
// its positive neighbours (NEEDED). Allocation replaces both by a tile index.
const CONTENT: u32 = 0xffffffffu;
const NEEDED: u32 = 0xfffffffeu;
const NONE: u32 = 0xffffffffu;
// Per leaf slot, u32: packed coordinate, parent node | octant << 29, albedo (rgba8unorm),
// normal (rgba8snorm), emission and the surface's distance (2 x f16 each).
const SLOT_STRIDE: u32 = 6u;
// Per leaf slot, the build's sums of its fragments and the static slot an update's slot stands
// in for (voxels/octree/build_shared.wgsl's `scratch`, which only builds and updates bind).
const ACCUM_STRIDE: u32 = 14u;
const STANDS_IN: u32 = 13u;
// Word 1 of a static leaf slot while an update's slot stands in for it: no pass lights it, and
// the next update's clear gives it back its parent.
const HIDDEN: u32 = 0xffffffffu;

fn octant_of(c: vec3<u32>, shift: u32) -> u32 {
    let b = (c >> vec3<u32>(shift)) & vec3<u32>(1u);
    return b.x | (b.y << 1u) | (b.z << 2u);
}

fn octant_offset(o: u32) -> vec3<u32> {
    return vec3<u32>(o & 1u, (o >> 1u) & 1u, (o >> 2u) & 1u);
}

// The class (0 V, 1 E, 2 O) of the tiles at depth t + 1, whose parents' bricks hold level
// depth - 1 - t.
fn brick_class(level: u32) -> u32 {
    if level == 0u {
        return 0u;
    }
    return select(2u, 1u, (level & 1u) == 0u);
}

fn class_base(tree: Octree, cls: u32) -> u32 {
    return select(select(tree.base_o, tree.base_e, cls == 1u), tree.base_v, cls == 0u);
}

fn class_end(tree: Octree, cls: u32) -> u32 {
    return select(select(tree.base_v, tree.base_o, cls == 1u), tree.tiles, cls == 0u);
}

// The word of node n's child pointer in the node buffer: a four-word record for the nodes of
// the root tile and of classes E and O, one word for a leaf voxel (class V).
fn child_word(tree: Octree, n: u32) -> u32 {
    let leaves = 8u * tree.base_v;
    return select(NODE_HEADER + n * NODE_STRIDE, NODE_HEADER + leaves * NODE_STRIDE + (n - leaves), n >= leaves);
}

// The index of the brick of `tile` (which holds `level`) in that level's atlas.
fn brick_index(tree: Octree, tile: u32, level: u32) -> u32 {
    return tile - class_base(tree, brick_class(level));
}

// The atlas direction block of direction `dir` (0..6: +X, -X, +Y, -Y, +Z, -Z): 0 when the
// octree is isotropic.
fn dir_block(tree: Octree, dir: u32) -> u32 {
    return select(0u, dir, tree.dirs > 1u);
}

// First texel of direction block `block` of brick `b` in an atlas of shape `a`.
fn brick_texel(a: AtlasShape, b: u32, block: u32) -> vec3<u32> {
    let x = b & ((1u << a.shift.x) - 1u);
    let y = (b >> a.shift.x) & ((1u << a.shift.y) - 1u);
    let z = b >> (a.shift.x + a.shift.y);
    return 3u * vec3<u32>(x, y, z) + vec3<u32>(0u, 0u, a.z0 + block * a.block);
}

// The atlas region of `level`: the leaf region for level 0, else the even or the odd one.
fn atlas_shape(tree: Octree, level: u32) -> AtlasShape {
    if level == 0u {
        return tree.leaf_atlas;
    }
    if (level & 1u) == 0u {
        return tree.even_atlas;
    }
    return tree.odd_atlas;
}

// A value of voxel octant `o` of a node m's brick also lies in the positive border of the bricks
// of m's negative neighbours: those along the axes of `s` (bits: 1 x, 2 y, 4 z), when `o` is
// 0 along each of them. `around[s]` is m shifted by -1 along the axes of s (0: none).
fn border_holds(o: u32, s: u32) -> bool {
    return (s & o) == 0u;
}

// Where in that neighbour's brick the value lies: 2 along the axes of s, o's bit elsewhere.
fn border_local(o: u32, s: u32) -> vec3<u32> {
    let bits = octant_offset(o);
    return select(bits, vec3<u32>(2u), octant_offset(s) == vec3<u32>(1u));
}
