// filter: builds the volume's mip levels from the finest one. Isotropic: the mean of the 2x2x2
// children. Anisotropic (Crassin et al. 2011, section 9): per direction, the children are first
// composited front to back along it, two at a time, then the four results are averaged, so a
// one-voxel wall stays opaque across itself at coarser levels instead of turning half
// transparent. One dispatch writes one level of every direction's block (+X, -X, +Y, -Y, +Z,
// -Z stacked along z: the direction the cone travels).

// After a build every voxel is redone (`whole`); after a change only the voxels listed as
// having a changed child (`listed`, one dispatch per level sized by `prepare` from its list;
// changed.wgsl): the rest have the same children as before, so the result equals a whole
// filter to the bit.

//!include shared/volume.wgsl
//!include shared/specular_lobe.wgsl
//!include voxels/changed.wgsl

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
    // The level written, less one (0: the level above the finest).
    step: u32,
    // Cubes stacked along z in every level and block (`Volume::windows`).
    windows: u32,
    // 1: the slots keep specular lobes (`leaf_direct` two vec4 a slot): every level keeps
    // their moments in two more blocks (specular_lobe.wgsl, "The lobe chain"), and the first
    // folds their wide share into the six directions.
    lobes: u32,
    _pad2: u32,
}

@group(0) @binding(0) var<uniform> params: FilterParams;
@group(0) @binding(1) var src: texture_3d<f32>;
@group(0) @binding(2) var dst: texture_storage_3d<rgba16float, write>;
// The finest level's normals and their agreement (read with `ndf`).
@group(0) @binding(3) var normals: texture_3d<f32>;
// Per finest voxel: 0 empty, 2 + its leaf's slot (build_shared.wgsl's `occupancy`).
@group(0) @binding(4) var<storage, read> occupancy: array<u32>;
// Per slot: its direct light, and with `lobes` its specular lobe after it (leaves.wgsl's
// `leaf_direct`).
@group(0) @binding(5) var<storage, read> leaf_direct: array<vec4<f32>>;
// The volume's counters: the levels' bits and lists (changed.wgsl).
@group(0) @binding(6) var<storage, read_write> counters: array<atomic<u32>>;

// A child, premultiplied: the finest level stores optical depth, the chains opacity
// (shared/volume.wgsl says why).
fn child(base: vec3<i32>, o: vec3<i32>) -> vec4<f32> {
    let v = textureLoad(src, base + o, 0);
    return select(from_depth(v), v, params.src_blocked != 0u);
}

// A finest voxel as direction `block` counts it: its Lambertian light (weighed by its normals
// with `ndf`) and, on the first directional level, what its specular lobe sends that way.
fn leaf_child(base: vec3<i32>, o: vec3<i32>, block: u32) -> vec4<f32> {
    var w = 1.0;
    if params.ndf != 0u {
        w = ndf_weight(textureLoad(normals, base + o, 0), block);
    }
    let v = child(base, o);
    var lobe = vec3<f32>(0.0);
    if params.src_blocked == 0u && params.lobes != 0u && v.a > 0.0 {
        lobe = leaf_lobe(base + o, block);
    }
    // Apart, so that a voxel without a lobe filters to the same bits as before lobes were.
    if all(lobe == vec3<f32>(0.0)) {
        return w * v;
    }
    return w * v + vec4<f32>(v.a * lobe, 0.0);
}

// Finest voxel `c`'s specular lobe, packed (zero without one).
fn leaf_packed_lobe(c: vec3<i32>) -> vec4<f32> {
    let r = params.dst_res * 2u;
    let occupied = occupancy[u32(c.x) + r * (u32(c.y) + r * u32(c.z))];
    if occupied < 2u || occupied == 0xffffffffu {
        return vec4<f32>(0.0);
    }
    return leaf_direct[2u * (occupied - 2u) + 1u];
}

// The radiance finest voxel `c`'s specular lobe sends towards the cones of direction `block`.
fn leaf_lobe(c: vec3<i32>, block: u32) -> vec3<f32> {
    let packed = leaf_packed_lobe(c);
    if all(packed.rgb <= vec3<f32>(0.0)) {
        return vec3<f32>(0.0);
    }
    let n = textureLoad(normals, c, 0).xyz;
    // Only the lobe's wide share: the rest goes up the lobe blocks (`filter_lobes`).
    return lobe_radiance(wide_share(unpack_lobe(packed)), n / max(length(n), 1e-4), block);
}

// Lobe block `block` (LOBE_EXITANCE or LOBE_DIRECTION) of the voxel `id` whose children start
// at `base`: the mean of its eight children's moments, the leaves' own on the first level.
fn filter_lobes(base: vec3<i32>, id: vec3<u32>, block: u32) {
    var sum = vec4<f32>(0.0);
    for (var i = 0; i < 8; i++) {
        let o = vec3<i32>(i & 1, (i >> 1) & 1, (i >> 2) & 1);
        if params.src_blocked != 0u {
            sum += textureLoad(src, base + o, 0);
            continue;
        }
        let a = child(base, o).a;
        if a <= 0.0 {
            continue;
        }
        let packed = leaf_packed_lobe(base + o);
        if any(packed.rgb > vec3<f32>(0.0)) {
            let n = textureLoad(normals, base + o, 0).xyz;
            let lobe = narrow_share(unpack_lobe(packed), n / max(length(n), 1e-4));
            sum += lobe_moments(lobe, a, block);
        } else if block == LOBE_EXITANCE && lobe_covers(packed) {
            // Covered without a lobe, facing a light: it dilutes the exitance per covered area.
            sum.a += a;
        }
    }
    textureStore(dst, id, sum * 0.125);
}

// Level `params.step + 1`'s voxel `gid` in direction block `block` from its eight children.
fn filter_voxel(gid: vec3<u32>, block: u32) {
    let n = params.dst_res;
    let depth = n * params.windows;
    let id = vec3<u32>(gid.xy, block * depth + gid.z);
    var base = vec3<i32>(gid) * 2;
    base.z += i32(block * 2u * depth * params.src_blocked);
    if block >= LOBE_EXITANCE {
        filter_lobes(base, id, block);
        return;
    }
    if params.mode == 0u {
        var sum = vec4<f32>(0.0);
        for (var i = 0; i < 8; i++) {
            sum += child(base, vec3<i32>(i & 1, (i >> 1) & 1, (i >> 2) & 1));
        }
        textureStore(dst, id, sum * 0.125);
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
    textureStore(dst, id, sum * 0.25);
}

// Twin: `Filtering::blocks`. The lobe chain's blocks come after the six directions.
fn blocks() -> u32 {
    return select(select(1u, 6u, params.mode == 1u), LOBE_DIRECTION + 1u, params.lobes != 0u);
}

// Every voxel of the level (after a build); the bits and counts are cleared after
// (`FilterPass::record`).
@compute @workgroup_size(4, 4, 4)
fn whole(@builtin(global_invocation_id) tid: vec3<u32>) {
    let n = params.dst_res;
    let depth = n * params.windows;
    let block = tid.z / depth;
    if any(tid.xy >= vec2<u32>(n)) || block >= blocks() {
        return;
    }
    filter_voxel(vec3<u32>(tid.xy, tid.z % depth), block);
}

// The voxels the level's list holds: x and y over the list (x up to 65,535 workgroups, as
// many rows as that takes), z over the direction blocks. Each lists its parent for the next
// level and clears its own bit (nothing lists this level while it runs).
@compute @workgroup_size(64)
fn listed(@builtin(global_invocation_id) tid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let n = params.dst_res;
    let level = params.step + 1u;
    let res = n << level;
    let k = tid.x + tid.y * nwg.x * 64u;
    if k >= atomicLoad(&counters[COUNTS + level - 1u]) {
        return;
    }
    let w = params.windows;
    let i = atomicLoad(&counters[list_of(res, w, level) + k]);
    let gid = vec3<u32>(i % n, (i / n) % n, i / (n * n));
    if tid.z == 0u {
        if level < levels_above(res) {
            mark_level(res, w, level + 1u, gid >> vec3<u32>(1u));
        }
        atomicAnd(&counters[bits_of(res, w, level) + i / 32u], ~(1u << (i % 32u)));
    }
    filter_voxel(gid, tid.z);
}

// --- prepare: one thread before each listed level sizes its dispatch from its list; `done`
// empties the lists after the last level.

// Per level: a dispatch's workgroups (x, y, z). Bound apart from the levels
// (`FilterPass::prepare_layout`): a dispatch cannot write the buffer it is sized from.
@group(0) @binding(7) var<storage, read_write> level_args: array<u32>;

@compute @workgroup_size(1)
fn prepare() {
    let level = params.step + 1u;
    let count = atomicLoad(&counters[COUNTS + level - 1u]);
    if level == 1u {
        atomicStore(&counters[REDONE], count);
    } else {
        atomicAdd(&counters[REDONE], count);
    }
    let groups = (count + 63u) / 64u;
    level_args[3u * params.step] = min(groups, 65535u);
    level_args[3u * params.step + 1u] = (groups + 65534u) / 65535u;
    level_args[3u * params.step + 2u] = blocks();
}

@compute @workgroup_size(1)
fn done() {
    for (var k = 0u; k < MAX_LEVELS; k++) {
        atomicStore(&counters[COUNTS + k], 0u);
    }
}
