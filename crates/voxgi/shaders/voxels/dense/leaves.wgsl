// The dense volume's leaves: the occupied finest voxels, one slot each. The lighting passes
// (inject, bounce, bounce_store) reach a structure's leaves through these names only:
//
//   fn leaf_slot(t) -> u32                        the slot of leaf t, numbered 0.. as a
//                                                 dispatch over `leaf_dispatch` numbers its
//                                                 threads, or NO_LEAF past the last leaf
//   fn leaf_exists(i) -> bool                     slot i holds a leaf
//   fn leaf_is_new(i) -> bool                     made by the last update or a build of
//                                                 part of the structure: its slot held
//                                                 another leaf before (or none)
//   fn leaf_direct_kept(i) -> bool                new, but its direct light is that of the
//                                                 leaf that held its voxel before the build
//                                                 (a moved window's voxels in both places)
//   fn leaf_coord(i) -> vec3<u32>                 the leaf's finest-grid voxel
//   fn leaf_center(i) -> vec3<f32>                its centre, metres
//   fn leaf_size(i) -> f32                        its edge, metres
//   fn leaf_size_max() -> f32                     the largest leaf's edge
//   fn leaf_albedo(i) / leaf_normal(i) / leaf_emission(i)   what the build resolved
//   fn leaf_surface(i) -> f32                     how far its centre lies in front of its
//                                                 surface along the normal, voxels
//   leaf_direct[direct_index(i)], leaf_next[i]    per-leaf light: direct (inject) and bounced
//   fn leaf_lobes() -> bool                       leaf_direct[2i + 1] holds the direct light's
//                                                 specular lobe (shared/specular_lobe.wgsl)
//
// and voxels/<kind>/leaf_store.wgsl's store_leaf_radiance(i, premultiplied). All at
// @group(2) (the store at @group(3)); `DenseVolume::leaves_layout` is the twin. The clipmap
// takes this file as it is, with a placement.wgsl of its own.

//!include shared/volume.wgsl

@group(2) @binding(0) var<uniform> leaf_grid: Volume;
@group(2) @binding(1) var leaf_albedo_tex: texture_3d<f32>;
@group(2) @binding(2) var leaf_normal_tex: texture_3d<f32>;
@group(2) @binding(3) var leaf_emission_tex: texture_3d<f32>;
// Per slot: the voxel's linear index.
@group(2) @binding(4) var<storage, read> slot_voxel: array<u32>;
// The slots each window holds (voxels/dense/slots.wgsl).
// Read-write: the leaf stores list the voxels they write in it for the filter (changed.wgsl).
@group(2) @binding(5) var<storage, read_write> counters: array<atomic<u32>>;
// Per leaf: direct radiance (rgb) and opacity, kept for the bounces; with lobes
// (`Filtering::lobes`, the buffer twice as long) its specular lobe after each.
@group(2) @binding(6) var<storage, read_write> leaf_direct: array<vec4<f32>>;
// Per leaf: the last bounce's outgoing radiance and opacity.
@group(2) @binding(7) var<storage, read_write> leaf_next: array<vec4<f32>>;

//!include voxels/slots.wgsl

const NO_LEAF: u32 = 0xffffffffu;

fn leaf_lobes() -> bool {
    return arrayLength(&leaf_direct) >= 2u * arrayLength(&slot_voxel);
}

// Where leaf i's direct light lies in `leaf_direct`.
fn direct_index(i: u32) -> u32 {
    return select(i, 2u * i, leaf_lobes());
}

fn leaf_slot(t: u32) -> u32 {
    return filled_slot(t, leaf_grid.windows);
}

fn leaf_exists(i: u32) -> bool {
    return slot_filled(i, leaf_grid.windows);
}

// Slots above a window's static geometry's are handed out anew by every update
// (dense_update); a window the last build rebuilt alone has new leaves in every slot
// (`leaf_window_rebuilt` of voxels/<kind>/placement.wgsl).
fn leaf_is_new(i: u32) -> bool {
    return !slot_static(i, leaf_grid.windows) || leaf_window_rebuilt(i / window_slots(leaf_grid.windows));
}

// The build's `keep` handed these slots their voxel's direct light from before the move.
fn leaf_direct_kept(i: u32) -> bool {
    let c = window_slots(leaf_grid.windows);
    let w = i / c;
    return leaf_window_rebuilt(w) && i - w * c < atomicLoad(&counters[window_word(w, W_KEPT)]);
}

fn leaf_coord(i: u32) -> vec3<u32> {
    return voxel_coord(slot_voxel[i], leaf_grid.resolution);
}

// Where leaves lie: voxels/<kind>/placement.wgsl (leaf_center, leaf_size, leaf_size_max).
//!include voxels/placement.wgsl

// Albedo (rgb) and opacity.
fn leaf_albedo(i: u32) -> vec4<f32> {
    return textureLoad(leaf_albedo_tex, leaf_coord(i), 0);
}

// Mean normal (xyz) and how well the fragments' normals agree (w).
fn leaf_normal(i: u32) -> vec4<f32> {
    return textureLoad(leaf_normal_tex, leaf_coord(i), 0);
}

fn leaf_emission(i: u32) -> vec3<f32> {
    return textureLoad(leaf_emission_tex, leaf_coord(i), 0).rgb;
}

fn leaf_surface(i: u32) -> f32 {
    return textureLoad(leaf_emission_tex, leaf_coord(i), 0).a;
}
