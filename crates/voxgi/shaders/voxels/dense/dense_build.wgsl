// dense_build: voxel fragments -> the dense volume's finest level. Integer atomics average the
// fragments of each voxel, so the result does not depend on thread order (deterministic).
//
// Entry points, in the order the host runs them:
//   begin           remember the previous slot count, reset the slot counter
//   clear_previous  zero the voxels the previous build filled (cheaper than clearing N^3)
//   prepare_fragments / prepare_slots  indirect dispatch sizes from the counters
//   allocate        one slot per occupied voxel
//   accumulate      integer sums per slot
//   resolve         averages -> albedo/opacity, normal, emission textures

//!include shared/volume.wgsl
//!include shared/fragment.wgsl

@group(0) @binding(0) var<uniform> vol: Volume;
// The fragments, as voxelize (or any other source) left them: the only input.
@group(0) @binding(1) var<storage, read> fragments: array<Fragment>;
@group(0) @binding(2) var<storage, read> fragment_count: array<u32>;
// [0] slots (occupied voxels, counted past the capacity), [1] slots of the previous build.
@group(0) @binding(3) var<storage, read_write> counters: array<atomic<u32>>;
// Per voxel: 0 empty, 2 + slot once allocated, LOCKED while allocating (or past capacity).
@group(0) @binding(4) var<storage, read_write> occupancy: array<atomic<u32>>;
// Per slot: the voxel's linear index.
@group(0) @binding(5) var<storage, read_write> slot_voxel: array<u32>;
// Per slot, ACCUM_STRIDE u32 sums: count, albedo rgb (8-bit units), normal xyz (snorm16 units,
// two's complement), emission rgb (1/4096 units).
@group(0) @binding(6) var<storage, read_write> accum: array<atomic<u32>>;
@group(0) @binding(7) var albedo_out: texture_storage_3d<rgba8unorm, write>;
@group(0) @binding(8) var normal_out: texture_storage_3d<rgba8snorm, write>;
@group(0) @binding(9) var emission_out: texture_storage_3d<rgba16float, write>;
@group(0) @binding(10) var radiance_out: texture_storage_3d<rgba16float, write>;
// Indirect dispatch arguments: [0..3] over slots, [3..6] over fragments. Only the prepare_*
// entry points bind them (a buffer cannot be storage and indirect in one dispatch).
@group(1) @binding(0) var<storage, read_write> args: array<u32>;

const ACCUM_STRIDE: u32 = 10u;
const LOCKED: u32 = 0xffffffffu;
const EMISSION_SCALE: f32 = 4096.0;
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
    return min(fragment_count[0], arrayLength(&fragments));
}

@compute @workgroup_size(1)
fn begin() {
    atomicStore(&counters[1], atomicLoad(&counters[0]));
    atomicStore(&counters[0], 0u);
}

@compute @workgroup_size(1)
fn prepare_fragments() {
    write_args(3u, stored_fragments());
}

@compute @workgroup_size(1)
fn prepare_slots() {
    write_args(0u, min(atomicLoad(&counters[0]), arrayLength(&slot_voxel)));
}

@compute @workgroup_size(64)
fn clear_previous(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let s = flat(gid, nwg);
    if s >= min(atomicLoad(&counters[1]), arrayLength(&slot_voxel)) {
        return;
    }
    let c = voxel_coord(slot_voxel[s], vol.resolution);
    textureStore(albedo_out, c, vec4<f32>(0.0));
    textureStore(normal_out, c, vec4<f32>(0.0));
    textureStore(emission_out, c, vec4<f32>(0.0));
    textureStore(radiance_out, c, vec4<f32>(0.0));
}

@compute @workgroup_size(64)
fn allocate(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = flat(gid, nwg);
    if i >= stored_fragments() {
        return;
    }
    let v = voxel_index(unpack_coord(fragments[i].coord), vol.resolution);
    // The first fragment of a voxel takes it; the weak exchange may fail spuriously, so retry
    // while the voxel is still unclaimed.
    for (var tries = 0u; tries < 64u; tries++) {
        let r = atomicCompareExchangeWeak(&occupancy[v], 0u, LOCKED);
        if r.exchanged {
            // Counted even past the capacity, so the host can see how many slots it needs;
            // voxels beyond it stay unallocated (LOCKED) and are skipped.
            let s = atomicAdd(&counters[0], 1u);
            if s < arrayLength(&slot_voxel) {
                slot_voxel[s] = v;
                atomicStore(&occupancy[v], s + 2u);
            }
            return;
        }
        if r.old_value != 0u {
            return;
        }
    }
}

@compute @workgroup_size(64)
fn accumulate(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = flat(gid, nwg);
    if i >= stored_fragments() {
        return;
    }
    let f = fragments[i];
    let v = voxel_index(unpack_coord(f.coord), vol.resolution);
    let o = atomicLoad(&occupancy[v]);
    if o < 2u || o == LOCKED {
        return;
    }
    let s = o - 2u;
    let base = s * ACCUM_STRIDE;
    let albedo = unpack4x8unorm(f.albedo);
    let n = vec3<i32>(round(oct_decode(unpack2x16snorm(f.normal)) * 32767.0));
    let e = vec3<u32>(round(unpack_rgb9e5(f.emission) * EMISSION_SCALE));
    atomicAdd(&accum[base], 1u);
    atomicAdd(&accum[base + 1u], u32(round(albedo.r * 255.0)));
    atomicAdd(&accum[base + 2u], u32(round(albedo.g * 255.0)));
    atomicAdd(&accum[base + 3u], u32(round(albedo.b * 255.0)));
    atomicAdd(&accum[base + 4u], bitcast<u32>(n.x));
    atomicAdd(&accum[base + 5u], bitcast<u32>(n.y));
    atomicAdd(&accum[base + 6u], bitcast<u32>(n.z));
    atomicAdd(&accum[base + 7u], e.r);
    atomicAdd(&accum[base + 8u], e.g);
    atomicAdd(&accum[base + 9u], e.b);
}

@compute @workgroup_size(64)
fn resolve(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let s = flat(gid, nwg);
    if s >= min(atomicLoad(&counters[0]), arrayLength(&slot_voxel)) {
        return;
    }
    let base = s * ACCUM_STRIDE;
    let count = f32(max(atomicLoad(&accum[base]), 1u));
    let albedo = vec3<f32>(
        f32(atomicLoad(&accum[base + 1u])),
        f32(atomicLoad(&accum[base + 2u])),
        f32(atomicLoad(&accum[base + 3u])),
    ) / (255.0 * count);
    let nsum = vec3<f32>(
        f32(bitcast<i32>(atomicLoad(&accum[base + 4u]))),
        f32(bitcast<i32>(atomicLoad(&accum[base + 5u]))),
        f32(bitcast<i32>(atomicLoad(&accum[base + 6u]))),
    ) / (32767.0 * count);
    let e = vec3<f32>(
        f32(atomicLoad(&accum[base + 7u])),
        f32(atomicLoad(&accum[base + 8u])),
        f32(atomicLoad(&accum[base + 9u])),
    ) / (EMISSION_SCALE * count);
    let c = voxel_coord(slot_voxel[s], vol.resolution);
    // A voxel that geometry touches blocks all rays through it: opacity 1 (conservative).
    textureStore(albedo_out, c, vec4<f32>(albedo, 1.0));
    // w: how well the fragments' normals agree (1: one orientation, ~0: opposite faces).
    let len = length(nsum);
    textureStore(normal_out, c, vec4<f32>(select(vec3<f32>(0.0), nsum / len, len > 1e-4), len));
    textureStore(emission_out, c, vec4<f32>(e, 1.0));
}
