// filter: builds the volume's mip levels from the finest one. Isotropic: the mean of the 2x2x2
// children. Anisotropic (Crassin et al. 2011, section 9): per direction, the children are first
// composited front to back along it, two at a time, then the four results are averaged, so a
// one-voxel wall stays opaque across itself at coarser levels instead of turning half
// transparent. One dispatch writes one level of every direction's block (+X, -X, +Y, -Y, +Z,
// -Z stacked along z: the direction the cone travels).

// Only the voxels above the finest ones written since the last filter are redone (`region`
// sizes each level's dispatch from that box): the rest have the same children as before, so
// the result equals a whole filter to the bit.

//!include shared/volume.wgsl

struct FilterParams {
    // 0: isotropic mean, 1: directional.
    mode: u32,
    // Voxels per side of a block of the level written.
    dst_res: u32,
    // 1: the source is the chains' previous level (blocks stacked like the destination's),
    // 0: the finest level (one block, shared by every direction).
    src_blocked: u32,
    // 1: weigh each finest voxel per direction by its normals (`ndf_weight`; first level only).
    ndf: u32,
    // This level's index into `boxes` (0: the level above the finest).
    step: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

// A level's voxels to redo: the box's lowest voxel and its size (z: per block).
struct LevelBox {
    lo: vec4<u32>,
    size: vec4<u32>,
}

@group(0) @binding(0) var<uniform> params: FilterParams;
@group(0) @binding(1) var src: texture_3d<f32>;
@group(0) @binding(2) var dst: texture_storage_3d<rgba16float, write>;
// The finest level's normals and their agreement (read with `ndf`).
@group(0) @binding(3) var normals: texture_3d<f32>;
@group(0) @binding(4) var<storage, read> boxes: array<LevelBox>;

fn child(base: vec3<i32>, o: vec3<i32>) -> vec4<f32> {
    return from_depth(textureLoad(src, base + o, 0));
}

// A finest voxel as direction `block` counts it.
fn leaf_child(base: vec3<i32>, o: vec3<i32>, block: u32) -> vec4<f32> {
    var w = 1.0;
    if params.ndf != 0u {
        w = ndf_weight(textureLoad(normals, base + o, 0), block);
    }
    return w * child(base, o);
}

@compute @workgroup_size(4, 4, 4)
fn main(@builtin(global_invocation_id) tid: vec3<u32>) {
    let n = params.dst_res;
    let b = boxes[params.step];
    let block = tid.z / max(b.size.z, 1u);
    let gid = b.lo.xyz + vec3<u32>(tid.xy, tid.z % max(b.size.z, 1u));
    if any(tid.xy >= b.size.xy) || block >= select(1u, 6u, params.mode == 1u) {
        return;
    }
    let id = vec3<u32>(gid.xy, block * n + gid.z);
    var base = vec3<i32>(gid) * 2;
    base.z += i32(block * 2u * n * params.src_blocked);
    if params.mode == 0u {
        var sum = vec4<f32>(0.0);
        for (var i = 0; i < 8; i++) {
            sum += child(base, vec3<i32>(i & 1, (i >> 1) & 1, (i >> 2) & 1));
        }
        textureStore(dst, id, to_depth(sum * 0.125));
        return;
    }
    let axis = i32(block / 2u);
    let positive = (block & 1u) == 0u;
    var sum = vec4<f32>(0.0);
    for (var i = 0; i < 4; i++) {
        var front = vec3<i32>(0);
        var back = vec3<i32>(0);
        // The two other axes take the column's offsets.
        front[(axis + 1) % 3] = i & 1;
        front[(axis + 2) % 3] = i >> 1;
        back = front;
        front[axis] = select(1, 0, positive);
        back[axis] = select(0, 1, positive);
        let f = leaf_child(base, front, block);
        let b = leaf_child(base, back, block);
        sum += f + (1.0 - f.a) * b;
    }
    textureStore(dst, id, to_depth(sum * 0.25));
}

// --- region: each level's box and dispatch size from the voxels written since the last
// filter, then the box emptied. One thread, before the levels.

struct RegionParams {
    // Finest voxels per side, levels above the finest, blocks per level (6 or 1).
    resolution: u32,
    steps: u32,
    blocks: u32,
    // 1: the whole volume (after a build), whatever was written.
    all: u32,
}

// Bound apart from the levels' (`FilterPass::region_layout`).
@group(0) @binding(5) var<uniform> region_params: RegionParams;
// The volume's counters: [8..16] the box of finest voxels written since the last filter
// (voxels/dense/changed.wgsl).
@group(0) @binding(6) var<storage, read_write> counters: array<atomic<u32>>;
@group(0) @binding(7) var<storage, read_write> boxes_out: array<LevelBox>;
// Per level: a dispatch's workgroups (x, y, z).
@group(0) @binding(8) var<storage, read_write> level_args: array<u32>;

@compute @workgroup_size(1)
fn region() {
    var lo = vec3<u32>(0u);
    var hi1 = vec3<u32>(region_params.resolution);
    if region_params.all == 0u {
        for (var k = 0u; k < 3u; k++) {
            lo[k] = 0xffffffffu - atomicLoad(&counters[8u + k]);
            hi1[k] = atomicLoad(&counters[12u + k]);
        }
    }
    let empty = any(hi1 == vec3<u32>(0u));
    for (var i = 0u; i < region_params.steps; i++) {
        var size = vec3<u32>(0u);
        var l = vec3<u32>(0u);
        if !empty {
            let level = i + 1u;
            l = lo >> vec3<u32>(level);
            size = ((hi1 - 1u) >> vec3<u32>(level)) - l + 1u;
        }
        boxes_out[i] = LevelBox(vec4<u32>(l, 0u), vec4<u32>(size, 0u));
        level_args[3u * i] = (size.x + 3u) / 4u;
        level_args[3u * i + 1u] = (size.y + 3u) / 4u;
        level_args[3u * i + 2u] = (size.z * region_params.blocks + 3u) / 4u;
    }
    for (var k = 0u; k < 8u; k++) {
        atomicStore(&counters[8u + k], 0u);
    }
}
