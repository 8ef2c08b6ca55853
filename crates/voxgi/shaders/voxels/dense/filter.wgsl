// filter: builds the volume's mip levels from the finest one. Isotropic: the mean of the 2x2x2
// children. Anisotropic (Crassin et al. 2011, section 9): per direction, the children are first
// composited front to back along it, two at a time, then the four results are averaged, so a
// one-voxel wall stays opaque across itself at coarser levels instead of turning half
// transparent. One dispatch writes one level of every direction's block (+X, -X, +Y, -Y, +Z,
// -Z stacked along z: the direction the cone travels).

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
}

@group(0) @binding(0) var<uniform> params: FilterParams;
@group(0) @binding(1) var src: texture_3d<f32>;
@group(0) @binding(2) var dst: texture_storage_3d<rgba16float, write>;
// The finest level's normals and their agreement (read with `ndf`).
@group(0) @binding(3) var normals: texture_3d<f32>;

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
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let n = params.dst_res;
    let block = id.z / n;
    let gid = vec3<u32>(id.xy, id.z % n);
    if any(id.xy >= vec2<u32>(n)) || block >= select(1u, 6u, params.mode == 1u) {
        return;
    }
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
