// debug: the octree's voxel views. Ray-marches each camera ray at one level with a 3D DDA (one
// cell of that level per step), looking cells up by descending the tree, and writes the first
// hit into the HDR target:
//   mode 0 (albedo):   the first cell of opacity > 0.5; the albedo of the first occupied leaf
//                      the ray crosses inside it (failing that, the cell's mean),
//   mode 1 (opacity):  the hit cell's opacity as grey,
//   mode 2 (radiance): the hit cell's radiance, un-premultiplied,
//   mode 3 (nodes):    the first node of the level's depth that has children (at level 0: an
//                      occupied leaf voxel), coloured by level and shaded by the face the ray
//                      entered, with its edges darkened: the octree's occupied nodes.

//!include shared/scene.wgsl
//!include shared/volume.wgsl
//!include shared/voxel_debug.wgsl
//!include voxels/tree.wgsl

struct DebugParams {
    mode: u32,
    level: u32,
    // The directional block shown above level 0 (+X, -X, +Y, -Y, +Z, -Z).
    block: u32,
    _pad: u32,
}

@group(0) @binding(0) var<uniform> frame: Frame;
@group(0) @binding(1) var<uniform> tree: Octree;
@group(0) @binding(2) var<uniform> params: DebugParams;
@group(0) @binding(3) var<storage, read> nodes: array<u32>;
@group(0) @binding(4) var<storage, read> slots: array<u32>;
@group(0) @binding(5) var even_atlas: texture_3d<f32>;
@group(0) @binding(6) var odd_atlas: texture_3d<f32>;
@group(0) @binding(7) var hdr: texture_storage_2d<rgba32float, write>;

const MODE_ALBEDO: u32 = 0u;
const MODE_OPACITY: u32 = 1u;
const MODE_RADIANCE: u32 = 2u;
const MODE_NODES: u32 = 3u;

// The node of depth t holding finest-or-coarser coordinate c (at depth t's resolution), or 0.
fn node_at(c: vec3<u32>, t: u32) -> u32 {
    var node = 0u;
    for (var i = 0u; i < t; i++) {
        let tile = nodes[child_word(tree, node)];
        if tile == 0u {
            return 0u;
        }
        node = tile * 8u + octant_of(c, t - 1u - i);
    }
    return node;
}

// Premultiplied value of cell c at level `lvl`.
fn cell_value(c: vec3<u32>, lvl: u32) -> vec4<f32> {
    let n = node_at(c >> vec3<u32>(1u), tree.depth - 1u - lvl);
    let tile = select(0u, nodes[child_word(tree, n)], n != 0u || lvl == tree.depth - 1u);
    if tile == 0u {
        return vec4<f32>(0.0);
    }
    let block = select(dir_block(tree, params.block), 0u, lvl == 0u);
    let p = brick_texel(atlas_shape(tree, lvl), brick_index(tree, tile, lvl), block) + (c & vec3<u32>(1u));
    // Level 0 stores optical depth; the levels above, premultiplied opacity.
    if lvl == 0u {
        return from_depth(textureLoad(even_atlas, p, 0));
    }
    if (lvl & 1u) == 0u {
        return textureLoad(even_atlas, p, 0);
    }
    return textureLoad(odd_atlas, p, 0);
}

// Whether the node of level `lvl`'s cell c (a node of depth D - lvl) has children.
fn cell_has_children(c: vec3<u32>, lvl: u32) -> bool {
    let n = node_at(c, tree.depth - lvl);
    return (n != 0u || lvl == tree.depth) && nodes[child_word(tree, n)] != 0u;
}

// The leaf slot of finest voxel c, or NONE.
fn leaf_slot(c: vec3<u32>) -> u32 {
    let n = node_at(c, tree.depth);
    let v = select(0u, nodes[child_word(tree, n)], n != 0u);
    return select(NONE, v - 1u, v != 0u);
}

// Albedo of the first occupied leaf the ray (finest-voxel units) crosses inside the cell
// `cell` of `scale` finest voxels per side, entered at t0.
fn albedo_under(o: vec3<f32>, d: vec3<f32>, inv_d: vec3<f32>, cell: vec3<i32>, scale: i32, t0: f32) -> vec3<f32> {
    let lo = cell * scale;
    var c = clamp(vec3<i32>(floor(o + d * (t0 + 1e-4))), lo, lo + scale - 1);
    let stp = vec3<i32>(sign(d));
    var t_max = (vec3<f32>(c) + select(vec3<f32>(0.0), vec3<f32>(1.0), d > vec3<f32>(0.0)) - o) * inv_d;
    let t_delta = abs(inv_d);
    for (var i = 0; i < 3 * scale + 3; i++) {
        let s = leaf_slot(vec3<u32>(c));
        if s != NONE {
            return unpack4x8unorm(slots[s * SLOT_STRIDE + 2u]).rgb;
        }
        if t_max.x < t_max.y && t_max.x < t_max.z {
            c.x += stp.x;
            t_max.x += t_delta.x;
        } else if t_max.y < t_max.z {
            c.y += stp.y;
            t_max.y += t_delta.y;
        } else {
            c.z += stp.z;
            t_max.z += t_delta.z;
        }
        if any(c < lo) || any(c >= lo + scale) {
            break;
        }
    }
    // The ray crossed only empty leaves (the cell is opaque as a whole): the mean albedo of
    // the cell's occupied leaves, on a lattice of at most 8^3 samples (as the dense view).
    let stride = max(scale / 8, 1);
    var sum = vec4<f32>(0.0);
    for (var z = 0; z < scale; z += stride) {
        for (var y = 0; y < scale; y += stride) {
            for (var x = 0; x < scale; x += stride) {
                let s = leaf_slot(vec3<u32>(lo + vec3<i32>(x, y, z)));
                if s != NONE {
                    sum += vec4<f32>(unpack4x8unorm(slots[s * SLOT_STRIDE + 2u]).rgb, 1.0);
                }
            }
        }
    }
    return sum.rgb / max(sum.w, 1.0);
}

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if f32(id.x) >= frame.size.x || f32(id.y) >= frame.size.y {
        return;
    }
    let px = id.xy;
    let uv = (vec2<f32>(px) + 0.5) * frame.inv_size;
    let ndc = vec2<f32>(uv.x * 2.0 - 1.0, 1.0 - uv.y * 2.0);
    let near = frame.inv_view_proj * vec4<f32>(ndc, 0.0, 1.0);
    let far = frame.inv_view_proj * vec4<f32>(ndc, 1.0, 1.0);
    let wn = near.xyz / near.w;
    let wf = far.xyz / far.w;
    let o = (wn - tree.origin) / tree.voxel_size;
    var d = normalize((wf - wn) / tree.voxel_size);
    d = select(d, vec3<f32>(1e-7), abs(d) < vec3<f32>(1e-7));
    let inv_d = 1.0 / d;

    // The nodes view shows depth D - level, whose cells are level `level`'s voxels; the
    // others read level `level`, which the octree has below its top.
    let lvl = select(min(params.level, tree.depth - 1u), min(params.level, tree.depth), params.mode == MODE_NODES);
    let scale = 1 << lvl;
    let res = i32(tree.resolution) >> lvl;
    let extent = f32(tree.resolution);
    var out = frame.background.rgb;
    let span = ray_box(o, inv_d, vec3<f32>(0.0), vec3<f32>(extent));
    let inside = all(o > vec3<f32>(0.0)) && all(o < vec3<f32>(extent));
    if span.x < span.y {
        let s = f32(scale);
        let oc = o / s;
        let inv_dc = inv_d * s;
        var c = clamp(vec3<i32>(floor(oc + d * (span.x / s + 1e-4))), vec3<i32>(0), vec3<i32>(res - 1));
        let stp = vec3<i32>(sign(d));
        var t_max = (vec3<f32>(c) + select(vec3<f32>(0.0), vec3<f32>(1.0), d > vec3<f32>(0.0)) - oc) * inv_dc;
        let t_delta = abs(inv_dc);
        var t_enter = span.x / s;
        // The axis the ray entered the current cell through (for the nodes view's shading).
        let first = oc + d * t_enter - vec3<f32>(c);
        let edge = min(first, 1.0 - first);
        var axis = select(select(2u, 1u, edge.y <= edge.z), 0u, edge.x <= edge.y && edge.x <= edge.z);
        for (var i = 0; i < 3 * res + 3; i++) {
            let cu = vec3<u32>(c);
            if params.mode == MODE_NODES {
                // The cell the camera stands in is skipped: from inside, it would fill the view.
                if cell_has_children(cu, lvl) && !(i == 0 && inside) {
                    out = node_colour(lvl, oc + d * t_enter, axis);
                    break;
                }
            } else {
                let v = cell_value(cu, lvl);
                if v.a > 0.5 {
                    switch params.mode {
                        case MODE_ALBEDO: {
                            out = albedo_under(o, d, inv_d, c, scale, t_enter * s);
                        }
                        case MODE_OPACITY: {
                            out = vec3<f32>(v.a);
                        }
                        default: {
                            out = v.rgb / v.a;
                        }
                    }
                    break;
                }
            }
            t_enter = min(t_max.x, min(t_max.y, t_max.z));
            if t_max.x < t_max.y && t_max.x < t_max.z {
                c.x += stp.x;
                t_max.x += t_delta.x;
                axis = 0u;
            } else if t_max.y < t_max.z {
                c.y += stp.y;
                t_max.y += t_delta.y;
                axis = 1u;
            } else {
                c.z += stp.z;
                t_max.z += t_delta.z;
                axis = 2u;
            }
            if any(c < vec3<i32>(0)) || any(c >= vec3<i32>(res)) {
                break;
            }
        }
    }
    textureStore(hdr, px, vec4<f32>(out, 1.0));
}
