// The dense volume's build resources and helpers, shared by dense_build (the static geometry,
// from scratch) and dense_update (the dynamic geometry, merged into the static build).

//!include shared/volume.wgsl
//!include shared/fragment.wgsl

@group(0) @binding(0) var<uniform> vol: Volume;
// The fragments, as voxelize (or any other source) left them: the only input.
@group(0) @binding(1) var<storage, read> fragments: array<Fragment>;
// [0] slots asked for (occupied voxels, counted past the capacity) of every window, [1] the
// most any window asked for (its part of the pool must hold them), [2] the fragments made
// (counted past their buffer; copied from their count before each build and update, which
// leaves a storage binding for `kept`), [3] entries of `touched` of
// this update, [4] of the previous update, [5] fragments of the static geometry (those from
// there on are the dynamic geometry's), [7] a bit per window the next build rebuilds (set by
// the host; the others keep their slots); each window's own words (slots.wgsl).
@group(0) @binding(2) var<storage, read_write> counters: array<atomic<u32>>;
// Per voxel: 0 empty, 2 + slot once allocated, LOCKED while allocating (or past capacity).
@group(0) @binding(3) var<storage, read_write> occupancy: array<atomic<u32>>;
// Per slot: the voxel's linear index.
@group(0) @binding(4) var<storage, read_write> slot_voxel: array<u32>;
// Per slot, ACCUM_STRIDE u32: the FRAGMENT_SUMS of shared/fragment.wgsl, then the largest
// coverage.
@group(0) @binding(5) var<storage, read_write> accum: array<atomic<u32>>;
@group(0) @binding(6) var albedo_out: texture_storage_3d<rgba8unorm, write>;
@group(0) @binding(7) var normal_out: texture_storage_3d<rgba8snorm, write>;
@group(0) @binding(8) var emission_out: texture_storage_3d<rgba16float, write>;
@group(0) @binding(9) var radiance_out: texture_storage_3d<rgba16float, write>;
// Per slot, DYN_STRIDE u32: the ACCUM_STRIDE sums of the dynamic fragments, apart from the
// static sums in `accum` so that undoing an update is zeroing them; then (static slots) 1
// while the slot is listed as touched; then entry `slot` of the touched list: the slots the
// dynamic fragments of this update fell into (static slots they share, and new slots above
// the static ones), resolved now and restored by the next update. (Eight storage buffers per
// stage is the minimum limit: the flag and the list share this one.)
@group(0) @binding(10) var<storage, read_write> dyn_accum: array<atomic<u32>>;
// A moved window's state from before its build (`DenseVolume::kept`): [0] the window plus one
// (0: the build keeps none), [1..4] how far it moved (its new corner minus the old, in voxels,
// i32: a voxel's old index is its new one plus this), [4] the words of a slot's direct light
// (4, or 8 with its specular lobe), from KEPT_OCCUPANCY its occupancy before
// the build, then its part's slots' voxels, then their static sums (ACCUM_STRIDE words a slot),
// then their direct light ([4] words a slot), then the direct light `keep` hands on, by the
// slot the voxel holds now (the host copies it into the leaves' after the step).
@group(0) @binding(11) var<storage, read_write> kept: array<u32>;
// The voxels written since the last filter, listed for the filter (changed.wgsl).
//!include voxels/changed.wgsl
//!include voxels/slots.wgsl

// Indirect dispatch arguments: [0..3] over slots, [3..6] over fragments, [6..9] over
// `touched`. Only the prepare kernels bind them (a buffer cannot be storage and indirect in
// one dispatch).
@group(1) @binding(0) var<storage, read_write> args: array<u32>;

const ACCUM_STRIDE: u32 = 13u;
const ACCUM_SUMS: u32 = FRAGMENT_SUMS;
const ACCUM_COVERAGE: u32 = FRAGMENT_SUMS;
const DYN_STRIDE: u32 = 15u;
const DYN_FLAG: u32 = 13u;
const DYN_LIST: u32 = 14u;

// Entry `i` of the touched list.
fn touched(i: u32) -> u32 {
    return atomicLoad(&dyn_accum[i * DYN_STRIDE + DYN_LIST]);
}
const LOCKED: u32 = 0xffffffffu;
const WG: u32 = 64u;

// Flat thread index for 2D indirect dispatches (65535 workgroups per dimension at most).
fn flat(gid: vec3<u32>, nwg: vec3<u32>) -> u32 {
    return gid.x + gid.y * nwg.x * WG;
}

fn write_args(offset: u32, count: u32) {
    let groups = (count + WG - 1u) / WG;
    let x = min(groups, 65535u);
    args[offset] = max(x, 1u);
    args[offset + 1u] = max((groups + 65534u) / 65535u, 1u);
    args[offset + 2u] = 1u;
}

// Fragments made and kept: the count runs past the buffer when it overflowed.
fn stored_fragments() -> u32 {
    return min(atomicLoad(&counters[FRAGMENTS]), arrayLength(&fragments));
}

fn slot_limit() -> u32 {
    return arrayLength(&slot_voxel);
}

const REBUILD: u32 = 7u;
const FRAGMENTS: u32 = 2u;
const KEPT_OCCUPANCY: u32 = 64u;

fn kept_by() -> vec3<i32> {
    return vec3<i32>(bitcast<i32>(kept[1]), bitcast<i32>(kept[2]), bitcast<i32>(kept[3]));
}

// Whether the build keeps voxel `v` (it lies in the kept window's old place too).
fn kept_voxel(v: u32) -> bool {
    let r = vol.resolution;
    if kept[0] == 0u || window_of_voxel(v) != kept[0] - 1u {
        return false;
    }
    let old = vec3<i32>(voxel_coord(v % (r * r * r), r)) + kept_by();
    return all(old >= vec3<i32>(0)) && all(old < vec3<i32>(i32(r)));
}

// The window voxel `v` (a linear index through the stacked cubes) lies in.
fn window_of_voxel(v: u32) -> u32 {
    let r = vol.resolution;
    return v / (r * r * r);
}

// Whether the build rebuilds window `w`.
fn rebuilding(w: u32) -> bool {
    return (atomicLoad(&counters[REBUILD]) & (1u << w)) != 0u;
}

// A slot for voxel `v`, in its window's part: its index, or past the pool (`slot_limit()`)
// when the part is full (counted all the same, so the host sees how many it needs).
fn take_slot(v: u32) -> u32 {
    let w = window_of_voxel(v);
    let k = atomicAdd(&counters[window_word(w, W_COUNT)], 1u);
    let c = window_slots(vol.windows);
    if k >= c {
        return slot_limit();
    }
    return w * c + k;
}

// The pool's totals from the windows' counts (words 0 and 1), and the dispatch over the
// leaves. Only the kernels that bind the arguments.
fn count_windows() {
    var total = 0u;
    var most = 0u;
    // One thread a leaf: `leaf_slot` finds its slot.
    var filled = 0u;
    let c = window_slots(vol.windows);
    for (var w = 0u; w < vol.windows; w++) {
        let n = atomicLoad(&counters[window_word(w, W_COUNT)]);
        total += n;
        most = max(most, n);
        filled += min(n, c);
    }
    atomicStore(&counters[0], total);
    atomicStore(&counters[1], most);
    write_args(0u, filled);
}

// Adds fragment `f`'s attributes to slot `s`'s static or dynamic sums.
fn add_fragment(s: u32, f: Fragment, dynamic: bool) {
    let v = fragment_sums(f);
    let coverage = fragment_coverage(f);
    for (var k = 0u; k < ACCUM_SUMS; k++) {
        if dynamic {
            atomicAdd(&dyn_accum[s * DYN_STRIDE + k], v[k]);
        } else {
            atomicAdd(&accum[s * ACCUM_STRIDE + k], v[k]);
        }
    }
    if dynamic {
        atomicMax(&dyn_accum[s * DYN_STRIDE + ACCUM_COVERAGE], coverage);
    } else {
        atomicMax(&accum[s * ACCUM_STRIDE + ACCUM_COVERAGE], coverage);
    }
}

// Averages slot `s`'s sums (the static ones, plus the dynamic ones when `dynamic`) into the
// finest level's albedo/opacity, normal and emission.
fn resolve_slot(s: u32, dynamic: bool) {
    let base = s * ACCUM_STRIDE;
    var sum = array<u32, FRAGMENT_SUMS>();
    for (var k = 0u; k < ACCUM_SUMS; k++) {
        sum[k] = atomicLoad(&accum[base + k]);
        if dynamic {
            // Wrapping adds: the normal sums are two's complement.
            sum[k] += atomicLoad(&dyn_accum[s * DYN_STRIDE + k]);
        }
    }
    var coverage = atomicLoad(&accum[base + ACCUM_COVERAGE]);
    if dynamic {
        coverage = max(coverage, atomicLoad(&dyn_accum[s * DYN_STRIDE + ACCUM_COVERAGE]));
    }
    let a = resolve_sums(sum, coverage);
    let c = voxel_coord(slot_voxel[s], vol.resolution);
    textureStore(albedo_out, c, a.albedo);
    textureStore(normal_out, c, a.normal);
    // Alpha: where the surface lies (leaves.wgsl's leaf_surface).
    textureStore(emission_out, c, vec4<f32>(a.emission, a.surface));
    // The normals feed the first level's NDF weights.
    mark_changed(c, vol.resolution, vol.windows);
}

// Empties voxel `c` of the finest level.
fn clear_voxel(c: vec3<u32>) {
    textureStore(albedo_out, c, vec4<f32>(0.0));
    textureStore(normal_out, c, vec4<f32>(0.0));
    textureStore(emission_out, c, vec4<f32>(0.0));
    textureStore(radiance_out, c, vec4<f32>(0.0));
    mark_changed(c, vol.resolution, vol.windows);
}

