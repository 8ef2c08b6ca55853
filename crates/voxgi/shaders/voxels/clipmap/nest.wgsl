// nest: a coarser level's mips filtered from the finer level where they overlap. Voxelized from
// the geometry, a coarse voxel that a wall crosses is as opaque as the wall, where the finer
// level's mip of the same size is partly open; a wide sample that reads the coarser level
// should see what the finer level's mips see, or the levels disagree in the hand-over.
//
// Window k (level k), after the filter (voxels/dense/filter.wgsl, bound here as it binds it,
// at group 0), per chain level c: each texel wholly inside window k - 1 takes window k - 1's
// texel of the same place and size (its chain level c + 1), and the texels astride its faces,
// or all of them where the windows' lattices do not meet at that level, are filtered again
// from their own children as the filter does. The finest voxels stay the level's own: they are
// its leaves', and the chains can always be made from them again (after the finer window
// moved, the texels it left are filtered again: `restore` steps, with nothing to copy).
// Windows are nested finest first, so a texel deep inside copies what the finest window
// holding it made. A box copied whole (no texel astride) is a texture copy instead of this
// pass (nest.rs: `copy_step`). Twin: `NestParams` in src/voxel/clipmap/nest.rs.

//!include voxels/dense/filter.wgsl

struct NestParams {
    // The box of texels written, window-local at the chain level.
    lo: vec3<i32>,
    // The window written.
    window: u32,
    size: vec3<u32>,
    _pad0: u32,
    // The texels copied from the finer window, [copy_lo, copy_hi) (empty where the lattices
    // do not meet).
    copy_lo: vec3<i32>,
    _pad1: u32,
    copy_hi: vec3<i32>,
    _pad2: u32,
    // The finer window's corner in these texels (where the lattices meet).
    finer_lo: vec3<i32>,
    _pad3: u32,
}

// The finer window's chain level one above the one written.
@group(1) @binding(0) var finer: texture_3d<f32>;
@group(1) @binding(1) var<uniform> nest: NestParams;

@compute @workgroup_size(4, 4, 4)
fn main(@builtin(global_invocation_id) tid: vec3<u32>) {
    let block = tid.z / nest.size.z;
    if any(tid.xy >= nest.size.xy) || block >= blocks() {
        return;
    }
    let t = nest.lo + vec3<i32>(vec3<u32>(tid.xy, tid.z % nest.size.z));
    let n = i32(params.dst_res);
    let gid = vec3<u32>(vec3<i32>(t.xy, i32(nest.window) * n + t.z));
    if any(t < nest.copy_lo) || any(t >= nest.copy_hi) {
        filter_voxel(gid, block);
        return;
    }
    // The finer window's texel of the same place and size: one level above in a window of
    // half the voxel size, so half as many texels a side.
    let m = n / 2;
    let w = i32(params.windows);
    let u = t - nest.finer_lo;
    let id = vec3<i32>(vec2<i32>(gid.xy), i32(block) * n * w + i32(gid.z));
    let at = vec3<i32>(u.xy, i32(block) * m * w + (i32(nest.window) - 1) * m + u.z);
    textureStore(dst, id, textureLoad(finer, at, 0));
}
