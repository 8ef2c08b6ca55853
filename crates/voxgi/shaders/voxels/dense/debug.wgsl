// debug: voxel views. Ray-marches each camera ray through the volume at one mip level with a
// 3D DDA (one cell of that level per step) and writes the first cell whose opacity exceeds 0.5
// into the HDR target, replacing the composite's output:
//   mode 0 (albedo):   the finest albedo under the hit (the first occupied finest voxel the ray
//                      crosses inside the hit cell; failing that, the mean occupied albedo of
//                      the cell),
//   mode 1 (opacity):  the hit cell's opacity as grey,
//   mode 2 (radiance): the hit cell's radiance, un-premultiplied,
//   mode 3 (nodes):    the first cell with any opacity, coloured by level and shaded by the
//                      face the ray entered, edges darkened (the octree's view of the same
//                      name shows its nodes).
// Level 0 reads the finest (isotropic) radiance; level L > 0 reads mip L - 1 of the chosen
// directional chain (the host binds it; in isotropic mode the one chain). Rays that hit nothing
// get the background.

//!include shared/scene.wgsl
//!include shared/volume.wgsl
//!include shared/voxel_debug.wgsl

struct DebugParams {
    // 0 albedo, 1 opacity, 2 radiance.
    mode: u32,
    // Mip level, 0 = finest.
    level: u32,
    // The block of the chains shown (+X, -X, +Y, -Y, +Z, -Z).
    block: u32,
    // The window shown (`Volume::windows`; `vol` places it): 0, or a clipmap's level.
    window: u32,
}

@group(0) @binding(0) var<uniform> frame: Frame;
@group(0) @binding(1) var<uniform> vol: Volume;
@group(0) @binding(2) var<uniform> params: DebugParams;
@group(0) @binding(3) var albedo: texture_3d<f32>;
@group(0) @binding(4) var radiance0: texture_3d<f32>;
// The directional chains (their mip 0 is the volume's level 1), blocks stacked along z.
@group(0) @binding(5) var chain: texture_3d<f32>;
@group(0) @binding(6) var hdr: texture_storage_2d<rgba32float, write>;

const MODE_ALBEDO: u32 = 0u;
const MODE_OPACITY: u32 = 1u;
const MODE_RADIANCE: u32 = 2u;
const MODE_NODES: u32 = 3u;

// Cell c of the shown window at a level `n` cells a side, in the stacked textures.
fn in_window(c: vec3<i32>, n: i32) -> vec3<i32> {
    return c + vec3<i32>(0, 0, n * i32(params.window));
}

fn cell_value(c: vec3<i32>) -> vec4<f32> {
    if params.level == 0u {
        return from_depth(textureLoad(radiance0, in_window(c, i32(vol.resolution)), 0));
    }
    let n = i32(vol.resolution) >> params.level;
    let block = n * i32(vol.windows) * i32(params.block);
    // The chains store premultiplied opacity, the finest level optical depth.
    return textureLoad(chain, in_window(c, n) + vec3<i32>(0, 0, block), i32(params.level) - 1);
}

// Finest albedo under the coarse cell `cell` (of `scale` finest voxels per side) that the ray
// (in finest-voxel units) enters at t0.
fn albedo_under(o: vec3<f32>, d: vec3<f32>, inv_d: vec3<f32>, cell: vec3<i32>, scale: i32, t0: f32) -> vec3<f32> {
    let lo = vec3<f32>(cell * scale);
    let hi = lo + f32(scale);
    // Fine DDA inside the cell.
    let p = o + d * (t0 + 1e-4);
    var c = clamp(vec3<i32>(floor(p)), cell * scale, cell * scale + scale - 1);
    let stp = vec3<i32>(sign(d));
    let next = vec3<f32>(c) + select(vec3<f32>(0.0), vec3<f32>(1.0), d > vec3<f32>(0.0));
    var t_max = (next - o) * inv_d;
    let t_delta = abs(inv_d);
    for (var i = 0; i < 3 * scale + 3; i++) {
        let a = textureLoad(albedo, in_window(c, i32(vol.resolution)), 0);
        if a.a > 0.0 {
            return a.rgb;
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
        if any(vec3<f32>(c) < lo) || any(vec3<f32>(c) >= hi) {
            break;
        }
    }
    // The ray crossed only empty finest voxels (the cell is opaque as a whole): the mean
    // occupied albedo of the cell, on a lattice of at most 8^3 samples.
    let stride = max(scale / 8, 1);
    var sum = vec4<f32>(0.0);
    for (var z = 0; z < scale; z += stride) {
        for (var y = 0; y < scale; y += stride) {
            for (var x = 0; x < scale; x += stride) {
                let a = textureLoad(albedo, in_window(cell * scale + vec3<i32>(x, y, z), i32(vol.resolution)), 0);
                if a.a > 0.0 {
                    sum += vec4<f32>(a.rgb, 1.0);
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
    // The camera ray through the pixel centre (near and far plane points).
    let uv = (vec2<f32>(px) + 0.5) * frame.inv_size;
    let ndc = vec2<f32>(uv.x * 2.0 - 1.0, 1.0 - uv.y * 2.0);
    let near = frame.inv_view_proj * vec4<f32>(ndc, 0.0, 1.0);
    let far = frame.inv_view_proj * vec4<f32>(ndc, 1.0, 1.0);
    let wn = near.xyz / near.w;
    let wf = far.xyz / far.w;
    // Finest-voxel units: the volume is [0, resolution]^3.
    let o = (wn - vol.origin) / vol.voxel_size;
    var d = (wf - wn) / vol.voxel_size;
    d = normalize(d);
    // Keep the DDA away from division by zero.
    d = select(d, vec3<f32>(1e-7), abs(d) < vec3<f32>(1e-7));
    let inv_d = 1.0 / d;

    let scale = 1 << params.level;
    let res = i32(vol.resolution) >> params.level;
    let extent = f32(vol.resolution);
    var out = frame.background.rgb;
    let span = ray_box(o, inv_d, vec3<f32>(0.0), vec3<f32>(extent));
    let inside = all(o > vec3<f32>(0.0)) && all(o < vec3<f32>(extent));
    if span.x < span.y {
        // Coarse DDA in level units.
        let s = f32(scale);
        let oc = o / s;
        let inv_dc = inv_d * s;
        let p = oc + d * (span.x / s + 1e-4);
        var c = clamp(vec3<i32>(floor(p)), vec3<i32>(0), vec3<i32>(res - 1));
        let stp = vec3<i32>(sign(d));
        let next = vec3<f32>(c) + select(vec3<f32>(0.0), vec3<f32>(1.0), d > vec3<f32>(0.0));
        var t_max = (next - oc) * inv_dc;
        let t_delta = abs(inv_dc);
        var t_enter = span.x / s;
        let first = oc + d * t_enter - vec3<f32>(c);
        let edge = min(first, 1.0 - first);
        var axis = select(select(2u, 1u, edge.y <= edge.z), 0u, edge.x <= edge.y && edge.x <= edge.z);
        for (var i = 0; i < 3 * res + 3; i++) {
            let v = cell_value(c);
            let t_exit = min(t_max.x, min(t_max.y, t_max.z));
            // The cell the camera stands in is skipped: from inside, it would fill the view.
            if params.mode == MODE_NODES && v.a > 0.0 && !(i == 0 && inside) {
                out = node_colour(params.level, oc + d * t_enter, axis);
                break;
            }
            if params.mode != MODE_NODES && v.a > 0.5 {
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
            t_enter = t_exit;
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
