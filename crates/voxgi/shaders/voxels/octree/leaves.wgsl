// The octree's leaves: the occupied finest voxels, one slot each (the names are those of the
// dense volume's leaves.wgsl, which lists them). All at @group(2); `OctreeVolume::leaves_layout`
// is the twin.

//!include shared/volume.wgsl
//!include shared/fragment.wgsl
//!include voxels/tree.wgsl

@group(2) @binding(0) var<uniform> leaf_tree: Octree;
// Per slot, SLOT_STRIDE u32 (voxels/octree/tree.wgsl).
@group(2) @binding(1) var<storage, read> leaf_slots: array<u32>;
@group(2) @binding(2) var<storage, read_write> leaf_direct: array<vec4<f32>>;
@group(2) @binding(3) var<storage, read_write> leaf_next: array<vec4<f32>>;
// The header (its word 0: slots of the last build, counted past the capacity), then the nodes.
@group(2) @binding(4) var<storage, read> leaf_nodes: array<u32>;

const NO_LEAF: u32 = 0xffffffffu;

// Whether `leaf_direct` keeps a specular lobe after each leaf's direct light.
fn leaf_lobes() -> bool {
    return leaf_tree.lobes != 0u;
}

// Where leaf i's direct light lies in `leaf_direct`.
fn direct_index(i: u32) -> u32 {
    return select(i, 2u * i, leaf_lobes());
}

fn leaf_slot(t: u32) -> u32 {
    return select(NO_LEAF, t, leaf_exists(t));
}

// A static leaf whose voxel an update's slot holds (with its dynamic geometry) is hidden.
fn leaf_exists(i: u32) -> bool {
    return i < min(leaf_nodes[0], leaf_tree.slots) && leaf_slots[i * SLOT_STRIDE + 1u] != HIDDEN;
}

// An update hands out the slots after the static build's anew (octree_update.wgsl).
fn leaf_is_new(i: u32) -> bool {
    return i >= leaf_nodes[STATIC_SLOTS];
}

// The octree keeps no leaf's light through a build.
fn leaf_direct_kept(i: u32) -> bool {
    return false;
}

fn leaf_coord(i: u32) -> vec3<u32> {
    return unpack_coord(leaf_slots[i * SLOT_STRIDE]);
}

fn leaf_center(i: u32) -> vec3<f32> {
    return leaf_tree.origin + (vec3<f32>(leaf_coord(i)) + 0.5) * leaf_tree.voxel_size;
}

fn leaf_size(i: u32) -> f32 {
    return leaf_tree.voxel_size;
}

fn leaf_size_max() -> f32 {
    return leaf_tree.voxel_size;
}

fn leaf_albedo(i: u32) -> vec4<f32> {
    return unpack4x8unorm(leaf_slots[i * SLOT_STRIDE + 2u]);
}

fn leaf_normal(i: u32) -> vec4<f32> {
    return unpack4x8snorm(leaf_slots[i * SLOT_STRIDE + 3u]);
}

fn leaf_emission(i: u32) -> vec3<f32> {
    let rg = unpack2x16float(leaf_slots[i * SLOT_STRIDE + 4u]);
    let b = unpack2x16float(leaf_slots[i * SLOT_STRIDE + 5u]);
    return vec3<f32>(rg, b.x);
}

fn leaf_surface(i: u32) -> f32 {
    return unpack2x16float(leaf_slots[i * SLOT_STRIDE + 5u]).y;
}
